"""The --report workbook of ``diff``: a per-column error table, and the worst column's two
curves with their difference."""
import re
from pathlib import Path

import numpy as np

from ..engine.decimate import minmax_indices
from ..xlsx.charts import nice_range
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.report import Style, axis, chart_size, one_page, report_workbook
from ..xlsx.sheets import write_number_columns


def write_diff_report(report, path, force=False):
    with report_workbook(path, force) as wb:
        style = Style(wb)
        ws = wb.add_worksheet("Diff")
        shot = f"{Path(report.legacy).name} vs {Path(report.new).name}"
        # diff's two sides are LEGACY and NEW; compare's are two archived runs, by their refs
        legacy, new = (("legacy", "new") if report.labels == ("LEGACY", "NEW")
                       else tuple(report.labels))
        prefix = ("LEGACY ", "NEW ") if legacy == "legacy" else ("", "")
        ws.write_string(0, 0, f"{prefix[0]}{report.legacy}", style.bold)
        ws.write_string(1, 0, f"{prefix[1]}{report.new}", style.bold)
        ws.write_string(2, 0, ("within tolerance" if report.same else "DIFFERENT")
                        + f" (rtol {report.rtol:g}, atol {report.atol:g})")
        row = 4
        if report.inputs:
            ws.write_string(row, 0, "Input cells that differ", style.bold)
            for addr, label, x, y in report.inputs:
                row += 1
                ws.write_row(row, 0, [addr, label, str(x), str(y)])
            row += 2
        headers = ["Column", "Header", f"Rows ({legacy})", f"Rows ({new})", "Max abs error",
                   "Max relative error", "Rows outside", "First outside: row",
                   "First outside: time (ms)", f"First outside: {legacy}",
                   f"First outside: {new}"]
        ws.write_row(row, 0, headers, style.header)
        ws.set_row(row, 30)
        ws.set_column(0, 0, 13)
        ws.set_column(1, 1, 24)
        ws.set_column(2, 10, 13)
        sci = style.fmt("0.00E+00")
        value = style.fmt("0.000000E+00")  # 7 significant digits: 1e-12 differences show
        codes = ("count", "s", None, None)
        for c in report.columns:
            row += 1
            ws.write_row(row, 0, [c.column, c.header])
            ws.write_number(row, 2, c.rows_legacy, style.of("count"))
            ws.write_number(row, 3, c.rows_new, style.of("count"))
            ws.write_number(row, 4, c.max_abs, sci)
            ws.write_number(row, 5, c.max_rel, sci)
            ws.write_number(row, 6, c.outside, style.of("count"))
            if c.first_outside:
                f = c.first_outside
                for k, key in enumerate(("row", "time", "legacy", "new")):
                    if f[key] is None:  # a final mass has no time; an empty macro cell
                        ws.write_string(row, 7 + k, "n/a")
                    elif codes[k]:
                        style.number(ws, row, 7 + k, f[key], codes[k])
                    else:
                        ws.write_number(row, 7 + k, f[key], value)
        for label, names in ((f"Only in {legacy}", report.only_legacy),
                             (f"Only in {new}", report.only_new)):
            if names:
                row += 2
                ws.write_string(row, 0, label, style.bold)
                ws.write_string(row, 1, "; ".join(names))
        one_page(ws, max(row, 16), len(headers) - 1, shot=shot, title="Diff")
        if report.worst is not None:
            name, time, legacy, new = report.worst
            _write_worst(wb, name, time, legacy, new, shot=shot)


def _write_worst(wb, name, time, x, y, shot=None):
    ws = wb.add_worksheet("Worst column", worksheet_class=ColumnsWorksheet)
    ws.write_row(0, 0, ["Time (ms)", f"legacy {name}", f"new {name}", "new - legacy"])
    diff = y - x
    keep = np.union1d(minmax_indices(x, 20_000), minmax_indices(diff, 20_000))
    t_ms = time[keep] * 1e3
    write_number_columns(ws, 1, {0: t_ms, 1: x[keep], 2: y[keep], 3: diff[keep]}, Style(wb))
    n = len(keep)
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    # the legacy curve wide and pale, the new one thin and dashed over it: both show where
    # they agree
    for col, line in ((1, {"color": "#9dc3e6", "width": 4.0}),
                      (2, {"color": "#c00000", "width": 1.0, "dash_type": "dash"})):
        chart.add_series({"name": ["Worst column", 0, col], "line": line,
                          "marker": {"type": "none"},
                          "categories": ["Worst column", 1, 0, n, 0],
                          "values": ["Worst column", 1, col, n, col]})
    chart.add_series({"name": ["Worst column", 0, 3], "y2_axis": True,
                      "line": {"color": "#548235", "width": 1.0}, "marker": {"type": "none"},
                      "categories": ["Worst column", 1, 0, n, 0],
                      "values": ["Worst column", 1, 3, n, 3]})
    lo, hi = nice_range(np.r_[x, y])
    dlo, dhi = nice_range(diff)
    tlo, thi = nice_range(t_ms)
    # Titles that hold a workbook's own header text point at its cell: xlsxwriter would read
    # a chart name such as "x!A1" or "=..." as a formula.
    ws.write_string(n + 2, 0, f"Worst column: {name}, both curves and their difference")
    chart.set_title({"name": ["Worst column", n + 2, 0]})
    chart.set_x_axis(axis("Time (ms)", tlo, thi))
    # the value axes carry the column's unit, as its header gives it (in brackets at its end)
    unit = re.search(r"\(([^()]+)\)\s*$", name)
    shown = f"({unit.group(1)})" if unit else "(the column's unit)"
    ws.write_string(n + 3, 0, name if unit else f"{name} {shown}")
    ws.write_string(n + 4, 0, f"new - legacy {shown}")
    y_axis = axis("", lo, hi)
    y_axis["name"] = ["Worst column", n + 3, 0]
    chart.set_y_axis(y_axis)
    y2_axis = axis("", dlo, dhi, gridlines=False, num_format="0.0E+00")
    y2_axis["name"] = ["Worst column", n + 4, 0]
    chart.set_y2_axis(y2_axis)
    chart.set_legend({"position": "bottom"})
    chart.set_size(chart_size(16, 26))
    ws.insert_chart(1, 5, chart)
    one_page(ws, 27, 20, first_col=5, shot=shot, title="Worst column")  # the chart alone
