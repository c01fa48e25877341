#!/usr/bin/python3
"""The issue-16 sweep as a table and a plot: the bare quaternion hinge's figures over stock btHingeConstraint's.

Reads the CSV of `quathinge-sweep` (one row per scene x basis x order x iteration count; run by demos/make_sweep.sh)
and writes, for one basis and order against `stock`:
  sweep_report.md  the ratio table (max and RMS separation per iteration count, the worst misalignment and energy
                   ratios) and Gazebo's inertia-ratio test (out-of-plane angle against its 0.21 rad bound);
  sweep.png        the same ratios as a heat map (log scale: blue where the quaternion rows do better, red worse).
With --matched (the CSV of `quathinge-sweep --matched`) the report adds the same separation and misalignment ratios
with both kinds stepped from the same states, on stock's own trajectory and on the quaternion hinge's: the rows
compared without the trajectories they lead to (docs/ROW_BASIS.md, "Matched states").
A ratio's two figures are first raised to a floor (MEASURES: 1e-5 m, 0.01 deg, 1e-3 of the energy scale), so two
runs that both hold a joint to round-off read 1.00, not a ratio of round-offs.
Uses Debian's python3-matplotlib.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# (CSV column, short name, floor in the column's unit)
MEASURES = [
    ("max_separation_m", "max sep", 1e-5),
    ("rms_separation_m", "RMS sep", 1e-5),
    ("max_misalignment_deg", "max mis", 0.01),
    ("rms_misalignment_deg", "RMS mis", 0.01),
    ("energy_drift", "energy", 1e-3),
]
# the bound set in bold: quaternion within this factor of stock
BOUND = 1.2
GAZEBO_BOUND_RAD = 0.21


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"sweep_report: {path} has no rows")
    return rows


def ratio(ours, stock, floor):
    """ours / stock with both raised to floor; None where either is not measured (negative: not applicable)."""
    if ours < 0 or stock < 0:
        return None
    return max(ours, floor) / max(stock, floor)


def fmt(r):
    if r is None:
        return "–"
    if math.isinf(r):
        return "**∞**"
    text = f"{r:.2f}"
    return f"**{text}**" if r > BOUND else text


def matched_table(rows, basis, order, scenes, within_free):
    """The matched-state ratios: per scene and trajectory (stock's, the quaternion hinge's), the worst over the
    iteration counts of the quaternion rows' figure over stock's, both stepped from the same states."""
    worst = {}  # (scene, leader, group) -> (ratio, iterations)
    floor = {col: f for col, _, f in MEASURES}
    groups = {"sep": ["max_separation_m", "rms_separation_m"], "mis": ["max_misalignment_deg", "rms_misalignment_deg"]}
    blown = set()
    for r in rows:
        if r["basis"] != basis or r["order"] != order or r["skipped"]:
            continue
        if r["blew_up"] != "0":
            blown.add((r["scene"], r["leader"]))
            continue
        for group, cols in groups.items():
            for col in cols:
                value = ratio(float(r["quaternion_" + col]), float(r["stock_" + col]), floor[col])
                key = (r["scene"], r["leader"], group)
                if key not in worst or value > worst[key][0]:
                    worst[key] = (value, int(r["iterations"]))
    if not worst:
        sys.exit(f"sweep_report: the matched CSV has no runs of basis {basis!r} with order {order!r}")

    def cell(s, leader, group):
        if (s, leader) in blown:
            return "blew up"
        w = worst.get((s, leader, group))
        return "–" if w is None else f"{fmt(w[0])} ({w[1]})"

    lines = [
        "Matched states: before every step, the following kind's bodies are set to the leading kind's state, both "
        "step once, and both joints' errors are measured; so the two sets of rows are compared from the same states, "
        "without the trajectories they lead to. Worst ratio (quaternion over stock, max or RMS, floored as above) over "
        "the iteration counts, at the count in brackets. Each step inherits the leading run's error, so a difference "
        "that builds up over many steps shows here only in part (docs/ROW_BASIS.md, \"Matched states\"):",
        "",
        "| scene | separation, on stock's states | separation, on the quaternion hinge's | "
        "misalignment, on stock's | misalignment, on the quaternion hinge's |",
        "|---|---|---|---|---|",
    ]
    within = []
    for s in scenes:
        if not any((s, leader, "sep") in worst for leader in ("stock", "quaternion")):
            continue
        lines.append(f"| {s} | {cell(s, 'stock', 'sep')} | {cell(s, 'quaternion', 'sep')} | "
                     f"{cell(s, 'stock', 'mis')} | {cell(s, 'quaternion', 'mis')} |")
        seps = [worst[(s, leader, "sep")][0] for leader in ("stock", "quaternion") if (s, leader, "sep") in worst]
        if seps and max(seps) <= BOUND and not any((s, leader) in blown for leader in ("stock", "quaternion")):
            within.append(s)
    measured = sum(1 for s in scenes if (s, "stock", "sep") in worst or (s, "quaternion", "sep") in worst)
    newly = [s for s in within if s not in within_free]
    lines += [
        "",
        f"From the same states the quaternion rows separate within {BOUND} × of stock's on {len(within)} of "
        f"{measured} scenes, on both trajectories"
        + (f" (among them {', '.join(newly)}, above it in the free runs)" if newly else "") + ".",
    ]
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--basis", default="radial")
    ap.add_argument("--order", default="point-first")
    ap.add_argument("--out", default=".")
    ap.add_argument("--note", default="", help="a line that says where and when the sweep ran")
    ap.add_argument("--matched", help="the CSV of quathinge-sweep --matched (same basis and order)")
    args = ap.parse_args()

    rows = load(args.csv)
    scenes, iterations = [], set()
    runs = {}
    for r in rows:
        if r["basis"] not in ("stock", args.basis) or (r["basis"] != "stock" and r["order"] != args.order):
            continue
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
        it = int(r["iterations"])
        iterations.add(it)
        runs[(r["scene"], r["basis"], it)] = r
    iterations = sorted(iterations)
    if not scenes:
        sys.exit(f"sweep_report: no runs of basis {args.basis!r} with order {args.order!r} in {args.csv}")

    # ratios[scene][measure][iteration] (inf where ours blew up and stock's did not)
    ratios = {}
    for s in scenes:
        ratios[s] = {}
        for col, _, floor in MEASURES:
            ratios[s][col] = {}
            for it in iterations:
                ours, stock = runs.get((s, args.basis, it)), runs.get((s, "stock", it))
                if ours is None or stock is None:
                    sys.exit(f"sweep_report: {s} at {it} iterations lacks its stock or {args.basis} run")
                if ours["blew_up"] != "0" or stock["blew_up"] != "0":
                    r = math.inf if ours["blew_up"] != "0" and stock["blew_up"] == "0" else None
                else:
                    r = ratio(float(ours[col]), float(stock[col]), floor)
                ratios[s][col][it] = r

    def worst(s, cols):
        values = [ratios[s][c][it] for c in cols for it in iterations if ratios[s][c][it] is not None]
        return max(values) if values else None

    sep = ["max_separation_m", "rms_separation_m"]
    mis = ["max_misalignment_deg", "rms_misalignment_deg"]
    its = " / ".join(str(i) for i in iterations)
    lines = []
    if args.note:
        lines += [args.note, ""]
    lines += [
        f"Bare `btQuaternionHingeConstraint` (rows: `{args.basis}`, {args.order}) over stock `btHingeConstraint` in the "
        f"same scene, step and iteration count; each figure is raised to a floor first (separation 1e-5 m, "
        f"misalignment 0.01°, energy drift 1e-3 of the scene's energy scale), so round-off against round-off reads "
        f"1.00. **Bold**: above {BOUND} ×. *energy*: conservative scenes only.",
        "",
        f"| scene | max separation, {its} it | RMS separation, {its} it | misalignment (worst, max or RMS) "
        f"| energy drift (worst) |",
        "|---|---|---|---|---|",
    ]
    within, above = [], []
    for s in scenes:
        maxsep = " ".join(fmt(ratios[s]["max_separation_m"][it]) for it in iterations)
        rmssep = " ".join(fmt(ratios[s]["rms_separation_m"][it]) for it in iterations)
        lines.append(f"| {s} | {maxsep} | {rmssep} | {fmt(worst(s, mis))} | {fmt(worst(s, ['energy_drift']))} |")
        w = worst(s, sep)
        if w is not None and w <= BOUND:
            within.append(s)
        else:
            where = max(((ratios[s][c][it], c, it) for c in sep for it in iterations
                         if ratios[s][c][it] is not None), key=lambda t: t[0])
            above.append(f"{s} {where[0]:.2f} ({where[1].split('_')[0]} separation at {where[2]} it)")
    lines += [
        "",
        f"Within {BOUND} × of stock in max and RMS separation at every iteration count: {len(within)} of "
        f"{len(scenes)} scenes. Above: " + ("; ".join(above) if above else "none") + ".",
    ]
    oop = [(it, float(runs[("inertia_ratio", "stock", it)]["max_out_of_plane_rad"]),
            float(runs[("inertia_ratio", args.basis, it)]["max_out_of_plane_rad"]))
           for it in iterations if ("inertia_ratio", "stock", it) in runs]
    if oop:
        lines += [
            "",
            f"Gazebo's inertia-ratio test (scene `inertia_ratio`: largest out-of-plane angle of either link over 3 s, "
            f"rad; Gazebo's bound {GAZEBO_BOUND_RAD} at its 250 iterations):",
            "",
            "| iterations | " + " | ".join(str(it) for it, _, _ in oop) + " |",
            "|---|" + "---|" * len(oop),
            "| stock | " + " | ".join(f"{st:.3f}" for _, st, _ in oop) + " |",
            "| quaternion | " + " | ".join(f"{q:.3f}" for _, _, q in oop) + " |",
        ]
    if args.matched:
        lines += [""] + matched_table(load(args.matched), args.basis, args.order, scenes, within)
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "sweep_report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")

    # the heat map: scenes down, measure x iterations across, log2 of the ratio
    cols = [(c, name, it) for c, name, _ in MEASURES for it in iterations]
    grid = [[ratios[s][c][it] for c, _, it in cols] for s in scenes]
    values = [[math.log2(r) if r is not None and not math.isinf(r) else (3.0 if r else math.nan) for r in row]
              for row in grid]
    fig, ax = plt.subplots(figsize=(1.0 + 0.42 * len(cols), 1.2 + 0.3 * len(scenes)))
    cmap = matplotlib.colormaps["RdBu_r"].copy()
    cmap.set_bad("#dddddd")
    image = ax.imshow(values, cmap=cmap, vmin=-2, vmax=2, aspect="auto")
    for i, row in enumerate(grid):
        for j, r in enumerate(row):
            if r is None:
                continue
            text = "∞" if math.isinf(r) else (f"{r:.2f}" if r < 10 else f"{r:.0f}")
            ax.text(j, i, text, ha="center", va="center", fontsize=5.5,
                    color="white" if abs(values[i][j]) > 1.3 else "black",
                    fontweight="bold" if r > BOUND else "normal")
    ax.set_yticks(range(len(scenes)), scenes, fontsize=7)
    ax.set_xticks(range(len(cols)), [str(it) for _, _, it in cols], fontsize=6)
    for k, (_, name, _) in enumerate(MEASURES):
        ax.text(k * len(iterations) + (len(iterations) - 1) / 2, -0.7, name, ha="center", va="bottom", fontsize=8)
        if k:
            ax.axvline(k * len(iterations) - 0.5, color="black", linewidth=0.8)
    ax.set_xlabel("solver iterations")
    ax.set_title("bare quaternion hinge over stock btHingeConstraint (grey: not measured)", pad=22, fontsize=9)
    bar = fig.colorbar(image, ax=ax, fraction=0.03, pad=0.01, ticks=[-2, -1, 0, 1, 2])
    bar.ax.set_yticklabels(["0.25×", "0.5×", "1×", "2×", "4×"], fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "sweep.png"), dpi=110)
    print(f"sweep_report: {len(within)} of {len(scenes)} scenes within {BOUND} × in separation", file=sys.stderr)


if __name__ == "__main__":
    main()
