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

Then, as :class:`airgun_xl.outputs.Outputs` selects, the report pages (Parameters, Summary,
Charts, the input's Outputs block) and after them the data sheets (Tracked, Spectrum,
ChartData). Sheet 1 prints its parameter block; each data sheet prints by itself, all its
rows one page wide. A run longer than the sheets may hold writes every
N-th row (N in the Summary) and, by default, its full history to a sidecar file.
"""
import dataclasses
import math

import numpy as np
from xlsxwriter.utility import xl_rowcol_to_cell

from ..cells import PARAMETER_COLUMNS
from ..engine.summary import summarize
from ..outputs import SHEET_NAME, Outputs
from ..provenance import Provenance
from ..readers.formula_eval import Evaluator, FormulaFailure
from ..readers.law_sheet import SHEET_NAME as LAW_SHEET
from ..transaction import atomic_path, check_output, display
from ..xlsx.charts import add_charts, series_data, spectrum_range
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.law_sheet import write_law_sheet
from ..xlsx.report import Style, data_pages
from ..xlsx.sheets import (
    Ref,
    data_format,
    variant_name,
    write_chart_data,
    write_number_columns,
    write_parameters,
    write_spectrum,
    write_summary,
    write_tracked,
)
from ..xlsx.shot_sheets import (
    print_outputs_block,
    print_parameter_block,
    sheet_names,
    write_cells,
)
from ..xlsx.workbook import close_workbook, new_workbook

#: Header text per 0-based column index, as the macro writes it (P is ours).
HEADERS = {
    7: "Time", 8: "Y1 (MEM)", 9: "Y31 (OBR Front Plate)", 10: "Y32 (OBR Back Plate)",
    11: "Y33 (Test Item)", 12: "Crush Factor", 13: "M31", 14: "Mitigator Deflection",
    15: "Plastic Wave Front", 17: "Time", 18: "Acceleration (m/s^2)", 19: "Velocity (m/s)",
    20: "Acceleration (kG's)", 26: "Time", 27: "Filtered Acceleration",
}




#: Sheet 1 result columns (0-based) -> (output group, History/Result attribute).
SHEET1_COLUMNS = {
    7: ("positions", "time"), 8: ("positions", "y1"), 9: ("positions", "y31"),
    10: ("positions", "y32"), 11: ("positions", "y33"), 12: ("crush", "crush_factor"),
    13: ("crush", "m31"), 14: ("crush", "deflection"), 15: ("crush", "x_plastic"),
    18: ("accel", "accel"), 19: ("accel", "velocity"), 20: ("accel", "accel_kg"),
}
HEADER_GROUPS = {17: "accel", 26: "filtered", 27: "filtered"}


def _values(result, name):
    source = result if name in ("accel", "velocity", "accel_kg") else result.history
    return getattr(source, name)


def _sheet1_columns(result, outputs, keep):
    """Column -> array over the kept rows; NaN for cells the macro leaves empty."""
    cols = {col: _values(result, name)[keep] for col, (group, name) in SHEET1_COLUMNS.items()
            if group in outputs and _values(result, name) is not None}
    if cols and 7 not in cols:
        cols[7] = result.history.time[keep]  # time goes with any sheet 1 group
    return cols


def _filtered_cells(result, stride):
    """(sheet row, value) of the filtered samples that fall on written rows."""
    return [(r // stride + 1, v) for r, v in zip(result.filtered.rows.tolist(),
                                                  result.filtered.values.tolist(), strict=True)
            if r % stride == 0]


class _LazyColumns(dict):
    """Result columns for the formula evaluator, built only when a formula reaches them.

    A column is a list of values for sheet rows 1.. (None for empty), header first.
    """

    def __init__(self, columns, sheet, finals):
        super().__init__()
        self.columns, self.sheet, self.finals = columns, sheet, finals

    def get(self, key, default=None):
        if key in self:
            return self[key]
        sheet, col = key
        if sheet != self.sheet or col - 1 not in self.columns:
            return default
        cells = [HEADERS.get(col - 1)] + [None if math.isnan(v) else v
                                          for v in self.columns[col - 1].tolist()]
        if col - 1 == 8 and self.finals is not None:
            cells += [None, *self.finals]
        self[key] = cells
        return cells

    def items(self):  # sizes are not known up front; the view asks per column
        return ()


def _block_values(source, columns, rows, finals):
    """Cached values for the parameter block's formulas, evaluated against this run."""
    sheet = source.sheet_title.upper()
    view = source.view(extra_columns=_LazyColumns(columns, sheet, finals))
    view.max_row[sheet] = max(view.max_row[sheet], rows + 4)
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
            warnings.append(f"{xl_rowcol_to_cell(row - 1, col - 1)}: {exc}; kept the input's "
                            "cached value")
    return values, warnings


