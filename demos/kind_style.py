"""One colour and marker per joint kind, shared by every plot of the reports (plot_report.py, plot_peers.py)."""

KIND_STYLE = {
    "stock": ("tab:red", "o"),
    "stock+mlcp": ("darkred", "P"),
    "stock+nncg": ("salmon", "X"),
    "6dof2": ("tab:orange", "s"),
    "quaternion": ("tab:blue", "^"),
    "quaternion+mlcp": ("navy", "<"),
    "quaternion+nncg": ("deepskyblue", ">"),
    "quaternion+stab": ("tab:green", "D"),
    "stock+stab": ("tab:brown", "h"),
    "6dof2+stab": ("tab:olive", "8"),
    "multibody": ("tab:purple", "v"),
    "multibody-damped": ("violet", "*"),
}
