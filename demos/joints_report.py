#!/usr/bin/python3
"""Two generated sections from demos/make_joints.sh's runs (Debian's python3 alone, no plot):

- `stabilized-joints` in docs/STABILIZED_JOINTS.md: the stabilizer holding the hinges an app already has (stock and
  6-dof hinges, no class swapped), each scene without and with it: largest pivot separation (m), axis misalignment
  (rad) and excursion past a stop (rad) over every hinge and step;
- `picture` in docs/RESULTS.md: the front page's picture (heavy1000, stock beside quaternion+stab) measured over the
  picture's own window (its last frame, 1.75 s) and over the scene's own duration, so a caption and a table that
  quote different windows say which.

  joints_report.py --joints JOINTS.json --window WINDOW.json --whole WHOLE.json --joints-page P --results-page P
"""
import argparse
import json
import math

import readme_section  # noqa: E402  (beside this script)

# (scene, kind without the stabilizer, what the joints are)
ROWS = [("spider", "stock", "24 `btHingeConstraint`s (spider.bullet), limits and motors"),
        ("chain10", "stock", "stock hinges"),
        ("chain100", "stock", "stock hinges"),
        ("ragdoll", "stock", "stock hinges, limits"),
        ("kuka_iiwa", "stock", "stock hinges, limits"),
        ("panda", "stock", "stock hinges, limits (URDF fixed joints: stock hinges locked at 0)"),
        ("minitaur", "stock", "stock hinges (closed loops)"),
        ("chain10", "6dof2", "6-dof hinges"),
        ("chain100", "6dof2", "6-dof hinges"),
        ("kuka_iiwa", "6dof2", "6-dof hinges, limits"),
        ("panda", "6dof2", "6-dof hinges, limits (URDF fixed joints: welds)"),
        ("minitaur", "6dof2", "6-dof hinges (closed loops; URDF fixed joints: welds)")]


def runs(path):
    with open(path) as f:
        return {(r["scene"], r["kind"]): r for r in json.load(f)["runs"] if not r["skipped"]}


def fmt(v):
    return "–" if v is None or v < 0 else f"{v:.1e}"


def triple(r):
    return [fmt(r["max_separation_m"]), fmt(math.radians(r["max_misalignment_deg"])), fmt(r["limit_violation_rad"])]


def joints_table(at):
    lines = ["| scene | kind | joints | sep without (m) | mis without (rad) | past without (rad) | sep with (m) | "
             "mis with (rad) | past with (rad) |", "|" + "---|" * 9]
    for scene, kind, what in ROWS:
        if (scene, kind) not in at:
            continue
        lines.append(f"| {scene} | {kind} | {what} | " + " | ".join(triple(at[(scene, kind)]) +
                                                                    triple(at[(scene, kind + "+stab")])) + " |")
    return "\n".join(lines)


def picture_table(window, whole, window_s):
    lines = ["| kind | max sep (m), 0 – %g s (the picture) | max sep (m), the scene's %g s |" % (
        window_s, whole[("heavy1000", "stock")]["steps"] * whole[("heavy1000", "stock")]["dt"]), "|---|---|---|"]
    for kind in ("stock", "quaternion+stab"):
        lines.append(f"| {kind} | {fmt(window[('heavy1000', kind)]['max_separation_m'])} | "
                     f"{fmt(whole[('heavy1000', kind)]['max_separation_m'])} |")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--joints", required=True)
    p.add_argument("--window", required=True)
    p.add_argument("--whole", required=True)
    p.add_argument("--window-s", type=float, default=1.75)
    p.add_argument("--joints-page", default="docs/STABILIZED_JOINTS.md")
    p.add_argument("--results-page", default="docs/RESULTS.md")
    p.add_argument("--note", default="")
    a = p.parse_args()
    readme_section.replace("stabilized-joints", f"{a.note}\n\n{joints_table(runs(a.joints))}", a.joints_page)
    window_note = a.note.replace(", each scene's own duration", "")
    readme_section.replace("picture", f"{window_note}\n\n{picture_table(runs(a.window), runs(a.whole), a.window_s)}",
                           a.results_page)
    print(f"wrote {a.joints_page} (stabilized-joints), {a.results_page} (picture)")


if __name__ == "__main__":
    main()
