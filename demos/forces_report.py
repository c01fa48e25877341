#!/usr/bin/python3
"""The generated section `forces` of docs/ENERGY.md ("Under an app's forces") from demos/make_forces.sh's runs
(Debian's python3 alone, no plot): the force scenes of tests/test_stabilizer_forces.cpp in the float and the double
build, read from the `[forces] case=ID key=value ...` lines the test prints (one a scene):

  forces_report.py --run float FLOAT.txt --run double DOUBLE.txt --page docs/ENERGY.md --note NOTE

Keys: d60 and d240 the stabilizer's defaults at 60 and 240 Hz, stock the stock reference at 1 kHz, bare the bare
quaternion hinges at 60 Hz, sep the largest pivot separation of the stabilized runs (m), guard the time the 60 Hz
default run's energy guard first held the island (s; −1: never), dp a free chain's largest ‖ΔP‖ (kg·m/s). A scene
missing from a run stops the script (the test binary's filter or output changed). Cases ID-step (the app spring on two
box links against the step): d960 the defaults at 960 Hz, stock60, stock240 and stock960 stock at those steps.
"""
import argparse
import math

import readme_section  # noqa: E402  (beside this script)

# (case, scene, figure, bound the test asserts); the order of the table
ROWS = [("push", "push across a swinging 3-link chain at 1 s", "kept at 21 s, of 1.1 s", "within 15% of 1 kHz"),
        ("spring200", "app spring k = 200 N/m, hanging 2-link chain", "change over 20 s", "10%; 240 Hz ≤ half"),
        ("spring20", "app spring k = 20 N/m, pendulum, zero gravity", "change over 20 s", "10%; 240 Hz ≤ half"),
        ("gravity", "gravity g → 2g → g/2 → 0, 3-D 3-link chain, 5 s each",
         "largest change within a stretch, magnitude", "5%"),
        ("damping", "damping 0.1 (linear and angular), 3-D 3-link chain", "energy at 20 s against 1 kHz, − 1", "15%"),
        ("chain3", "conservative 3-D 3-link chain, released horizontally", "change over 20 s", "10%; 240 Hz ≤ half"),
        ("tip100", "4-link chain, 1:100 tip", "change over 20 s", "10%; 240 Hz ≤ half"),
        ("tip1000", "4-link chain, 1:1000 tip", "change over 20 s", "≤ +2%, ≥ half kept"),
        ("motor", "motor burst (4 rad/s, at most 50 N·m, 0.5 s), hanging 2-link chain",
         "change over the free swing, 1–20 s", "15%"),
        ("tumble", "free 3-link chain tumbling about (0.3, 0.5, 1.9) rad/s, zero gravity, 30 s",
         "largest ‖ΔL‖/‖L₀‖", "bare + 0.005"),
        ("tumble-momentum", "the same", "largest ‖ΔP‖ (kg·m/s)", "1e-5 kg·m/s"),
        ("spring50", "app spring k = 50 N/m, 2 links, zero gravity", "change over 20 s",
         "less lost than stock at 60, 240, 960 Hz; a 4× smaller step under half the loss (Limitations)"),
        ("spring50-nogyro", "the same, Bullet's implicit gyroscopic step off on the links", "change over 20 s",
         "10%; 240 Hz ≤ half"),
        ("kinematic", "kinematic anchor driven at 1 m/s for 1 s, then still, hanging 2-link chain",
         "energy after the stop, 1.5–2.5 s (J)", "within 3% of 1 kHz; 240 Hz closer")]
COLUMNS = [("d60", "default, 60 Hz"), ("d240", "default, 240 Hz"), ("stock", "stock, 1 kHz"), ("bare", "bare, 60 Hz")]
# The app spring on two box links against the step (cases ID-step: the default at 960 Hz, stock at the default's steps)
STEP_CASES = ["spring50", "spring50-nogyro"]
STEP_COLUMNS = [("d960", "default, 960 Hz"), ("stock60", "stock, 60 Hz"), ("stock240", "stock, 240 Hz"),
                ("stock960", "stock, 960 Hz")]


def read(path):
    """{case: {key: value}} from a test run's output."""
    found = {}
    for line in open(path):
        if line.startswith("[forces] "):
            fields = dict(f.split("=", 1) for f in line.split()[1:])
            case = fields.pop("case")
            found[case] = {k: float(v) for k, v in fields.items()}
    if "tumble" in found:
        found["tumble-momentum"] = {"d60": found["tumble"].pop("dp")}
    missing = [case for case, *_ in ROWS if case not in found] + [
        case + "-step" for case in STEP_CASES if case + "-step" not in found]
    if missing:
        raise SystemExit(f"{path}: no [forces] line for {', '.join(missing)}")
    return found


def fmt(v, case):
    """Two significant digits (a kept fraction near 1 and an energy in J: three); a small magnitude as 2.1e-6."""
    if v is None:
        return "–"
    if case == "push":
        return f"{v:.3f}"
    if case == "kinematic":
        return f"{v:.2f}"
    sign = "+" if case not in ("kinematic", "gravity", "tumble", "tumble-momentum", "sep") and v > 0 else ""
    if v != 0 and abs(v) < 1e-4:
        mantissa, exponent = f"{v:.1e}".split("e")
        text = f"{mantissa}e{int(exponent)}"
    else:
        text = f"{v:.{max(0, 1 - math.floor(math.log10(abs(v)))) if v else 1}f}"
    return sign + ("−" + text[1:] if text.startswith("-") else text)


def table(runs):
    lines = ["| case | build | scene | figure | " + " | ".join(title for _, title in COLUMNS) +
             " | max sep (m) | guard from (s) | bound (asserted) |", "|" + "---|" * (len(COLUMNS) + 7)]
    for build, found in runs:
        for case, scene, figure, bound in ROWS:
            row = found[case]
            cells = [fmt(row.get(key), case) for key, _ in COLUMNS]
            sep = fmt(row["sep"], "sep") if "sep" in row else "–"
            guard = f"{row['guard']:.2f}" if row.get("guard", -1) >= 0 else "–"
            lines.append(f"| {case} | {build} | {scene} | {figure} | " + " | ".join(cells) +
                         f" | {sep} | {guard} | {bound} |")
    return "\n".join(lines)


def step_table(runs):
    """The app spring on two box links at each step: the default's and stock's change over 20 s."""
    lines = ["| case | build | " + " | ".join(title for _, title in STEP_COLUMNS) + " |",
             "|" + "---|" * (len(STEP_COLUMNS) + 2)]
    for build, found in runs:
        for case in STEP_CASES:
            row = found[case + "-step"]
            lines.append(f"| {case} | {build} | " + " | ".join(fmt(row.get(key), case) for key, _ in STEP_COLUMNS) + " |")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--run", nargs=2, action="append", metavar=("BUILD", "OUTPUT"), required=True)
    p.add_argument("--page", default="docs/ENERGY.md")
    p.add_argument("--note", default="")
    a = p.parse_args()
    runs = [(build, read(path)) for build, path in a.run]
    steps = ("The app spring on two box links (`spring50`, with and without Bullet's implicit gyroscopic step) against "
             "the step: the change over 20 s with the stabilizer's defaults at 960 Hz and with stock at 60, 240 and "
             "960 Hz (the default's other steps and stock's 1 kHz are in the table above).")
    readme_section.replace("forces", f"{a.note}\n\n{table(runs)}\n\n{steps}\n\n{step_table(runs)}", a.page)


if __name__ == "__main__":
    main()
