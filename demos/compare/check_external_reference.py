#!/usr/bin/python3
"""CTest compare_external_reference: the fine-step reference read from another quathinge-compare process
(--reference-exe, how the float build takes its reference from the double build) gives the same trajectory error as
the reference computed in-process, when both are the same build. Checks the plumbing (command line, scene
arguments, parsing, step alignment) exactly: relative difference ≤ 1e-9 (the text round trip keeps 17 digits).

    check_external_reference.py QUATHINGE_COMPARE OUT_DIR MODELS_DIR [SCENES]

SCENES (comma-separated, default chain10,pendulum5): a built-in scene and one read from MODELS_DIR where the build
has the URDF scenes (CMake passes chain10,double_pendulum to a build without urdfdom).
"""
import json
import subprocess
import sys

kRelTol = 1e-9  # dimensionless


def run(compare, out, models, extra, scenes):
    cmd = [compare, "-s", *scenes, "-k", "stock", "quaternion", "-d", "1", "-j", "1", "--models", models,
           "-o", out] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return {(r["scene"], r["kind"]): r for r in json.load(open(out + "/results.json"))["runs"]}


def main():
    compare, out, models = sys.argv[1:4]
    scenes = (sys.argv[4] if len(sys.argv) > 4 else "chain10,pendulum5").split(",")
    inside = run(compare, out + "/inside", models, [], scenes)
    outside = run(compare, out + "/outside", models, ["--reference-exe", compare], scenes)
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
