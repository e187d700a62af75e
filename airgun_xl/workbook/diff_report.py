"""The --report workbook of ``diff``: a per-column error table, and the worst column's two
curves with their difference."""
import numpy as np

from ..engine.decimate import minmax_indices
from ..transaction import atomic_path, check_output
from .charts import nice_range
from .columns_sheet import ColumnsWorksheet
from .report import one_page
from .sheets import write_number_columns
from .writer import close_workbook, new_workbook


def write_diff_report(report, path, force=False):
    check_output(path, force)
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet("Diff")
        bold = wb.add_format({"bold": True})
        sci = wb.add_format({"num_format": "0.00E+00"})
        ws.write_string(0, 0, f"LEGACY {report.legacy}", bold)
        ws.write_string(1, 0, f"NEW {report.new}", bold)
        ws.write_string(2, 0, ("within tolerance" if report.same else "DIFFERENT")
                        + f" (rtol {report.rtol:g}, atol {report.atol:g})")
        row = 4
        if report.inputs:
            ws.write_string(row, 0, "Input cells that differ", bold)
            for addr, label, x, y in report.inputs:
                row += 1
                ws.write_row(row, 0, [addr, label, str(x), str(y)])
            row += 2
        headers = ["Column", "Header", "Rows (legacy)", "Rows (new)", "Max abs error",
                   "Max relative error", "Rows outside", "First outside: row", "time",
                   "legacy", "new"]
        ws.write_row(row, 0, headers, bold)
        ws.set_column(0, 0, 12)
        ws.set_column(1, 1, 28)
        ws.set_column(2, 10, 18)  # wide enough for each header in print
        for c in report.columns:
            row += 1
            ws.write_row(row, 0, [c.column, c.header, c.rows_legacy, c.rows_new])
            ws.write_number(row, 4, c.max_abs, sci)
            ws.write_number(row, 5, c.max_rel, sci)
            ws.write_number(row, 6, c.outside)
            if c.first_outside:
                f = c.first_outside
                for k, key in enumerate(("row", "time", "legacy", "new")):
                    if f[key] is not None:
                        ws.write_number(row, 7 + k, f[key])
                    else:  # a final mass has no time; an empty cell of the macro's no value
                        ws.write_string(row, 7 + k, "n/a")
        for label, names in (("Only in legacy", report.only_legacy),
                             ("Only in new", report.only_new)):
            if names:
                row += 2
                ws.write_string(row, 0, label, bold)
                ws.write_string(row, 1, "; ".join(names))
        one_page(ws, row, len(headers) - 1)
        if report.worst is not None:
            _write_worst(wb, *report.worst)
        close_workbook(wb, path)


def _write_worst(wb, name, time, x, y):
    ws = wb.add_worksheet("Worst column", worksheet_class=ColumnsWorksheet)
    ws.write_row(0, 0, ["Time (s)", f"legacy {name}", f"new {name}", "new - legacy"])
    diff = y - x
    keep = np.union1d(minmax_indices(x, 20_000), minmax_indices(diff, 20_000))
    write_number_columns(ws, 1, {0: time[keep], 1: x[keep], 2: y[keep], 3: diff[keep]})
    n = len(keep)
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    for col, color in ((1, "#1f4e79"), (2, "#c00000")):
        chart.add_series({"name": ["Worst column", 0, col], "line": {"color": color},
                          "categories": ["Worst column", 1, 0, n, 0],
                          "values": ["Worst column", 1, col, n, col]})
    chart.add_series({"name": ["Worst column", 0, 3], "y2_axis": True,
                      "line": {"color": "#548235", "dash_type": "dash"},
                      "categories": ["Worst column", 1, 0, n, 0],
                      "values": ["Worst column", 1, 3, n, 3]})
    lo, hi = nice_range(np.r_[x, y])
    dlo, dhi = nice_range(diff)
    tlo, thi = nice_range(time)
    # Titles that hold a workbook's own header text point at its cell: xlsxwriter would read
    # a chart name such as "x!A1" or "=..." as a formula.
    ws.write_string(n + 2, 0, f"Worst column: {name}, both curves and their difference")
    chart.set_title({"name": ["Worst column", n + 2, 0]})
    chart.set_x_axis({"name": "Time (s)", "min": tlo, "max": thi})
    chart.set_y_axis({"name": ["Worst column", 0, 1], "min": lo, "max": hi,
                      "num_format": "0.00E+00"})
    chart.set_y2_axis({"name": "new - legacy", "min": dlo, "max": dhi,
                       "num_format": "0.0E+00"})
    chart.set_legend({"position": "bottom"})
    chart.set_size({"width": 760, "height": 420})
    ws.insert_chart(1, 5, chart)
    one_page(ws, 23, 17, first_col=5)  # the chart alone (21 rows by 12 default columns)
