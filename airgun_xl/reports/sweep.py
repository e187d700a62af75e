"""The sweep workbook: one row a shot, charts of the peak against each varied parameter, and
for a Monte Carlo the spread and a histogram."""
import numpy as np
from xlsxwriter.utility import xl_range_abs

from ..cells import BY_ADDRESS
from ..engine.batch import FIGURES
from ..xlsx.charts import nice_range
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.report import (
    Style,
    axis,
    chart_size,
    data_pages,
    fit_wrapped_row,
    general_format,
    one_page,
    report_workbook,
)
from ..xlsx.sheets import write_data_sheet, write_number_columns

FIGURE_HEADERS = {"peak_kg": "Peak (kG)", "time_of_peak": "Time of peak (s)",
                  "filtered_peak_kg": "Filtered peak (kG)",
                  "pulse_duration": "Pulse duration (s)", "max_crush": "Max crush (m)"}

#: How a chart axis shows a cell of each unit: the shown unit and the number format (the
#: trailing commas show Pa as MPa, without a copy of the values).
AXIS_UNITS = {"Pa": ("MPa", "#,##0.0,,"), "m/s": ("m/s", "0.0"), "N/m": ("N/m", "0.00E+00"),
              "s": ("s", "0.00E+00")}

#: Most levels a family of curves has (one series per level); an input with more is drawn
#: at :data:`FAMILY_SHOWN` of its levels, evenly spaced (first and last included).
MAX_FAMILY = 12
FAMILY_SHOWN = 7

#: A curve of more points than this is drawn as a line without markers: at print size a
#: marker a point would merge them into a band.
MARKED_POINTS = 25


def _label(cell, unit=None):
    c = BY_ADDRESS.get(cell)
    if c is None:
        return cell
    unit = unit if unit is not None else c.unit
    return f"{cell} {c.label}" + (f" ({unit})" if unit else "")


def _cell_axis(cell, values):
    """(title, number format) of a chart axis over ``cell``'s ``values``."""
    c = BY_ADDRESS.get(cell)
    unit, fmt = AXIS_UNITS.get(c.unit if c else "", (None, None))
    return _label(cell, unit), fmt or general_format(values, digits=3)


def write_sweep(result, path, force, stats=None, sensitivity=None, shot=None, seed=None):
    """The sweep's workbook at ``path``: the Sweep table and Charts (a grid over two or more
    inputs: a family of curves, one series per level of the second); with ``stats`` (a Monte
    Carlo) the Spread sheet and the band's convergence; with ``sensitivity`` (Sobol) the
    Sensitivity sheet and its bar charts. ``shot`` names the input in the page headers;
    ``seed``, the draws' seed, is shown on the Spread and Sensitivity pages (the study
    repeats from it)."""
    with report_workbook(path, force) as wb:
        style = Style(wb)
        # the report pages first (the workbook opens on the Charts), the data sheets after
        family_data = _write_charts(wb, result, shot)
        if stats is not None:
            _write_spread(wb, result, stats, style, shot, seed)
            _write_band(wb, result, style, shot)
        if sensitivity is not None:
            _write_sensitivity(wb, sensitivity, style, shot, seed)
        _write_warnings(wb, result, style, shot)
        ws = wb.add_worksheet("Sweep", worksheet_class=ColumnsWorksheet)
        headers = ([_label(c) for c in result.cells]
                   + [FIGURE_HEADERS[f] for f in FIGURES]
                   + ["Diverged", "Invalid", "Warnings (count)", "Warnings"])
        k = len(result.cells)
        columns = {i: result.values[:, i] for i in range(k)}
        columns.update({k + j: result.figures[:, j] for j in range(len(FIGURES))})
        columns[k + len(FIGURES)] = result.diverged.astype(float)
        columns[k + len(FIGURES) + 1] = result.invalid.astype(float)
        flags = result.flags or [[] for _ in result.values]
        columns[k + len(FIGURES) + 2] = np.array([len(f) for f in flags], dtype=float)
        write_data_sheet(ws, headers, columns, style, shot)
        ws.set_column(len(headers) - 1, len(headers) - 1, 60, style.wrap)
        for r, found in enumerate(flags, start=1):  # text stays text: never a formula
            if found:
                ws.write_string(r, len(headers) - 1, " | ".join(found), style.wrap)
        _write_chart_data(wb, family_data, shot)


