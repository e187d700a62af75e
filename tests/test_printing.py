"""Issue 10: output a test engineer reads and prints.

The page counts come from LibreOffice's PDF export, which prints every sheet: report sheets on
one page each, first; then each data sheet by itself, its pages numbered (issue 35; before,
a data sheet printed nothing) (airgun_xl/xlsx/report.py).
"""
import re
import shutil
import subprocess
import zipfile

import numpy as np
import openpyxl
import pytest
from conftest import CASES, REFERENCE, TEMPLATE, write_trace_csv

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.engine.summary import summarize

needs_lo = pytest.mark.skipif(not (shutil.which("soffice") and shutil.which("pdftotext")),
                              reason="needs LibreOffice and poppler-utils")


def _pdf_pages(path, tmp_path):
    """The text of each page of LibreOffice's PDF of ``path``."""
    done = subprocess.run(["soffice", f"-env:UserInstallation=file://{tmp_path}/lo",
                           "--headless", "--convert-to", "pdf", "--outdir", str(tmp_path),
                           str(path)], capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    pdf = tmp_path / (path.stem + ".pdf")
    text = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                          text=True, check=True).stdout
    return text.split("\f")[:-1]  # pdftotext ends every page with a form feed


def _split_pages(pages):
    """(report pages, {data sheet: its pages}): a data sheet's pages are numbered in the
    footer, its name at the footer's right; the report pages come first."""
    numbered = [re.search(r"Page \d+ of \d+", p) is not None for p in pages]
    first = numbered.index(True) if True in numbered else len(pages)
    assert all(numbered[first:]), "a report page after a data sheet"
    data: dict = {}
    for page in pages[first:]:
        data.setdefault(re.split(r"\s{2,}", page.strip().splitlines()[-1])[-1], []).append(page)
    return pages[:first], data


@needs_lo
def test_fill_prints_its_five_report_pages_then_its_data(tmp_path):
    """Sheet 1's parameter block (not its result columns), Parameters, Summary, Charts,
    Outputs: one page each, first (the workbook printed 1,303 pages before issue 10). Then
    Tracked, Spectrum and ChartData, each by itself, its header row on every page."""
    out = tmp_path / "shot.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--compare-models"]) == 0
    report, data = _split_pages(_pdf_pages(out, tmp_path))
    assert len(report) == 5
    assert "Damping Factor (Zeta)" in report[0] and "Y33 (Test Item)" not in report[0]
    assert "###" not in report[0]  # every number fits its column
    assert "Damping Factor (Zeta)" in report[1]
    assert re.search(r"Peak acceleration \(raw\)\s+11\.994 kG", report[2])
    assert re.search(r"Time of peak\s+0\.2885 ms", report[2])
    assert re.search(r"Time step\s+0\.500 µs", report[2])
    assert "Charts of this shot" in report[3] and "Acceleration, rigid model" in report[3]
    assert re.search(r"positions\s+TRUE", report[4]) and not re.search(r"positions\s+1 ",
                                                                         report[4])
    assert list(data) == ["Tracked", "Spectrum", "ChartData"]
    assert all("Time (s)" in page and "M1 (kg)" in page for page in data["Tracked"])
    assert all("Frequency (Hz)" in page for page in data["Spectrum"])
    # 12,002 rows of Tracked, a few dozen a page (at the scale one page wide allows)
    assert 100 < len(data["Tracked"]) < 600


@needs_lo
def test_diff_report_prints_its_table_and_whole_chart(tmp_path):
    case = CASES["low_velocity_60"]
    new = tmp_path / "new.xlsx"
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(new), "--only",
                 "positions,crush,accel,filtered"]) == 0
    report = tmp_path / "report.xlsx"
    main(["diff", str(REFERENCE / case["legacy_output"]), str(new), "--report", str(report)])
    pages = _pdf_pages(report, tmp_path)
    assert len(pages) == 2
    assert "Max relative" in pages[0] and "Worst column" in pages[1]
    assert "Worst column" in pages[1]


