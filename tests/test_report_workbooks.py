"""Issue 20: every workbook the commands write reads and prints like the fill's Summary.

One workbook of each kind (tests/report_workbooks.py) is scanned and printed through
LibreOffice: one page per report sheet, then each data sheet by itself (issue 35: all its
rows, one page wide, its header row on every page, no blank print area), no float shown as a
General number of more than 7 significant digits, a header naming the shot and the version,
and a grid sweep's charts with one series per level."""
import functools
import json
import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import openpyxl
import pytest
from openpyxl.utils.cell import range_boundaries
from report_workbooks import EXPECTED_CODES, make_all

needs_lo = pytest.mark.skipif(not (shutil.which("soffice") and shutil.which("pdftotext")),
                              reason="needs LibreOffice and poppler-utils")

#: The most significant digits a General number may show: Excel's General shows up to 11
#: characters, LibreOffice's up to 10 digits; a figure past 7 looks exact and is not read.
MAX_DIGITS = 7


@pytest.fixture(scope="module")
def workbooks(tmp_path_factory):
    folder = tmp_path_factory.mktemp("reports")
    paths, codes = make_all(folder)
    # diff exits 0 (the legacy input filled equals its legacy output); the rest succeed, but
    # for a shot that fails its specification
    assert codes == {**dict.fromkeys(codes, 0), **EXPECTED_CODES}, codes
    return paths


@functools.lru_cache(maxsize=None)
def _print_setups(path):
    """[(sheet, (min_col, min_row, max_col, max_row), pages tall)] of every sheet: a report
    page is fitted to one page (OOXML's fitToHeight, 1 when absent), a data sheet to as many
    as its rows need (0). Read once a workbook (the module's workbooks are written once and
    never changed; loading the fill's 12,000-row sheets took seconds a call)."""
    wb = openpyxl.load_workbook(path)
    out = []
    for ws in wb.worksheets:
        area = ws.print_area
        assert area, f"{path.name}: {ws.title} has no print area"
        bounds = range_boundaries(str(area[0] if isinstance(area, list) else area)
                                  .split("!")[-1].replace("$", ""))
        assert ws.sheet_properties.pageSetUpPr.fitToPage, (path.name, ws.title)
        tall = ws.page_setup.fitToHeight
        out.append((ws, bounds, 1 if tall is None else int(tall)))
    return out


def report_sheets(path):
    """[(sheet, bounds)] of the sheets that print on one page."""
    return [(ws, bounds) for ws, bounds, tall in _print_setups(path) if tall == 1]


def data_sheets(path):
    """[(sheet, bounds)] of the sheets that print all their rows, one page wide."""
    return [(ws, bounds) for ws, bounds, tall in _print_setups(path) if tall == 0]


def significant_digits(x):
    """Significant digits of the shortest repr of ``x``: 0.1 -> 1, 680.388555 -> 9."""
    mantissa = repr(abs(float(x))).lower().split("e")[0].replace(".", "")
    return len(mantissa.strip("0"))


def test_significant_digits():
    assert [significant_digits(x) for x in (0.1, 680.388555, 2.7e7, 1.25e-9, 100.0)] == [
        1, 9, 2, 3, 1]


KINDS = ("fill", "diff", "grid", "montecarlo", "sobol", "convergence", "srs", "design_srs",
         "compare", "calibrate_law", "calibrate_fit", "campaign", "history")


@pytest.mark.parametrize("kind", KINDS)
def test_no_report_sheet_shows_a_long_general_number(workbooks, kind):
    """Every number on a printed sheet has a format: none is a General float of more than 7
    significant digits (the workbooks showed '105.925372517729 Hz', '24152274.0490178')."""
    long, numbers = [], 0
    for ws, (c0, r0, c1, r1) in report_sheets(workbooks[kind]):
        for row in ws.iter_rows(min_row=r0, max_row=r1, min_col=c0, max_col=c1):
            for cell in row:
                if isinstance(cell.value, (int, float)) and not isinstance(cell.value, bool):
                    numbers += 1
                    if (cell.number_format == "General"
                            and significant_digits(cell.value) > MAX_DIGITS):
                        long.append(f"{ws.title}!{cell.coordinate}={cell.value!r}")
    assert numbers > 0 and not long, long[:10]


