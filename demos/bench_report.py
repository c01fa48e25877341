#!/usr/bin/python3
"""Turns quathinge-bench's JSON into the ratio table (Markdown) and the scaling plot (PNG).

    /usr/bin/python3 demos/bench_report.py bench.json --out demos/out/bench [--command "..."] [--machine machine.txt]

The JSON comes from a run with --benchmark_repetitions=N --benchmark_report_aggregates_only=true; every figure here
is the median of the N repetitions (CPU time). Ratios are against stock in the same run: kind time / stock time for
the same benchmark (joint/<angle>/<config>, step/<scene>). Writes bench_report.md and scaling.png into --out and
prints the Markdown. Python 3 and Debian's python3-matplotlib only.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

KINDS = ["stock", "6dof2", "quaternion", "quaternion+stab", "multibody"]
UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def load(path):
    """{(benchmark, kind): {"median": ns, "cv": fraction or None, "counters": {...}}} and the run's context."""
    with open(path) as f:
        data = json.load(f)
    rows = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") != "aggregate" or b.get("error_occurred"):
            continue
        name = re.sub(r"/(iterations|repeats|min_time):[^/]+", "", b["run_name"])
        group, _, kind = name.rpartition("/")
        entry = rows.setdefault((group, kind), {"counters": {}})
        agg = b["aggregate_name"]
        scale = UNIT_NS[b.get("time_unit", "ns")]
        if agg == "median":
            entry["median"] = b["cpu_time"] * scale
            for key in ("rows", "joints", "contacts", "stab_newton", "stab_factorizations", "stab_islands",
                        "stab_limit_rows", "stab_contact_rows"):
                if key in b:
                    entry["counters"][key] = b[key]
        elif agg == "min":
            entry["min"] = b["cpu_time"] * scale
        elif agg == "cv":
            entry["cv"] = b["cpu_time"]  # cv aggregates are fractions, reported without a unit
    errors = sorted({re.sub(r"/(iterations|repeats|min_time):[^/]+", "", b["run_name"]) + ": " + b.get("error_message", "")
                     for b in data.get("benchmarks", []) if b.get("error_occurred")})
    return {k: v for k, v in rows.items() if "median" in v}, data.get("context", {}), errors


def fmt_time(ns):
    if ns >= 1e6:
        return f"{ns / 1e6:.2f} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.1f} µs"
    return f"{ns:.0f} ns"


def fmt_ratio(r):
    return "–" if r is None else f"{r:.2f}"


def machine_line(machine_file):
    text = ""
    if machine_file and os.path.exists(machine_file):
        with open(machine_file) as f:
            text = f.read()
    else:
        try:
            text = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
        except OSError:
            text = ""
    model = re.search(r"^Model name:\s*(.+)$", text, re.M)
    cpus = re.search(r"^CPU\(s\):\s*(\d+)$", text, re.M)
    return (model.group(1).strip() if model else "unknown CPU") + ", " + (cpus.group(1) + " cores" if cpus else "? cores")


JOINT_CONFIGS = ["free", "limit_inside", "limit_active", "motor", "limit_active+motor"]


def group_key(rows, group):
    """joint/<angle>/<config>: by angle, then the configurations in the benchmark's order; step/<scene>: chains by size,
    then the rest by joints."""
    parts = group.split("/")
    if parts[0] == "joint" and len(parts) == 3:
        config = JOINT_CONFIGS.index(parts[2]) if parts[2] in JOINT_CONFIGS else len(JOINT_CONFIGS)
        return (0, parts[1], config, parts[2])
    joints = max((v["counters"].get("joints", 0) for (g, _k), v in rows.items() if g == group), default=0)
    return (1, 0 if re.match(r"step/chain\d+$", group) else 1, joints, group)


def groups_of(rows, prefix):
    seen = sorted({group for (group, _kind) in rows if group.startswith(prefix)}, key=lambda g: group_key(rows, g))
    return seen


def ratio(rows, group, kind, stat="median"):
    if (group, kind) not in rows or (group, "stock") not in rows:
        return None
    a, b = rows[(group, kind)].get(stat), rows[(group, "stock")].get(stat)
    return a / b if a and b else None


def min_ratios(rows, groups, kind):
    """The same ratios from the fastest repetitions (less sensitive to other work on the machine), if reported."""
    values = [(g, ratio(rows, g, kind, "min")) for g in groups]
    values = [f"{g.split('/', 1)[1]} {r:.2f}" for g, r in values if r is not None]
    return f" (from the fastest repetitions: {', '.join(values)})" if values else ""


def geomean(values):
    values = [v for v in values if v is not None]
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else None


def slope(points):
    """Least-squares slope of log t against log n."""
    if len(points) < 2:
        return None
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx else None