def test_summary_values_are_in_their_shown_units_with_fitting_formats(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--only", "summary"]) == 0
    ws = openpyxl.load_workbook(out)["Summary"]
    rows = {r[0].value: r for r in ws.iter_rows(min_row=2)}
    result = airgun_xl.load(TEMPLATE).run()
    s = summarize(result)
    expected = {  # label: (value in the shown unit, unit, number format)
        "Peak acceleration (raw)": (s.peak_kg, "kG", "0.000"),
        "Time of peak": (s.time_of_peak * 1e3, "ms", "0.0000"),
        "Dominant frequency 1": (s.spectrum.peaks[0] * 1e-3, "kHz", "0.00"),
        "Maximum crush": (s.max_crush, "m", "0.0000"),
        "Rows": (12_002, None, "#,##0"),
    }
    for label, (value, unit, fmt) in expected.items():
        cell, unit_cell = rows[label][1], rows[label][2]
        # xlsxwriter writes a lone number with 16 significant digits: 1e-15 covers it
        assert cell.value == pytest.approx(value, rel=1e-15)
        assert unit_cell.value == unit and cell.number_format == fmt
    assert ws.print_area == "'Summary'!$A$1:$D$" + str(ws.max_row)
    assert ws.page_setup.orientation == "landscape" and ws.sheet_properties.pageSetUpPr.fitToPage


def _chartdata_bytes(path):
    with zipfile.ZipFile(path) as z:
        sheets = openpyxl.load_workbook(path, read_only=True).sheetnames
        return z.getinfo(f"xl/worksheets/sheet{sheets.index('ChartData') + 1}.xml").file_size


def test_every_shrinks_chartdata_and_keeps_the_peak(tmp_path):
    """--every 10 thins ChartData's copies to the rows kept on the sheets (min and max of each
    bucket), so the peak survives exactly."""
    full, tenth = tmp_path / "a.xlsx", tmp_path / "b.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(full)]) == 0
    assert main(["fill", str(TEMPLATE), "-o", str(tenth), "--every", "10"]) == 0
    assert _chartdata_bytes(tenth) < 0.5 * _chartdata_bytes(full)
    ws = openpyxl.load_workbook(tenth, read_only=True)["ChartData"]
    rows = list(ws.iter_rows(min_row=2, values_only=True))
    col = rows[0].index("accel_kg")
    values = [r[col] for r in rows[1:] if r[col] is not None]
    assert len(values) <= 1_201 and max(values) == airgun_xl.load(TEMPLATE).run().peak_kg


def test_spectrum_chart_from_the_lobe_end_with_its_dominant_and_natural_marks(tmp_path):
    """Issue 18.9: the chart's curve starts where the pulse's own lobe ends (shot A: 1.83 kHz,
    past the 1.33 kHz shoulder that used to be its tallest peak), its axis at the whole kHz
    below (issue 46: ticks on round kHz, 1, 3, 5..., not 1.8, 3.8, 5.8), and it marks the
    Summary's dominant frequencies, the same numbers as the Summary's rows."""
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out)]) == 0
    with zipfile.ZipFile(out) as z:
        xml = next(z.read(n).decode() for n in z.namelist()
                   if n.startswith("xl/charts/chart") and b"FFT" in z.read(n))
    assert '<c:min val="1000.0"/>' in xml and '<c:max val="15000.0"/>' in xml
    spectrum = summarize(airgun_xl.load(TEMPLATE).run()).spectrum
    first = 1 + int(np.searchsorted(spectrum.frequency, spectrum.band_start))  # its sheet row
    assert f"<c:f>Spectrum!$A${first + 1}:" in xml  # the curve from the lobe's end
    assert spectrum.frequency[first - 2] < spectrum.band_start <= spectrum.frequency[first - 1]
    assert "OBR chain natural frequencies (initial masses)" in xml
    assert "Dominant frequencies (the Summary's)" in xml
    summary = {r[0]: r[1] for r in openpyxl.load_workbook(out, read_only=True)[
        "Summary"].iter_rows(values_only=True) if r and r[0]}
    reported = [round(summary[f"Dominant frequency {i}"], 2) for i in (1, 2, 3)]  # kHz
    data = openpyxl.load_workbook(out, read_only=True)["ChartData"]
    rows = list(data.iter_rows(min_row=2, values_only=True))
    col = rows[0].index("dominant")
    marked = [r[col - 1] for r in rows[1:] if r[col - 1] is not None]
    assert [round(f / 1e3, 2) for f in marked] == reported == [5.33, 4.83, 9.0]
    spectrum = summarize(airgun_xl.load(TEMPLATE).run()).spectrum
    shown = spectrum.frequency >= 1800
    tallest = spectrum.frequency[shown][np.argmax(spectrum.amplitude[shown])]
    assert tallest > 2000  # the lobe's 1.33 kHz shoulder is off the chart
    ws = openpyxl.load_workbook(out, read_only=True)["ChartData"]
    rows = list(ws.iter_rows(min_row=2, values_only=True))
    col = rows[0].index("natural")
    marks = sorted({r[col - 1] for r in rows[1:] if r[col - 1] is not None})
    natural = summarize(airgun_xl.load(TEMPLATE).run()).natural_initial
    np.testing.assert_array_equal(marks, sorted(natural))


@needs_lo
def test_compare_and_calibration_workbooks_print_their_reports(tmp_path):
    """compare-measured: two pages, the scores and the rating, then the three charts; then its
    data sheets. calibrate: the shot's sheet 1, its parameters, its Outputs block, the Crush
    law and the Calibration report, a page each; then the Law and Pulses data. LibreOffice
    opens both (the PDF is its reading)."""
    from airgun_xl.studies.calibrate import synthetic_measurement

    p = airgun_xl.load(TEMPLATE).params
    trace = synthetic_measurement(p.replace(sigmay=p.sigmay * 1.05), seed=5)
    m = write_trace_csv(tmp_path / "m.csv", trace)
    compared = tmp_path / "compared.xlsx"
    assert main(["compare-measured", str(TEMPLATE), str(m), "--cfc", "1000", "-o",
                 str(compared)]) == 0
    pages, data = _split_pages(_pdf_pages(compared, tmp_path))
    assert len(pages) == 2 and list(data) == ["Traces", "Spectra", "SRS"]
    assert re.search(r"Overall rating R\s+0\.9\d\d", pages[0])
    assert "Test against prediction (Fig. 13)" in pages[1]
    calibrated = tmp_path / "calibrated.xlsx"
    assert main(["calibrate", str(TEMPLATE), str(m), "--cfc", "1000", "-o",
                 str(calibrated)]) == 0
    pages, data = _split_pages(_pdf_pages(calibrated, tmp_path))
    assert len(pages) == 5 and list(data) == ["Law", "Pulses"]
    assert "Damping Factor (Zeta)" in pages[0] and "Damping Factor (Zeta)" in pages[1]
    assert re.search(r"positions\s+TRUE", pages[2])
    assert re.search(r"Law\s+fitted", pages[3])
    assert "Crush-law iteration" in pages[4] and "Figs. 7-8" in pages[4]
