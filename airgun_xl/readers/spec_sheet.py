"""The ``Specification`` sheet of a shot workbook: what the shot must meet (issue 25).

Layout: one field a row, column A its label, B its value, C its unit, D what it means (the
rows of :data:`ROWS`); an SRS requirement as rows of frequency [Hz] and level [g] in F and G
from row 2. The template writes it empty. ``fill``, ``design`` and ``accept`` read it through
the reader's guard and formula checks, as the parameter cells; a bad cell is one line naming
it (``'Specification'!B3``). Blank cells specify nothing.
"""
from __future__ import annotations

import math
from decimal import Decimal

from ..errors import CellError
from ..params import Found, describe
from ..specification import KEYS, MAX_SRS_ROWS, Specification, SrsRequirement, from_keys
from ..units import KG_MS2, G

SHEET_NAME = "Specification"
KEY = SHEET_NAME.upper()

#: (field, label, meaning) a row, from row 2.
ROWS = (
    ("shape", "Shape", "half-sine, sawtooth (terminal peak), trapezoid, or none (limits only)"),
    ("peak", "Peak", "nominal peak acceleration"),
    ("peak_tolerance", "Peak tolerance", "± % of the nominal peak (10), or -10%,+20%"),
    ("duration", "Duration", "nominal pulse duration (the shape's base)"),
    ("duration_tolerance", "Duration tolerance", "± % of the nominal duration, or -10%,+20%"),
    ("velocity_change", "Velocity change", "nominal velocity change"),
    ("velocity_change_tolerance", "Velocity change tolerance",
     "± % of the nominal, or -10%,+20%"),
    ("corridor", "Corridor", "± % of the nominal peak round the ideal pulse"),
    ("time_slack", "Time slack", "± % of the duration the corridor may slide"),
    ("window", "Window (both)", "both windows below, the same each side (kept one release)"),
    ("record", "Record judged", "unfiltered, or CFC 60, 180, 600 or 1000"),
    ("placement", "Placement", "least-squares (default) or peak: where the ideal pulse sits"),
    ("srs_q", "SRS Q", "quality factor of the SRS requirement (blank: 10)"),
    ("srs_lower_db", "SRS lower tolerance", "dB below the requirement allowed (blank: -3)"),
    ("srs_upper_db", "SRS upper tolerance", "dB above the requirement allowed (blank: +6)"),
    ("srs_outside", "SRS outside", "% of the frequencies allowed outside (blank: 0)"),
    ("dv_window", "Velocity change window", "before,after the pulse: 0.4D,0.1D or 1ms,0.5ms "
                                            "(blank: 0.5D,0.5D)"),
    ("monitor", "Monitoring window", "before,after the pulse, where the corridor is judged "
                                     "(blank: 1D,1D)"),
    ("duration_def", "Duration definition", "base (each shape's D; blank) or width@10%"),
    ("decay", "Sawtooth decay allowance", "% of the duration (blank: 10)"),
)
FIRST_ROW = 2

#: The unit column's words where they say more than the unit of the number (a bare number in
#: the value column is in the key's unit, :data:`airgun_xl.specification.KEYS`).
UNITS_SHOWN = {"corridor": "% of peak", "time_slack": "% of duration", "window": "ms",
               "decay": "% of duration"}
SRS_COLUMNS = (6, 7)  # F, G

#: The Test block (issue 63): a label a row in I, its value in J, from row 2, in the order of
#: :data:`airgun_xl.identification.FIELDS`.
TEST_COLUMNS = (9, 10)  # I, J
TEST_FIRST_ROW = 2


#: The last row the sheet is read to: the field rows, or the SRS rows up to
#: :data:`~airgun_xl.specification.MAX_SRS_ROWS`; a cell past it is refused, not dropped.
LAST_ROW = FIRST_ROW + MAX_SRS_ROWS - 1


def _where(col_letter: str, row: int) -> str:
    return f"'{SHEET_NAME}'!{col_letter}{row}"


