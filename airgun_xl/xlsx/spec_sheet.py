"""The ``Specification`` sheet written, empty, for the template (the layout is
:mod:`airgun_xl.readers.spec_sheet`'s, which reads it back)."""
from ..identification import FIELDS as TEST_FIELDS
from ..readers.spec_sheet import (
    FIRST_ROW,
    ROWS,
    SHEET_NAME,
    TEST_COLUMNS,
    TEST_FIRST_ROW,
    UNITS_SHOWN,
)
from ..specification import KEYS
from .report import one_page


def write_spec_sheet(wb, shot=None):
    """Add the sheet, empty, to an xlsxwriter workbook (the template's)."""
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
    # the Test block: what the report names the test by (issue 63), blank to fill in
    label_col, value_col = (c - 1 for c in TEST_COLUMNS)
    ws.set_column(label_col, label_col, 24)
    ws.set_column(value_col, value_col, 28)
    ws.write_string(0, label_col, "Test", bold)
    ws.write_string(0, value_col, "Value (text)", bold)
    for k, (_name, words) in enumerate(TEST_FIELDS):
        ws.write_string(TEST_FIRST_ROW - 1 + k, label_col, words)
    for k, (name, label, meaning) in enumerate(ROWS):
        row = FIRST_ROW - 1 + k
        ws.write_string(row, 0, label)
        ws.write_string(row, 2, UNITS_SHOWN[name] if name in UNITS_SHOWN else KEYS[name].unit)
        ws.write_string(row, 3, meaning, wrap)
    note_row = FIRST_ROW + len(ROWS)
    ws.write_string(note_row, 0, "fill, design and accept read this sheet over a --profile; "
                    "their options (--peak 12kG:10%...) override it field by field. A number "
                    "is in the row's unit; text carries its own (12kG, 0.3ms, -3dB). The Test "
                    "block names the test on accept's report (--client... override it).")
    # an input form, not a report page: the template opens on sheet 1, the macro's, alone
    # (grouped with it, what a user types on sheet 1 would be written here too)
    one_page(ws, note_row, value_col, shot=shot, title=SHEET_NAME, report=False)
    return ws
