#!/usr/bin/python3
"""The peers report (docs/PEERS.md) from demos/make_peers.sh's runs (Debian's python3-matplotlib only).

  plot_peers.py --references REFS.csv --grid GRID.json [GRID.json ...] --images DIR --results docs/RESULTS.md
                --peers docs/PEERS.md [--note TEXT]

- docs/images/peers_pareto.png: per scene, the trajectory error against the common reference (left) and the maximum
  joint separation (right) against run time (thread CPU time per simulated second), every kind's runs over step and
  iterations as points, its Pareto front as a line, blown-up runs as crosses at the top;
- the choice table (docs/RESULTS.md, peers markers): per scene, the cheapest run within each separation and
  trajectory-error bound;
- docs/PEERS.md's generated sections: the references (peers-references), what each peer does on its own terms
  (peers-own: MLCP fallbacks, multibody blow-ups, damping's energy).
"""
import argparse
import csv
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import readme_section  # noqa: E402  (beside this script)

from kind_style import KIND_STYLE  # noqa: E402  (beside this script)
from plot_report import pareto  # noqa: E402  (the same front as the report's plots)
CLASS = {"pendulum": "one joint", "double_pendulum": "chain", "chain10": "chain", "chain30": "chain",
         "heavy100": "mass ratio 1:100", "four_bar": "closed loop", "kuka_iiwa": "robot (URDF)"}
SEPARATION_BOUNDS = [1e-2, 1e-3, 1e-4]  # m
TRAJECTORY_BOUNDS = [1e-1, 1e-2, 1e-3]  # m


def load(paths):
    runs = []
    for path in paths:
        with open(path) as f:
            runs += [r for r in json.load(f)["runs"] if not r["skipped"]]
    return runs


def skipped(paths):
    out = []
    for path in paths:
        with open(path) as f:
            out += [r for r in json.load(f)["runs"] if r["skipped"]]
    return out


def hz(r):
    return round(1 / r["dt"])


def setting(r):
    return f"{r['kind']} {hz(r)} Hz {r['iterations']} it"


def plot(runs, scenes, out):
    fig, axes = plt.subplots(len(scenes), 2, figsize=(12, 3.4 * len(scenes)), squeeze=False)
    for row, scene in enumerate(scenes):
        for col, (key, label) in enumerate([("reference_error_m", "trajectory error (m)"),
                                            ("max_separation_m", "max joint separation (m)")]):
            ax = axes[row][col]
            for kind, (color, marker) in KIND_STYLE.items():
                mine = [r for r in runs if r["scene"] == scene and r["kind"] == kind]
                pts = [(r["cpu_per_sim_s"], max(r[key], 1e-12)) for r in mine if not r["blew_up"] and r[key] >= 0]
                if pts:
                    ax.scatter([p[0] for p in pts], [p[1] for p in pts], color=color, marker=marker, s=12, alpha=0.45)
                    front = pareto(pts)
                    ax.plot([p[0] for p in front], [p[1] for p in front], color=color, label=kind, lw=1.2)
                blown = [r for r in mine if r["blew_up"]]
                if blown:
                    ax.scatter([r["cpu_per_sim_s"] for r in blown], [10.0] * len(blown), color=color, marker="x")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"{scene}: {label.split(' (')[0]}")
            ax.set_xlabel("CPU s per simulated s")
            ax.set_ylabel(label)
            ax.grid(True, which="both", alpha=0.3)
            if row == 0 and col == 0:
                ax.legend(fontsize=6, ncol=2)
    fig.suptitle("Peers: error against run time over 60-480 Hz and iterations (line: Pareto front; x at 10: blew up)")
    fig.tight_layout(rect=(0, 0, 1, 0.985))
    fig.savefig(os.path.join(out, "peers_pareto.png"), dpi=70)
    plt.close(fig)