def spec_from_cells(cells: dict, percent_cells=frozenset()) -> Specification | None:
    """The specification a sheet's cells ``{(row, col): (value, formula)}`` (formulas already
    evaluated) give, or None when it is empty. Each field's cell is read by the
    specification's grammar (a number in the row's unit, or text such as ``12kG`` or
    ``-10%,+20%``); the SRS rows run from row 2 to the first blank row, and a cell after it is
    refused, naming it. A number in a % row whose cell is formatted as a percentage
    (``percent_cells``: typed "10%", it holds 0.1) is read as the percentage it shows.

    Raises
    ------
    CellError, OptionError
        Naming the cell at fault.
    """
    rows_of = {name: FIRST_ROW + k for k, (name, _, _) in enumerate(ROWS)}
    labels = {name: label for name, label, _ in ROWS}
    values: dict = {}
    for name, row in rows_of.items():
        value = cells.get((row, 2), (None, None))[0]
        if isinstance(value, Found):
            raise CellError(_where("B", row), labels[name], str(value), "a value (a formula "
                            "the tool can evaluate)")
        if (row, 2) in percent_cells and name in KEYS and KEYS[name].unit == "%" and isinstance(
                value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            value = float(Decimal(repr(float(value))) * 100)  # 0.1 shown as 10% is 10
        if value is not None:
            values[name] = value
    srs = _srs_rows(cells)
    if not any(v is not None and not (isinstance(v, str) and not v.strip())
               for v in values.values()) and srs is None:
        return None
    return from_keys(values, f"the '{SHEET_NAME}' sheet",
                     lambda key: f"{_where('B', rows_of[key])} ({labels[key]})", srs)


def _srs_rows(cells: dict) -> SrsRequirement | None:
    """The SRS requirement of columns F and G: rows from :data:`FIRST_ROW` to the first blank
    one, at most :data:`~airgun_xl.specification.MAX_SRS_ROWS`."""
    rows: list[tuple[float, float]] = []
    end = None
    for (row, col), (value, _) in sorted(cells.items()):
        if col not in SRS_COLUMNS or row < FIRST_ROW or value is None or (
                isinstance(value, str) and not value.strip()):
            continue
        letter = "F" if col == SRS_COLUMNS[0] else "G"
        if row > LAST_ROW:
            raise CellError(_where(letter, row), "SRS requirement", describe(value),
                            f"nothing past row {LAST_ROW:,} (at most {MAX_SRS_ROWS:,} rows)")
    for row in range(FIRST_ROW, LAST_ROW + 1):
        f = cells.get((row, SRS_COLUMNS[0]), (None, None))[0]
        level = cells.get((row, SRS_COLUMNS[1]), (None, None))[0]
        if _blank(f) and _blank(level):
            end = row
            break
        for letter, v in (("F", f), ("G", level)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (
                    math.isfinite(v) and v > 0):
                raise CellError(_where(letter, row), "SRS requirement", describe(v),
                                "a positive number (frequency in Hz, level in g)")
        if rows and f <= rows[-1][0]:
            raise CellError(_where("F", row), "SRS requirement", describe(f),
                            f"a frequency above the row before's {rows[-1][0]:g} Hz")
        rows.append((float(f), float(level) * G / KG_MS2))
    if end is not None:  # nothing may follow the blank row that ends the requirement
        for (row, col), (value, _) in sorted(cells.items()):
            if col in SRS_COLUMNS and row > end and not _blank(value):
                letter = "F" if col == SRS_COLUMNS[0] else "G"
                raise CellError(_where(letter, row), "SRS requirement", describe(value),
                                f"nothing after the blank row {end} that ends the "
                                "requirement (or fill that row)")
    if not rows:
        return None
    freqs, levels = zip(*rows, strict=True)
    return SrsRequirement(tuple(freqs), tuple(levels))


def _blank(value) -> bool:
    return value is None or (isinstance(value, str) and not value.strip())


def test_from_cells(cells: dict) -> dict[str, str]:
    """The Test block's fields (:mod:`airgun_xl.identification`) a sheet's cells give, each
    as text; a blank cell gives none. A formula the tool cannot evaluate is refused, naming
    its cell."""
    from ..identification import FIELDS, text_of

    found = {}
    for k, (name, label) in enumerate(FIELDS):
        row = TEST_FIRST_ROW + k
        value = cells.get((row, TEST_COLUMNS[1]), (None, None))[0]
        if isinstance(value, Found):
            raise CellError(_where("J", row), label, str(value), "a value (a formula the tool "
                            "can evaluate)")
        if _blank(value):
            continue
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        found[name] = text_of(value) + (" m/s" if name == "velocity" and numeric else "")
    return found
