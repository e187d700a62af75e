"""``history --calibration -o``: the lab's record of its predictions (issue 45). The P(PASS)
each ``next`` predicted for a shot before it was fired, against the shot's verdict: a band a
row (shots, passes, mean prediction, observed rate with its Wilson 95 % interval, honest or
not), the Brier score, a reliability chart (observed against predicted, the diagonal where
they agree), and a shot a row; one printed page."""
from ..xlsx.report import Style, axis, chart_size, one_page, report_workbook

#: The bands' table: (heading, width).
BAND_COLUMNS = (("P(PASS) predicted", 16), ("Shots", 8), ("Passed", 8),
                ("Mean predicted", 11), ("Observed rate", 11), ("95 % low", 9),
                ("95 % high", 9), ("Honest", 22))
SHEET = "Reliability"


def write_reliability(path, bands, brier, shots, title, force=False, label=None):
    """Write the record at ``path`` (atomically).

    Parameters
    ----------
    bands : list of airgun_xl.studies.closed_loop.Band
    brier : float
        The Brier score over ``shots`` (NaN when there are none).
    shots : list of dict
        Each shot judged after a prediction: ``lot``, ``proposal``, ``shot``, ``predicted``
        (P(PASS), 0-1), ``verdict``.
    """
    with report_workbook(path, force) as wb:
        style = Style(wb)
        ws = wb.add_worksheet(SHEET)
        ws.write_string(0, 0, title, style.title)
        ws.write_string(1, 0, f"Brier score over {len(shots)} shot{'s' * (len(shots) != 1)}: " + (
            f"{brier:.4f} (0 is perfect; always saying 0.5 scores 0.25)" if shots else
            "none yet (no shot fired from a proposal has a verdict)"))
        head = 3
        for col, (heading, width) in enumerate(BAND_COLUMNS):
            ws.write_string(head, col, heading, style.header)
            ws.set_column(col, col, width)
        ws.set_row(head, 30)
        for r, band in enumerate(bands, start=head + 1):
            lo, hi = band.interval
            ws.write_string(r, 0, f"{band.low:.2f} to {band.high:.2f}")
            style.number(ws, r, 1, band.shots, "count")
            style.number(ws, r, 2, band.passed, "count")
            if band.shots:
                style.number(ws, r, 3, band.mean_predicted, "fraction")
                style.number(ws, r, 4, band.rate, "fraction")
                style.number(ws, r, 5, lo, "fraction")
                style.number(ws, r, 6, hi, "fraction")
            ws.write_string(r, 7, "no shot" if not band.shots else
                            "yes" if band.honest else
                            "NO" if band.shots >= 30 else "under 30 shots")
        last = head + len(bands)
        chart = wb.add_chart({"type": "scatter"})
        rows = [r for r, band in enumerate(bands, start=head + 1) if band.shots]
        if rows:
            chart.add_series({
                "name": "Observed rate (95 % interval)",
                "categories": [SHEET, head + 1, 3, last, 3],
                "values": [SHEET, head + 1, 4, last, 4],
                "marker": {"type": "circle", "size": 7, "fill": {"color": "#1f4e79"},
                           "border": {"color": "#1f4e79"}},
                "y_error_bars": {"type": "custom",
                                 "plus_values": [max(0.0, b.interval[1] - b.rate)
                                                 if b.shots else 0.0 for b in bands],
                                 "minus_values": [max(0.0, b.rate - b.interval[0])
                                                  if b.shots else 0.0 for b in bands]}})
        diagonal = last + 2
        ws.write_row(diagonal, 9, [0.0, 1.0])
        ws.write_row(diagonal + 1, 9, [0.0, 1.0])
        chart.add_series({"name": "Predicted = observed",
                          "categories": [SHEET, diagonal, 9, diagonal, 10],
                          "values": [SHEET, diagonal + 1, 9, diagonal + 1, 10],
                          "line": {"color": "#7f7f7f", "dash_type": "dash"},
                          "marker": {"type": "none"}})
        chart.set_title({"name": "Reliability: observed pass rate against predicted P(PASS)",
                         "name_font": {"size": 11}})
        chart.set_x_axis(axis("Predicted P(PASS) (mean of the band)", 0.0, 1.0,
                              num_format="0.0"))
        chart.set_y_axis(axis("Observed pass rate", 0.0, 1.0, num_format="0.0"))
        chart.set_legend({"position": "bottom"})
        chart.set_size(chart_size(8, 16))
        ws.insert_chart(last + 2, 0, chart)
        row = last + 2 + 17
        for col, heading in enumerate(("Lot", "Proposal", "P(PASS)", "Verdict",
                                       "Shot fired")):
            ws.write_string(row, col, heading, style.header)
        for k, shot in enumerate(shots, start=row + 1):
            ws.write_string(k, 0, str(shot["lot"]))
            ws.write_string(k, 1, str(shot["proposal"]))
            style.number(ws, k, 2, shot["predicted"], "fraction")
            ws.write_string(k, 3, str(shot["verdict"]))
            ws.write_string(k, 4, str(shot["shot"]))
        one_page(ws, row + len(shots), len(BAND_COLUMNS) - 1, shot=label, title=SHEET)
