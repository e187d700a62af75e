"""Write a run into a new workbook in the macro's layout (xlsxwriter).

Sheet 1 is the input's parameter block as it was (values, labels, formulas as formulas), with
the result columns exactly where ArtSim writes them when it starts at H1:

======  ==========================  =====================================================
column  header                      rows
======  ==========================  =====================================================
H       Time                        2..rows+1, from t = -delta
I..L    Y1 (MEM) .. Y33 (Test Item) 2..rows+1
M, N    Crush Factor, M31           4..rows+1 (the row being computed)
O       Mitigator Deflection        4..rows+1 (header only in the macro; filled here)
P       Plastic Wave Front          4..rows+1 (not in the macro; as the report's appendix)
R       Time                        header only, as the macro
S..U    accelerations, velocity     3..rows
AA      Time                        header only, as the macro
AB      Filtered Acceleration       the sample rows
I       final M1, final m31         rows+3 and rows+4
======  ==========================  =====================================================
"""
import datetime
import math

import numpy as np
from xlsxwriter.utility import xl_rowcol_to_cell

from ..cells import PARAMETER_COLUMNS
from ..errors import OutputError
from .atomic import atomic_path, check_output
from .columns_sheet import SHEET_ROWS, ColumnsWorksheet, fast_deflate
from .formula_eval import Evaluator, FormulaFailure

#: Fixed document properties, so the same run gives the same bytes.
PROPERTIES = {
    "title": "ArtSim results",
    "subject": "Air gun impact simulation (ARL-TR-3559)",
    "author": "airgun-xl",
    "company": "",
    "comments": "Written by airgun-xl",
    "created": datetime.datetime(2005, 8, 1),
}

#: Header text per 0-based column index, as the macro writes it (P is ours).
HEADERS = {
    7: "Time", 8: "Y1 (MEM)", 9: "Y31 (OBR Front Plate)", 10: "Y32 (OBR Back Plate)",
    11: "Y33 (Test Item)", 12: "Crush Factor", 13: "M31", 14: "Mitigator Deflection",
    15: "Plastic Wave Front", 17: "Time", 18: "Acceleration (m/s^2)", 19: "Velocity (m/s)",
    20: "Acceleration (kG's)", 26: "Time", 27: "Filtered Acceleration",
}


def new_workbook(path):
    """An xlsxwriter Workbook with the project's fixed options and properties."""
    import xlsxwriter

    wb = xlsxwriter.Workbook(str(path), {"nan_inf_to_errors": True, "in_memory": True})
    wb.set_properties(PROPERTIES)
    return wb


def result_columns(result):
    """0-based column index -> (first 0-based row, values) of the result columns."""
    h = result.history
    return {
        7: (1, h.time), 8: (1, h.y1), 9: (1, h.y31), 10: (1, h.y32), 11: (1, h.y33),
        12: (3, h.crush_factor[2:]), 13: (3, h.m31[2:]), 14: (3, h.deflection[2:]),
        15: (3, h.x_plastic[2:]), 18: (2, result.accel[1:-1]), 19: (2, result.velocity[1:-1]),
        20: (2, result.accel_kg[1:-1]),
    }


class _LazyColumns(dict):
    """Result columns for the formula evaluator, built only when a formula reaches them."""

    def __init__(self, result, sheet):
        super().__init__()
        self.result, self.sheet = result, sheet

    def get(self, key, default=None):
        if key in self:
            return self[key]
        sheet, col = key
        if sheet != self.sheet or col <= PARAMETER_COLUMNS:
            return default
        values = sheet_column(self.result, col - 1)
        self[key] = values
        return values

    def items(self):  # sizes are not known up front; the view asks per column
        return ()


def sheet_column(result, col):
    """Values of 0-based column ``col`` for sheet rows 1.. as a list (None for empty)."""
    n = result.rows
    out = [None] * (n + 4)
    if col in HEADERS:
        out[0] = HEADERS[col]
    cols = result_columns(result)
    if col in cols:
        first, values = cols[col]
        for i, v in enumerate(values.tolist()):
            out[first + i] = None if math.isnan(v) else v
    if col == 8:
        out[n + 2], out[n + 3] = result.history.final_m1, result.history.final_m31
    if col == 27:
        for r, v in zip(result.filtered.rows.tolist(), result.filtered.values.tolist()):
            while len(out) <= r + 1:
                out.append(None)
            out[r + 1] = v
    return out


