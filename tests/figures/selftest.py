#!/usr/bin/python3
"""check_figures.py fails where it should (CTest: docs_figures_selftest): on a temporary copy of README.md, docs/ and
tests/figures/, each mutation below must make the check fail, naming the page, and the unmutated copy must pass.

  /usr/bin/python3 tests/figures/selftest.py SOURCE_DIR
"""
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

src = pathlib.Path(sys.argv[1]).resolve()
check = src / "tests/figures/check_figures.py"
MUTATIONS = [  # (what, page, old, new)
    ("a quoted figure off by one in its last digit", "README.md", None, None),  # README's first d.de-N figure
    ("a quoted figure whose row is gone", "README.md", "scene=chain100, kind=stock -> sep with", "scene=chain101, kind=stock -> sep with"),
    ("a new hand-typed figure", "README.md", "## What it fixes\n", "## What it fixes\n\nIt holds to 7.7e-7 m.\n"),
    ("a new hand-typed figure with a unit", "docs/STABILIZER.md", "\n", "\nIt costs 1.23 × stock.\n"),
    ("an unmet goal", "docs/ENERGY.md", "\n", "\nThe 1 % goal is not yet met.\n"),
    ("history", "docs/MIGRATING.md", "\n", "\nBefore this release it was 0.1 m; now it is less.\n"),
]


def run(root):
    return subprocess.run([sys.executable, str(check), str(root)], capture_output=True, text=True)


failures = 0
with tempfile.TemporaryDirectory() as tmp:
    root = pathlib.Path(tmp)
    shutil.copy(src / "README.md", root / "README.md")
    shutil.copytree(src / "docs", root / "docs", ignore=shutil.ignore_patterns("images"))
    shutil.copytree(src / "tests/figures", root / "tests/figures")
    clean = run(root)
    if clean.returncode != 0:
        print("the unmutated copy fails:\n" + clean.stderr)
        failures += 1
    for what, page, old, new in MUTATIONS:
        path = root / page
        original = path.read_text()
        if old is None:  # the first annotated figure of the form d.de-N, its last digit changed (9 becomes 8)
            m = re.search(r'(\d\.)(\d)(e-\d+ m<!-- fig )', original)
            if m:
                old, new = m.group(0), m.group(1) + str((int(m.group(2)) + 1) % 10 if m.group(2) != '9' else 8) + m.group(3)
        if old is None or old not in original:
            print(f"{what}: '{(old or 'a d.de-N figure').strip()}' is not in {page} (update the self-test)")
            failures += 1
            continue
        path.write_text(original.replace(old, new, 1))
        result = run(root)
        path.write_text(original)
        caught = result.returncode != 0 and page in result.stderr
        print(f"{what} ({page}): {'caught' if caught else 'NOT caught'}")
        failures += not caught
sys.exit(1 if failures else 0)
