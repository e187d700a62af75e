"""The ``compare-measured`` workbook: the scores, and the two aligned traces with a chart."""
from ..transaction import atomic_path, check_output
from .charts import nice_range
from .columns_sheet import ColumnsWorksheet
from .page_setup import not_printed, one_page
from .sheets import write_about, write_number_columns
from .writer import close_workbook, new_workbook

ROWS = (("Peak acceleration", "peak_kg", "kG", 1.0, "0.000"),
        ("Time of peak, after impact", "time_of_peak", "ms", 1e3, "0.0000"),
        ("Pulse duration (>= 10% of peak)", "pulse_duration", "ms", 1e3, "0.0000"),
        ("Velocity change", "delta_v", "m/s", 1.0, "0.00"))


def write_comparison(path, comparison, about, force=False):
    """Write the Compared sheet (figures, errors, correlation, alignment) and the Traces sheet
    (time, predicted, measured) with a chart of both, at ``path``."""
    c = comparison
    check_output(path, force)
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        ws = wb.add_worksheet("Compared")
        bold = wb.add_format({"bold": True})
        pct = wb.add_format({"num_format": "0.00%"})
        ws.set_column(0, 0, 34)
        ws.set_column(1, 4, 14)
        head = write_about(ws, about, bold) + 1
        ws.write_row(head, 0, ["Figure", "Predicted", "Measured", "Unit", "Error"], bold)
        for i, (label, key, unit, factor, fmt) in enumerate(ROWS, start=head + 1):
            form = wb.add_format({"num_format": fmt})
            ws.write_string(i, 0, label)
            ws.write_number(i, 1, getattr(c.predicted, key) * factor, form)
            ws.write_number(i, 2, getattr(c.measured, key) * factor, form)
            ws.write_string(i, 3, unit)
            if key == "time_of_peak":
                ws.write_number(i, 4, c.errors[key] * factor, form)
            else:
                ws.write_number(i, 4, c.errors[key], pct)
        row = head + len(ROWS) + 2
        for label, value in (("Correlation (Pearson r)", c.correlation),
                             ("Shift of the measured time (ms)", c.shift * 1e3)):
            ws.write_string(row, 0, label)
            ws.write_number(row, 1, value)
            row += 1
        data = wb.add_worksheet("Traces", worksheet_class=ColumnsWorksheet)
        data.write_row(0, 0, ["Time after impact (s)", "Predicted (kG)", "Measured (kG)"], bold)
        write_number_columns(data, 1, {0: c.time, 1: c.predicted_kg, 2: c.measured_kg})
        not_printed(data)
        n = len(c.time)
        chart = wb.add_chart({"type": "scatter", "subtype": "straight"})
        for col, name, color in ((2, "Measured", "#c00000"), (1, "Predicted", "#1f4e79")):
            chart.add_series({"name": name, "categories": ["Traces", 1, 0, n, 0],
                              "values": ["Traces", 1, col, n, col],
                              "line": {"color": color, "width": 1.25},
                              "marker": {"type": "none"}})
        lo, hi = nice_range(c.time)
        ylo, yhi = nice_range(list(c.predicted_kg) + list(c.measured_kg), include_zero=True)
        chart.set_title({"name": "Test against prediction (Fig. 13)"})
        chart.set_x_axis({"name": "Time after impact (s)", "min": lo, "max": hi})
        chart.set_y_axis({"name": "Acceleration (kG)", "min": ylo, "max": yhi})
        chart.set_legend({"position": "bottom"})
        chart.set_size({"width": 720, "height": 420})
        ws.insert_chart(row + 1, 0, chart)
        one_page(ws, row + 23, 8)  # the table and the chart (420 px: about 21 rows)
        close_workbook(wb, path)