def cheapest(runs, scene, key, bound):
    ok = [r for r in runs if r["scene"] == scene and not r["blew_up"] and 0 <= r[key] <= bound]
    return min(ok, key=lambda r: r["cpu_per_sim_s"]) if ok else None


def cell(r):
    return "none in the grid" if r is None else f"{setting(r)} ({1e3 * r['cpu_per_sim_s']:.2g} ms)"


def choice_table(runs, scenes):
    lines = ["| class | scene | criterion | bound (m) | cheapest run (CPU ms / sim-s) | cheapest quaternion+stab |",
             "|---|---|---|---|---|---|"]
    for scene in scenes:
        for key, name, bounds in [("max_separation_m", "separation", SEPARATION_BOUNDS),
                                  ("reference_error_m", "trajectory error", TRAJECTORY_BOUNDS)]:
            for bound in bounds:
                best = cheapest(runs, scene, key, bound)
                stab = cheapest([r for r in runs if r["kind"] == "quaternion+stab"], scene, key, bound)
                lines.append(f"| {CLASS.get(scene, '')} | {scene} | {name} | {bound:g} | {cell(best)} | {cell(stab)} |")
    return "\n".join(lines)


def front_summary(runs, scenes):
    """Per scene and kind: the least trajectory error and separation reached, and at what cost."""
    lines = ["| scene | kind | least traj. error (m) | at | least max sep (m) | at | energy drift range |",
             "|---|---|---|---|---|---|---|"]
    for scene in scenes:
        for kind in KIND_STYLE:
            mine = [r for r in runs if r["scene"] == scene and r["kind"] == kind and not r["blew_up"]]
            if not mine:
                continue
            te = [r for r in mine if r["reference_error_m"] >= 0]
            bt = min(te, key=lambda r: r["reference_error_m"]) if te else None
            bs = min(mine, key=lambda r: r["max_separation_m"])
            ed = [r["energy_drift"] for r in mine if r["energy_drift"] >= 0]
            lines.append("| {} | {} | {} | {} | {:.2g} | {} | {} |".format(
                scene, kind, f"{bt['reference_error_m']:.2g}" if bt else "–",
                f"{hz(bt)} Hz {bt['iterations']} it, {1e3 * bt['cpu_per_sim_s']:.2g} ms" if bt else "–",
                bs["max_separation_m"], f"{hz(bs)} Hz {bs['iterations']} it, {1e3 * bs['cpu_per_sim_s']:.2g} ms",
                f"{min(ed):.2g} – {max(ed):.2g}" if ed else "–"))
    return "\n".join(lines)