def _write_sheet1(wb, result, outputs, keep, stride, title):
    """Sheet 1: the parameter block and the macro's columns; returns (refs, warnings)."""
    source = result.shot.source
    ws = wb.add_worksheet(title, worksheet_class=ColumnsWorksheet)
    columns = _sheet1_columns(result, outputs, keep)
    rows = len(keep)
    finals = None
    if "positions" in outputs:
        finals = (result.history.final_m1, result.history.final_m31)
    warnings, block = [], {}
    if source is not None:
        block = {k: v for k, v in source.block.items() if k[1] <= PARAMETER_COLUMNS}
        values, warnings = _block_values(source, columns, rows, finals)
        warnings += write_cells(ws, block, values, Style(wb))
    for col in sorted(set(columns) | {c for c, g in HEADER_GROUPS.items() if g in outputs}):
        ws.write_string(0, col, HEADERS[col])
    style = Style(wb)
    write_number_columns(ws, 1, columns, style)  # shown in 7 digits; the cells hold all 17
    if finals is not None:
        shown = style.get(num_format=data_format(np.array(finals, dtype=float)))
        ws.write_number(rows + 2, 8, finals[0], shown)
        ws.write_number(rows + 3, 8, finals[1], shown)
    if "filtered" in outputs:
        cells = _filtered_cells(result, stride)
        shown = style.get(num_format=data_format(np.array([v for _, v in cells], dtype=float)))
        for row, value in cells:
            ws.write_number(row, 27, value, shown)
    if block:  # the input's own page
        print_parameter_block(ws, block, display(source.path.name), title)
    else:  # no input's block (a shot made in Python): the macro's columns, as data
        data_pages(ws, rows, 27)
    refs = {}
    if rows == result.rows:
        title = ws.get_name()
        for col, key in ((8, "y1"), (9, "y31"), (10, "y32"), (11, "y33"), (20, "accel_kg")):
            if col in columns and np.isfinite(columns[col]).any():
                refs[key] = Ref(title, 7, col, 1, rows, rows)
    return refs, warnings


def _write_srs_sheets(wb, result, requirement, shot, name, warnings):
    """The SRS and SRS table sheets of a design to a required spectrum: the designed shot's
    SRS over the requirement's band (and at least 100 Hz-10 kHz), the requirement drawn
    over it."""
    from ..studies.shock import default_frequencies, srs
    from ..xlsx.srs_sheets import add_srs_sheets

    frequencies, required, q = requirement
    pulse = result.accel_kg[np.isfinite(result.accel_kg)]
    freqs = default_frequencies(min(100.0, float(frequencies[0])),
                                max(10_000.0, float(frequencies[-1])))
    about = [("Shot", shot or ""), ("Quality factor Q", f"{q:g}"),
             ("Required", f"{len(frequencies)} levels, {frequencies[0]:,.0f} to "
                          f"{frequencies[-1]:,.0f} Hz (design --target-srs)")]
    add_srs_sheets(wb, freqs, srs(pulse, result.params.delta, freqs, q), about, shot,
                   (frequencies, required), name, warnings)


def write_workbook(result, path, force=False, outputs=Outputs(), summary=None, info=None,
                   force_word="force=True"):
    """Write ``result`` to a new .xlsx at ``path``, atomically (see :func:`render_workbook`).

    Parameters
    ----------
    result : airgun_xl.result.Result
    path : str or pathlib.Path
    force : bool
        Overwrite an existing file.
    outputs, summary, info
        As :func:`render_workbook`.
    force_word : str
        How the "already exists" message names ``force``.

    Returns
    -------
    list of str
        Warnings.

    Raises
    ------
    airgun_xl.errors.OutputError
    """
    source = result.shot.source
    check_output(path, force, inputs=[source.path] if source is not None else [],
                 force_word=force_word)
    with atomic_path(path, force, force_word) as tmp:
        return render_workbook(result, tmp, outputs, summary, info, shown=path)


