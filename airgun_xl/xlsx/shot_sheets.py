"""What every workbook made from a shot's carries: sheet 1's cells copied as they were
(formulas as formulas, text as text), the added sheets' names (renamed away from sheet 1's),
and the Outputs block on its printed page. The fill's workbook and the calibrated workbook
are written with them."""
import math

from xlsxwriter.utility import xl_rowcol_to_cell

from ..cells import PARAMETER_COLUMNS
from ..outputs import SHEET_NAME
from ..readers.law_sheet import SHEET_NAME as LAW_SHEET
from .report import VALUE_COLUMN_CHARS, one_page, value_format
from .safe_text import copyable_formula, sheet_title

#: The sheets a fill adds after sheet 1, by their fixed names.
OUTPUT_SHEETS = ("Parameters", "Summary", "Charts", "Tracked", "Spectrum", "ChartData", "SRS",
                 "SRS table", SHEET_NAME, LAW_SHEET)


def sheet_names(source_title):
    """Sheet 1's title (made valid) and the added sheets' names, renamed when sheet 1 already
    has one of them (``Summary`` -> ``Summary (2)``)."""
    first = sheet_title(source_title if source_title is not None else "Sheet1")
    names = {"first": first}
    for name in OUTPUT_SHEETS:
        names[name] = sheet_title(name, taken=[first])
    return names


def write_cells(ws, cells, values=None, style=None):
    """Copy ``{(row, col): (value, formula)}`` cells (1-based) as they were; return warnings.

    Formulas stay formulas, cached with ``values[(row, col)]``, unless they reach outside the
    workbook (DDE, another file, a web call): those are written as their cached value. Text is
    always written as text; numbers exactly, shown (with ``style``, a
    :class:`~airgun_xl.xlsx.report.Style`) in at most 7 significant digits
    (:func:`~airgun_xl.xlsx.report.value_format`) rather than as General.
    """
    values = values or {}
    warnings = []

    def shown(number):
        if style is None or not isinstance(number, (int, float)) or isinstance(number, bool):
            return None
        return style.get(num_format=value_format(number))

    for (row, col), (cached, formula) in sorted(cells.items()):
        r, c = row - 1, col - 1
        if formula is not None and copyable_formula(formula):
            value = values.get((row, col), cached)
            ws.write_formula(r, c, formula, shown(value), "" if value is None else value)
            continue
        if formula is not None:
            warnings.append(f"{ws.get_name()}!{xl_rowcol_to_cell(r, c)}: the formula reaches "
                            "outside the workbook (DDE, another file or a web call); written "
                            "as its cached value")
        if cached is None:
            continue
        if isinstance(cached, bool):
            ws.write_boolean(r, c, cached)
        elif isinstance(cached, (int, float)) and math.isfinite(cached):
            ws.write_number_column(r, c, [cached], shown(cached))  # exact: all 17 digits
        elif isinstance(cached, (int, float)):
            ws.write_number(r, c, cached)  # NaN/inf: written as an error cell
        else:
            ws.write_string(r, c, str(cached))  # text stays text, whatever it starts with
    return warnings


def print_parameter_block(ws, block, shot, title):
    """Sheet 1's parameter block on one page, its columns (A to G, where the labels overflow)
    wide enough for the numbers as :func:`write_cells` shows them; its result columns from H
    are data, printed from the Tracked sheet and summed up on the Summary. It prints when
    printed by itself, not in the report's print: the Parameters page shows it readably."""
    ws.set_column(0, PARAMETER_COLUMNS - 1, VALUE_COLUMN_CHARS)
    one_page(ws, max(r for r, _ in block) - 1, PARAMETER_COLUMNS - 1, shot=shot, title=title,
             report=False)


def print_outputs_block(ws, block, shot):
    """The Outputs block on one page, its columns wide enough for their text (a label used
    to run past the print area and be cut off)."""
    widths: dict = {}
    cells_in_row: dict = {}
    for (row, _), (cached, _) in block.items():
        cells_in_row[row] = cells_in_row.get(row, 0) + (cached is not None)
    for (row, col), (cached, _) in block.items():
        if cached is not None and cells_in_row[row] > 1:  # a row's lone note overflows
            widths[col] = max(widths.get(col, 0), len(str(cached)))
    for col, chars in widths.items():
        ws.set_column(col - 1, col - 1, min(max(chars + 2, 6), 120))
    one_page(ws, max(r for r, _ in block) - 1, max(c for _, c in block) - 1, shot=shot,
             title="Outputs")
