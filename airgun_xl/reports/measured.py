"""The ``compare-measured`` workbook: the scores (headline figures, ISO/TS 18571 rating,
spectra and SRS), the aligned traces, and the report's Figs. 13-15 as native charts."""
import math

import numpy as np

from ..units import G_PER_KG
from ..xlsx.charts import line_series, log_axis, nice_range, titled
from ..xlsx.columns_sheet import ColumnsWorksheet
from ..xlsx.report import Style, axis, chart_size, one_page, report_workbook
from ..xlsx.sheets import write_about, write_data_sheet, write_warnings

ROWS = (("Peak acceleration", "peak_kg", "kG", 1.0, "0.000"),
        ("Time of peak, after impact", "time_of_peak", "ms", 1e3, "0.0000"),
        ("Pulse duration (>= 10% of peak)", "pulse_duration", "ms", 1e3, "0.0000"),
        ("Velocity change", "delta_v", "m/s", 1.0, "0.00"))

ISO_ROWS = (("Corridor (weight 0.4)", "corridor"), ("Phase (0.2)", "phase"),
            ("Magnitude (0.2)", "magnitude"), ("Slope (0.2)", "slope"),
            ("Overall rating R", "overall"))

PREDICTED, MEASURED, RIGID = "#1f4e79", "#c00000", "#7f7f7f"
SPECTRUM_FROM_HZ = 1_000.0  # below: the pulse's own shape, as the fill's chart
SPECTRUM_TO_HZ = 15_000.0

#: Default columns a chart of the Charts sheet spans (two a row).
CHART_COLS = 10


def _series(chart, sheet, name, n, x_col, y_col, color, dash=None):
    line_series(chart, sheet, name, 1, n, x_col, y_col, color, dash)


