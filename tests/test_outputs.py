"""Issue 3: tracked values, charts, the Summary sheet, output selection, reduced models and
the sheet limit with its sidecar."""
import hashlib
import re
import shutil
import subprocess
import zipfile

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE, column, sheet_values

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.outputs import SHEET_DATA_ROWS, Outputs
from airgun_xl.reports import sidecar as sidecar_module
from airgun_xl.xlsx.columns_sheet import ColumnsWorksheet


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The template filled with the default outputs, and the same shot run by the API."""
    out = tmp_path_factory.mktemp("full") / "shot_a.out.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out)]) == 0
    return out, airgun_xl.load(TEMPLATE).run()


def _summary(path):
    ws = openpyxl.load_workbook(path, data_only=True)["Summary"]
    return {r[0].value: (r[1].value, r[2].value, r[3].value) for r in ws.iter_rows(min_row=2)}


def _set(path, sheet=0, **cells):
    wb = openpyxl.load_workbook(path)
    ws = wb.worksheets[sheet] if isinstance(sheet, int) else wb[sheet]
    for address, value in cells.items():
        ws[address] = value
    wb.save(path)


def test_sheets_in_order(full):
    """The macro's sheet first; the report pages; the data sheets after them (issue 35)."""
    out, _ = full
    assert openpyxl.load_workbook(out, read_only=True).sheetnames == [
        "Sheet1", "Parameters", "Summary", "Charts", "Outputs", "Tracked", "Spectrum",
        "ChartData"]


def test_six_charts_with_titles_axis_titles_and_explicit_ranges(full):
    """Every axis has a title and an explicit range; the displacements chart has a second
    value axis (Y32, Y33 relative to Y31), so a chart title and three axes there."""
    out, _ = full
    with zipfile.ZipFile(out) as z:
        charts = sorted(n for n in z.namelist() if re.fullmatch(r"xl/charts/chart\d+\.xml", n))
        assert len(charts) == 6
        for name in charts:
            xml = z.read(name).decode()
            axes = xml.count("<c:valAx>")
            assert axes in (2, 4), name  # x and y; or x, y and the hidden x of y2, and y2
            titled = 3 if axes == 2 else 4
            assert xml.count("<c:title>") == titled, name
            assert xml.count("<c:min ") == xml.count("<c:max ") == titled - 1, name
            assert "<c:scatterChart>" in xml


def test_summary_matches_the_report_figures(full):
    """Shared notes, shot A at dt <= 1 us: 11.99 kG near 0.29 ms, crush 0.506 m (final length
    0.395 m), a pulse of about 5 ms (0.05-5.04 ms at >= 10 %), OBR modes near 6 and 12 kHz."""
    out, result = full
    s = _summary(out)
    assert s["Peak acceleration (raw)"][0] == pytest.approx(11.99446, abs=5e-6)
    assert s["Peak acceleration (raw)"][0] == result.peak_kg
    assert s["Time of peak"][:2] == (pytest.approx(0.29, abs=0.01), "ms")
    assert s["Pulse start"][0] == pytest.approx(0.05, abs=0.01)
    assert s["Pulse end"][0] == pytest.approx(5.04, abs=0.01)
    assert "10%" in s["Pulse duration"][2]
    assert s["Maximum crush"][0] == pytest.approx(0.506, abs=5e-4)
    assert s["Final mitigator length"][0] == pytest.approx(0.395, abs=5e-4)
    assert s["Dominant frequency 1"][1] == "kHz" and 5 <= s["Dominant frequency 1"][0] <= 6
    assert 11 <= s["OBR chain natural frequency 2 (initial masses)"][0] <= 12.5
    assert s["Final M1"][0] == result.history.final_m1
    assert s["Rows"][0] == 12_002
    assert s["Time step"][:2] == (pytest.approx(0.5, rel=1e-15), "µs")  # 5e-7 s x 1e6
    assert s["Input SHA-256"][0] == hashlib.sha256(TEMPLATE.read_bytes()).hexdigest()
    assert s["Engine version"][0] == airgun_xl.__version__
    assert s["Model"][0].startswith("4-mass")
    assert s["Kernel run time"][1] == "s"


