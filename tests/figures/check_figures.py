#!/usr/bin/python3
"""The figures of README.md and docs/*.md against the generated report sections they quote (docs/CONTRIBUTING.md,
"Figures come from the reports").

  /usr/bin/python3 tests/figures/check_figures.py SOURCE_DIR        (CTest: docs_figures)

Three checks, each failure printed with its page and line:

1. Every figure annotated `<!-- fig SECTION: FILTERS -> COLUMN [AGG] [*SCALE] -->` matches the generated section
   SECTION (the text between <!-- SECTION:begin --> and <!-- SECTION:end --> in README.md or docs/*.md) within the
   printed precision: the cell rounded to the quoted figure's last digit is the quoted figure (|quoted - cell| <= half a
   unit of that digit), and the quote has no more digits than the cell. FILTERS are `column=value` (or `column!=value`) pairs, comma-separated, that pick rows of the section's Markdown tables (none:
   every row); COLUMN is the column quoted; AGG is `min`, `max` or `count` (over the rows picked; count: the rows whose
   COLUMN is not "–"); SCALE multiplies the cell (e.g. `*1e6` for a figure quoted in µm, `*100` for a percentage).
   Several queries separated by ` ; ` annotate the same number of figures before the comment, in order ("1.4–1.7 ×").
   The figures are the last numbers before the comment on its line.
2. Every figure outside a generated section, a code block, inline code and an annotation's reach is listed in
   tests/figures/exempt.txt (reviewed settings and non-measurements: "60 Hz", a version) or, for pages not yet
   annotated, in tests/figures/baseline.txt with its count on the page: a new hand-typed figure fails, and so does a
   baseline entry no longer on its page (the baseline only shrinks). A figure: a number with a decimal point or an
   exponent, or any number followed by a unit (m, µm, mm, rad, s, ms, µs, Hz, %, ×, °, k, M).
3. No page states history or unmet goals (tests/figures/history_phrases.txt, one regular expression a line, matched
   case-insensitively outside code, generated sections included): those belong in CHANGELOG.md.
"""
import math
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "demos"))
from report_tables import pages, sections, tables  # noqa: E402 (the reports' own reader)

NUMBER = r"[-−]?\d+(?:\.\d+)?(?:e[-+−]?\d+)?"
NUMBER_RE = re.compile(r"(?<![\w.])" + NUMBER + r"(?![\w.]*\d)")
UNIT = r"(?:\s?(?:µm|mm|m|rad|ms|µs|s|Hz|k|M)\b|\s?[%×°])"
FIGURE_RE = re.compile(r"(?<![\w.\-−/])[-−]?(?:\d+\.\d+(?:e[-+−]?\d+)?|\d+e[-+−]?\d+|\d+" + UNIT + r")(?![\w.]*\d)")
FIG_RE = re.compile(r"<!-- fig (?P<section>[\w-]+): (?P<queries>.*?) -->")


def value(text):
    """A printed number and half a unit of its last digit."""
    text = re.sub(r"\s*[×%°k]$", "", text.strip().replace("−", "-"))  # a cell's unit ("1.016 ×", "365.9 k")
    m = re.fullmatch(r"[-+]?(\d+)(?:\.(\d+))?(?:e([-+]?\d+))?", text)
    if not m:
        return None
    decimals = len(m.group(2) or "")
    exponent = int(m.group(3) or 0)
    return float(text), 0.5 * 10.0 ** (exponent - decimals)


def table_rows(body):
    """Every row of a section's Markdown tables, as a dict column -> cell."""
    return [dict(zip(header, row)) for header, rows in tables(body) for row in rows]


def answer(rows, query):
    """(value, half unit) of one query over the section's rows, or an error string."""
    m = re.fullmatch(r"\s*(?P<filters>.*?)\s*->\s*(?P<column>[^*]+?)\s*(?:\b(?P<agg>min|max|count))?"
                     r"\s*(?:\*\s*(?P<scale>\S+))?\s*", query)
    if not m:
        return f"cannot read the query '{query}'"
    filters = [re.fullmatch(r"\s*(.+?)\s*(!=|=)\s*(.+?)\s*", f) for f in m.group("filters").split(",") if f.strip()]
    if not all(filters):
        return f"a filter is not column=value or column!=value in '{query}'"
    column, agg = m.group("column").strip(), m.group("agg")
    picked = [r for r in rows if column in r and all((r.get(f.group(1)) == f.group(3)) == (f.group(2) == "=")
                                                     for f in filters)]
    if agg == "count":
        return float(sum(1 for r in picked if r[column] not in ("–", "-", ""))), 0.5
    values = [value(r[column]) for r in picked if r[column] not in ("–", "-", "")]
    if not values or any(v is None for v in values):
        return f"no number in column '{column}' of the rows picked by '{query}' ({len(picked)} rows)"
    if agg is None and len(picked) != 1:
        return f"'{query}' picks {len(picked)} rows, not one (add a filter or min/max)"
    v = (min if agg == "min" else max)(values, key=lambda x: x[0])
    scale = float(m.group("scale")) if m.group("scale") else 1.0
    return v[0] * scale, v[1] * abs(scale)


