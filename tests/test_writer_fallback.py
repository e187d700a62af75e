"""Issue 11: the fast sheet writer uses xlsxwriter internals; without them (another
xlsxwriter), ColumnsWorksheet writes through the public write_number to the same values."""
import openpyxl
import pytest
from conftest import TEMPLATE

from airgun_xl.cli import main
from airgun_xl.xlsx import columns_sheet


def _cells(path):
    """{(sheet, row, col): value} of every sheet but the run-time Summary cells."""
    wb = openpyxl.load_workbook(path, read_only=True)
    out = {}
    for ws in wb.worksheets:
        for row in ws.iter_rows():
            for c in row:
                if c.value is not None and hasattr(c, "column"):
                    out[(ws.title, c.row, c.column)] = c.value
    return out


def test_public_path_writes_the_same_cells(tmp_path, monkeypatch):
    fast, public = tmp_path / "fast.xlsx", tmp_path / "public.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(fast), "--reproducible", "--every", "3"]) == 0
    monkeypatch.setattr(columns_sheet, "FAST", False)
    assert main(["fill", str(TEMPLATE), "-o", str(public), "--reproducible", "--every",
                 "3"]) == 0
    a, b = _cells(fast), _cells(public)
    assert a.keys() == b.keys() and len(a) > 50_000
    if _public_path_is_exact(tmp_path):  # xlsxwriter >= 3.2 formats with format(): Exact
        assert all(a[k] == b[k] for k in a)
    else:  # 3.1.x formats with '%.16G' %: 16 digits, 1e-15 relative at most
        assert all(a[k] == pytest.approx(b[k], rel=1e-15) if isinstance(a[k], float)
                   else a[k] == b[k] for k in a)


def _public_path_is_exact(tmp_path):
    import xlsxwriter

    path = tmp_path / "probe.xlsx"
    wb = xlsxwriter.Workbook(str(path))
    wb.add_worksheet().write_number(0, 0, columns_sheet.Exact(0.1 + 0.2))
    wb.close()
    return openpyxl.load_workbook(path).active["A1"].value == 0.1 + 0.2


@pytest.mark.parametrize("x", [0.1, 1 / 3, 2.0 ** -1074, 1.7976931348623157e308, -5e-7])
def test_exact_formats_17_digits(x):
    assert float(f"{columns_sheet.Exact(x):.16G}") == x
    assert float(f"{x:.16G}") == x or f"{x:.16G}" != f"{columns_sheet.Exact(x):.16G}"


def test_row_properties_before_and_after_xlsxwriter_3_3():
    class Old:
        set_rows = {3: [15, None]}

    class New:
        row_info = {4: "info"}
        set_rows = {}

    assert columns_sheet._row_properties(Old()) == {3: [15, None]}
    assert columns_sheet._row_properties(New()) == {4: "info"}