def table(rows, groups, with_stab):
    lines = []
    head = "| benchmark | stock (median) | 6dof2 / stock | quaternion / stock |"
    sep = "|---|---|---|---|"
    if with_stab:
        head += " quaternion+stab / stock | multibody / stock |"
        sep += "---|---|"
    head += " rows (stock, 6dof2, quaternion) | max cv |"
    sep += "---|---|"
    lines += [head, sep]
    for g in groups:
        if (g, "stock") not in rows:
            continue
        cells = [g, fmt_time(rows[(g, "stock")]["median"]), fmt_ratio(ratio(rows, g, "6dof2")),
                 fmt_ratio(ratio(rows, g, "quaternion"))]
        if with_stab:
            cells.append(fmt_ratio(ratio(rows, g, "quaternion+stab")))
            cells.append(fmt_ratio(ratio(rows, g, "multibody")))
        counts = [rows[(g, k)]["counters"].get("rows") for k in ("stock", "6dof2", "quaternion") if (g, k) in rows]
        cells.append(", ".join("?" if c is None else f"{c:.0f}" for c in counts))
        cvs = [rows[(g, k)].get("cv") for k in KINDS if (g, k) in rows and rows[(g, k)].get("cv") is not None]
        cells.append(f"{100 * max(cvs):.1f}%" if cvs else "–")
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", help="quathinge-bench --benchmark_format=json output (with repetitions, aggregates only)")
    ap.add_argument("--out", default="demos/out/bench", help="directory for bench_report.md and scaling.png")
    ap.add_argument("--command", default=None, help="the command that produced the JSON (printed in the report)")
    ap.add_argument("--machine", default=None, help="saved lscpu output (default: run lscpu now)")
    ap.add_argument("--revision", default=None, help="source revision the benchmark was built from")
    args = ap.parse_args()

    rows, context, errors = load(args.json)
    if not rows:
        sys.exit(f"{args.json}: no median aggregates (run with --benchmark_repetitions=N "
                 "--benchmark_report_aggregates_only=true)")
    os.makedirs(args.out, exist_ok=True)
    joint_groups = groups_of(rows, "joint/")
    step_groups = groups_of(rows, "step/")

    md = ["# quathinge-bench: the quaternion hinge against the stock hinge", ""]
    md.append(f"Machine: {machine_line(args.machine)}; load average at the start "
              f"{', '.join(f'{x:.2f}' for x in context.get('load_avg', [])) or '?'}; {context.get('date', '')}.")
    if args.revision:
        md.append(f"Source: {args.revision}.")
    md.append(f"Command: `{args.command or ' '.join(context.get('executable', '?').split())}`")
    md.append("")
    md.append("Medians of the repetitions (CPU time); a ratio is the kind's median over stock's in the same run. "
              "*max cv*: the largest coefficient of variation of the repetitions among the kinds of that row "
              "(the noise of a shared machine).")
    if context.get("library_build_type") == "debug":
        md.append("(Google Benchmark reports its own library as a debug build — Debian builds it without NDEBUG; "
                  "the timed code is this project's Release build.)")
    md.append("")

    # 1. per joint
    md.append("## getInfo1 + getInfo2 per joint")
    md.append("")
    md += table(rows, joint_groups, with_stab=False)
    md.append("")
    # 2. full steps
    md.append("## A full world step (60 Hz, 10 iterations)")
    md.append("")
    md += table(rows, step_groups, with_stab=True)
    md.append("")

    # 3. scaling
    chains = [g for g in step_groups if re.match(r"step/chain\d+$", g)]
    chains.sort(key=lambda g: rows[(g, "stock")]["counters"].get("joints", 0) if (g, "stock") in rows else 0)
    md.append("## Scaling (chains)")
    md.append("")
    md.append("| kind | " + " | ".join(f"µs/joint-step, {g[5:]}" for g in chains) + " | log-log slope |")
    md.append("|---|" + "---|" * (len(chains) + 1))
    slopes = {}
    for kind in KINDS:
        pts = [(rows[(g, kind)]["counters"].get("joints"), rows[(g, kind)]["median"]) for g in chains if (g, kind) in rows]
        pts = [(n, t) for n, t in pts if n]
        if not pts:
            continue
        slopes[kind] = slope(pts)
        per = [f"{t / n / 1e3:.2f}" for n, t in pts]
        fitted = f"{slopes[kind]:.2f}" if slopes[kind] is not None else "–"
        md.append(f"| {kind} | " + " | ".join(per) + f" | {fitted} |")
    # the stabilizer's own cost: quaternion+stab minus quaternion, per joint-step
    own = [(rows[(g, "quaternion")]["counters"].get("joints"),
            rows[(g, "quaternion+stab")]["median"] - rows[(g, "quaternion")]["median"])
           for g in chains if (g, "quaternion") in rows and (g, "quaternion+stab") in rows]
    own = [(n, t) for n, t in own if n and t > 0]
    slopes["stabilizer alone"] = slope(own)
    if own:
        fitted = "–" if slopes["stabilizer alone"] is None else f"{slopes['stabilizer alone']:.2f}"
        md.append("| stabilizer alone (quaternion+stab − quaternion) | "
                  + " | ".join(f"{t / n / 1e3:.2f}" for n, t in own) + f" | {fitted} |")
    md.append("")
    md.append("![time per step against joints](scaling.png)")
    md.append("")

    # 4. each world step's ratios against stock, and its contacts at the end (the manual states limits with these
    # figures; it lists no targets)
    md.append("## Ratios against stock")
    md.append("")
    others = [g for g in step_groups if g not in chains]
    for g in others:
        md.append(f"- {g[5:]}: quaternion {fmt_ratio(ratio(rows, g, 'quaternion'))} × stock, quaternion+stab "
                  f"{fmt_ratio(ratio(rows, g, 'quaternion+stab'))} × stock (contact points at the end: "
                  + ", ".join(f"{k} {rows[(g, k)]['counters'].get('contacts', 0):.0f}" for k in KINDS if (g, k) in rows)
                  + ").")
    # 5. what the stabilizer did per step in each scene (averages over the timed steps of one repetition)
    work = [(g, rows[(g, "quaternion+stab")]["counters"]) for g in step_groups if (g, "quaternion+stab") in rows]
    work = [(g, c) for g, c in work if "stab_islands" in c]
    if work:
        md.append("")
        md.append("## The stabilizer's work per step")
        md.append("")
        md.append("Kind quaternion+stab, means over the timed steps. *islands*: islands computed (not those at rest, "
                  "whose result is replayed); *factorizations*: numeric factorizations of K over all of them; *Newton*: "
                  "the most Newton iterations any island used; *limit rows*, *contact rows*: the one-sided rows "
                  "projected (a stop or a contact point reached at some iteration).")
        md.append("")
        md.append("| benchmark | islands | factorizations | factorizations per island | Newton | limit rows | contact rows |")
        md.append("|---|---|---|---|---|---|---|")
        for g, c in work:  # every stabilized case reports all five counters (quathinge-bench's benchStep)
            isl, fac = c["stab_islands"], c["stab_factorizations"]
            per_island = f"{fac / isl:.2f}" if isl > 0 else "–"
            md.append(f"| {g} | {isl:.1f} | {fac:.1f} | {per_island} | {c['stab_newton']:.2f} | "
                      f"{c['stab_limit_rows']:.1f} | {c['stab_contact_rows']:.1f} |")
    if errors:
        md.append("")
        md.append("Benchmarks that reported an error: " + "; ".join(errors))
    md.append("")

    # the plot
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, per) = plt.subplots(1, 2, figsize=(12, 5))
    colours = {"stock": "tab:blue", "6dof2": "tab:orange", "quaternion": "tab:green", "quaternion+stab": "tab:red",
               "multibody": "tab:purple"}
    for kind in KINDS:
        pts = [(rows[(g, kind)]["counters"].get("joints"), rows[(g, kind)]["median"] / 1e3) for g in chains if (g, kind) in rows]
        pts = [(n, t) for n, t in pts if n]
        if pts:
            ax.plot([n for n, _ in pts], [t for _, t in pts], "o-", color=colours[kind], label=f"{kind} (chain)")
            per.plot([n for n, _ in pts], [t / n for n, t in pts], "o-", color=colours[kind], label=f"{kind} (chain)")
        for g in others:
            if not g.startswith("step/ragdolls"):
                continue  # the robots and the scenes at rest: in the table, not on the chains' plot
            if (g, kind) in rows and rows[(g, kind)]["counters"].get("joints"):
                n = rows[(g, kind)]["counters"]["joints"]
                t = rows[(g, kind)]["median"] / 1e3
                ax.plot(n, t, "s", color=colours[kind], markerfacecolor="none", markersize=9, label=f"{kind} ({g[5:]})")
                per.plot(n, t / n, "s", color=colours[kind], markerfacecolor="none", markersize=9, label=f"{kind} ({g[5:]})")
    per.set_xscale("log")
    per.set_ylim(bottom=0)
    per.set_xlabel("joints")
    per.set_ylabel("time per joint and step (µs)")
    per.set_title("per joint: flat is linear scaling")
    per.grid(True, which="both", alpha=0.3)
    if chains and (chains[0], "stock") in rows:
        n0 = rows[(chains[0], "stock")]["counters"].get("joints")
        t0 = rows[(chains[0], "stock")]["median"] / 1e3
        if n0:
            xs = [n0, n0 * 100]
            ax.plot(xs, [t0, t0 * 100], ":", color="grey", label="linear (slope 1)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("joints")
    ax.set_ylabel("time per step (µs, median CPU)")
    ax.set_title("full world step, 60 Hz, 10 iterations (log-log)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "scaling.png"), dpi=120)

    text = "\n".join(md)
    with open(os.path.join(args.out, "bench_report.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
