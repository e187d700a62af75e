"""Shared helpers: the legacy cases and reading result columns back from a workbook."""
import json
from pathlib import Path

import numpy as np
import openpyxl
import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "legacy_reference"
TEMPLATE = ROOT / "templates" / "shot_a.xlsx"
CASES = json.loads((REFERENCE / "cases.json").read_text())

#: Calc and Excel store 15 significant digits: a faithful port agrees to 1e-12 of the column's
#: largest magnitude (the rule of legacy_reference/README.md).
LEGACY_RTOL = 1e-12

#: Result columns the macro writes values into, by letter.
MACRO_COLUMNS = ("H", "I", "J", "K", "L", "M", "N", "S", "T", "U", "AB")


def sheet_values(path):
    """{(row, col_letter): value} of the first sheet, read with openpyxl (values only)."""
    wb = openpyxl.load_workbook(path, read_only=True, data_only=True)
    ws = wb.worksheets[0]
    cells = {}
    for row in ws.iter_rows():
        for cell in row:
            if cell.value is not None and hasattr(cell, "column_letter"):
                cells[(cell.row, cell.column_letter)] = cell.value
    wb.close()
    return cells


def column(cells, letter, rows):
    """Rows 2..rows+1 of a column as floats, NaN where empty."""
    return np.array([cells.get((r, letter), np.nan) for r in range(2, rows + 2)], dtype=float)


def relative_error(a, b):
    """Largest |a - b| over the largest |b|, NaN positions required to agree."""
    assert np.array_equal(np.isnan(a), np.isnan(b)), "empty cells differ"
    scale = np.nanmax(np.abs(b)) if np.isfinite(b).any() else 0.0
    diff = np.nanmax(np.abs(a - b)) if np.isfinite(b).any() else 0.0
    return diff / scale if scale else diff


def macro_rows(cells):
    """Time rows of a filled sheet: the last row of column H, less the header."""
    return max(r for (r, c) in cells if c == "H") - 1


def columns_off_the_macro(legacy, new):
    """The macro's columns (MACRO_COLUMNS) where ``new`` is further than LEGACY_RTOL from
    ``legacy`` (both from :func:`sheet_values`); [] when the port agrees everywhere."""
    rows = macro_rows(legacy)
    off = []
    for letter in MACRO_COLUMNS:
        expected, got = column(legacy, letter, rows + 3), column(new, letter, rows + 3)
        if letter == "I":  # the final masses below I are compared on their own
            expected, got = expected[:rows], got[:rows]
        if not relative_error(got, expected) <= LEGACY_RTOL:
            off.append(letter)
    return off


def template_with(tmp_path, **cells):
    """A copy of the template in ``tmp_path`` with some parameter cells changed (openpyxl)."""
    shot = tmp_path / "shot.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    for address, value in cells.items():
        wb["Sheet1"][address] = value
    wb.save(shot)
    return shot


@pytest.fixture
def shot_copy(tmp_path):
    """A copy of the template in tmp_path, so tests can fill it beside itself."""
    path = tmp_path / "shot.xlsx"
    path.write_bytes(TEMPLATE.read_bytes())
    return path
