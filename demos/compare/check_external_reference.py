#!/usr/bin/python3
"""CTest compare_external_reference: the fine-step reference read from another quathinge-compare process
(--reference-exe, how the float build takes its reference from the double build) gives the same trajectory error as
the reference computed in-process, when both are the same build. Checks the plumbing (command line, scene
arguments, parsing, step alignment) exactly: relative difference ≤ 1e-9 (the text round trip keeps 17 digits).

    check_external_reference.py QUATHINGE_COMPARE OUT_DIR MODELS_DIR
"""
import json
import subprocess
import sys

kRelTol = 1e-9  # dimensionless


def run(compare, out, models, extra):
    cmd = [compare, "-s", "chain10", "pendulum5", "-k", "stock", "quaternion", "-d", "1", "-j", "1", "--models", models,
           "-o", out] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return {(r["scene"], r["kind"]): r for r in json.load(open(out + "/results.json"))["runs"]}


def main():
    compare, out, models = sys.argv[1:4]
    inside = run(compare, out + "/inside", models, [])
    outside = run(compare, out + "/outside", models, ["--reference-exe", compare])
    for key, a in inside.items():
        b = outside[key]
        ea, eb = a["trajectory_error"], b["trajectory_error"]
        print(f"{key}: in-process {ea:.17g}, external {eb:.17g} ({b['reference']})")
        if "precision (" not in b["reference"]:
            sys.exit(f"{key}: the external reference was not used: {b['reference']}")
        if not (ea > 0) or abs(ea - eb) > kRelTol * abs(ea):
            sys.exit(f"{key}: trajectory errors differ: {ea} vs {eb}")


if __name__ == "__main__":
    main()
