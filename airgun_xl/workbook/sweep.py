"""The sweep workbook: one row a shot, charts of the peak against each varied parameter, and
for a Monte Carlo the spread and a histogram."""
import numpy as np
from xlsxwriter.utility import xl_range_abs

from ..cells import BY_ADDRESS
from ..engine.batch import FIGURES
from ..transaction import atomic_path, check_output
from .charts import nice_range
from .columns_sheet import ColumnsWorksheet
from .report import not_printed, one_page
from .sheets import write_number_columns
from .writer import close_workbook, new_workbook

FIGURE_HEADERS = {"peak_kg": "Peak (kG)", "time_of_peak": "Time of peak (s)",
                  "filtered_peak_kg": "Filtered peak (kG)",
                  "pulse_duration": "Pulse duration (s)", "max_crush": "Max crush (m)"}


def _label(cell):
    c = BY_ADDRESS.get(cell)
    return f"{cell} {c.label} ({c.unit})" if c and c.unit else cell


def write_sweep(result, path, force, stats=None, sensitivity=None):
    """The sweep's workbook at ``path``: the Sweep table and Charts; with ``stats`` (a Monte
    Carlo) the Spread sheet and the band's convergence; with ``sensitivity`` (Sobol) the
    Sensitivity sheet and its bar charts."""
    check_output(path, force)
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet("Sweep", worksheet_class=ColumnsWorksheet)
        bold = wb.add_format({"bold": True})
        headers = ([_label(c) for c in result.cells]
                   + [FIGURE_HEADERS[f] for f in FIGURES]
                   + ["Diverged", "Invalid", "Warnings (count)", "Warnings"])
        ws.write_row(0, 0, headers, bold)
        ws.set_column(0, len(headers) - 2, 16)
        ws.set_column(len(headers) - 1, len(headers) - 1, 120)
        k = len(result.cells)
        columns = {i: result.values[:, i] for i in range(k)}
        columns.update({k + j: result.figures[:, j] for j in range(len(FIGURES))})
        columns[k + len(FIGURES)] = result.diverged.astype(float)
        columns[k + len(FIGURES) + 1] = result.invalid.astype(float)
        flags = result.flags or [[] for _ in result.values]
        columns[k + len(FIGURES) + 2] = np.array([len(f) for f in flags], dtype=float)
        write_number_columns(ws, 1, columns)
        for r, found in enumerate(flags, start=1):  # text stays text: never a formula
            if found:
                ws.write_string(r, len(headers) - 1, " | ".join(found))
        not_printed(ws)
        _write_warnings(wb, result, bold)
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
        one_page(charts, 20 * len(result.cells) + 1, 9, landscape=False)
        if stats is not None:
            _write_spread(wb, result, stats, bold)
            _write_band(wb, result, bold)
        if sensitivity is not None:
            _write_sensitivity(wb, sensitivity, bold)
        close_workbook(wb, path)


def _write_warnings(wb, result, bold):
    """The Warnings sheet: how many shots have a warning, how often each cell is named, and
    every distinct warning with its count; printed on one page."""
    ws = wb.add_worksheet("Warnings")
    ws.set_column(0, 0, 14)
    ws.set_column(1, 1, 120)
    flagged, cells = result.flagged()
    ws.write_string(0, 0, "Shots", bold)
    ws.write_string(0, 1, f"{flagged:,} of {len(result.values):,} shots have warnings (the "
                          "Sweep sheet's Warnings column names them, shot by shot)")
    ws.write_row(2, 0, ["Cell", "Shots whose warnings name it"], bold)
    row = 3
    for cell, n in sorted(cells.items()):
        ws.write_string(row, 0, cell)
        ws.write_string(row, 1, f"{n:,}")
        row += 1
    counts = {}
    for found in result.flags or []:
        for text in found:
            key = text if len(text) < 200 else text[:200] + "..."
            counts[key] = counts.get(key, 0) + 1
    ws.write_row(row + 1, 0, ["Shots", "Warning (as the first shot with it says it)"], bold)
    row += 2
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    for text, n in sorted(counts.items(), key=lambda item: -item[1])[:40]:
        ws.write_number(row, 0, n, wb.add_format({"num_format": "#,##0"}))
        ws.write_string(row, 1, text, wrap)
        row += 1
    one_page(ws, row, 1)


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
    one_page(ws, max(8 + len(counts), 18), 12)