def test_tracked_sheet_holds_the_kernel_values(full):
    out, result = full
    ws = openpyxl.load_workbook(out, read_only=True)["Tracked"]
    rows = list(ws.iter_rows(values_only=True))
    assert rows[0] == ("Time (s)", "Mitigator force (N)", "Plastic wave front x_p (m)",
                       "Mitigator deflection (m)", "M1 (kg)", "m31 (kg)",
                       "OBR front plate velocity (m/s)", "MEM velocity (m/s)")
    data = np.array([[np.nan if v is None else v for v in r] for r in rows[1:]], dtype=float)
    h = result.history
    for col, values in enumerate((h.time, h.force, h.x_plastic, h.deflection, h.m1, h.m31,
                                  h.v31, h.v1)):
        np.testing.assert_array_equal(data[:, col], values)  # 17 digits: exact
    assert data[1, 6] == pytest.approx(243.53532, rel=1e-6)  # OBR leaves at v0


def test_spectrum_sheet_is_numpys_fft(full):
    out, result = full
    ws = openpyxl.load_workbook(out, read_only=True)["Spectrum"]
    rows = [r for r in ws.iter_rows(min_row=2, values_only=True) if r[0] is not None]
    freq = np.array([r[0] for r in rows])
    a = result.accel_kg[1:-1]
    expected = np.abs(np.fft.rfft(a)) * 2 / len(a)
    expected[0] /= 2
    assert freq[-1] <= 15_000 and freq[1] == pytest.approx(1 / (len(a) * 5e-7))
    np.testing.assert_allclose([r[1] for r in rows], expected[:len(rows)], rtol=1e-12)


@pytest.mark.skipif(not (shutil.which("soffice") and shutil.which("pdftoppm")),
                    reason="needs LibreOffice and poppler-utils")
def test_libreoffice_renders_every_chart(full, tmp_path):
    """Convert the output to PDF in LibreOffice, find the Charts page, and check that each of
    the six chart cells has its first series drawn (#1f4e79 lines)."""
    out, _ = full
    done = subprocess.run(["soffice", f"-env:UserInstallation=file://{tmp_path}/lo",
                           "--headless", "--convert-to", "pdf", "--outdir", str(tmp_path),
                           str(out)], capture_output=True, text=True, timeout=900, check=False)
    assert done.returncode == 0, done.stderr
    pdf = tmp_path / "shot_a.out.pdf"
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True,
                          check=True).stdout.split("\f")
    page = next(i + 1 for i, t in enumerate(text) if "Charts of this shot" in t)
    subprocess.run(["pdftoppm", "-r", "100", "-f", str(page), "-l", str(page), str(pdf),
                    str(tmp_path / "charts")], check=True)
    img = _read_ppm(next(tmp_path.glob("charts*.ppm"))).astype(int)
    shutil.copy(next(tmp_path.glob("charts*.ppm")), tmp_path / "keep.ppm")
    ink = img.sum(axis=2) < 700
    ys, xs = np.nonzero(ink)
    blue = (img[..., 2] - img[..., 0] > 40) & (img[..., 2] < 200)
    height, width = (ys.max() - ys.min()) / 3, (xs.max() - xs.min()) / 2
    for r in range(3):
        for c in range(2):
            cell = blue[int(ys.min() + r * height):int(ys.min() + (r + 1) * height),
                        int(xs.min() + c * width):int(xs.min() + (c + 1) * width)]
            assert cell.sum() > 100, f"chart in row {r + 1}, column {c + 1} looks empty"


def _read_ppm(path):
    data = path.read_bytes()
    magic, w, h, _, pixels = data.split(maxsplit=4)
    assert magic == b"P6"
    return np.frombuffer(pixels[:int(w) * int(h) * 3], dtype=np.uint8).reshape(int(h), int(w), 3)