def median(values):
    values = sorted(values)
    return values[len(values) // 2] if values else None


def own_terms(runs, skips):
    lines = []
    mlcp = [r for r in runs if r.get("mlcp_fallbacks", -1) >= 0]
    if mlcp:
        lines += ["MLCP (btMLCPSolver + btDantzigSolver): the solves Dantzig failed and sequential impulse redid "
                  "(btMLCPSolver::getNumFallbacks), summed over the grid, and the cost of the direct solve: median CPU "
                  "time per simulated second at 60 Hz over the iteration counts, against stock's (sequential impulse) "
                  "in the same grid.", "",
                  "| scene | kind | rows | fallbacks / steps | CPU ms / sim-s at 60 Hz | stock's | ratio |",
                  "|---|---|---|---|---|---|---|"]
        for scene in sorted({r["scene"] for r in mlcp}, key=[r["scene"] for r in mlcp].index):
            stock = median([1e3 * r["cpu_per_sim_s"] for r in runs
                            if r["scene"] == scene and r["kind"] == "stock" and hz(r) == 60])
            for kind in ("stock+mlcp", "quaternion+mlcp"):
                mine = [r for r in mlcp if r["scene"] == scene and r["kind"] == kind]
                if not mine:
                    continue
                at60 = median([1e3 * r["cpu_per_sim_s"] for r in mine if hz(r) == 60])
                lines.append(f"| {scene} | {kind} | {median([r['rows_per_step'] for r in mine]):.0f} | "
                             f"{sum(r['mlcp_fallbacks'] for r in mine)} / {sum(r['steps'] for r in mine)} | "
                             f"{at60:.3g} | {stock:.3g} | {at60 / stock:.1f} |")
        lines.append("")
    lines += ["Blow-ups over the grid (a non-finite or far-flung state, or energy above its start by 10x the energy "
              "scale), per scene and kind: runs that blew up of the 12, and the earliest and latest time:", "",
              "| scene | kind | blew up | at (s) |", "|---|---|---|---|"]
    blown = [r for r in runs if r["blew_up"]]
    for scene in list(dict.fromkeys(r["scene"] for r in blown)):
        for kind in KIND_STYLE:
            mine = [r for r in blown if r["scene"] == scene and r["kind"] == kind]
            if not mine:
                continue
            total = sum(1 for r in runs if r["scene"] == scene and r["kind"] == kind)
            steps = sorted({hz(r) for r in mine})
            t = [r["blow_up_time_s"] for r in mine]
            lines.append(f"| {scene} | {kind} | {len(mine)} of {total} ({', '.join(map(str, steps))} Hz) | "
                         f"{min(t):.2f} – {max(t):.2f} |")
    quiet = [k for k in KIND_STYLE if any(r["kind"] == k for r in runs) and not any(r["kind"] == k for r in blown)]
    lines += ["", "No blow-up in the grid: " + ", ".join(quiet) + ".", ""]
    cap = sorted({(r["scene"], r["kind"], r["skipped"]) for r in skips})
    if cap:
        lines.append("Not run:")
        lines += [f"- {s} {k}: {why}" for s, k, why in cap]
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--references", required=True, help="quathinge-compare --write-reference's CSV")
    p.add_argument("--grid", nargs="+", required=True, help="quathinge-compare JSON of the step x iterations runs")
    p.add_argument("--images", default="docs/images")
    p.add_argument("--results", help="docs/RESULTS.md: the choice table and plot between the peers markers")
    p.add_argument("--peers", help="docs/PEERS.md: its generated sections")
    p.add_argument("--note", default="")
    a = p.parse_args()
    runs = load(a.grid)
    scenes = list(dict.fromkeys(r["scene"] for r in runs))
    os.makedirs(a.images, exist_ok=True)
    plot(runs, scenes, a.images)
    with open(a.references) as f:
        refs = list(csv.DictReader(f))
    ref_lines = ["| scene | reference kind | precision | step (s) | iterations | halving change over the horizon (m) | "
                 "halving change past 1e-4 m at (s) | 1e-9 kick grows past 1e-6 m at (s) | horizon (s) |",
                 "|---|---|---|---|---|---|---|---|---|"]

    def when(v):
        return "not within 3 s" if float(v) < 0 else f"{float(v):.3g}"
    for r in sorted(refs, key=lambda r: scenes.index(r["scene"]) if r["scene"] in scenes else 99):
        ref_lines.append(f"| {r['scene']} | {r['kind']} | {r['precision']} | {float(r['step_s']):.3g} | {r['iterations']} | "
                         f"{float(r['halving_change_m']):.2g} | {when(r['halving_time_s'])} | "
                         f"{when(r['divergence_time_s'])} | {float(r['horizon_s']):.3g} |")
    table = choice_table(runs, scenes)
    summary = front_summary(runs, scenes)
    print(table)
    if a.results:
        readme_section.replace("peers", f"{a.note}\n\n{table}\n\n![peers](images/peers_pareto.png)", a.results)
    if a.peers:
        readme_section.replace("peers-references", "\n".join(ref_lines), a.peers)
        readme_section.replace("peers-fronts", f"{a.note}\n\n{summary}", a.peers)
        readme_section.replace("peers-own", own_terms(runs, skipped(a.grid)), a.peers)


if __name__ == "__main__":
    main()
