"""The campaign workbook: one row a shot (``fill --summary``) or a run (``history -o``),
the peak against the impact speed, and every warning; one printed page."""
import numpy as np

from ..xlsx.charts import nice_range
from ..xlsx.report import Style, axis, chart_size, one_page, report_workbook
from ..xlsx.sheets import write_warnings
from ..xlsx.workbook import PROPERTIES

#: The title (document properties) of a campaign table: left out of a folder too, whatever
#: its name.
TABLE_TITLE = "airgun-xl campaign table"

#: The campaign table, one row a shot: (heading, key, quantity code of
#: :data:`airgun_xl.xlsx.report.QUANTITIES` or None for text).
TABLE = (
    ("Shot", "file", None), ("v0 (m/s)", "v0", "m/s"), ("Peak (kG)", "peak_kg", "kG"),
    ("Filtered peak (kG)", "filtered_peak_kg", "kG"), ("Time of peak (ms)", "time_of_peak", "s"),
    ("Pulse (ms)", "pulse_duration", "s"), ("Max crush (m)", "max_crush", "m"),
    ("Final length (m)", "final_length", "m"), ("Warnings", "warning_count", "count"),
    ("Predicted verdict", "verdict", None), ("Status", "status", None),
    ("Output", "output", None),
)

#: ``history -o``: the campaign table of an archive's runs.
HISTORY_TABLE = (
    ("Entry", "file", None), ("Created (UTC)", "created", None), ("v0 (m/s)", "v0", "m/s"),
    ("Peak (kG)", "peak_kg", "kG"), ("Filtered peak (kG)", "filtered_peak_kg", "kG"),
    ("Time of peak (ms)", "time_of_peak", "s"), ("Pulse (ms)", "pulse_duration", "s"),
    ("Max crush (m)", "max_crush", "m"), ("Final length (m)", "final_length", "m"),
    ("Warnings", "warning_count", "count"), ("Integrator", "integrator", None),
    ("Crush law", "crush_law", None),
)


#: Widths (characters) of the table's text columns.
TEXT_WIDTHS = {"file": 28, "status": 12, "output": 28, "entry": 18, "created": 20,
               "integrator": 16, "crush_law": 22}


def write_campaign(path, rows, title, force=False, columns=TABLE, label=None):
    """Write the table of ``rows`` (dicts keyed as ``columns`` name them), a chart of the
    peak against v0 and the warnings, at ``path`` (atomically).

    Parameters
    ----------
    rows : list of dict
        A row's ``warnings`` (list of str) are listed under the table, and its figures are
        flagged (red) when it has any; a failed row's ``message`` is its status's text.
    title : str
        The sheet's heading (what the table is: a day's fill, an archive's history).
    columns : tuple of (heading, key, quantity code or None)
    label : str, optional
        What the page header names (the folder, the archive).
    """
    with report_workbook(path, force) as wb:
        wb.set_properties(dict(PROPERTIES, title=TABLE_TITLE))  # a folder campaign skips it
        style = Style(wb)
        ws = wb.add_worksheet("Shots")
        ws.write_string(0, 0, title, style.title)
        head = 2
        ws.write_row(head, 0, [h for h, _, _ in columns], style.header)
        ws.set_row(head, 30)
        for col, (_, key, code) in enumerate(columns):
            ws.set_column(col, col, TEXT_WIDTHS.get(key, 11) if code is None else 11)
        for r, row in enumerate(rows, start=head + 1):
            flagged = bool(row.get("warnings"))
            for col, (_, key, code) in enumerate(columns):
                value = row.get(key)
                if value is None or value == "":
                    continue
                if code is None:
                    ws.write_string(r, col, str(value))
                else:
                    style.number(ws, r, col, value, code, flagged and key != "warning_count")
        last = head + len(rows)
        warnings = [f"{row['file']}: {w}" for row in rows for w in row.get("warnings", [])]
        failures = [f"{row['file']}: {row['status']}: {row['message']}" for row in rows
                    if row.get("message")]
        width = len(columns) - 1
        last = write_warnings(wb, ws, last + 2, warnings, width, line_chars=170)
        if failures:
            last = write_warnings(wb, ws, last + 2, failures, width, line_chars=170,
                                  heading="Not filled")
        keys = [k for _, k, _ in columns]
        chart_row = last + 2
        if "v0" in keys and "peak_kg" in keys:
            x_col, y_col = keys.index("v0"), keys.index("peak_kg")
            done = [k for k, row in enumerate(rows) if row.get("peak_kg") is not None]
            chart = wb.add_chart({"type": "scatter"})
            chart.add_series({"name": "Peak (raw)",
                              "categories": ["Shots", head + 1, x_col, last, x_col],
                              "values": ["Shots", head + 1, y_col, last, y_col],
                              "marker": {"type": "circle", "size": 6,
                                         "border": {"color": "#1f4e79"},
                                         "fill": {"color": "#1f4e79"}}})
            v = np.array([rows[k]["v0"] for k in done], dtype=float)
            peak = np.array([rows[k]["peak_kg"] for k in done], dtype=float)
            lo, hi = nice_range(v) if len(v) else (0.0, 1.0)
            plo, phi = nice_range(peak, include_zero=True) if len(peak) else (0.0, 1.0)
            chart.set_title({"name": "Peak acceleration against impact speed",
                             "name_font": {"size": 11}})
            chart.set_x_axis(axis("v0 (m/s)", lo, hi, num_format="0.0"))
            chart.set_y_axis(axis("Peak (kG)", plo, phi, num_format="0.0"))
            chart.set_legend({"none": True})
            chart.set_size(chart_size(12, 18))
            ws.insert_chart(chart_row, 0, chart)
            last = chart_row + 18
        one_page(ws, last, len(columns) - 1, shot=label, title="Shots")
        ws.freeze_panes(head + 1, 0)
