"""The ``Specification`` sheet of a shot workbook: what the shot must meet (issue 25).

Layout: one field a row, column A its label, B its value, C its unit, D what it means (the
rows of :data:`ROWS`); an SRS requirement as rows of frequency [Hz] and level [g] in F and G
from row 2. The template writes it empty. ``fill``, ``design`` and ``accept`` read it through
the reader's guard and formula checks, as the parameter cells; a bad cell is one line naming
it (``'Specification'!B3``). Blank cells specify nothing.
"""
from __future__ import annotations

import math

from ..errors import CellError
from ..params import describe
from ..specification import FIELDS, MAX_SRS_ROWS, Specification, from_fields
from ..units import KG_MS2, G

SHEET_NAME = "Specification"
KEY = SHEET_NAME.upper()

#: (field, label, meaning) a row, from row 2.
ROWS = (
    ("shape", "Shape", "half-sine, sawtooth (terminal peak), trapezoid, or none (limits only)"),
    ("peak", "Peak", "nominal peak acceleration"),
    ("peak_tolerance", "Peak tolerance", "± % of the nominal peak"),
    ("duration", "Duration", "nominal pulse duration (the shape's base)"),
    ("duration_tolerance", "Duration tolerance", "± % of the nominal duration"),
    ("velocity_change", "Velocity change", "nominal velocity change"),
    ("velocity_change_tolerance", "Velocity change tolerance", "± % of the nominal"),
    ("corridor", "Corridor", "± % of the nominal peak round the ideal pulse"),
    ("time_slack", "Time slack", "± % of the duration the corridor may slide"),
    ("window", "Window", "monitored before and after the pulse (blank: half the duration)"),
    ("record", "Record judged", "unfiltered, or CFC 60, 180, 600 or 1000"),
    ("placement", "Placement", "least-squares (default) or peak: where the ideal pulse sits"),
    ("srs_q", "SRS Q", "quality factor of the SRS requirement (blank: 10)"),
    ("srs_lower_db", "SRS lower tolerance", "dB below the requirement allowed (blank: -3)"),
    ("srs_upper_db", "SRS upper tolerance", "dB above the requirement allowed (blank: +6)"),
    ("srs_outside", "SRS outside", "% of the frequencies allowed outside (blank: 0)"),
)
FIRST_ROW = 2
SRS_COLUMNS = (6, 7)  # F, G


def _where(col_letter: str, row: int) -> str:
    return f"'{SHEET_NAME}'!{col_letter}{row}"


def spec_from_cells(cells: dict) -> Specification | None:
    """The specification a sheet's cells ``{(row, col): (value, formula)}`` (formulas already
    evaluated) give, or None when it is empty.

    Raises
    ------
    CellError
        Naming the cell at fault.
    OptionError
        For fields that cannot be judged together (a corridor without a shape), naming the
        sheet.
    """
    values: dict = {}
    for k, (name, label, _) in enumerate(ROWS):
        row = FIRST_ROW + k
        value = cells.get((row, 2), (None, None))[0]
        if value is None or (isinstance(value, str) and not value.strip()):
            continue
        kind = FIELDS[name][0]
        if kind == "text":
            if not isinstance(value, str) and name == "record" and isinstance(
                    value, (int, float)) and not isinstance(value, bool):
                value = f"cfc {int(value)}" if float(value).is_integer() else str(value)
            if not isinstance(value, str):
                raise CellError(_where("B", row), label, describe(value), "text")
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not \
                math.isfinite(value):
            raise CellError(_where("B", row), label, describe(value),
                            f"a number in {FIELDS[name][1]}")
        values[name] = value
    rows: list[tuple[float, float]] = []
    for row in range(FIRST_ROW, FIRST_ROW + MAX_SRS_ROWS + 1):
        f = cells.get((row, SRS_COLUMNS[0]), (None, None))[0]
        level = cells.get((row, SRS_COLUMNS[1]), (None, None))[0]
        if f is None and level is None:
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
    if not values and not rows:
        return None
    return from_fields(values, f"the '{SHEET_NAME}' sheet", rows or None)


def write_spec_sheet(wb, shot=None):
    """Add the sheet, empty, to an xlsxwriter workbook (the template's)."""
    from .report import one_page

    ws = wb.add_worksheet(SHEET_NAME)
    bold = wb.add_format({"bold": True})
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    ws.set_column(0, 0, 24)
    ws.set_column(1, 1, 14)
    ws.set_column(2, 2, 14)
    ws.set_column(3, 3, 52)
    ws.set_column(5, 6, 14)
    for col, text in enumerate(("Field", "Value", "Unit", "Meaning")):
        ws.write_string(0, col, text, bold)
    ws.write_string(0, 5, "Frequency [Hz]", bold)
    ws.write_string(0, 6, "SRS level [g]", bold)
    for k, (name, label, meaning) in enumerate(ROWS):
        row = FIRST_ROW - 1 + k
        ws.write_string(row, 0, label)
        ws.write_string(row, 2, FIELDS[name][1])
        ws.write_string(row, 3, meaning, wrap)
    note_row = FIRST_ROW + len(ROWS)
    ws.write_string(note_row, 0, "fill, design and accept read this sheet; their options "
                    "(--peak 12kG:10%, --profile NAME...) override it field by field.")
    one_page(ws, note_row, 6, shot=shot, title=SHEET_NAME)
    return ws
