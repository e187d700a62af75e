"""The sweep workbook: one row a shot, charts of the peak against each varied parameter, and
for a Monte Carlo the spread and a histogram."""
import numpy as np

from ..cells import BY_ADDRESS
from ..engine.batch import FIGURES
from ..transaction import atomic_path, check_output
from .columns_sheet import ColumnsWorksheet
from .sheets import write_number_columns
from .writer import close_workbook, new_workbook

FIGURE_HEADERS = {"peak_kg": "Peak (kG)", "time_of_peak": "Time of peak (s)",
                  "filtered_peak_kg": "Filtered peak (kG)",
                  "pulse_duration": "Pulse duration (s)", "max_crush": "Max crush (m)"}


def _label(cell):
    c = BY_ADDRESS.get(cell)
    return f"{cell} {c.label} ({c.unit})" if c and c.unit else cell


def write_sweep(result, path, force, stats=None):
    check_output(path, force)
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet("Sweep", worksheet_class=ColumnsWorksheet)
        bold = wb.add_format({"bold": True})
        headers = ([_label(c) for c in result.cells]
                   + [FIGURE_HEADERS[f] for f in FIGURES] + ["Diverged", "Invalid"])
        ws.write_row(0, 0, headers, bold)
        ws.set_column(0, len(headers), 16)
        k = len(result.cells)
        columns = {i: result.values[:, i] for i in range(k)}
        columns.update({k + j: result.figures[:, j] for j in range(len(FIGURES))})
        columns[k + len(FIGURES)] = result.diverged.astype(float)
        columns[k + len(FIGURES) + 1] = result.invalid.astype(float)
        write_number_columns(ws, 1, columns)
        n = len(result.values)
        charts = wb.add_worksheet("Charts")
        for i, cell in enumerate(result.cells):
            chart = wb.add_chart({"type": "scatter"})
            chart.add_series({"name": "Peak", "categories": ["Sweep", 1, i, n, i],
                              "values": ["Sweep", 1, k, n, k],
                              "marker": {"type": "circle", "size": 4}})
            finite = result.values[:, i][np.isfinite(result.values[:, i])]
            peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
            chart.set_title({"name": f"Peak acceleration against {cell}"})
            chart.set_x_axis({"name": _label(cell),
                              "min": float(finite.min()) if len(finite) else 0.0,
                              "max": float(finite.max()) if len(finite) else 1.0})
            chart.set_y_axis({"name": "Peak (kG)", "min": 0.0,
                              "max": float(np.ceil(peaks.max())) if len(peaks) else 1.0})
            chart.set_legend({"none": True})
            charts.insert_chart(1 + 20 * i, 1, chart)
        if stats is not None:
            _write_spread(wb, result, stats, bold)
        close_workbook(wb, path)


def _write_spread(wb, result, stats, bold):
    ws = wb.add_worksheet("Spread")
    ws.set_column(0, 0, 30)
    rows = [("Shots counted", stats["n"], ""), ("Mean peak", stats["mean"], "kG"),
            ("Standard deviation", stats["sd"], "kG"), ("5th percentile", stats["p5"], "kG"),
            ("95th percentile", stats["p95"], "kG")]
    ws.write_row(0, 0, ["Peak acceleration (raw)", "Value", "Unit"], bold)
    for r, (label, value, unit) in enumerate(rows, start=1):
        ws.write_string(r, 0, label)
        ws.write_number(r, 1, value)
        ws.write_string(r, 2, unit)
    peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
    counts, edges = np.histogram(peaks, bins=min(30, max(5, len(peaks) // 20)))
    ws.write_row(7, 0, ["Bin centre (kG)", "Shots"], bold)
    for i, (c, lo, hi) in enumerate(zip(counts, edges, edges[1:]), start=8):
        ws.write_number(i, 0, float(0.5 * (lo + hi)))
        ws.write_number(i, 1, int(c))
    chart = wb.add_chart({"type": "column"})
    chart.add_series({"name": "Shots", "categories": ["Spread", 8, 0, 7 + len(counts), 0],
                      "values": ["Spread", 8, 1, 7 + len(counts), 1], "gap": 10})
    chart.set_title({"name": "Spread of the peak acceleration (Monte Carlo)"})
    chart.set_x_axis({"name": "Peak (kG)", "num_format": "0.00"})
    chart.set_y_axis({"name": "Shots", "min": 0, "max": int(counts.max()) + 1})
    chart.set_legend({"none": True})
    ws.insert_chart(1, 4, chart)
