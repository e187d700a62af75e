"""The ``Crush law`` sheet read: a fitted crush-factor law that ``fill`` runs instead of the
macro's (written by :mod:`airgun_xl.xlsx.law_sheet`).

Layout (column A labels, column B values)::

    A1 Law              B1 fitted        (or legacy: the macro's polynomial, Eq. 8)
                        C1 From          D1 the archive's law version it is (LOT@N), if any
    A2 Valid from [m/s] B2 lowest relative velocity the law was fitted over
    A3 Valid to [m/s]   B3 highest
    A4..A10 c0..c6      B4..B10 the polynomial's coefficients, constant term first

A workbook without the sheet runs the macro's law, so a legacy workbook is unchanged. Every
cell is checked; a fault is one line naming it (``'Crush law'!B5``).
"""
import math
import re

from ..crush_law import DEGREE, LEGACY_LAW, CrushLaw
from ..errors import CellError
from ..params import describe

SHEET_NAME = "Crush law"
KEY = SHEET_NAME.upper()
NAMES = ("legacy", "fitted")
FIRST_COEFFICIENT_ROW = 4

#: C1's label and D1's form: a law version of an archive's library, NAME@N.
FROM_LABEL = "From"
_VERSION = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,79}@[0-9]{1,9}")


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
    return CrushLaw(tuple(coefficients), (lo, hi), "fitted", named=_named(cells))


def _named(cells):
    """D1 under C1 "From": the law version the sheet says it is ('' when C1 is not the
    label or D1 is empty)."""
    if cells.get((1, 3), (None, None))[0] != FROM_LABEL:
        return ""
    value = cells.get((1, 4), (None, None))[0]
    if value is None or value == "":
        return ""
    if not (isinstance(value, str) and _VERSION.fullmatch(value)):
        raise CellError(f"'{SHEET_NAME}'!D1", FROM_LABEL, describe(value),
                        "a law version NAME@N of an archive (airgun-xl next writes it), or "
                        "empty")
    return value
