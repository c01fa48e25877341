#!/usr/bin/python3
"""Plots and the results table (docs/RESULTS.md) from quathinge-compare's JSON (Debian's python3-matplotlib only).

  plot_report.py --sweep SWEEP.json --series SERIES.json --table TABLE.json --images DIR
                 [--markdown demos/out/results.md] [--readme docs/RESULTS.md]

- error against run time: one panel per scene, log-log, run time per simulated second (the run's own thread CPU
  time, so other load on the machine does not move the points; wall time for JSON written before it was recorded)
  against the maximum joint separation, each kind's runs as points and its Pareto front as a line (sweep over step
  and iterations);
- drift and energy over time for each kind (series);
- the results table (TABLE.json, one run per scene × kind) as Markdown into --markdown, and into the page given (docs/RESULTS.md) between the
  markers <!-- results:begin --> and <!-- results:end --> when --readme is given (no figure in the manual is typed by
  hand).
Any of --sweep, --series, --table may be left out: that plot or table is then not made.
"""
import argparse
import json
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import readme_section  # noqa: E402  (beside this script)

from kind_style import KIND_STYLE  # noqa: E402  (beside this script)


def load(path):
    with open(path) as f:
        return [r for r in json.load(f)["runs"] if not r["skipped"]]


def pareto(points):
    """Points (time, error) that no other point beats on both; sorted by time."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def run_time(r):
    """Seconds of run time per simulated second: thread CPU time where recorded, else wall time."""
    return r.get("cpu_per_sim_s", r["wall_per_sim_s"])


def floor(v):
    return max(v, 1e-12)  # log axes: an exact zero shows at the bottom


def plot_sweep(runs, out):
    scenes = sorted({r["scene"] for r in runs}, key=lambda s: [r["scene"] for r in runs].index(s))
    cols = min(3, len(scenes))
    rows = math.ceil(len(scenes) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 4 * rows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        for kind, (color, marker) in KIND_STYLE.items():
            pts = [(run_time(r), floor(r["max_separation_m"]), r) for r in runs
                   if r["scene"] == scene and r["kind"] == kind and not r["blew_up"]]
            if not pts:
                continue
            ax.scatter([p[0] for p in pts], [p[1] for p in pts], color=color, marker=marker, s=14, alpha=0.5)
            front = pareto([(p[0], p[1]) for p in pts])
            ax.plot([p[0] for p in front], [p[1] for p in front], color=color, label=kind)
            blown = [r for r in runs if r["scene"] == scene and r["kind"] == kind and r["blew_up"]]
            if blown:
                ax.scatter([run_time(r) for r in blown], [1e1] * len(blown), color=color, marker="x")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(scene)
        ax.set_xlabel("CPU time per simulated second (s)")
        ax.set_ylabel("max joint separation (m)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.suptitle("Error against run time (sweep over step and iterations; line: Pareto front; x: blew up)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "error_vs_time.png"), dpi=80)
    plt.close(fig)


def plot_series(runs, out):
    scenes = sorted({r["scene"] for r in runs if "series" in r}, key=lambda s: [r["scene"] for r in runs].index(s))
    fig, axes = plt.subplots(len(scenes), 2, figsize=(11, 3.2 * len(scenes)), squeeze=False)
    for row, scene in enumerate(scenes):
        for r in runs:
            if r["scene"] != scene or "series" not in r:
                continue
            color = KIND_STYLE.get(r["kind"], ("k", "."))[0]
            label = r["kind"] + (f" (blew up at {r['blow_up_time_s']:.2f} s)" if r["blew_up"] else "")
            t = [p[0] for p in r["series"]]
            axes[row][0].plot(t, [floor(p[1]) for p in r["series"]], color=color, label=label, lw=1)
            e0 = r["series"][0][3]
            axes[row][1].plot(t, [p[3] - e0 for p in r["series"]], color=color, label=label, lw=1)
        # energy axis: the range of the runs that did not blow up (a runaway would flatten every other curve)
        kept = [p[3] - r["series"][0][3] for r in runs if r["scene"] == scene and "series" in r and not r["blew_up"]
                for p in r["series"]]
        if kept and min(kept) < max(kept):
            pad = 0.1 * (max(kept) - min(kept))
            axes[row][1].set_ylim(min(kept) - pad, max(kept) + pad)
        axes[row][0].set_yscale("log")
        axes[row][0].set_ylabel("max separation (m)")
        axes[row][0].set_title(f"{scene}: joint drift")
        axes[row][1].set_ylabel("E(t) − E(0) (J)")
        axes[row][1].set_title(f"{scene}: energy")
        for ax in axes[row]:
            ax.set_xlabel("t (s)")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "drift_energy.png"), dpi=80)
    plt.close(fig)


def fmt(v, spec=".1e"):
    return "–" if v is None or v < 0 else format(v, spec)


def table(runs):
    lines = [
        "| scene | kind | max sep (m) | max mis (°) | recovery (s) | limit past (rad) | final θ (rad) | energy drift | traj. error | blow-up (s) | CPU ms / sim-s | rows |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in runs:
        lines.append("| {} | {} | {} | {} | {} | {} | {:.3g} | {} | {} | {} | {:.2f} | {:.1f} |".format(
            r["scene"], r["kind"], fmt(r["max_separation_m"]), fmt(r["max_misalignment_deg"], ".2g"),
            fmt(r["recovery_time_s"], ".3f"), fmt(r["limit_violation_rad"]), r["final_theta_rad"],
            fmt(r["energy_drift"], ".2g"),
            fmt(r["trajectory_error"]), fmt(r["blow_up_time_s"], ".2f") if r["blew_up"] else "–",
            1e3 * run_time(r), r["rows_per_step"]))
    return "\n".join(lines)


GLANCE = [("chain30", "chain30 (30 links)"), ("heavy1000", "heavy1000 (1:1000 load)"), ("ragdoll", "ragdoll"),
          ("panda", "panda (robot arm)")]
GLANCE_KINDS = [("stock", "stock"), ("quaternion", "quaternion"), ("quaternion+stab", "quaternion + stabilizer"),
                ("stock+stab", "stock + stabilizer"), ("multibody", "btMultiBody (damping 0)")]


def glance(runs):
    """The front page's table (README.md, the glance markers): a few scenes' largest separation per kind, and the
    flipped start's recovery time, from the same runs as the results table."""
    at = {(r["scene"], r["kind"]): r for r in runs}
    lines = ["| scene | " + " | ".join(label for _, label in GLANCE_KINDS) + " |", "|" + "---|" * (1 + len(GLANCE_KINDS))]
    for scene, label in GLANCE:
        cells = []
        for kind, _ in GLANCE_KINDS:
            r = at.get((scene, kind))
            if r is None:
                cells.append("–")
                continue
            cell = fmt(r["max_separation_m"], ".2g")
            if r["blew_up"]:
                cell += f", blows up at {r['blow_up_time_s']:.2g} s"
            cells.append(cell)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    cells = [fmt(at[("flipped180", k)]["recovery_time_s"], ".2g") if ("flipped180", k) in at else "–"
             for k, _ in GLANCE_KINDS]
    lines.append("| flipped180, recovery (s) | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sweep", help="quathinge-compare JSON of a --sweep-dt/--sweep-iterations run")
    p.add_argument("--series", help="quathinge-compare JSON of a --series run")
    p.add_argument("--table", help="quathinge-compare JSON, one run per scene x kind")
    p.add_argument("--images", default="demos/out", help="directory for the PNGs (default demos/out)")
    p.add_argument("--markdown", default="demos/out/results.md", help="the results table as Markdown")
    p.add_argument("--readme", help="manual page to write the table into, between the results markers (docs/RESULTS.md)")
    p.add_argument("--front", help="front page to write the glance table into, between the glance markers (README.md)")
    p.add_argument("--note", default="", help="one line said above the table (machine, command)")
    a = p.parse_args()
    os.makedirs(a.images, exist_ok=True)
    wrote = []
    if a.sweep:
        plot_sweep(load(a.sweep), a.images)
        wrote.append(os.path.join(a.images, "error_vs_time.png"))
    if a.series:
        plot_series(load(a.series), a.images)
        wrote.append(os.path.join(a.images, "drift_energy.png"))
    if not a.table:
        print("wrote " + ", ".join(wrote))
        return
    md = table(load(a.table))
    os.makedirs(os.path.dirname(a.markdown) or ".", exist_ok=True)
    with open(a.markdown, "w") as f:
        f.write(md + "\n")
    wrote.append(a.markdown)
    if a.readme:
        readme_section.replace("results", f"{a.note}\n\n{md}", a.readme)
        wrote.append(a.readme)
    if a.front:
        readme_section.replace("glance", glance(load(a.table)), a.front)
        wrote.append(a.front)
    print("wrote " + ", ".join(wrote))


if __name__ == "__main__":
    main()