@pytest.mark.parametrize("kind", KINDS)
def test_every_report_sheet_has_the_header(workbooks, kind):
    """The page header names the shot (or the compared files), the sheet and the version."""
    for ws, _ in report_sheets(workbooks[kind]):
        header = ws.oddHeader
        assert "airgun-xl" in header.right.text and "&D" in header.right.text, ws.title
        assert header.left.text and header.center.text, ws.title
        assert ws.page_setup.orientation == "landscape", ws.title


@pytest.mark.parametrize("kind", KINDS)
def test_every_data_sheet_prints_by_itself(workbooks, kind):
    """Issue 35: no print-nothing trick. A data sheet's print area is its table from A1 to
    its last row and column, one page wide, its header row(s) repeated on every page, each
    page numbered; its numbers have formats (none General)."""
    for ws, (c0, r0, c1, r1) in data_sheets(workbooks[kind]):
        assert (c0, r0) == (1, 1) and r1 >= 2 and c1 >= 1, (kind, ws.title)
        assert r1 >= ws.max_row - 1 and c1 >= 1, (kind, ws.title, r1, ws.max_row)
        assert ws.page_setup.fitToWidth in (None, 1), (kind, ws.title)
        assert (ws.print_title_rows or "").startswith("$1:"), (kind, ws.title)
        assert "&P" in ws.oddFooter.center.text and "&N" in ws.oddFooter.center.text
        general = [c.coordinate for row in ws.iter_rows(min_row=2, max_row=min(r1, 200))
                   for c in row if isinstance(c.value, float) and c.number_format == "General"]
        assert general == [], (kind, ws.title, general[:5])