def _write_scores(wb, ws, c, head, bold, models):
    pct = wb.add_format({"num_format": "0.00%"})
    score = wb.add_format({"num_format": "0.000"})
    ws.write_row(head, 0, ["Figure", "Predicted", "Measured", "Unit", "Error"], bold)
    row = head + 1
    for label, key, unit, factor, fmt in ROWS:
        form = wb.add_format({"num_format": fmt})
        ws.write_string(row, 0, label)
        ws.write_number(row, 1, getattr(c.predicted, key) * factor, form)
        ws.write_number(row, 2, getattr(c.measured, key) * factor, form)
        ws.write_string(row, 3, unit)
        if key == "time_of_peak":  # an absolute error: its unit in its format
            ws.write_number(row, 4, c.errors[key] * factor, wb.add_format(
                {"num_format": f'{fmt}" ms"'}))
        else:
            ws.write_number(row, 4, c.errors[key], pct)
        row += 1
    khz = wb.add_format({"num_format": "0.00"})
    for k in range(3):
        p = c.predicted_spectrum.peaks[k] if k < len(c.predicted_spectrum.peaks) else None
        m = c.measured_spectrum.peaks[k] if k < len(c.measured_spectrum.peaks) else None
        if p is None and m is None:
            continue
        ws.write_string(row, 0, f"FFT peak {k + 1} (strongest first)")
        for col, value in ((1, p), (2, m)):
            if value is not None:
                ws.write_number(row, col, value / 1e3, khz)
        ws.write_string(row, 3, "kHz")
        if k == 0 and "dominant_frequency" in c.errors:
            ws.write_number(row, 4, c.errors["dominant_frequency"], pct)
        row += 1
    ws.write_string(row, 0, "SRS peak (maximax, Q = 10)")
    g = wb.add_format({"num_format": "#,##0.0"})
    ws.write_number(row, 1, float(c.predicted_srs.max()) * G_PER_KG, g)
    ws.write_number(row, 2, float(c.measured_srs.max()) * G_PER_KG, g)
    ws.write_string(row, 3, "g")
    ws.write_number(row, 4, c.errors["srs_peak"], pct)
    row += 1
    ws.write_string(row, 0, "SRS of the record")
    ws.write_string(row, 1, c.srs_record)
    row += 2
    r = c.iso
    ws.write_row(row, 0, ["ISO/TS 18571", "Score"], bold)
    row += 1
    if r is None:
        ws.write_string(row, 0, "Rating")
        ws.write_string(row, 1, "not computed (see the warnings)")
        row += 1
    else:
        for label, key in ISO_ROWS:
            ws.write_string(row, 0, label)
            ws.write_number(row, 1, getattr(r, key), score)
            row += 1
        ws.write_string(row, 0, "Grade")
        ws.write_string(row, 1, r.grade)
        row += 1
    ms = wb.add_format({"num_format": "0.0000"})
    kg = wb.add_format({"num_format": "0.0000"})
    rows = [("Evaluation interval from", c.interval[0] * 1e3, "ms", ms),
            ("Evaluation interval to", c.interval[1] * 1e3, "ms", ms)]
    if r is not None:
        rows.append(("Phase shift n_eps", float(r.shift), "samples at 10 kHz",
                     wb.add_format({"num_format": "0"})))
    rows += [("Correlation (Pearson r)", c.correlation, "", score),
             ("Shift of the measured time (used)", c.shift * 1e3, "ms", ms)]
    for method, value in sorted(c.shifts.items()):
        rows.append((f"Shift by {method}", value * 1e3, "ms", ms))
    if c.baseline is not None:
        at_rest = f"at rest {c.baseline.where} the pulse"
        rows += [(f"Baseline offset removed (median {at_rest})", c.baseline.offset, "kG", kg),
                 (f"Noise {at_rest} (1 sigma)", c.baseline.noise, "kG", kg),
                 ("Noise at rest after the filter", c.noise_filtered, "kG", kg),
                 (f"Samples {at_rest}", float(c.baseline.samples), "",
                  wb.add_format({"num_format": "#,##0"})),
                 ("Impact level (fraction of the peak)", c.level, "", pct)]
    rows.append(("Anti-alias model on the prediction", c.anti_alias or 0.0,
                 "Hz (0: none)", wb.add_format({"num_format": "#,##0"})))
    for label, value, unit, form in rows:
        ws.write_string(row, 0, label)
        if not math.isnan(value):  # NaN (no pre-trigger) stays an empty cell
            ws.write_number(row, 1, value, form)
        ws.write_string(row, 3, unit)
        row += 1
    if c.rigid_kg is not None:
        ws.write_string(row, 0, f"Peak of the {models[1]} model (kG)")
        ws.write_number(row, 1, float(np.max(c.rigid_kg)), score)
        row += 1
    return row


def _traces_chart(wb, c, n, models):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    _series(chart, "Traces", "Measured", n, 0, 2, MEASURED)
    _series(chart, "Traces", f"Predicted, {models[0]} model", n, 0, 1, PREDICTED)
    values = list(c.predicted_kg) + list(c.measured_kg)
    if c.rigid_kg is not None:
        _series(chart, "Traces", f"Predicted, {models[1]} model", n, 0, 3, RIGID, "dash")
        values += list(c.rigid_kg)
    lo, hi = nice_range(c.time * 1e3)
    ylo, yhi = nice_range(values, include_zero=True)
    chart = titled(chart, "Test against prediction (Fig. 13)",
                   axis("Time after impact (ms)", lo, hi),
                   axis("Acceleration (kG)", ylo, yhi))
    chart.set_size(chart_size(2 * CHART_COLS, 21))
    return chart


def _spectrum_chart(wb, c, n):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    _series(chart, "Spectra", "Measured", n, 0, 2, MEASURED)
    _series(chart, "Spectra", "Predicted", n, 0, 1, PREDICTED)
    keep = c.predicted_spectrum.frequency >= SPECTRUM_FROM_HZ
    _, yhi = nice_range(list(c.predicted_spectrum.amplitude[keep])
                        + list(c.measured_spectrum.amplitude[keep]), include_zero=True)
    chart = titled(chart, "Spectra of test and prediction (Figs. 14-15)",
                   axis("Frequency (kHz)", SPECTRUM_FROM_HZ, SPECTRUM_TO_HZ, num_format="0,"),
                   axis("Amplitude (kG)", 0, yhi))
    chart.set_size(chart_size(CHART_COLS, 20))
    return chart