def test_only_accel_and_filtered(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--only", "accel,filtered"]) == 0
    wb = openpyxl.load_workbook(out, read_only=True)
    assert wb.sheetnames == ["Sheet1", "Outputs"]
    cells = sheet_values(out)
    letters = {c for (r, c) in cells if r == 1 and (len(c) > 1 or c >= "H")}
    assert letters == {"H", "R", "S", "T", "U", "AA", "AB"}
    assert np.nanmax(column(cells, "U", 12_002)) == pytest.approx(11.99446, abs=5e-6)
    assert (12_005, "I") not in cells  # final masses go with positions


def test_no_charts(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--no-charts"]) == 0
    with zipfile.ZipFile(out) as z:
        assert not [n for n in z.namelist() if n.startswith("xl/charts/")]
    assert "Charts" not in openpyxl.load_workbook(out, read_only=True).sheetnames


def test_every_tenth_row_and_its_sidecar(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--every", "10"]) == 0
    result = airgun_xl.load(TEMPLATE).run()
    cells = sheet_values(out)
    rows = -(-12_002 // 10)
    np.testing.assert_array_equal(column(cells, "H", rows), result.history.time[::10])
    np.testing.assert_array_equal(column(cells, "L", rows), result.history.y33[::10])
    assert (rows + 2, "H") not in cells
    assert cells[(rows + 3, "I")] == result.history.final_m1  # two rows below the last Y1
    assert _summary(out)["Every N-th row"][0] == 10
    history = _read_sidecar(tmp_path / "o.history.parquet")
    assert len(history) == 12_002
    np.testing.assert_array_equal(history["y33"], result.history.y33)
    np.testing.assert_array_equal(history["force"], result.history.force)


def _read_sidecar(path):
    import pandas as pd

    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    # round_trip: pandas < 2.2's default parser can miss the last bit of a 17-digit number;
    # pandas 3 parses exactly by default and deprecates the argument
    if int(pd.__version__.split(".")[0]) >= 3:
        return pd.read_csv(path)
    return pd.read_csv(path, float_precision="round_trip")


def test_outputs_block_in_the_workbook(tmp_path):
    shot = tmp_path / "shot.xlsx"
    shutil.copy(TEMPLATE, shot)
    wb = openpyxl.load_workbook(shot)
    row = next(r for r in range(1, 20) if wb["Outputs"][f"A{r}"].value == "charts")
    wb["Outputs"][f"B{row}"] = False
    wb.save(shot)
    assert main(["fill", str(shot)]) == 0
    names = openpyxl.load_workbook(shot.with_name("shot.out.xlsx"), read_only=True).sheetnames
    assert "Charts" not in names and "Summary" in names
    assert main(["fill", str(shot), "-o", str(tmp_path / "b.xlsx"), "--only", "charts"]) == 0
    assert "Charts" in openpyxl.load_workbook(tmp_path / "b.xlsx", read_only=True).sheetnames


def test_bad_outputs_cell_is_named(tmp_path, capsys):
    shot = tmp_path / "shot.xlsx"
    shutil.copy(TEMPLATE, shot)
    _set(shot, "Outputs", B9="maybe")
    before = shot.read_bytes()
    assert main(["fill", str(shot)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["airgun-xl: error: Outputs!B9 (charts): found 'maybe', expected TRUE or "
                   "FALSE"]
    assert shot.read_bytes() == before and not shot.with_name("shot.out.xlsx").exists()


@pytest.mark.parametrize("flags,phrase", [
    (["--only", "accel,bogus"], "--only"), (["--every", "0"], "--every"),
    (["--every", "2.5"], "--every"), (["--max-sheet-rows", "x"], "--max-sheet-rows")])
def test_bad_output_flags(tmp_path, capsys, flags, phrase):
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), *flags]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and phrase in err[0] and not list(tmp_path.iterdir())


@pytest.mark.parametrize("cells,masses,last", [
    ({"D2": None, "C6": None, "A30": None}, 2, "K"),
    ({"D2": 0, "C6": None, "C2": None, "B6": None, "A29": None, "A30": None}, 1, "J"),
])
def test_reduced_models_run(tmp_path, cells, masses, last):
    """No test item (D2, C6 blank): the model drops m33 and reports Y32's acceleration; an OBR
    of one mass drops m32 too."""
    shot = tmp_path / "shot.xlsx"
    shutil.copy(TEMPLATE, shot)
    _set(shot, **cells)
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot), "-o", str(out), "--no-charts"]) == 0
    summary = _summary(out)
    assert summary["Model"][0].startswith(f"{masses + 1}-mass")
    values = sheet_values(out)
    n = 12_002
    assert np.isnan(column(values, "L", n)).all()
    y = column(values, last, n)
    accel = column(values, "S", n)
    np.testing.assert_allclose(accel[1:-1], (y[2:] + y[:-2] - 2 * y[1:-1]) / 5e-7 ** 2,
                               rtol=1e-9, atol=1e-6)  # rounding of the re-derived difference
    assert np.nanmax(column(values, "U", n)) > 1


def test_a_long_run_fits_the_sheet_and_keeps_everything_in_the_sidecar(tmp_path):
    """dt = 5 ns over 1 ms: 200,002 rows, over the default 32,767 sheet rows."""
    shot = tmp_path / "shot.xlsx"
    shutil.copy(TEMPLATE, shot)
    _set(shot, E2=5e-9, E6=1e-3)
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot), "-o", str(out)]) == 0
    stride = 7  # ceil(200,002 / 32,767)
    summary = _summary(out)
    assert summary["Every N-th row"][0] == stride
    assert summary["Rows on the sheets"][0] == 28_572  # ceil(200,002 / 7)
    wb = openpyxl.load_workbook(out, read_only=True)
    assert wb["Sheet1"].max_row == 28_572 + 1 + 3  # header, rows, gap, final masses
    history = _read_sidecar(tmp_path / "o.history.parquet")
    result = airgun_xl.load(shot).run()
    assert len(history) == 200_002
    h = result.history
    for name, values in (("y1", h.y1), ("y33", h.y33), ("force", h.force), ("v31", h.v31),
                         ("accel_kg", result.accel_kg)):
        np.testing.assert_array_equal(history[name], values)


