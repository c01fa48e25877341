#!/usr/bin/python3
"""One generated section of a manual page (docs/*.md) replaced: the text between <!-- NAME:begin --> and <!-- NAME:end -->.

Every script that publishes into the manual goes through `replace` (make_bench.sh, make_sweep.sh, make_soak.sh,
make_report.sh and plot_report.py), so no generated figure is typed by hand and each section is found the same
way: exactly one pair of markers, or the script stops and says which is missing.
"""
import re


def replace(name, body, readme):
    """Writes `body` between the section's markers (a line break after the first, one before the second)."""
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    with open(readme) as f:
        text = f.read()
    block = begin + "\n" + body + "\n" + end
    text, n = re.subn(re.escape(begin) + ".*?" + re.escape(end), lambda _: block, text, flags=re.S)
    if n != 1:
        raise SystemExit(f"{readme} has no single {begin} ... {end} section (found {n})")
    with open(readme, "w") as f:
        f.write(text)
