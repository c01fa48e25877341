"""The generated sections of README.md and docs/*.md (<!-- NAME:begin --> … <!-- NAME:end -->) and their Markdown
tables, as the reports write them: read by demos/compare_sections.py (check_generated.sh) and
tests/figures/check_figures.py."""
import pathlib
import re

SECTION_RE = re.compile(r"<!-- ([\w-]+):begin -->\n(.*?)\n<!-- \1:end -->", re.S)
SEPARATOR_RE = re.compile(r":?-+:?")


def pages(root):
    """README.md and the manual's pages, in a fixed order."""
    root = pathlib.Path(root)
    return [root / "README.md"] + sorted((root / "docs").glob("*.md"))


def sections(root):
    """Every generated section: name -> (page name, body)."""
    found = {}
    for page in pages(root):
        for m in SECTION_RE.finditer(page.read_text()):
            found[m.group(1)] = (page.name, m.group(2))
    return found


def tables(body):
    """Every Markdown table of a section body, in order: (header cells, rows of cells), separator rows dropped."""
    out, current = [], None
    for line in body.splitlines():
        if not line.startswith("|"):
            current = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if current is None:
            current = (cells, [])
            out.append(current)
        elif not all(SEPARATOR_RE.fullmatch(c) for c in cells):
            current[1].append(cells)
    return out
