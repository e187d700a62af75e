"""The ``Crush law`` sheet written: a law's values exact (``fill`` reads them back through
:mod:`airgun_xl.readers.law_sheet`, whose layout this follows), on one printed page."""
from ..crush_law import DEGREE
from ..readers.law_sheet import FIRST_COEFFICIENT_ROW, FROM_LABEL, SHEET_NAME
from .columns_sheet import ColumnsWorksheet
from .report import one_page

NOTE = ("airgun-xl fill runs this law when B1 says fitted (fill --crush-law legacy runs the "
        "macro's instead). crush factor = max(1, c0 + c1 V + ... + c6 V^6), V the relative "
        "velocity of OBR front plate and MEM [m/s].")


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
    if law.source:  # the archive's version it is: fill --archive checks it and keys the lot
        ws.write_string(0, 2, FROM_LABEL)
        ws.write_string(0, 3, law.source)
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
