"""The ``srs`` workbook: a shot's shock response spectrum as a table and a log-log chart."""

from ..transaction import atomic_path, check_output
from .charts import log_axis, titled
from .report import one_page
from .sheets import write_about
from .writer import close_workbook, new_workbook


def write_srs(path, frequencies, spectrum, about, force=False):
    """Write the SRS table (frequency [Hz], maximax response [kG]) and its log-log chart.

    ``about`` is a list of (label, text) lines for the head of the sheet (shot, Q, filter).
    """
    check_output(path, force)
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet("SRS")
        bold = wb.add_format({"bold": True})
        ws.set_column(0, 0, 22)
        ws.set_column(1, 1, 18)
        head = write_about(ws, about, bold) + 1
        ws.write_row(head, 0, ["Frequency (Hz)", "SRS maximax (kG)"], bold)
        for i, (f, s) in enumerate(zip(frequencies.tolist(), spectrum.tolist()), start=1):
            ws.write_number(head + i, 0, f)
            ws.write_number(head + i, 1, s)
        n = len(frequencies)
        chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
        chart.add_series({"name": "SRS", "categories": ["SRS", head + 1, 0, head + n, 0],
                          "values": ["SRS", head + 1, 1, head + n, 1],
                          "line": {"color": "#1f4e79", "width": 1.5},
                          "marker": {"type": "none"}})
        titled(chart, "Shock response spectrum of the test-item acceleration",
               log_axis("Natural frequency (Hz)", frequencies, gridlines=True),
               log_axis("Peak response (kG)", spectrum, gridlines=True), 440, legend=None)
        ws.insert_chart(1, 3, chart)
        one_page(ws, max(head + n, 24), 13)
        close_workbook(wb, path)