def render_workbook(result, tmp, outputs=Outputs(), summary=None, info=None, shown=None):
    """Render ``result`` into the file ``tmp`` (a temp file that the caller publishes).

    Parameters
    ----------
    result : airgun_xl.result.Result
    tmp : pathlib.Path
    outputs : airgun_xl.outputs.Outputs
        Which groups, sheets and charts to write, and the row stride.
    summary : airgun_xl.engine.summary.Summary, optional
        Computed here when a selected output needs it and none is given.
    info : airgun_xl.provenance.Provenance, optional
        What the Summary says of the run (input, SHA-256, run times, warnings, ...).
    shown : path, optional
        The output's final name, for messages.

    Returns
    -------
    list of str
        Warnings (block formulas that could not be evaluated keep the input's cached value).
    """
    source = result.shot.source
    stride = outputs.stride(result.rows)
    keep = np.arange(0, result.rows, stride)
    needs_summary = outputs.groups & {"summary", "spectrum", "charts"}
    if summary is None and needs_summary:
        summary = summarize(result)
    wb = new_workbook(tmp)
    names = sheet_names(source.sheet_title if source is not None else None)
    refs, warnings = _write_sheet1(wb, result, outputs, keep, stride, names["first"])
    shot = display(source.path.name) if source is not None else None
    info = (info or Provenance()).written(stride, len(keep), shot)
    if "summary" in outputs:
        write_parameters(wb, result.params, shot, names["Parameters"])
        write_summary(wb, result, summary, info, names["Summary"])
        # the workbook opens on its Summary, the page its figures are read from; sheet 1
        # stays first, where fill and diff read it (the legacy macro reads the active sheet:
        # docs/output.md says to click sheet 1's tab before running it on this workbook)
        wb.get_worksheet_by_name(names["Summary"]).activate()
    charts_ws = wb.add_worksheet(names["Charts"]) if "charts" in outputs else None
    if info.srs_requirement is not None:
        _write_srs_sheets(wb, result, info.srs_requirement, shot, names["SRS"],
                          list(info.warnings))
    if source is not None and source.outputs_block:
        outputs_ws = wb.add_worksheet(names[SHEET_NAME], worksheet_class=ColumnsWorksheet)
        warnings += write_cells(outputs_ws, source.outputs_block, style=Style(wb))
        print_outputs_block(outputs_ws, source.outputs_block, shot)
    if not result.params.crush_law.is_legacy:  # a fitted law goes with the shot
        write_law_sheet(wb, result.params.crush_law, names[LAW_SHEET], shot=shot)
    # the data sheets after the report pages, so a whole-workbook print starts with the report
    if "tracked" in outputs:
        refs.update(write_tracked(wb, result, keep, ColumnsWorksheet, names["Tracked"], shot))
    if "spectrum" in outputs:
        refs.update(write_spectrum(wb, summary.spectrum, ColumnsWorksheet, names["Spectrum"],
                                   shot))
    if charts_ws is not None:
        compared = info.compared
        data = series_data(result, summary.spectrum, compared, summary.natural_initial)
        if "spectrum" in refs:  # the chart's curve from the lobe's end, as its data
            skipped = int(np.searchsorted(summary.spectrum.frequency,
                                          summary.spectrum.band_start))
            refs["spectrum"] = dataclasses.replace(
                refs["spectrum"], first_row=refs["spectrum"].first_row + skipped,
                total=refs["spectrum"].total - skipped)
        placed = write_chart_data(wb, data, refs, ColumnsWorksheet, names["ChartData"],
                                  budget=len(keep),  # --every N thins the copies too
                                  time_ms=result.history.time[keep] * 1e3, shot=shot)
        labels = None
        if compared is not None:
            labels = {"compared_kg": f"Acceleration, {variant_name(compared)}",
                      "accel_kg": "Acceleration, the macro's unloading (quirk)"
                      if compared.params.unloading == "continuous" else
                      f"Acceleration, {variant_name(result)}"}
        add_charts(wb, charts_ws, placed, data, float(result.history.time[-1]) * 1e3, labels,
                   {"spectrum": spectrum_range(summary.spectrum)}, shot)
    close_workbook(wb, shown if shown is not None else tmp)
    return warnings
