"""The shock response spectrum sheets: a log-log chart in g (with a requirement drawn over it
when there is one) and its table. The ``srs`` workbook is made of them
(:mod:`airgun_xl.reports.srs`), and so are the SRS sheets of a design to a required spectrum."""
import numpy as np

from ..units import G_PER_KG
from .charts import log_axis, titled
from .report import Style, chart_size, one_page
from .sheets import write_about, write_warnings

#: The SRS sheet's column of the chart's data, right of its printed range.
CHART_DATA_COL = 20

#: Rows of each column group of the SRS table: 81 frequencies in three groups fit a page.
TABLE_ROWS = 27


def add_srs_sheets(wb, frequencies, spectrum_kg, about, shot=None, requirement=None,
                   name="SRS", warnings=None):
    """Add the SRS sheet (the about lines and the chart, one landscape page) and the
    ``{name} table`` sheet (frequency [Hz], SRS [g] and [kG], in column groups of
    :data:`TABLE_ROWS`, one page).

    Parameters
    ----------
    frequencies : numpy.ndarray
        Natural frequencies [Hz].
    spectrum_kg : numpy.ndarray
        Maximax response [kG].
    about : list of (str, str)
        Label and text lines for the head of the SRS sheet.
    requirement : (numpy.ndarray, numpy.ndarray), optional
        A required spectrum's frequencies [Hz] and levels [kG], drawn over the SRS.
    warnings : list of str, optional
        The run's warnings, listed under the about lines (the spectrum is of that run).
    """
    style = Style(wb)
    table = f"{name} table"
    ws = wb.add_worksheet(name)
    tab = wb.add_worksheet(table)
    ws.set_column(0, 0, 22)
    ws.set_column(1, 1, 14)
    head = write_about(ws, about, style.bold)
    if warnings is not None:  # the run's warnings travel with its spectrum
        head = write_warnings(wb, ws, head + 1, warnings, 8, line_chars=110) + 1
    g = np.asarray(spectrum_kg, dtype=float) * G_PER_KG
    n = len(frequencies)
    for group in range(-(-n // TABLE_ROWS)):
        col = 4 * group
        tab.set_column(col, col, 14)
        tab.set_column(col + 1, col + 2, 12)
        tab.set_column(col + 3, col + 3, 3)
        tab.write_row(0, col, ["Frequency (Hz)", "SRS (g)", "SRS (kG)"], style.header)
        for r in range(TABLE_ROWS):
            k = group * TABLE_ROWS + r
            if k >= n:
                break
            style.number(tab, 1 + r, col, float(frequencies[k]), "Hz-plain")
            style.number(tab, 1 + r, col + 1, float(g[k]), "g")
            style.number(tab, 1 + r, col + 2, float(spectrum_kg[k]), "kG")
    groups = -(-n // TABLE_ROWS)
    one_page(tab, TABLE_ROWS + 1, 4 * groups - 2, shot=shot, title=f"{name}: table")

    # the chart's series: one contiguous copy, right of the printed range
    ws.write_row(0, CHART_DATA_COL, ["Chart data: frequency (Hz)", "SRS (g)"], style.bold)
    for i, (f, v) in enumerate(zip(frequencies.tolist(), g.tolist(), strict=True), start=1):
        style.number(ws, i, CHART_DATA_COL, f, "Hz-plain")
        style.number(ws, i, CHART_DATA_COL + 1, v, "g")
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    chart.add_series({"name": "SRS (maximax)",
                      "categories": [name, 1, CHART_DATA_COL, n, CHART_DATA_COL],
                      "values": [name, 1, CHART_DATA_COL + 1, n, CHART_DATA_COL + 1],
                      "line": {"color": "#1f4e79", "width": 2.0},
                      "marker": {"type": "none"}})
    shown = [g]
    if requirement is not None:
        freq_req, level_kg = requirement
        level_g = np.asarray(level_kg, dtype=float) * G_PER_KG
        row = head + 2
        ws.write_row(row, 0, ["Required: frequency (Hz)", "SRS (g)"], style.header)
        for i, (f, v) in enumerate(zip(freq_req, level_g, strict=True), start=1):
            style.number(ws, row + i, 0, float(f), "Hz-plain")
            style.number(ws, row + i, 1, float(v), "g")
        chart.add_series({"name": "Required", "categories": [name, row + 1, 0,
                                                             row + len(level_g), 0],
                          "values": [name, row + 1, 1, row + len(level_g), 1],
                          "line": {"color": "#c00000", "width": 1.5, "dash_type": "dash"},
                          "marker": {"type": "diamond", "size": 6,
                                     "border": {"color": "#c00000"},
                                     "fill": {"color": "#c00000"}}})
        shown.append(level_g)
        head = row + len(level_g) + 1
    x_axis = log_axis("Natural frequency (Hz)", frequencies, gridlines=True)
    y_axis = log_axis("Peak response (g)", np.concatenate(shown), gridlines=True)
    for axis in (x_axis, y_axis):
        axis["num_format"] = "#,##0"
        axis["minor_gridlines"] = {"visible": True, "line": {"color": "#eeeeee"}}
    titled(chart, "Shock response spectrum of the test-item acceleration", x_axis, y_axis,
           legend="bottom" if requirement is not None else None)
    chart.set_size(chart_size(17, 26))
    ws.insert_chart(head + 1, 0, chart)
    one_page(ws, head + 28, 15, shot=shot, title=name)
