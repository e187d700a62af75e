"""The ``calibrate`` workbook: a shot ``fill`` can run with the fitted values, and the
calibration's report.

Sheet 1 is the first shot's parameter block with E40 and E43 replaced by their fitted values
(when fitted); the Outputs block follows it; ``Crush law`` holds a fitted law (when one was
fitted). ``Calibration`` reports the iterations, the fitted values, each shot's scores before
and after, the law against the macro's (the report's Figs. 7-8) and the first shot's pulses;
``Law`` and ``Pulses`` hold the charts' data.
"""
import math

import numpy as np

from ..cells import address
from ..crush_law import LEGACY_LAW
from ..studies.calibrate import AT_BOUND
from ..transaction import display
from ..xlsx.charts import line_series, nice_range, titled
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.law_sheet import write_law_sheet
from ..xlsx.report import (
    Style,
    axis,
    chart_size,
    one_page,
    report_workbook,
    shown,
)
from ..xlsx.sheets import write_about, write_data_sheet, write_parameters, write_warnings
from ..xlsx.shot_sheets import (
    print_outputs_block,
    print_parameter_block,
    sheet_names,
    write_cells,
)

#: Fitted name -> (parameter cell (row, col), ShotParams field).
CELLS = {address("sigmay"): ((40, 5), "sigmay"), address("zeta"): ((43, 5), "zeta")}

#: How the Fitted table shows each fitted value: a quantity code of the report layer.
FITTED_CODES = {address("sigmay"): "Pa", address("zeta"): "fraction", "scale": "ratio"}

#: Default columns and rows of each chart, right of the tables.
CHART_COLS, CHART_ROWS = 10, 22


def _parameter_sheet(wb, shot, params, names, fitted):
    source = shot.source
    block = {k: v for k, v in source.block.items() if k[1] <= 7}
    for name, (cell, field) in CELLS.items():
        if name in fitted:
            block[cell] = (getattr(params, field), None)  # the fitted value, a plain number
    ws = wb.add_worksheet(names["first"], worksheet_class=ColumnsWorksheet)
    warnings = write_cells(ws, block, {k: v[0] for k, v in block.items()}, Style(wb))
    print_parameter_block(ws, block, display(source.path.name), names["first"])
    write_parameters(wb, params, display(source.path.name), names["Parameters"])
    if source.outputs_block:
        out = wb.add_worksheet(names["Outputs"], worksheet_class=ColumnsWorksheet)
        warnings += write_cells(out, source.outputs_block, style=Style(wb))
        print_outputs_block(out, source.outputs_block, display(source.path.name))
    return warnings


def _law_chart(wb, n_grid, n_samples, v_range, values):
    """The fitted law, the macro's and the last iteration's samples, against the relative
    velocity (only when the law was fitted)."""
    chart = wb.add_chart({"type": "scatter"})
    if n_samples:
        chart.add_series({"name": "Measured samples (last iteration)",
                          "categories": ["Law", 1, 3, n_samples, 3],
                          "values": ["Law", 1, 4, n_samples, 4],
                          "marker": {"type": "circle", "size": 2,
                                     "fill": {"color": "#f4b183"}, "border": {"none": True}}})
    line_series(chart, "Law", "Fitted law", 1, n_grid, 0, 2, "#c00000")
    line_series(chart, "Law", "The macro's law, Eq. (8)", 1, n_grid, 0, 1, "#1f4e79", "dash")
    lo, hi = nice_range(v_range)
    ylo, yhi = nice_range(values, include_zero=True)
    title = "Crush factor against relative velocity (Figs. 7-8)"
    chart = titled(chart, title,
                   axis("Relative velocity (m/s)", lo, hi),
                   axis("Crush factor (-)", ylo, yhi))
    chart.set_size(chart_size(CHART_COLS, CHART_ROWS))
    chart.set_title({"name": title, "name_font": {"size": 11}})
    return chart


def _pulse_chart(wb, a):
    n = len(a.time)
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    for col, name, color in ((2, "Measured", "#c00000"), (1, "Calibrated model", "#1f4e79")):
        line_series(chart, "Pulses", name, 1, n, 0, col, color)
    lo, hi = nice_range(a.time * 1e3)
    ylo, yhi = nice_range(list(a.simulated_kg) + list(a.measured_kg), include_zero=True)
    title = "Shot 1: measured and calibrated pulses"
    chart = titled(chart, title,
                   axis("Time (ms)", lo, hi), axis("Acceleration (kG)", ylo, yhi))
    chart.set_size(chart_size(CHART_COLS, CHART_ROWS))
    chart.set_title({"name": title, "name_font": {"size": 11}})
    return chart


