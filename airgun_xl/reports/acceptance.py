"""The ``accept`` workbook: the verdict table, the pulse inside its corridor and the SRS
between its tolerance lines, each on one printed page; the data sheets behind the charts."""
from __future__ import annotations

import math

import numpy as np

from ..engine.decimate import minmax_indices
from ..units import G_PER_KG
from ..xlsx.charts import POINT_BUDGET, line_series, log_axis, nice_range, titled
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.report import SIGNATURE_LINES, Style, axis, chart_size, one_page, report_workbook
from ..xlsx.sheets import write_about, write_data_sheet, write_warnings, write_wrapped

RECORD, IDEAL, LIMIT, REQUIRED = "#c00000", "#1f4e79", "#7f7f7f", "#000000"

#: Printed columns of the Verdict page, and a chart's width in columns.
VERDICT_COLS, CHART_COLS = 8, 14

#: Characters a wrapped line of the Verdict page holds across its printed columns.
VERDICT_LINE_CHARS = 160


#: Characters a line of the Detail column (H, 60 wide) holds.
DETAIL_CHARS = 58


def write_verdict_table(wb, ws, verdict, row, bold):
    """The criteria (value, limits, margin, PASS/FAIL, detail) from ``row``; the next free
    row."""
    num = wb.add_format({"num_format": "0.000"})
    pct = wb.add_format({"num_format": '0.00" %"'})
    db = wb.add_format({"num_format": '+0.00" dB";-0.00" dB"'})
    good = wb.add_format({"bold": True, "font_color": "#006100", "bg_color": "#C6EFCE"})
    bad = wb.add_format({"bold": True, "font_color": "#9C0006", "bg_color": "#FFC7CE"})
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    ws.write_row(row, 0, ["Criterion", "Value", "Unit", "Lower limit", "Upper limit",
                          "Margin", "Verdict", "Detail"], bold)
    row += 1
    for c in verdict.criteria:
        ws.write_string(row, 0, c.name)
        if np.isfinite(c.value):
            ws.write_number(row, 1, c.value, num)
        else:
            ws.write_string(row, 1, "not measured")
        ws.write_string(row, 2, c.unit)
        if c.name == "corridor":  # its limits are the band round the ideal, not numbers
            ws.write_string(row, 3, "inside the band")
            ws.write_string(row, 4, "inside the band")
        for col, limit in ((3, c.low), (4, c.high)):
            if c.name == "corridor":
                continue
            if limit is None:
                ws.write_string(row, col, "none")
            else:
                ws.write_number(row, col, limit, num)
        if np.isfinite(c.margin):
            ws.write_number(row, 5, c.margin, db if c.margin_unit == "dB" else pct)
        else:
            ws.write_string(row, 5, "none")
        ws.write_string(row, 6, c.word, good if c.passed else bad)
        detail = "; ".join(filter(None, (
            f"U = {c.expanded:.3g} {c.unit} (k = 2)" if math.isfinite(c.expanded) else "",
            c.detail)))
        ws.write_string(row, 7, detail, wrap)
        if len(detail) > DETAIL_CHARS:  # as tall as its lines: it printed over the rows below
            ws.set_row(row, 15 * math.ceil(len(detail) / DETAIL_CHARS))
        row += 1
    ws.write_string(row, 0, "Overall")
    ws.write_string(row, 6, verdict.word, good if verdict.passed else bad)
    if verdict.warnings:  # the verdict is only as good as what the warnings below question
        n = len(verdict.warnings)
        ws.write_string(row, 7, f"with {n} warning{'s' * (n != 1)} below: read them before "
                                "relying on it", wrap)
    row += 2
    ws.write_string(row, 0, "Tolerances used, and definitions", bold)
    lines = verdict.tolerances() + verdict.definitions + [
        f"specification from: {verdict.spec.source or 'options'}"]
    row = write_wrapped(wb, ws, row + 1, lines, VERDICT_COLS - 1, VERDICT_LINE_CHARS)
    if verdict.spec.notes:  # a profile's caveats, in full
        ws.write_string(row + 1, 0, "Notes of the profile", bold)
        row = write_wrapped(wb, ws, row + 2, list(verdict.spec.notes), VERDICT_COLS - 1,
                            VERDICT_LINE_CHARS)
    return row


def write_signature(wb, ws, row, bold):
    """The test engineer's block from ``row``: a line to fill by hand for each of
    :data:`SIGNATURE_LINES` (a verdict a client signs; issue 63); the last row written."""
    line = wb.add_format({"bottom": 1})
    ws.write_string(row, 0, "Test engineer", bold)
    for label in SIGNATURE_LINES:
        row += 2
        ws.write_string(row, 0, f"{label}:")
        for col in range(1, 4):
            ws.write_blank(row, col, None, line)
    return row