SENSITIVITY_TITLES = {"peak_kg": "Peak acceleration", "pulse_duration": "Pulse duration",
                      "max_crush": "Maximum crush"}


def _write_sensitivity(wb, sensitivity, bold):
    """One block of rows a figure (input, S1, S1 +/-, ST, ST +/-) and a bar chart of S1 and ST
    with their 95 % confidence half-widths as error bars."""
    ws = wb.add_worksheet("Sensitivity")
    ws.set_column(0, 0, 34)
    ws.set_column(1, 4, 12)
    ws.write_string(0, 0, "Sobol indices (SALib; Saltelli sample, first and total order): S1 is "
                          "an input's share of the variance alone, ST with its interactions; "
                          "+/- is the 95 % confidence half-width.")
    row, k = 2, len(sensitivity.cells)
    for n, (name, found) in enumerate(sensitivity.indices.items()):
        ws.write_row(row, 0, [SENSITIVITY_TITLES[name], "S1", "S1 +/-", "ST", "ST +/-"], bold)
        for i, cell in enumerate(sensitivity.cells):
            ws.write_string(row + 1 + i, 0, _label(cell))
            for j, key in enumerate(("S1", "S1_conf", "ST", "ST_conf")):
                ws.write_number(row + 1 + i, 1 + j, float(found[key][i]))
        chart = wb.add_chart({"type": "column"})
        for col, key, color in ((1, "S1", "#1f4e79"), (3, "ST", "#c00000")):
            half_widths = "='Sensitivity'!" + xl_range_abs(row + 1, col + 1, row + k, col + 1)
            chart.add_series({
                "name": key, "categories": ["Sensitivity", row + 1, 0, row + k, 0],
                "values": ["Sensitivity", row + 1, col, row + k, col],
                "fill": {"color": color},
                # custom error bars take a formula: a list would be literal numbers
                "y_error_bars": {"type": "custom",
                                 "plus_values": half_widths,
                                 "minus_values": half_widths}})
        chart.set_title({"name": f"Sobol indices: {SENSITIVITY_TITLES[name]}"})
        chart.set_x_axis({"name": "Uncertain input"})
        chart.set_y_axis({"name": "Index", "min": 0.0, "max": 1.2})
        chart.set_legend({"position": "bottom"})
        ws.insert_chart(2 + 18 * n, 6, chart)
        row += k + 3
    one_page(ws, max(row, 2 + 18 * len(sensitivity.indices)), 14)


def _write_band(wb, result, bold):
    """The Monte Carlo's mean and 5-95 % band of the peak over its first n shots."""
    from ..studies.sensitivity import band_convergence

    rows = band_convergence(result.figures[:, 0])
    if not len(rows):
        return
    ws = wb.add_worksheet("Band convergence", worksheet_class=ColumnsWorksheet)
    ws.set_column(0, 3, 21)
    ws.write_row(0, 0, ["Shots", "Mean peak (kG)", "5th percentile (kG)",
                        "95th percentile (kG)"], bold)
    write_number_columns(ws, 1, {j: rows[:, j] for j in range(4)})
    n = len(rows)
    chart = wb.add_chart({"type": "scatter", "subtype": "straight_with_markers"})
    for col, name in ((1, "Mean"), (2, "5th percentile"), (3, "95th percentile")):
        chart.add_series({"name": name, "categories": ["Band convergence", 1, 0, n, 0],
                          "values": ["Band convergence", 1, col, n, col]})
    lo, hi = nice_range(rows[:, 1:4])
    chart.set_title({"name": "Monte Carlo: the peak's 5-95 % band against the number of shots"})
    chart.set_x_axis({"name": "Shots", "log_base": 10, "min": 10, "max": float(rows[-1, 0])})
    chart.set_y_axis({"name": "Peak (kG)", "min": lo, "max": hi, "num_format": "0.00"})
    chart.set_legend({"position": "bottom"})
    ws.insert_chart(1, 5, chart)
    one_page(ws, max(n, 16), 13)
