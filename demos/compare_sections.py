#!/usr/bin/python3
"""Compares generated sections of two copies of README.md and docs/*.md, table cell by table cell, leaving out the
timed columns (run time varies run to run); used by demos/check_generated.sh.

  compare_sections.py COMMITTED_DIR REGENERATED_DIR SECTION...

Fails (exit 1) on a section missing from either copy, a table of another shape, or any differing cell.
"""
import sys

from report_tables import sections, tables

TIMED = {"CPU ms / sim-s"}  # columns left out: each run's own thread CPU time


def rows(body):
    """Table rows (header rows included), timed columns blanked."""
    out = []
    for header, cells in tables(body):
        for row in [header] + cells:
            out.append([("(timed)" if h in TIMED else c) for h, c in zip(header, row)])
    return out


def main():
    committed, regenerated = sections(sys.argv[1]), sections(sys.argv[2])
    failures = 0
    for name in sys.argv[3:]:
        if name not in committed or name not in regenerated:
            print(f"compare_sections: section '{name}' missing ({'committed' if name not in committed else 'regenerated'})")
            failures += 1
            continue
        a, b = rows(committed[name][1]), rows(regenerated[name][1])
        if not a:
            print(f"compare_sections: section '{name}' has no table")
            failures += 1
        if len(a) != len(b):
            print(f"compare_sections: {name} ({committed[name][0]}): {len(a)} rows committed, {len(b)} regenerated")
            failures += 1
            continue
        diff = [(ra, rb) for ra, rb in zip(a, b) if ra != rb]
        for ra, rb in diff:
            print(f"compare_sections: {name} ({committed[name][0]}):\n  committed:   | {' | '.join(ra)} |\n"
                  f"  regenerated: | {' | '.join(rb)} |")
        failures += len(diff)
        print(f"compare_sections: {name}: {len(a)} rows, {len(diff)} differ")
    if failures:
        print("compare_sections: the committed generated sections differ from a fresh run: regenerate them "
              "(bash demos/make_report.sh) and commit, or find what made the run change")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