def _block_values(result):
    """Cached values for the parameter block's formulas, evaluated against this run."""
    source = result.shot.source
    sheet = source.sheet_title.upper()
    view = source.view(extra_columns=_LazyColumns(result, sheet))
    view.max_row[sheet] = max(view.max_row[sheet], result.rows + 4)
    view.max_col[sheet] = max(view.max_col[sheet], 28)
    evaluator = Evaluator(view)
    values, warnings = {}, []
    for (row, col), (cached, formula) in source.block.items():
        if formula is None:
            continue
        try:
            values[(row, col)] = evaluator.value(sheet, row, col)
        except FormulaFailure as exc:
            values[(row, col)] = cached
            warnings.append(f"{_a1(row, col)}: {exc}; kept the input's cached value")
    return values, warnings


def _a1(row, col):
    return xl_rowcol_to_cell(row - 1, col - 1)


def _write_block(ws, result):
    source = result.shot.source
    if source is None:
        return []
    values, warnings = _block_values(result)
    for (row, col), (cached, formula) in sorted(source.block.items()):
        if col > PARAMETER_COLUMNS:
            continue
        r, c = row - 1, col - 1
        if formula is not None:
            value = values.get((row, col))
            ws.write_formula(r, c, formula, None, "" if value is None else value)
        elif isinstance(cached, bool):
            ws.write_boolean(r, c, cached)
        elif isinstance(cached, (int, float)) and math.isfinite(cached):
            ws.write_number_column(r, c, [cached])  # exact: xlsxwriter keeps 16 digits
        elif isinstance(cached, (int, float)):
            ws.write_number(r, c, cached)  # NaN/inf: written as an error cell
        elif isinstance(cached, (datetime.date, datetime.time)):
            ws.write(r, c, str(cached))
        else:
            ws.write_string(r, c, str(cached))
    return warnings


def finite_runs(values):
    """``(start, stop)`` index pairs of the runs of finite values in ``values``."""
    finite = np.concatenate(([False], np.isfinite(values), [False]))
    edges = np.flatnonzero(np.diff(finite.astype(np.int8)))
    return list(zip(edges[0::2].tolist(), edges[1::2].tolist()))


def _write_results(ws, result):
    for col, text in HEADERS.items():
        ws.write_string(0, col, text)
    for col, (first, values) in result_columns(result).items():
        # NaN marks cells the macro leaves empty (e.g. Crush Factor before any loading)
        for start, stop in finite_runs(values):
            ws.write_number_column(first + start, col, values[start:stop])
    n = result.rows
    ws.write_number(n + 2, 8, result.history.final_m1)
    ws.write_number(n + 3, 8, result.history.final_m31)
    for r, v in zip(result.filtered.rows.tolist(), result.filtered.values.tolist()):
        ws.write_number(r + 1, 27, v)


def write_workbook(result, path, force=False):
    """Write ``result`` to a new .xlsx at ``path``, atomically.

    Parameters
    ----------
    result : airgun_xl.result.Result
    path : str or pathlib.Path
    force : bool
        Overwrite an existing file.

    Returns
    -------
    list of str
        Warnings (block formulas that could not be evaluated keep the input's cached value).

    Raises
    ------
    airgun_xl.errors.OutputError
    """
    source = result.shot.source
    check_output(path, force, inputs=[source.path] if source is not None else [])
    if result.rows + 4 > SHEET_ROWS:
        raise OutputError(f"{path}: the run has {result.rows:,} rows, more than a sheet holds "
                          f"({SHEET_ROWS - 4:,} with the final masses); expected a larger E2 "
                          "or a shorter E6")
    with atomic_path(path) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet(source.sheet_title if source is not None else "Sheet1",
                              worksheet_class=ColumnsWorksheet)
        warnings = _write_block(ws, result)
        _write_results(ws, result)
        with fast_deflate():
            wb.close()
    return warnings