def families(result, i):
    """The curves of the peak against cell ``i`` of a grid, ([(label, x, peak)], note): one
    per level of the other cell with the fewest levels (the rest held at their middle
    level), at most :data:`MAX_FAMILY` of them (past it, :data:`FAMILY_SHOWN` levels evenly
    spaced, first and last included, said in the note); None for samples (a Monte Carlo,
    Sobol) or a single input."""
    k = len(result.cells)
    if result.kind != "grid" or k < 2:
        return None
    levels = [np.unique(result.values[:, j]) for j in range(k)]
    j = min((m for m in range(k) if m != i), key=lambda m: len(levels[m]))
    shown = levels[j]
    if len(shown) > MAX_FAMILY:
        shown = shown[np.unique(np.round(np.linspace(0, len(shown) - 1,
                                                     FAMILY_SHOWN)).astype(int))]
    held = np.ones(len(result.values), dtype=bool)
    fixed = []
    for m in range(k):
        if m not in (i, j):
            middle = levels[m][len(levels[m]) // 2]
            held &= result.values[:, m] == middle
            fixed.append(f"{result.cells[m]} = {middle:.4g}")
    c = BY_ADDRESS.get(result.cells[j])
    unit, fmt = AXIS_UNITS.get(c.unit if c else "", (c.unit if c else "", None))
    scale = 1e-6 if unit == "MPa" else 1.0
    out = []
    for level in shown:
        rows = held & (result.values[:, j] == level)
        order = np.argsort(result.values[rows, i], kind="stable")
        name = f"{result.cells[j]} = {level * scale:.4g} {unit}".rstrip()
        if fixed:
            name += " (" + ", ".join(fixed) + ")"
        out.append((name, result.values[rows, i][order], result.figures[rows, 0][order]))
    note = (f"{len(shown)} of the {len(levels[j])} levels of {result.cells[j]}"
            if len(shown) < len(levels[j]) else "")
    return out, note


#: Charts on the sweep's Charts sheet: two a row, each this many default columns and rows.
CHART_COLS, CHART_ROWS = 10, 22


def _write_charts(wb, result, shot):
    """The Charts sheet: the peak against each input, two charts a row, on one page. A grid
    over two or more inputs draws a family of curves (their data on the Chart
    data sheet, written after the report pages by :func:`_write_chart_data` from the
    ``[(col, header, x, peak)]`` this returns); samples draw a scatter."""
    charts = wb.add_worksheet("Charts")
    data: list = []
    n, k = len(result.values), len(result.cells)
    peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
    plo, phi = nice_range(peaks, include_zero=True) if len(peaks) else (0.0, 1.0)
    col = 0
    for i, cell in enumerate(result.cells):
        family, note = families(result, i) or (None, "")
        finite = result.values[:, i][np.isfinite(result.values[:, i])]
        title, fmt = _cell_axis(cell, finite)
        if family is None:
            chart = wb.add_chart({"type": "scatter"})
            chart.add_series({"name": "Peak", "categories": ["Sweep", 1, i, n, i],
                              "values": ["Sweep", 1, k, n, k],
                              "marker": {"type": "circle", "size": 4}})
            chart.set_legend({"none": True})
        else:
            chart = wb.add_chart({"type": "scatter", "subtype": "straight_with_markers"})
            for m, (name, x, y) in enumerate(family):
                data.append((col, f"{cell} ({name})", x, y))
                color = FAMILY_COLORS[m % len(FAMILY_COLORS)]
                marker = ({"type": "circle", "size": 3, "border": {"color": color},
                           "fill": {"color": color}} if len(x) <= MARKED_POINTS
                          else {"type": "none"})
                chart.add_series({"name": name, "categories": ["Chart data", 1, col, len(x), col],
                                  "values": ["Chart data", 1, col + 1, len(x), col + 1],
                                  "line": {"color": color, "width": 1.25},
                                  "marker": marker})
                col += 2
            chart.set_legend({"position": "bottom"})
        lo = float(finite.min()) if len(finite) else 0.0
        hi = float(finite.max()) if len(finite) else 1.0
        chart.set_title({"name": f"Peak acceleration against {cell}"
                                 + (f"\n({note})" if note else ""),
                         "name_font": {"size": 11}})
        chart.set_x_axis(axis(title, lo, hi if hi > lo else lo + 1.0, num_format=fmt))
        chart.set_y_axis(axis("Peak (kG)", plo, phi, num_format="0.0"))
        chart.set_size(chart_size(CHART_COLS, CHART_ROWS))
        charts.insert_chart(1 + (i // 2) * CHART_ROWS, (i % 2) * CHART_COLS, chart)
    charts.write_string(0, 0, "Peak acceleration of the test item (raw) against each input"
                        + (" (one curve per level of another input)" if data else ""))
    one_page(charts, 1 + -(-k // 2) * CHART_ROWS, 2 * CHART_COLS - 1, shot=shot,
             title="Charts")
    return data


def _write_chart_data(wb, family_data, shot):
    """The Chart data sheet of a grid's families of curves (none for samples)."""
    if not family_data:
        return
    data = wb.add_worksheet("Chart data", worksheet_class=ColumnsWorksheet)
    style = Style(wb)
    for col, header, x, y in family_data:
        data.write_string(0, col, header, style.header)
        data.write_string(0, col + 1, "Peak (kG)", style.header)
        write_number_columns(data, 1, {col: x, col + 1: y}, style)
    data.set_column(0, max(c for c, *_ in family_data) + 1, 16)
    data_pages(data, max(len(x) for _, _, x, _ in family_data),
               max(c for c, *_ in family_data) + 1, shot=shot)


FAMILY_COLORS = ("#1f4e79", "#c00000", "#548235", "#7f6000", "#7030a0", "#00b0f0",
                 "#ff7f00", "#595959", "#a50021", "#2e75b6", "#92d050", "#bf9000")


#: The Warnings sheet's text column, in characters (a line of wrapped text holds about as
#: many: the default font's digits are its widest common glyphs).
WARNING_CHARS = 120


def _write_warnings(wb, result, style, shot):
    """The Warnings sheet: how many shots have a warning, how often each cell is named, and
    every distinct warning with its count; printed on one page."""
    ws = wb.add_worksheet("Warnings")
    ws.set_column(0, 0, 14)
    ws.set_column(1, 1, WARNING_CHARS)
    flagged, cells = result.flagged()
    bold = style.bold
    ws.write_string(0, 0, "Shots", bold)
    ws.write_string(0, 1, f"{flagged:,} of {len(result.values):,} shots have warnings (the "
                          "Sweep sheet's Warnings column names them, shot by shot)")
    ws.write_row(2, 0, ["Cell", "Shots whose warnings name it"], bold)
    row = 3
    for cell, n in sorted(cells.items()):
        ws.write_string(row, 0, cell)
        ws.write_string(row, 1, f"{n:,}")
        row += 1
    counts: dict = {}
    for found in result.flags or []:
        for text in found:
            key = text if len(text) < 200 else text[:200] + "..."
            counts[key] = counts.get(key, 0) + 1
    ws.write_row(row + 1, 0, ["Shots", "Warning (as the first shot with it says it)"], bold)
    row += 2
    for text, n in sorted(counts.items(), key=lambda item: -item[1])[:40]:
        ws.write_number(row, 0, n, style.of("count", valign="top"))  # beside its text's top
        ws.write_string(row, 1, text, style.wrap)
        fit_wrapped_row(ws, row, text, WARNING_CHARS)
        row += 1
    one_page(ws, row, 1, shot=shot, title="Warnings")


def _write_spread(wb, result, stats, style, shot, seed=None):
    ws = wb.add_worksheet("Spread")
    ws.set_column(0, 0, 30)
    ws.set_column(1, 1, 12)
    rows = [("Shots counted", stats["n"], "count"), ("Mean peak", stats["mean"], "kG"),
            ("Standard deviation", stats["sd"], "kG"), ("5th percentile", stats["p5"], "kG"),
            ("95th percentile", stats["p95"], "kG")]
    ws.write_row(0, 0, ["Peak acceleration (raw)", "Value", "Unit"], style.bold)
    for r, (label, value, code) in enumerate(rows, start=1):
        ws.write_string(r, 0, label)
        style.number(ws, r, 1, value, code)
        ws.write_string(r, 2, style.unit(code))
    if seed is not None:  # an identifier, as text: a seed past 2**53 is no Excel number
        ws.write_string(6, 0, "Seed of the draws")
        ws.write_string(6, 1, str(seed), style.get(align="right"))
    peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
    counts, edges = np.histogram(peaks, bins=min(30, max(5, len(peaks) // 20)))
    ws.write_row(7, 0, ["Bin centre (kG)", "Shots"], style.bold)
    for i, (c, lo, hi) in enumerate(zip(counts, edges, edges[1:], strict=False), start=8):
        style.number(ws, i, 0, float(0.5 * (lo + hi)), "kG")
        style.number(ws, i, 1, int(c), "count")
    chart = wb.add_chart({"type": "column"})
    chart.add_series({"name": "Shots", "categories": ["Spread", 8, 0, 7 + len(counts), 0],
                      "values": ["Spread", 8, 1, 7 + len(counts), 1], "gap": 10})
    chart.set_title({"name": "Spread of the peak acceleration (Monte Carlo)"})
    chart.set_x_axis({"name": "Peak (kG), bin centre", "num_format": "0.000"})
    chart.set_y_axis({"name": "Shots", "min": 0, "max": int(counts.max()) + 1,
                      "num_format": "#,##0"})
    chart.set_legend({"none": True})
    chart.set_size(chart_size(12, 24))
    ws.insert_chart(1, 4, chart)
    one_page(ws, max(8 + len(counts), 25), 15, shot=shot, title="Spread")


SENSITIVITY_TITLES = {"peak_kg": "Peak acceleration", "pulse_duration": "Pulse duration",
                      "max_crush": "Maximum crush"}


def _write_sensitivity(wb, sensitivity, style, shot, seed=None):
    """One block of rows a figure (input, S1, S1 +/-, ST, ST +/-) and a bar chart of S1 and ST
    with their 95 % confidence half-widths as error bars."""
    ws = wb.add_worksheet("Sensitivity")
    ws.set_column(0, 0, 34)
    ws.set_column(1, 4, 12)
    ws.write_string(0, 0, "Sobol indices (SALib; Saltelli sample, first and total order): S1 is "
                          "an input's share of the variance alone, ST with its interactions; "
                          "+/- is the 95 % confidence half-width."
                          + (f" Seed of the draws: {seed}." if seed is not None else ""))
    row, k = 2, len(sensitivity.cells)
    for n, (name, found) in enumerate(sensitivity.indices.items()):
        ws.write_row(row, 0, [SENSITIVITY_TITLES[name], "S1", "S1 +/-", "ST", "ST +/-"],
                     style.bold)
        for i, cell in enumerate(sensitivity.cells):
            ws.write_string(row + 1 + i, 0, _label(cell))
            for j, key in enumerate(("S1", "S1_conf", "ST", "ST_conf")):
                style.number(ws, row + 1 + i, 1 + j, float(found[key][i]), "ratio")
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
        chart.set_y_axis({"name": "Index", "min": 0.0, "max": 1.2, "num_format": "0.0"})
        chart.set_legend({"position": "bottom"})
        ws.insert_chart(2 + 18 * n, 6, chart)
        row += k + 3
    one_page(ws, max(row, 2 + 18 * len(sensitivity.indices)), 14, shot=shot,
             title="Sensitivity")


def _write_band(wb, result, style, shot):
    """The Monte Carlo's mean and 5-95 % band of the peak over its first n shots."""
    from ..studies.sensitivity import band_convergence

    rows = band_convergence(result.figures[:, 0])
    if not len(rows):
        return
    ws = wb.add_worksheet("Band convergence", worksheet_class=ColumnsWorksheet)
    ws.set_column(0, 3, 21)
    ws.write_row(0, 0, ["Shots", "Mean peak (kG)", "5th percentile (kG)",
                        "95th percentile (kG)"], style.bold)
    for r, values in enumerate(rows.tolist(), start=1):
        for j, value in enumerate(values):
            style.number(ws, r, j, value, "count" if j == 0 else "kG")
    n = len(rows)
    chart = wb.add_chart({"type": "scatter", "subtype": "straight_with_markers"})
    for col, name in ((1, "Mean"), (2, "5th percentile"), (3, "95th percentile")):
        chart.add_series({"name": name, "categories": ["Band convergence", 1, 0, n, 0],
                          "values": ["Band convergence", 1, col, n, col]})
    lo, hi = nice_range(rows[:, 1:4])
    chart.set_title({"name": "Monte Carlo: the peak's 5-95 % band against the number of shots"})
    chart.set_x_axis({"name": "Shots", "log_base": 10, "min": 10, "max": float(rows[-1, 0]),
                      "num_format": "#,##0"})
    chart.set_y_axis(axis("Peak (kG)", lo, hi, num_format="0.00"))
    chart.set_legend({"position": "bottom"})
    chart.set_size(chart_size(12, 24))
    ws.insert_chart(1, 5, chart)
    one_page(ws, max(n, 25), 16, shot=shot, title="Band convergence")