def _node_table(wb, ws, style, row, nodes):
    """The law at its nodes with their 95 % intervals, a weakly pinned one flagged (red) in
    its row and named below with the shots that pin it and the speed that would; returns the
    next free row."""
    if not nodes:
        return row
    ws.write_string(row, 0, "Crush law at its nodes, 95 % intervals (noise, baselines and "
                            "alignment; not model error)", style.bold)
    row += 1
    ws.write_row(row, 0, ["Node velocity (m/s)", "Law (-)", "95 % low (-)", "95 % high (-)",
                          "+/- (95 %)", "Pinned"], style.header)
    ws.set_row(row, 30)
    num = style.of("fraction")
    flag = wb.add_format({"bold": True, "font_color": "#9C0006"})
    for node in nodes:
        row += 1
        ws.write_number(row, 0, node.velocity, style.of("m/s"))
        for col, value in ((1, node.value), (2, node.low), (3, node.high)):
            if math.isfinite(value):
                ws.write_number(row, col, value, num)
            else:
                ws.write_string(row, col, "not identified", flag)
        if math.isfinite(node.half_width):
            ws.write_number(row, 4, node.half_width, style.of("%"))
        ws.write_string(row, 5, "WEAKLY" if node.weak else "yes", flag if node.weak else None)
    weak = [n.words() for n in nodes if n.weak]
    row += 1
    if weak:
        row = write_warnings(wb, ws, row, weak, 5, line_chars=95,
                             heading="Weakly pinned law nodes (over +/- 2 %)") + 1
    return row + 1


