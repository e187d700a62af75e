"""The ``Crush law`` sheet: a fitted crush-factor law that ``fill`` runs instead of the macro's.

Layout (column A labels, column B values)::

    A1 Law              B1 fitted        (or legacy: the macro's polynomial, Eq. 8)
    A2 Valid from [m/s] B2 lowest relative velocity the law was fitted over
    A3 Valid to [m/s]   B3 highest
    A4..A10 c0..c6      B4..B10 the polynomial's coefficients, constant term first

A workbook without the sheet runs the macro's law, so a legacy workbook is unchanged. Every
cell is checked; a fault is one line naming it (``'Crush law'!B5``).
"""
import math

from ..crush_law import DEGREE, LEGACY_LAW, CrushLaw
from ..errors import CellError
from ..params import describe
from .columns_sheet import ColumnsWorksheet
from .report import one_page

SHEET_NAME = "Crush law"
KEY = SHEET_NAME.upper()
NAMES = ("legacy", "fitted")
FIRST_COEFFICIENT_ROW = 4
NOTE = ("airgun-xl fill runs this law when B1 says fitted (fill --crush-law legacy runs the "
        "macro's instead). crush factor = max(1, c0 + c1 V + ... + c6 V^6), V the relative "
        "velocity of OBR front plate and MEM [m/s].")


def _where(row):
    return f"'{SHEET_NAME}'!B{row}"


def _number(cells, row, label):
    value = cells.get((row, 2), (None, None))[0]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise CellError(_where(row), label, describe(value), "a finite number")
    return float(value)


def law_from_cells(cells):
    """The law a ``Crush law`` sheet's cells ``{(row, col): (value, formula)}`` name.

    Raises
    ------
    CellError
        Naming the sheet's cell at fault.
    """
    name = cells.get((1, 2), (None, None))[0]
    if not isinstance(name, str) or name.strip().lower() not in NAMES:
        raise CellError(_where(1), "Law", repr(name), f"one of {', '.join(NAMES)}")
    if name.strip().lower() == "legacy":
        return LEGACY_LAW
    lo = _number(cells, 2, "Valid from [m/s]")
    hi = _number(cells, 3, "Valid to [m/s]")
    if not lo < hi:
        raise CellError(_where(3), "Valid to [m/s]", repr(hi), f"a velocity above B2 ({lo!r})")
    coefficients = [_number(cells, FIRST_COEFFICIENT_ROW + k, f"c{k}")
                    for k in range(DEGREE + 1)]
    return CrushLaw(tuple(coefficients), (lo, hi), "fitted")


def write_law_sheet(wb, law, name=SHEET_NAME, note=NOTE, shot=None):
    """Add the sheet for ``law`` to an xlsxwriter workbook: its values exact (fill reads them
    back), shown to 7 significant digits; printed on one page with the note wrapped."""
    ws = wb.add_worksheet(name, worksheet_class=ColumnsWorksheet)
    ws.set_column(0, 0, 18)
    ws.set_column(1, 1, 24)
    ws.set_column(2, 5, 14)
    speed = wb.add_format({"num_format": "0.000"})
    coefficient = wb.add_format({"num_format": "0.000000E+00"})
    ws.write_string(0, 0, "Law")
    ws.write_string(0, 1, law.name)
    ws.write_string(1, 0, "Valid from [m/s]")
    ws.write_number_column(1, 1, [law.v_range[0]], speed)  # exact: 17 digits
    ws.write_string(2, 0, "Valid to [m/s]")
    ws.write_number_column(2, 1, [law.v_range[1]], speed)
    for k, c in enumerate(law.coefficients):
        ws.write_string(FIRST_COEFFICIENT_ROW - 1 + k, 0, f"c{k}")
        ws.write_number_column(FIRST_COEFFICIENT_ROW - 1 + k, 1, [c], coefficient)
    row = FIRST_COEFFICIENT_ROW + DEGREE + 1
    ws.merge_range(row, 0, row, 5, "", wb.add_format({"text_wrap": True, "valign": "top"}))
    ws.write_string(row, 0, note, wb.add_format({"text_wrap": True, "valign": "top"}))
    ws.set_row(row, 48)
    one_page(ws, row, 5, shot=shot, title=name)
    return ws