@pytest.fixture(scope="module")
def lo_print(workbooks, tmp_path_factory):
    """What LibreOffice prints of every workbook (tests/lo_default_print.py), and the PDF
    export of :data:`PDF_KINDS`' (as ``soffice --convert-to pdf`` writes it), in one start of
    LibreOffice: [records in sorted(ALL_KINDS)'s order], each with its "pdf" (or None).
    Converting the same workbooks twice, once per test, cost 80 s and 57 s."""
    if not _has_uno():
        pytest.skip("needs LibreOffice and python3-uno")
    folder = tmp_path_factory.mktemp("lo_print")
    kinds = sorted(ALL_KINDS)
    done = subprocess.run([UNO_PYTHON, str(Path(__file__).with_name("lo_default_print.py")),
                           str(folder / "lo"), "--pdf", str(folder),
                           *(str(workbooks[k]) for k in kinds),
                           "--pdf-of", *(str(workbooks[k]) for k in PDF_KINDS)],
                          capture_output=True, text=True, timeout=900, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    printed = [json.loads(line) for line in done.stdout.splitlines()]
    assert [r["path"] for r in printed] == [str(workbooks[k]) for k in kinds]
    return dict(zip(kinds, printed, strict=True))


@needs_lo
def test_each_workbook_prints_its_report_pages_first_then_its_data(workbooks, lo_print):
    """LibreOffice's PDF export prints every sheet: each report sheet on one page, first
    (its title in the header, no page number); then each data sheet by itself, its pages
    numbered and its header row on each. Before: convergence 7 pages for its one sheet."""
    for kind in KINDS:
        path = workbooks[kind]
        text = subprocess.run(["pdftotext", "-layout", lo_print[kind]["pdf"], "-"],
                              capture_output=True, text=True, check=True).stdout
        pages = text.split("\f")[:-1]
        # no figure too wide for its column (ChartData's printed "###" at the default width)
        assert "###" not in text, (kind, [p.splitlines()[-1] for p in pages if "###" in p][:3])
        # the export prints what the counts say a print of every sheet gives
        assert len(pages) == lo_print[kind]["every_sheet"], kind
        sheets = [ws.title for ws, _ in report_sheets(path)]
        numbered = [bool(re.search(r"Page \d+ of \d+", p)) for p in pages]
        assert numbered == [False] * len(sheets) + [True] * (len(pages) - len(sheets)), kind
        for page in pages:
            assert "airgun-xl" in page.splitlines()[0], kind
        data = {ws.title: ws for ws, _ in data_sheets(path)}
        printed = {re.split(r"\s{2,}", line.strip())[-1] for p in pages[len(sheets):]
                   for line in p.splitlines()[-1:]}  # the footer's right: the sheet's name
        assert printed == set(data), (kind, printed, set(data))
    assert all(lo_print[k]["pdf"] is None for k in ALL_KINDS - set(PDF_KINDS))


#: The workbooks exported to PDF: each kind's pages checked, and a Summary with Design notes.
PDF_KINDS = (*KINDS, "design_confidence")


def test_every_summary_note_prints_whole(workbooks, lo_print):
    """Issue 60: a Summary's Design notes (design --confidence's: the model's own error, the
    probability's interval) and the predicted verdict's definitions are wrapped in their
    column, each row as tall as its lines: every word of each prints on the page. Before, a
    note of 300 characters in one cell ran past the page's right edge and printed cut."""
    for kind in ("design_confidence", "fill"):
        ws = openpyxl.load_workbook(workbooks[kind], read_only=True)["Summary"]
        notes = [str(row[3]) for row in ws.iter_rows(values_only=True)
                 if len(row) > 3 and row[0] in ("Design", None) and row[3]
                 and len(str(row[3])) > 110]
        if kind == "design_confidence":
            assert len(notes) >= 2, notes  # the long lines this checks are there
        text = subprocess.run(["pdftotext", lo_print[kind]["pdf"], "-"], capture_output=True,
                              text=True, check=True).stdout
        assert "###" not in text, kind  # its ChartData's figures printed whole too
        flat = " ".join(text.split())
        for note in notes:
            assert " ".join(note.split()) in flat, (kind, note)


def test_the_grid_sweeps_charts_have_one_series_per_level(workbooks):
    """--vary A28=150:250:5 --vary E40=2.5e7:3e7:3: the peak against A28 is three curves
    (one per E40 level), against E40 five (one per A28); the axes name their units (MPa)."""
    with zipfile.ZipFile(workbooks["grid"]) as z:
        charts = sorted(n for n in z.namelist() if re.fullmatch(r"xl/charts/chart\d+\.xml", n))
        xml = [z.read(n).decode() for n in charts]
    assert [x.count("<c:ser>") for x in xml] == [3, 5]
    assert "E40 = 25 MPa" in xml[0] and "A28 = 150 m/s" in xml[1]
    assert "E40 Yield Stress (MPa)" in xml[1] and 'formatCode="#,##0.0,,"' in xml[1]


def test_the_fills_charts_are_in_the_summarys_units(workbooks):
    """Time in ms, force in kN (the axis shows N / 1000), frequency in kHz."""
    with zipfile.ZipFile(workbooks["fill"]) as z:
        text = "".join(z.read(n).decode() for n in z.namelist()
                       if re.fullmatch(r"xl/charts/chart\d+\.xml", n))
    assert "Time (ms)" in text and "Time (s)" not in text
    assert "Force (kN)" in text and 'formatCode="#,##0,"' in text
    assert "Frequency (kHz)" in text
    # issue 46: the spectrum's axis starts on a whole kHz (shot A's lobe ends at 1.8 kHz,
    # whose ticks read 1.8, 3.8, 5.8 kHz before), so its ticks fall on round kHz
    spectrum = next(x for x in text.split("</c:chartSpace>") if "Frequency (kHz)" in x)
    minimum = re.search(r'<c:valAx>.*?<c:min val="([^"]+)"/>', spectrum, re.S).group(1)
    assert float(minimum) % 1000 == 0, minimum


def test_the_diff_reports_value_axes_name_the_columns_unit(workbooks):
    """Issue 46: both value axes of the "Worst column" chart carry the column's unit (the
    header's, in brackets), the difference's too."""
    from openpyxl import load_workbook

    ws = load_workbook(workbooks["diff"])["Worst column"]
    texts = [c.value for c in ws["A"] if isinstance(c.value, str)]
    titles = [t for t in texts if t.startswith("new - legacy")]
    assert len(titles) == 1 and re.fullmatch(r"new - legacy \(.+\)", titles[0]), titles
    with zipfile.ZipFile(workbooks["diff"]) as z:
        xml = "".join(z.read(n).decode() for n in z.namelist()
                      if re.fullmatch(r"xl/charts/chart\d+\.xml", n))
    # the axes' titles point at those cells (a header is workbook text: never a formula)
    assert xml.count("<c:tx><c:strRef>") >= 3


#: Workbooks in the macro's layout: their parameter sheet stays first (fill and diff read the
#: first sheet; the legacy macro reads the active one, and docs/output.md says to click its tab
#: before running the macro on them); they open on their Summary (issue 46).
MACRO_LAYOUT = {"fill", "design_srs", "design_confidence"}

#: Every kind make_all writes.
ALL_KINDS = set(KINDS) | {"accept", "accept_corridor", "design_confidence"}

#: The kinds whose first sheet is the shot's own in the macro's layout: its raw parameter
#: block prints on one page when printed by itself, and is not in the report's print (the
#: Parameters page, or the Calibration page, shows it readably).
SHOT_FIRST = MACRO_LAYOUT | {"calibrate_law", "calibrate_fit"}


@pytest.mark.parametrize("kind", sorted(ALL_KINDS - MACRO_LAYOUT))
def test_a_study_workbook_opens_on_its_first_report_page(workbooks, kind):
    """Issue 35: the active sheet is a report page (one printed page, not a data sheet),
    every report page comes before every data sheet but a shot's own
    sheets, and no number on the active sheet is a General number past 7 digits."""
    path = workbooks[kind]
    wb = openpyxl.load_workbook(path)
    printed = [ws.title for ws, _ in report_sheets(path)]
    active = wb.active
    assert active.title in printed, (kind, active.title, printed)
    assert active.sheet_properties.pageSetUpPr.fitToPage
    data = [ws.title for ws in wb.worksheets if ws.title not in printed]
    shot_sheets = {wb.worksheets[0].title} if kind in SHOT_FIRST else set()
    last_report = max(wb.sheetnames.index(t) for t in printed)
    assert all(wb.sheetnames.index(t) > last_report for t in data if t not in shot_sheets), \
        (kind, wb.sheetnames)
    if not shot_sheets:
        assert active.title == printed[0]
    long = [(c.coordinate, c.value) for row in active.iter_rows() for c in row
            if isinstance(c.value, float) and c.number_format == "General"
            and significant_digits(c.value) > MAX_DIGITS]
    assert long == [], (kind, long)


@pytest.mark.parametrize("kind", sorted(MACRO_LAYOUT))
def test_a_workbook_in_the_macros_layout_opens_on_its_summary(workbooks, kind):
    """Issue 46: it opens on its Summary (it opened on the raw parameter block, '5E-06',
    '-6.084E+09'); Sheet 1 stays first and prints its parameter block on one page, and no
    number on it, the macro's result columns included, is a General number past 7 digits."""
    path = workbooks[kind]
    wb = openpyxl.load_workbook(path)
    assert wb.active.title == "Summary" and wb.sheetnames[0] == "Sheet1"
    assert "Sheet1" in [ws.title for ws, _ in report_sheets(path)]
    long, numbers = [], 0
    for row in wb["Sheet1"].iter_rows():
        for c in row:
            if isinstance(c.value, (int, float)) and not isinstance(c.value, bool):
                numbers += 1
                if c.number_format == "General" and significant_digits(c.value) > MAX_DIGITS:
                    long.append((c.coordinate, c.value))
    assert numbers > 10_000 and long == [], (kind, long[:5])


#: Debian's python3, the one python3-uno is built for (the venv's cannot import it).
UNO_PYTHON = "/usr/bin/python3"


def _has_uno():
    if not (shutil.which("soffice") and os.path.exists(UNO_PYTHON)):
        return False
    return subprocess.run([UNO_PYTHON, "-c", "import uno"], capture_output=True,
                          check=False).returncode == 0


def test_the_default_print_is_the_report_pages_and_no_data(workbooks, lo_print):
    """Issue 46: printed as a user prints it (open, Ctrl+P, OK), every workbook gives its
    report pages, each once, in tab order, and no data page: LibreOffice itself counts the
    pages of its default print (tests/lo_default_print.py). The fill's gave 688 pages (5
    report pages, then Tracked, Spectrum and ChartData); each data sheet still prints all its
    pages when printed by itself, and each report page one page."""
    kinds = sorted(ALL_KINDS)
    printed = [lo_print[k] for k in kinds]
    for kind, r in zip(kinds, printed, strict=True):
        path = workbooks[kind]
        # the print dialog's default is "Selected sheets" while this setting is false, as
        # LibreOffice ships it (docs/output.md says how to check it)
        assert r["all_sheets_default"] is False
        sheets = openpyxl.load_workbook(path, read_only=True).sheetnames
        report = [ws.title for ws, _ in report_sheets(path)]
        if kind in SHOT_FIRST:
            report.remove(sheets[0])
        data = [ws.title for ws, _ in data_sheets(path)]
        assert r["default"] == report, (kind, r["default"], report)
        assert r["active"] in report, (kind, r["active"])
        assert r["active"] == ("Summary" if kind in MACRO_LAYOUT else
                               "Calibration" if kind.startswith("calibrate") else report[0])
        assert all(r["alone"][t] == 1 for t in report), (kind, r["alone"])
        assert all(r["alone"][t] >= 1 for t in data), (kind, r["alone"])
        assert r["every_sheet"] == sum(r["alone"].values()), kind
    fill = printed[kinds.index("fill")]
    # shot A's data sheets print hundreds of pages (Tracked and ChartData, 12,000 rows each)
    assert fill["every_sheet"] > 100 * len(fill["default"]), fill


def test_the_template_opens_on_sheet1_alone(tmp_path):
    """The template is the macro's input and the user's form: it opens on sheet 1 and no
    other sheet is selected with it (grouped, what a user types on sheet 1 would be written
    on the Specification sheet too, and the legacy macro, which reads the active sheet, would
    not read sheet 1)."""
    from airgun_xl.cli import main

    path = tmp_path / "t.xlsx"
    assert main(["template", str(path)]) == 0
    wb = openpyxl.load_workbook(path)
    assert wb.active.title == wb.sheetnames[0] == "Sheet1"
    assert [ws.title for ws in wb.worksheets if ws.sheet_view.tabSelected] == ["Sheet1"]


def test_a_sweeps_warning_counts_sit_at_their_texts_top(workbooks):
    """Each warning's count is top-aligned beside its wrapped text (it sat at the bottom of
    a row several lines tall, beside the next warning's first line); the grid's shots have
    warnings (the Monte Carlo's here have none)."""
    kind = "grid"
    ws = openpyxl.load_workbook(workbooks[kind])["Warnings"]
    rows = [r for r in range(1, ws.max_row + 1)
            if isinstance(ws.cell(r, 1).value, int) and isinstance(ws.cell(r, 2).value, str)]
    assert rows, kind  # the study has warnings to count
    assert all(ws.cell(r, 1).alignment.vertical == "top" for r in rows), kind