def write_calibration(path, shot, cal, files, options, force=False):
    """Write the calibrated workbook at ``path`` (atomically); returns the copy's warnings."""
    params = cal.params[0]
    law = params.crush_law
    with report_workbook(path, force) as wb:
        names = sheet_names(shot.source.sheet_title)
        warnings = _parameter_sheet(wb, shot, params, names, cal.fitted)
        if not law.is_legacy:
            write_law_sheet(wb, law, names["Crush law"], shot=display(shot.source.path.name))
        ws = wb.add_worksheet("Calibration")
        # the workbook opens on this page; the shot's sheet stays first, where fill reads it
        # (the legacy macro reads the active sheet: select sheet 1 before running it here)
        ws.activate()
        style = Style(wb)
        bold = style.bold
        pct = style.of("%")
        num = style.of("ratio")
        ws.set_column(0, 0, 40)
        ws.set_column(1, 5, 13)
        about = [(f"Shot {i}", f"{s} against {m}") for i, (s, m) in enumerate(files, start=1)]
        about += [("Filter", f"CFC {options.cfc}" if options.cfc else "none"),
                  ("Objective", options.objective + (" (derivative-free from the L2 fit; the "
                                                     "law by L2, rated by ISO)"
                                                     if options.objective == "iso18571"
                                                     else "")),
                  ("Anti-alias model", "none" if not cal.recordings or
                   cal.recordings[0].anti_alias is None else
                   f"4-pole Butterworth at {cal.recordings[0].anti_alias:,.0f} Hz"),
                  ("Runs", f"{cal.runs} in {cal.seconds:.2f} s"),
                  ("Verdict", "trusted: every fitted value identified, within its bounds, "
                   "and every residual improved" if cal.trusted else
                   f"NOT TRUSTED: {len(cal.warnings)} warning"
                   f"{'s' * (len(cal.warnings) > 1)} below")]
        row = write_about(ws, about, bold) + 1
        row = write_warnings(wb, ws, row, cal.warnings, 5, line_chars=95) + 2
        if cal.notes:
            row = write_warnings(wb, ws, row - 1, cal.notes, 5, line_chars=95,
                                 heading="Notes") + 2
        for i, rec in enumerate(cal.recordings, start=1):
            ws.write_string(row, 0, f"Shot {i}: baseline removed, noise at rest")
            ws.write_number(row, 1, rec.base.offset, num)
            if not math.isnan(rec.base.noise):
                ws.write_number(row, 2, rec.base.noise, num)
            ws.write_string(row, 3, "kG")
            row += 1
        row += 1
        lc = cal.law_calibration
        if lc is not None:
            ws.write_string(row, 0, "Crush-law iteration (report, section 3.2)", bold)
            row += 1
            ws.write_row(row, 0, ["Iteration", "Law change", "Worst RMS error", "Samples"],
                         style.header)
            for it in lc.iterations:
                row += 1
                style.number(ws, row, 0, it.number, "count")
                ws.write_number(row, 1, it.change, pct)
                ws.write_number(row, 2, it.rms_error, pct)
                style.number(ws, row, 3, it.samples, "count")
            row += 1
            ws.write_string(row, 0, "Converged (< 1 %)" if lc.converged else
                            "NOT converged: the last law was kept")
            row += 1
            ws.write_string(row, 0, "Then least squares on the law's values at 7 velocities")
            row += 1
            ws.write_string(row, 0, "Valid from / to (m/s)")
            ws.write_number(row, 1, law.v_range[0], num)
            ws.write_number(row, 2, law.v_range[1], num)
            row += 2
            row = _node_table(wb, ws, style, row, cal.law_intervals)
        if cal.fitted:
            ws.write_row(row, 0, ["Fitted (unit)", "Start", "Fitted", "Change",
                                  "Standard error", "At a bound"], style.header)
            for name, value in cal.fitted.items():
                row += 1
                lo, hi = cal.bounds[name]
                code = FITTED_CODES.get(name, "sci")
                unit = style.unit(code)
                ws.write_string(row, 0, name + (f" ({unit})" if unit else ""))
                style.number(ws, row, 1, cal.start[name], code)
                style.number(ws, row, 2, value, code)
                ws.write_number(row, 3, value / cal.start[name] - 1 if cal.start[name]
                                else 0.0, pct)
                error = cal.errors.get(name, float("inf"))
                if math.isfinite(error):
                    ws.write_number(row, 4, shown(error, code), style.fmt("0.00E+00"))
                else:
                    ws.write_string(row, 4, "not identified")
                ws.write_string(row, 5, "YES" if min(value - lo, hi - value)
                                <= AT_BOUND * (hi - lo) else "no")
            row += 2
        ws.write_row(row, 0, ["Shot", "RMS error before", "RMS error after",
                              "ISO/TS 18571 before", "ISO/TS 18571 after"], style.header)
        ws.set_row(row, 30)
        for i, (b, a) in enumerate(zip(cal.before, cal.after, strict=True), start=1):
            row += 1
            style.number(ws, row, 0, i, "count")
            ws.write_number(row, 1, b.rms, pct)
            ws.write_number(row, 2, a.rms, pct)
            for col, iso in ((3, b.iso), (4, a.iso)):
                if not math.isnan(iso):
                    ws.write_number(row, col, iso, num)
                else:
                    ws.write_string(row, col, "n/a (too short a pulse)")
        row += 2

        # the law against the macro's, over its range; the last iteration's samples
        grid = np.linspace(law.v_range[0], law.v_range[1], 101)
        data = wb.add_worksheet("Law", worksheet_class=ColumnsWorksheet)
        headers = ["Relative velocity (m/s)", "Macro's law (-)", "Fitted law (-)",
                   "Sample velocity (m/s)", "Sample crush factor (-)"]
        columns = {0: grid, 1: LEGACY_LAW(grid), 2: law(grid)}
        v = lc.velocity if lc is not None else np.zeros(0)
        x = lc.factor if lc is not None else np.zeros(0)
        if len(v):
            columns.update({3: v, 4: x})
        write_data_sheet(data, headers, columns, style, display(shot.source.path.name))
        a = cal.aligned[0]
        pulses = wb.add_worksheet("Pulses", worksheet_class=ColumnsWorksheet)
        write_data_sheet(pulses, ["Time (ms)", "Calibrated model (kG)", "Measured (kG)"],
                         {0: a.time * 1e3, 1: a.simulated_kg, 2: a.measured_kg}, style,
                         display(shot.source.path.name))
        values = list(columns[1]) + list(columns[2]) + list(np.percentile(x, [1, 99])
                                                            if len(x) else [])
        # the charts right of the tables: the law's only when a law was fitted
        charts = [_pulse_chart(wb, a)]
        if lc is not None:
            charts.insert(0, _law_chart(wb, len(grid), len(v), law.v_range, values))
        for k, chart in enumerate(charts):
            ws.insert_chart(1 + k * CHART_ROWS, 7, chart)
        one_page(ws, max(row, 1 + len(charts) * CHART_ROWS), 7 + CHART_COLS,
                 shot=display(shot.source.path.name), title="Calibration")
    return warnings
