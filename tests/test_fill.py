"""`airgun-xl fill` and `airgun-xl template` end to end, in-process."""
import hashlib
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import openpyxl
import pytest
import xlsxwriter
from conftest import LEGACY_RTOL, REFERENCE, ROOT, TEMPLATE, column, sheet_values

import airgun_xl
from airgun_xl.cli import main

DATA = Path(__file__).parent / "data"


def _set(path, **cells):
    wb = openpyxl.load_workbook(path)
    for address, value in cells.items():
        wb.worksheets[0][address] = value
    wb.save(path)


def test_fill_writes_beside_the_input_and_leaves_it_alone(shot_copy, capsys):
    before = hashlib.sha256(shot_copy.read_bytes()).hexdigest()
    assert main(["fill", str(shot_copy)]) == 0
    out = shot_copy.with_name("shot.out.xlsx")
    assert out.is_file()
    assert hashlib.sha256(shot_copy.read_bytes()).hexdigest() == before
    printed = capsys.readouterr().out
    assert "12,002 rows" in printed and "11.99446 kG" in printed


def test_template_at_half_a_microsecond_has_12002_rows(shot_copy, tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(out)]) == 0
    cells = sheet_values(out)
    assert max(r for r, c in cells if c == "H") == 12_003  # header + 12,002 rows
    # time accumulates by 12,001 additions, each rounding by at most half an ulp of the
    # running sum (4.3e-19 near 0.006): at most 5.2e-15 off
    assert cells[(12_003, "H")] == pytest.approx(0.006, abs=5.2e-15)


def test_template_at_five_microseconds_peaks_at_the_report_figure(shot_copy, tmp_path):
    """The report's appendix prints Max Accel 11.99257 kG at dt = 5 us (shared notes)."""
    _set(shot_copy, E2=5e-6)
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(out)]) == 0
    kg = column(sheet_values(out), "U", 1202)
    assert round(np.nanmax(kg), 5) == 11.99257


def test_force_overwrites(shot_copy, tmp_path):
    out = tmp_path / "o.xlsx"
    out.write_bytes(b"old")
    assert main(["fill", str(shot_copy), "-o", str(out), "--force"]) == 0
    assert zipfile.is_zipfile(out)


def test_output_is_deterministic(shot_copy, tmp_path):
    """Equal inputs give equal bytes with --reproducible; otherwise only the run times differ."""
    a, b = tmp_path / "a.xlsx", tmp_path / "b.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(a), "--reproducible"]) == 0
    assert main(["fill", str(shot_copy), "-o", str(b), "--reproducible"]) == 0
    assert a.read_bytes() == b.read_bytes()
    c, d = tmp_path / "c.xlsx", tmp_path / "d.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(c)]) == 0
    assert main(["fill", str(shot_copy), "-o", str(d)]) == 0
    wc, wd = openpyxl.load_workbook(c), openpyxl.load_workbook(d)
    differ = {(ws.title, cell.coordinate) for ws in wc.worksheets for row in ws.iter_rows()
              for cell in row if cell.value != wd[ws.title][cell.coordinate].value}
    labels = {wc["Summary"][f"A{coord[1:]}"].value for _, coord in differ}
    assert {s for s, _ in differ} <= {"Summary"} and labels <= {"Kernel run time", "Run time"}
    with zipfile.ZipFile(a) as z:
        core = z.read("docProps/core.xml").decode()
    assert "2005-08-01T00:00:00Z" in core


def test_parameter_block_is_copied_with_formulas(shot_copy, tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(out)]) == 0
    given = openpyxl.load_workbook(TEMPLATE).worksheets[0]
    written = openpyxl.load_workbook(out).worksheets[0]
    for row in given.iter_rows(max_col=7):
        for cell in row:
            assert written[cell.coordinate].value == cell.value, cell.coordinate
    assert written["E25"].value == "=E10*E22"
    cached = openpyxl.load_workbook(out, data_only=True).worksheets[0]
    assert cached["E25"].value == pytest.approx(385 * 0.022739834, rel=1e-15)
    assert cached["A22"].value == pytest.approx(1 / (680.388555 + 385 * 0.022739834), rel=1e-15)


def test_parameters_round_trip_exactly(shot_copy, tmp_path):
    """A value needing 17 digits (0.1 + 0.2) comes back bit for bit.

    openpyxl and xlsxwriter both round it when writing, so the input is edited as XML.
    """
    with zipfile.ZipFile(TEMPLATE) as src, zipfile.ZipFile(shot_copy, "w") as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == "xl/worksheets/sheet1.xml":
                old = b'<c r="E43"><v>0.02</v></c>'
                assert old in data
                data = data.replace(old, b'<c r="E43"><v>0.30000000000000004</v></c>')
            dst.writestr(item, data)
    assert airgun_xl.load(shot_copy).params.zeta == 0.1 + 0.2
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(out)]) == 0
    assert openpyxl.load_workbook(out).worksheets[0]["E43"].value == 0.30000000000000004
    assert airgun_xl.load(out).params == airgun_xl.load(shot_copy).params