def write_recording_block(wb, ws, verdict, row, bold):
    """"The recording": what it says about itself (rate, samples across D, step, noise at
    rest and its colour, clipping, dropouts, start and end), a row each from ``row``; the
    next free row."""
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    top = wb.add_format({"bold": True, "valign": "top"})
    ws.write_string(row, 0, "The recording, as read before it was judged", bold)
    row += 1
    nominal = verdict.spec.duration.nominal if verdict.spec.duration else None
    for label, text in verdict.quality.block(nominal):
        ws.write_string(row, 0, label, top)
        ws.merge_range(row, 1, row, VERDICT_COLS - 1, "", wrap)
        ws.write_string(row, 1, text, wrap)
        ws.set_row(row, 15 * max(1, -(-len(text) // (VERDICT_LINE_CHARS - 40))))
        row += 1
    return row


def _pulse_chart(wb, n, t_ms, values, has_corridor):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    line_series(chart, "Pulse data", "Record judged", 1, n, 0, 1, RECORD)
    if has_corridor:
        line_series(chart, "Pulse data", "Ideal pulse", 1, n, 0, 2, IDEAL, "dash")
        line_series(chart, "Pulse data", "Corridor, upper", 1, n, 0, 3, LIMIT)
        line_series(chart, "Pulse data", "Corridor, lower", 1, n, 0, 4, LIMIT)
    lo, hi = nice_range(t_ms)
    ylo, yhi = nice_range(values, include_zero=True)
    chart = titled(chart, "The pulse and its corridor" if has_corridor else
                   "The record judged", axis("Time (ms)", lo, hi),
                   axis("Acceleration (kG)", ylo, yhi))
    chart.set_size(chart_size(CHART_COLS, 24))
    return chart


def _srs_chart(wb, n, frequencies, values, has_requirement):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    line_series(chart, "SRS data", "SRS of the record", 1, n, 0, 1, RECORD)
    if has_requirement:
        line_series(chart, "SRS data", "Requirement", 1, n, 0, 2, REQUIRED)
        line_series(chart, "SRS data", "Lower tolerance", 1, n, 0, 3, LIMIT, "dash")
        line_series(chart, "SRS data", "Upper tolerance", 1, n, 0, 4, LIMIT, "dash")
    x_axis = log_axis("Natural frequency (Hz)", frequencies, gridlines=True)
    y_axis = log_axis("Peak response (g)", values, gridlines=True)
    for a in (x_axis, y_axis):
        a["num_format"] = "#,##0"
    chart = titled(chart, "SRS (maximax) and its tolerance", x_axis, y_axis)
    chart.set_size(chart_size(CHART_COLS // 2, 24))
    return chart


def _pv_chart(wb, n, frequencies, pv, col):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    line_series(chart, "SRS data", "Pseudo-velocity", 1, n, 0, col, IDEAL)
    x_axis = log_axis("Natural frequency (Hz)", frequencies, gridlines=True)
    y_axis = log_axis("Pseudo-velocity (m/s)", pv, gridlines=True)
    x_axis["num_format"] = "#,##0"
    y_axis["num_format"] = "General"
    chart = titled(chart, "Pseudo-velocity shock spectrum", x_axis, y_axis)
    chart.set_size(chart_size(CHART_COLS - CHART_COLS // 2, 24))
    return chart


def write_acceptance(path, verdict, about, pulse, spectra, force=False, shot=None,
                     publication=None):
    """Write the Verdict page, the Pulse page (chart), the SRS page (chart and the shaker's
    figures) and their data sheets at ``path`` (staged in ``publication`` when given, which
    the caller commits; published alone otherwise).

    Parameters
    ----------
    pulse : dict
        ``time`` [s], ``kg`` the record judged, and with a corridor ``ideal``, ``upper``,
        ``lower`` [kG] on the same samples (NaN outside the window).
    spectra : dict
        ``frequencies`` [Hz], ``srs`` [kG], ``pv`` [m/s], optional ``required``, ``lower``,
        ``upper`` [kG]; ``equivalent`` (peak [kG], duration [s], governing [Hz]).
    """
    with report_workbook(path, force, publication=publication) as wb:
        bold = wb.add_format({"bold": True})
        # the report pages first (the workbook opens on the Verdict), their data after them
        ws = wb.add_worksheet("Verdict")
        charts = wb.add_worksheet("Pulse")
        srs_ws = wb.add_worksheet("SRS")
        data = wb.add_worksheet("Pulse data", worksheet_class=ColumnsWorksheet)
        srs_data = wb.add_worksheet("SRS data", worksheet_class=ColumnsWorksheet)
        ws.set_column(0, 0, 34)
        ws.set_column(1, 6, 12)
        ws.set_column(7, 7, 60)
        row = write_about(ws, about, bold) + 1
        row = write_verdict_table(wb, ws, verdict, row, bold)
        if verdict.quality is not None:
            row = write_recording_block(wb, ws, verdict, row + 1, bold)
        row = write_warnings(wb, ws, row + 1, verdict.warnings, VERDICT_COLS - 1,
                             line_chars=160)
        row = write_signature(wb, ws, row + 2, bold)
        one_page(ws, row, VERDICT_COLS - 1, shot=shot, title="Verdict")

        # a long record (2,000,000 samples) is charted by its every bucket's min and max:
        # its peak and every feature wider than a bucket kept, within Excel's rows
        kept = np.arange(len(pulse["time"]))
        if len(kept) > POINT_BUDGET:
            kept = minmax_indices(np.asarray(pulse["kg"], dtype=float), POINT_BUDGET)
        t_ms = np.asarray(pulse["time"])[kept] * 1e3
        has_corridor = "upper" in pulse
        names = ["Time (ms)", "Record judged (kG)"]
        columns = {0: t_ms, 1: np.asarray(pulse["kg"])[kept]}
        if has_corridor:
            names += ["Ideal pulse (kG)", "Corridor, upper (kG)", "Corridor, lower (kG)"]
            for col, key in ((2, "ideal"), (3, "upper"), (4, "lower")):
                columns[col] = np.asarray(pulse[key])[kept]
        write_data_sheet(data, names, columns, Style(wb), shot)
        shown = [v for v in columns.values()][1:]
        values = np.concatenate([v[np.isfinite(v)] for v in shown])
        charts.insert_chart(1, 0, _pulse_chart(wb, len(t_ms), t_ms, values, has_corridor))
        charts.write_string(0, 0, f"Verdict: {verdict.word}", bold)
        if len(kept) < len(pulse["time"]):
            charts.write_string(0, 4, f"charted: {len(kept):,} of the record's "
                                      f"{len(pulse['time']):,} samples, each bucket's least "
                                      "and largest (every sample was judged)")
        one_page(charts, 26, CHART_COLS - 1, shot=shot, title="Pulse")

        f = np.asarray(spectra["frequencies"])
        has_req = "required" in spectra
        names = ["Frequency (Hz)", "SRS (g)"]
        columns = {0: f, 1: np.asarray(spectra["srs"]) * G_PER_KG}
        if has_req:
            names += ["Requirement (g)", "Lower tolerance (g)", "Upper tolerance (g)"]
            for col, key in ((2, "required"), (3, "lower"), (4, "upper")):
                columns[col] = np.asarray(spectra[key]) * G_PER_KG
        names.append("Pseudo-velocity (m/s)")
        columns[len(names) - 1] = np.asarray(spectra["pv"])
        write_data_sheet(srs_data, names, columns, Style(wb), shot)
        plotted = np.concatenate([columns[k] for k in range(1, 5 if has_req else 2)])
        srs_ws.insert_chart(1, 0, _srs_chart(wb, len(f), f, plotted, has_req))
        srs_ws.insert_chart(1, CHART_COLS // 2, _pv_chart(wb, len(f), f, columns[len(names) - 1],
                                                         len(names) - 1))
        srs_ws.set_column(8, 8, 16)
        row = 27
        peak, duration, governing = spectra["equivalent"]
        kg = wb.add_format({"num_format": '0.000" kG"'})
        ms = wb.add_format({"num_format": '0.0000" ms"'})
        hz = wb.add_format({"num_format": '#,##0" Hz"'})
        mps = wb.add_format({"num_format": '0.000" m/s"'})
        ws_rows = [("Equivalent half-sine (smallest whose SRS envelops), peak", peak, kg),
                   ("Equivalent half-sine, duration", duration * 1e3, ms),
                   ("Equivalent half-sine, governed at", governing, hz),
                   ("Pseudo-velocity, largest", float(np.max(spectra["pv"])), mps)]
        for label, value, form in ws_rows:
            srs_ws.write_string(row, 0, label)
            srs_ws.write_number(row, 8, value, form)
            row += 1
        step, factor = spectra.get("step", (None, 1))
        decimated = (f"; computed on the record decimated 1 in {factor:,} to "
                     f"{1 / step:,.0f} samples a second, what its highest frequency needs"
                     if factor > 1 else "")
        srs_ws.write_string(0, 0, f"SRS at Q = {spectra['q']:g}; pseudo-velocity = SRS / "
                                  f"(2 pi f){decimated}", bold)
        one_page(srs_ws, row, CHART_COLS - 1, shot=shot, title="SRS")

