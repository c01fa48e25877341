#!/usr/bin/python3
"""The stabilizer's cost on the hinges an app already has (docs/STABILIZED_JOINTS.md, "What it costs"): instructions
per step under callgrind for quathinge-bench's step cases, the same harness for every kind; written into
docs/STABILIZED_JOINTS.md between the stabilized-cost markers (--page).

  /usr/bin/python3 demos/stabilized_cost.py [--bench build/demos/quathinge-bench] [--out demos/out/stabilized_cost]
                                            [--scenes spider kuka_iiwa panda minitaur chain100]

For each scene and kind (quaternion, 6dof2, quaternion+stab, stock+stab, 6dof2+stab) it runs the case once under
valgrind --tool=callgrind and reads the inclusive instructions of btDiscreteDynamicsWorld::stepSimulation (the whole
step) and btQuaternionHingeStabilizer::updateAction (the stabilizer's own), each over the number of steps taken (the
calls of stepSimulation: warm-up and timed steps), the benchmark's factorizations of K per step and the instructions
of each (BlockLDLT's and SparseLDLT's factorize, inclusive). Prints a Markdown table and writes it to
<out>/stabilized_cost.md. About a minute per scene on one core (the chains three).
"""
import argparse
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import readme_section  # noqa: E402  (beside this script)

KINDS = ["quaternion", "6dof2", "quaternion+stab", "stock+stab", "6dof2+stab"]
STEP = "btDiscreteDynamicsWorld::stepSimulation("
STABILIZER = "btQuaternionHingeStabilizer::updateAction("
FACTORIZE = re.compile(r"quathinge::stabilizer::(BlockLDLT<\d>|SparseLDLT)::factorize\(")


def inclusive(annotated, name, every=False):
    """The inclusive count of the first function whose line holds `name` (every: summed over all such lines)."""
    total = 0
    for line in annotated.splitlines():
        if name in line:
            total += int(re.match(r"\s*([\d,]+)", line).group(1).replace(",", ""))
            if not every:
                break
    return total


def calls(raw_path, name):
    """How often `name` was called: the calls= lines under each cfn naming it (callgrind's compressed names)."""
    names, total, target = {}, 0, False
    with open(raw_path) as f:
        for line in f:
            m = re.match(r"cfn=\((\d+)\)(?: (.*))?", line)
            if m:
                if m.group(2):
                    names[m.group(1)] = m.group(2)
                target = names.get(m.group(1), "").startswith(name)
                continue
            m = re.match(r"fn=\((\d+)\)(?: (.*))?", line)
            if m and m.group(2):
                names[m.group(1)] = m.group(2)
            if target and line.startswith("calls="):
                total += int(line.split("=")[1].split()[0])
                target = False
    return total


def measure(bench, scene, kind, out):
    base = os.path.join(out, f"{scene}.{kind}")
    pattern = f"step/{scene}/{re.escape(kind)}/"
    with open(base + ".json", "w") as js:
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={base}.callgrind", bench,
                        f"--benchmark_filter={pattern}", "--benchmark_format=json"], stdout=js,
                       stderr=subprocess.DEVNULL, check=True)
    run = json.load(open(base + ".json"))["benchmarks"]
    if not run or run[0].get("error_occurred"):
        return None
    annotated = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", base + ".callgrind"],
                               capture_output=True, text=True, check=True).stdout
    steps = calls(base + ".callgrind", STEP.rstrip("("))
    factorizations = run[0].get("stab_factorizations", 0.0)  # per step
    factorizing = sum(int(re.match(r"\s*([\d,]+)", line).group(1).replace(",", ""))
                      for line in annotated.splitlines() if FACTORIZE.search(line))
    return {"step": inclusive(annotated, STEP) / steps, "stabilizer": inclusive(annotated, STABILIZER) / steps,
            "factorizations": factorizations, "per_factorization": factorizing / (factorizations * steps)
            if factorizations else 0.0, "steps": steps}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench", default="build/demos/quathinge-bench")
    parser.add_argument("--out", default="demos/out/stabilized_cost")
    parser.add_argument("--page", default="docs/STABILIZED_JOINTS.md",
                        help="manual page whose stabilized-cost section gets the table ('' for none)")
    parser.add_argument("--scenes", nargs="+", default=["spider", "kuka_iiwa", "panda", "minitaur", "chain10", "chain100"])
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = ["| scene | the stabilizer on quaternion hinges (instructions per step) | on stock hinges | on 6-dof hinges "
            "| whole step, 6dof2+stab / quaternion+stab | bare step, 6dof2 / quaternion "
            "| factorizations per step (quaternion, 6-dof) | instructions per factorization (quaternion, 6-dof) |",
            "|---|---|---|---|---|---|---|---|"]
    for scene in args.scenes:
        m = {k: measure(args.bench, scene, k, args.out) for k in KINDS}
        if any(v is None for v in m.values()):
            print(f"stabilized_cost: {scene}: some kind did not run", file=sys.stderr)
            continue
        q = m["quaternion+stab"]
        rows.append(f"| {scene} | {q['stabilizer'] / 1e3:.1f} k | {m['stock+stab']['stabilizer'] / q['stabilizer']:.3f} × "
                    f"| {m['6dof2+stab']['stabilizer'] / q['stabilizer']:.3f} × "
                    f"| {m['6dof2+stab']['step'] / q['step']:.3f} × | {m['6dof2']['step'] / m['quaternion']['step']:.3f} × "
                    f"| {q['factorizations']:.2f}, {m['6dof2+stab']['factorizations']:.2f} "
                    f"| {q['per_factorization'] / 1e3:.1f} k, {m['6dof2+stab']['per_factorization'] / 1e3:.1f} k |")
        print(rows[-1], flush=True)
    table = "\n".join(rows) + "\n"
    open(os.path.join(args.out, "stabilized_cost.md"), "w").write(table)
    if args.page:
        readme_section.replace("stabilized-cost", table.rstrip("\n"), args.page)
    print(table)


if __name__ == "__main__":
    main()