def _srs_chart(wb, c, n):
    chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
    _series(chart, "SRS", "Measured", n, 0, 2, MEASURED)
    _series(chart, "SRS", "Predicted", n, 0, 1, PREDICTED)
    both = np.concatenate([c.predicted_srs, c.measured_srs]) * G_PER_KG
    x_axis = log_axis("Natural frequency (Hz)", c.srs_frequencies, gridlines=True)
    y_axis = log_axis("Peak response (g)", both, gridlines=True)
    for a in (x_axis, y_axis):
        a["num_format"] = "#,##0"
    chart = titled(chart, "Shock response spectra (maximax, Q = 10)", x_axis, y_axis)
    chart.set_size(chart_size(CHART_COLS, 20))
    return chart


def write_comparison(path, comparison, about, force=False, models=("4-mass", "rigid"),
                     shot=None):
    """Write the Compared sheet (figures, errors, the ISO/TS 18571 rating, spectra and SRS
    figures, one page), the Charts sheet (Figs. 13-15 and the SRS, one page) and the data
    sheets (Traces, Spectra, SRS) at ``path``; ``models`` names the prediction's model and the
    compared one, ``shot`` the input in the page headers."""
    c = comparison
    with report_workbook(path, force) as wb:
        ws = wb.add_worksheet("Compared")
        bold = wb.add_format({"bold": True})
        ws.set_column(0, 0, 50)
        ws.set_column(1, 4, 18)
        head = write_about(ws, about, bold) + 1
        row = _write_scores(wb, ws, c, head, bold, models)
        row = write_warnings(wb, ws, row + 1, c.warnings, 4, line_chars=115)
        one_page(ws, row, 4, shot=shot, title="Compared")
        charts = wb.add_worksheet("Charts")

        data = wb.add_worksheet("Traces", worksheet_class=ColumnsWorksheet)
        names = ["Time after impact (ms)", "Predicted (kG)", "Measured (kG)"]
        columns = {0: c.time * 1e3, 1: c.predicted_kg, 2: c.measured_kg}
        if c.rigid_kg is not None:
            names.append(f"Predicted, {models[1]} model (kG)")
            columns[3] = c.rigid_kg
        write_data_sheet(data, names, columns, Style(wb), shot)

        spectra = wb.add_worksheet("Spectra", worksheet_class=ColumnsWorksheet)
        f = c.predicted_spectrum.frequency
        n_spec = min(len(f), len(c.measured_spectrum.amplitude))
        write_data_sheet(spectra, ["Frequency (Hz)", "Predicted (kG)", "Measured (kG)"],
                         {0: f[:n_spec], 1: c.predicted_spectrum.amplitude[:n_spec],
                          2: c.measured_spectrum.amplitude[:n_spec]}, Style(wb), shot)

        srs = wb.add_worksheet("SRS", worksheet_class=ColumnsWorksheet)
        write_data_sheet(srs, ["Natural frequency (Hz)", "Predicted (g)", "Measured (g)"],
                         {0: c.srs_frequencies, 1: c.predicted_srs * G_PER_KG,
                          2: c.measured_srs * G_PER_KG}, Style(wb), shot)

        charts.write_string(0, 0, f"Measured record: {c.srs_record}")
        charts.insert_chart(1, 0, _traces_chart(wb, c, len(c.time), models))
        charts.insert_chart(22, 0, _spectrum_chart(wb, c, n_spec))
        charts.insert_chart(22, CHART_COLS, _srs_chart(wb, c, len(c.srs_frequencies)))
        one_page(charts, 42, 2 * CHART_COLS - 1, shot=shot, title="Charts")