def strip(text, generated=True):
    """Code blocks, inline code and (generated) the generated sections blanked (same length: offsets and lines stay)."""
    blank = lambda m: re.sub(r"[^\n]", " ", m.group(0))  # noqa: E731
    if generated:
        text = re.sub(r"<!-- ([\w-]+):begin -->.*?<!-- \1:end -->", blank, text, flags=re.S)
    text = re.sub(r"^```.*?^```", blank, text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", blank, text)


def check(src):
    errors, annotated = [], 0
    found = sections(src)
    exempt = {}
    for line in (src / "tests/figures/exempt.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            page, figure = line.split("\t")[:2]
            exempt.setdefault(page, set()).add(figure)
    baseline = {}
    for line in (src / "tests/figures/baseline.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            page, figure, count = line.split("\t")
            if page == "README.md":
                raise SystemExit("tests/figures/baseline.txt: README.md has no baseline: annotate its figures")
            baseline[(page, figure)] = int(count)
    phrases = [re.compile(p, re.I) for p in (src / "tests/figures/history_phrases.txt").read_text().splitlines()
               if p.strip() and not p.startswith("#")]
    seen = {}
    for page in pages(src):
        name = str(page.relative_to(src))
        text = page.read_text()
        prose = strip(text)
        lineno = lambda pos: text.count("\n", 0, pos) + 1  # noqa: E731
        covered = set()
        for m in FIG_RE.finditer(text):
            if prose[m.start():m.start() + 4] != "<!--":
                continue  # inside code or a generated section
            annotated += 1
            queries = m.group("queries").split(" ; ")
            line_start = text.rfind("\n", 0, m.start()) + 1
            before = FIG_RE.sub(lambda x: " " * len(x.group(0)), text[line_start:m.start()])
            numbers = list(NUMBER_RE.finditer(before))[-len(queries):]
            if len(numbers) != len(queries):
                errors.append(f"{name}:{lineno(m.start())}: {len(queries)} queries but {len(numbers)} numbers before")
                continue
            if m.group("section") not in found:
                errors.append(f"{name}:{lineno(m.start())}: no generated section '{m.group('section')}'")
                continue
            rows = table_rows(found[m.group("section")][1])
            for number, query in zip(numbers, queries):
                covered.add(line_start + number.start())
                quoted = value(number.group(0))
                got = answer(rows, query)
                if isinstance(got, str):
                    errors.append(f"{name}:{lineno(m.start())}: {got}")
                elif quoted[1] < got[1] * (1 - 1e-9):
                    errors.append(f"{name}:{lineno(m.start())}: quotes {number.group(0)}, more digits than "
                                  f"{m.group('section')} prints ({got[0]:.6g}) for '{query.strip()}'")
                elif abs(quoted[0] - got[0]) > quoted[1] * (1 + 1e-9):
                    errors.append(f"{name}:{lineno(m.start())}: quotes {number.group(0)}, but {m.group('section')} "
                                  f"({found[m.group('section')][0]}) says {got[0]:.6g} for '{query.strip()}'")
        bare = FIG_RE.sub(lambda x: " " * len(x.group(0)), prose)
        for m in FIGURE_RE.finditer(bare):
            if any(m.start() <= c < m.end() for c in covered):
                continue
            figure = m.group(0).strip()
            if figure in exempt.get(name, set()) | exempt.get("*", set()):
                continue
            seen.setdefault((name, figure), []).append(lineno(m.start()))
        for i, line in enumerate(strip(text, generated=False).splitlines(), 1):
            for p in phrases:
                if p.search(line):
                    errors.append(f"{name}:{i}: history or an unmet goal ('{p.pattern}'): state what is, "
                                  "with figures; history goes to CHANGELOG.md")
    for (name, figure), lines in sorted(seen.items()):
        allowed = baseline.get((name, figure), 0)
        if len(lines) > allowed:
            errors.append(f"{name}:{','.join(map(str, lines))}: '{figure}' has no source: annotate it with "
                          f"<!-- fig SECTION: ... --> or, if it is no measurement, add it to tests/figures/exempt.txt")
    for (name, figure), count in sorted(baseline.items()):
        if len(seen.get((name, figure), [])) < count:
            errors.append(f"tests/figures/baseline.txt: '{name}\t{figure}' is {count} there but "
                          f"{len(seen.get((name, figure), []))} on the page: lower or remove the entry")
    return errors, annotated, sum(len(v) for v in seen.values())


def main():
    src = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    if len(sys.argv) > 2 and sys.argv[2] == "--print-unsourced":
        errors, _, _ = check(src)
        for e in errors:
            print(e)
        return 0
    errors, annotated, unsourced = check(src)
    for e in errors:
        print(e, file=sys.stderr)
    print(f"check_figures: {annotated} annotated figures, {unsourced} baseline figures in docs/ not yet annotated, "
          f"{len(errors)} errors")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