def test_an_old_workbook_with_results_is_recomputed(tmp_path):
    """Filling the macro's own output gives the same numbers as filling its input."""
    case = "shot_a_appendix_5us"
    old, fresh = tmp_path / "old.xlsx", tmp_path / "fresh.xlsx"
    assert main(["fill", str(REFERENCE / f"{case}_legacy.xlsx"), "-o", str(old)]) == 0
    assert main(["fill", str(REFERENCE / f"{case}_input.xlsx"), "-o", str(fresh)]) == 0
    a, b = sheet_values(old), sheet_values(fresh)
    assert {k: v for k, v in a.items() if k[1] >= "H" or len(k[1]) > 1} == \
        {k: v for k, v in b.items() if k[1] >= "H" or len(k[1]) > 1}


def test_xls_input(tmp_path):
    """A .xls (LibreOffice's conversion of the template at 5 us) reads through calamine."""
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(DATA / "shot_a_5us.xls"), "-o", str(out)]) == 0
    kg = column(sheet_values(out), "U", 1202)
    assert round(np.nanmax(kg), 5) == 11.99257


def test_stale_cached_value_is_reported(tmp_path, capsys):
    """xlsxwriter caches 0 for a formula unless told otherwise: say so, use the evaluation."""
    shot = tmp_path / "shot.xlsx"
    src = openpyxl.load_workbook(TEMPLATE).worksheets[0]
    wb = xlsxwriter.Workbook(str(shot))
    ws = wb.add_worksheet()
    for row in src.iter_rows():
        for cell in row:
            if isinstance(cell.value, str) and cell.value.startswith("="):
                ws.write_formula(cell.coordinate, cell.value)  # cached value 0
            elif cell.value is not None:
                ws.write(cell.coordinate, cell.value)
    wb.close()
    shot_obj = airgun_xl.load(shot)
    assert shot_obj.params.mmitigator == pytest.approx(8.75483609, rel=1e-15)
    assert any(w.startswith("E25 (Mass of Mitigator): the cached value 0 disagrees with "
                            "=E10*E22") for w in shot_obj.warnings)
    assert main(["fill", str(shot), "-o", str(tmp_path / "o.xlsx")]) == 0
    assert "warning: E25 (Mass of Mitigator): the cached value 0 disagrees" in \
        capsys.readouterr().err


def test_missing_cached_values_are_evaluated_quietly(shot_copy):
    """openpyxl writes formulas without cached values: evaluate them, no warning."""
    _set(shot_copy, E2="=1/200000")
    shot = airgun_xl.load(shot_copy)
    assert shot.params.delta == 5e-6
    assert shot.warnings == []


def test_template_command_matches_the_committed_template(tmp_path):
    out = tmp_path / "t.xlsx"
    assert main(["template", str(out)]) == 0
    for data_only in (False, True):
        a = openpyxl.load_workbook(out, data_only=data_only)
        b = openpyxl.load_workbook(TEMPLATE, data_only=data_only)
        assert a.sheetnames == b.sheetnames == ["Sheet1", "Outputs", "Specification"]
        for sa, sb in zip(a.worksheets, b.worksheets, strict=True):
            assert [[c.value for c in r] for r in sa.iter_rows()] == \
                [[c.value for c in r] for r in sb.iter_rows()]


def test_api_to_frame():
    result = airgun_xl.load(REFERENCE / "shot_a_appendix_5us_input.xlsx").run()
    frame = result.to_frame()
    assert len(frame) == 1202 and frame.index.name == "time"
    assert frame["accel_kg"].max() == result.peak_kg
    assert round(result.peak_kg, 5) == 11.99257
    assert frame.attrs["units"]["force"] == "N"
    assert frame["filtered_accel"].notna().sum() == 34
    legacy = sheet_values(REFERENCE / "shot_a_appendix_5us_legacy.xlsx")
    np.testing.assert_allclose(frame["y33"], column(legacy, "L", 1202), rtol=0,
                               atol=LEGACY_RTOL * np.abs(frame["y33"]).max())


@pytest.mark.skipif(shutil.which("soffice") is None, reason="LibreOffice is not installed")
def test_libreoffice_reads_the_output(shot_copy, tmp_path):
    """LibreOffice opens the output without complaint and sees our cached values."""
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot_copy), "-o", str(out)]) == 0
    done = subprocess.run(["soffice", f"-env:UserInstallation=file://{tmp_path}/lo",
                           "--headless", "--convert-to", "csv", "--outdir", str(tmp_path),
                           str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = (tmp_path / "o.csv").read_text().splitlines()
    assert rows[0].split(",")[7] == "Time"
    assert rows[24].split(",")[4] == "8.75483609"  # E25 as cached
    assert float(rows[3].split(",")[12]) == pytest.approx(3.42657950207454, rel=1e-9)


@pytest.mark.skipif(shutil.which("soffice") is None, reason="LibreOffice is not installed")
def test_libreoffice_reads_the_template(tmp_path):
    """The committed template opens in LibreOffice with its cached formula values."""
    done = subprocess.run(["soffice", f"-env:UserInstallation=file://{tmp_path}/lo",
                           "--headless", "--convert-to", "csv", "--outdir", str(tmp_path),
                           str(TEMPLATE)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = [r.split(",") for r in (tmp_path / "shot_a.csv").read_text().splitlines()]
    assert rows[24][4] == "8.75483609"  # E25 = E10*E22
    assert rows[28][0] == "243.53532"  # A29 = A28
    assert float(rows[21][0]) == pytest.approx(1 / (680.388555 + 8.75483609), rel=1e-13)  # A22


def test_readme_names_the_setup_commands():
    text = (ROOT / "README.md").read_text()
    assert "airgun-xl fill templates/shot_a.xlsx" in text