def test_csv_sidecar_without_pyarrow(tmp_path, monkeypatch):
    monkeypatch.setattr(sidecar_module, "have_parquet", lambda: False)
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--every", "3",
                 "--only", "summary"]) == 0
    history = _read_sidecar(tmp_path / "o.history.csv")
    assert list(history.columns[:3]) == ["time [s]", "y1 [m]", "y31 [m]"]
    result = airgun_xl.load(TEMPLATE).run()
    np.testing.assert_array_equal(history["y33 [m]"], result.history.y33)  # %.17g: exact


def test_stride_keeps_a_run_within_the_sheet():
    assert Outputs().stride(12_002) == 1
    assert Outputs(max_sheet_rows=10**9).stride(1_200_002) == 2
    assert -(-1_200_002 // 2) <= SHEET_DATA_ROWS
    assert Outputs(every=7).stride(100) == 7


def test_a_column_past_the_last_row_is_refused():
    ws = ColumnsWorksheet()
    assert ws.write_number_column(1_048_570, 0, np.ones(10)) == -1


def test_summary_only_computes_no_tracked_values(tmp_path):
    shot = airgun_xl.load(TEMPLATE)
    outputs = Outputs().with_flags(only="accel")
    result = shot.run(track=outputs.tracked_series())
    assert result.history.force is None and result.history.v31 is None
    assert outputs.tracked_series() == frozenset()
    assert Outputs().with_flags(only="summary").tracked_series() == {"deflection", "v31", "v1"}
