"""Issue 46 (first part): what the report pages show at print size. A grid over an input of
many levels draws a family of at most 7 curves, each a line without markers when it has
many points; a wrapped text's row is sized to its lines; the campaign's title counts once;
the Newmark Summary's critical-step cells (tests/test_numerics.py)."""
import re
import zipfile

import openpyxl
import xlsxwriter
from conftest import TEMPLATE

from airgun_xl.cli import main
from airgun_xl.xlsx.report import LINE_POINTS, fit_wrapped_row


def test_a_grid_over_many_levels_draws_seven_curves_of_lines(tmp_path):
    """--vary A28=150:250:41 --vary E40=2.5e7:3e7:5: the peak against A28 is 5 curves (one
    per E40 level) of 41 points each, drawn as lines (markers would merge into a band);
    against E40, A28's 41 levels are too many for a legend: 7 of them, evenly spaced from
    150 to 250 m/s, one curve each of 5 points with markers, the title saying so."""
    out = tmp_path / "grid.xlsx"
    assert main(["sweep", str(TEMPLATE), "--vary", "A28=150:250:41", "--vary",
                 "E40=2.5e7:3e7:5", "-o", str(out), "--quiet"]) == 0
    with zipfile.ZipFile(out) as z:
        names = sorted(n for n in z.namelist() if re.fullmatch(r"xl/charts/chart\d+\.xml", n))
        xml = [z.read(n).decode() for n in names]
    assert [x.count("<c:ser>") for x in xml] == [5, 7]
    against_a28, against_e40 = xml
    assert against_a28.count('<c:symbol val="none"/>') == 5  # lines, no markers
    assert against_e40.count('<c:symbol val="circle"/>') == 7
    assert "7 of the 41 levels of A28" in against_e40
    assert "A28 = 150 m/s" in against_e40 and "A28 = 250 m/s" in against_e40
    assert "A28 = 200 m/s" in against_e40  # the middle level: evenly spaced


def test_a_wrapped_text_sizes_its_row_to_its_lines(tmp_path):
    """Three lines of a 100-character column for 250 characters; one line keeps the
    default height (no row written)."""
    path = tmp_path / "w.xlsx"
    wb = xlsxwriter.Workbook(path)
    ws = wb.add_worksheet()
    fit_wrapped_row(ws, 0, "x" * 250, 100)
    fit_wrapped_row(ws, 1, "x" * 100, 100)
    wb.close()
    rows = openpyxl.load_workbook(path).active.row_dimensions
    assert rows[1].height == 3 * LINE_POINTS and rows[2].height is None


def test_the_campaigns_title_counts_its_shots_once(tmp_path):
    day = tmp_path / "day"
    day.mkdir()
    for name in ("a", "b"):
        (day / f"{name}.xlsx").write_bytes(TEMPLATE.read_bytes())
    (day / "c.xlsx").write_bytes(b"not a workbook")
    summary = tmp_path / "campaign.xlsx"
    assert main(["fill", str(day), "--jobs", "1", "--summary", str(summary), "--quiet"]) == 2
    cells = [c for row in openpyxl.load_workbook(summary).worksheets[0].iter_rows(
        values_only=True) for c in row if isinstance(c, str)]
    # exit 2: a shot failed (each said); the summary is still written, with its count
    assert "Campaign of 3 shots by airgun-xl: 2 filled, 1 failed, 0 skipped" in cells, cells
