"""The convergence workbook (table and a log-log chart) and its PNG."""
import math

from ..errors import OutputError
from ..studies.convergence import QUANTITIES
from ..transaction import Publication, display
from ..xlsx.report import Style, chart_size, one_page
from ..xlsx.workbook import close_workbook, new_workbook

COLORS = ("#1f4e79", "#c00000", "#548235")


def write_convergence(ladders, path, force, shot, png=None):
    """Write the ladders' table and an error-against-run-time chart to ``path`` and, with
    ``png``, the figure as a PNG: one publication, so both are written or neither.

    Returns
    -------
    bool
        Whether the PNG was written (not without matplotlib).
    """
    figure = _figure(ladders) if png is not None else None
    with Publication(force) as pub:
        _render(ladders, pub.stage(path), path, shot)
        if figure is not None:
            try:
                figure.savefig(pub.stage(png), format="png", dpi=110,
                               metadata={"Software": None})
            except OSError as exc:
                raise OutputError(f"{display(png)}: cannot be written "
                                  f"({exc.strerror or exc})") from None
        pub.commit()
    if figure is not None:
        import matplotlib.pyplot as plt

        plt.close(figure)
    return figure is not None


#: Quantity codes (:data:`airgun_xl.xlsx.report.QUANTITIES`) of the figures' units.
_CODES = {"kG": "kG", "s": "s", "m": "m", "kg": "kg"}


def _render(ladders, tmp, path, shot):
    """The workbook, into the temp file ``tmp`` (``path`` names it in messages): a table of
    each level's figures and relative errors, then the observed orders, then the chart; one
    landscape page."""
    wb = new_workbook(tmp)
    style = Style(wb)
    ws = wb.add_worksheet("Convergence")
    headers = ["Integrator", "Time step (µs)", "Rows", "Kernel time (s)", "Total time (s)"]
    codes = [_CODES[unit] for _, _, unit in QUANTITIES]
    for (_, label, _), code in zip(QUANTITIES, codes, strict=True):
        headers += [f"{label} ({style.unit(code)})", f"{label}: relative error"]
    ws.write_row(0, 0, headers, style.header)
    ws.set_row(0, 62)
    ws.set_column(0, 0, 12)
    ws.set_column(1, len(headers) - 1, 11)
    row = 1
    spans = []
    for lad in ladders:
        first = row
        for lv in lad.levels:
            ws.write_string(row, 0, lv.integrator)
            style.number(ws, row, 1, lv.delta, "step")
            style.number(ws, row, 2, lv.rows, "count")
            style.number(ws, row, 3, lv.kernel_seconds, "runtime-fine")
            style.number(ws, row, 4, lv.total_seconds, "runtime-fine")
            for i, ((q, _, _), code) in enumerate(zip(QUANTITIES, codes, strict=True)):
                style.number(ws, row, 5 + 2 * i, lv.figures[q], code)
                if math.isfinite(lv.errors[q]):
                    ws.write_number(row, 6 + 2 * i, lv.errors[q], style.fmt("0.00E+00"))
            row += 1
        spans.append((lad, first, row - 2))  # the finest level is the reference
        ws.write_string(row, 0, f"{lad.integrator}: Richardson extrapolation", style.bold)
        for i, ((q, _, _), code) in enumerate(zip(QUANTITIES, codes, strict=True)):
            style.number(ws, row, 5 + 2 * i, lad.richardson[q], code)
        row += 1
        ws.write_string(row, 0, f"{lad.integrator}: coarsest time step with the raw peak "
                                f"within {lad.rtol:.2%} of the finest level", style.bold)
        if not math.isnan(lad.recommended):
            style.number(ws, row, 7, lad.recommended, "step")
            ws.write_string(row, 8, "µs")
        else:
            ws.write_string(row, 7, "none")
        row += 2
    ws.write_string(row, 0, "Observed order of each figure's error", style.bold)
    row += 1
    ws.write_row(row, 0, ["Integrator", "Time step (µs)"]
                 + [label for _, label, _ in QUANTITIES], style.header)
    ws.set_row(row, 30)
    for lad in ladders:
        for lv in lad.levels:
            if not any(lv.order.get(q) is not None for q, _, _ in QUANTITIES):
                continue
            row += 1
            ws.write_string(row, 0, lv.integrator)
            style.number(ws, row, 1, lv.delta, "step")
            for i, (q, _, _) in enumerate(QUANTITIES):
                value = lv.order.get(q)
                if value is not None:
                    style.number(ws, row, 2 + i, value, "ratio")
    row += 2
    name = display(shot.source.path.name) if shot.source else "API"
    ws.write_string(row, 0, f"Shot: {name}; errors are relative to the finest level of the "
                            "same integrator.")
    chart = wb.add_chart({"type": "scatter", "subtype": "straight_with_markers"})
    times, errors = [], []
    for i, (lad, first, last) in enumerate(spans):
        if last < first:
            continue
        chart.add_series({
            "name": f"{lad.integrator}: peak acceleration",
            "categories": ["Convergence", first, 4, last, 4],
            "values": ["Convergence", first, 6, last, 6],
            "line": {"color": COLORS[i % 3]},
            "marker": {"type": "circle", "border": {"color": COLORS[i % 3]},
                       "fill": {"color": COLORS[i % 3]}}})
        times += [lv.total_seconds for lv in lad.levels[:-1]]
        errors += [lv.errors["peak_kg"] for lv in lad.levels[:-1] if lv.errors["peak_kg"]]
    lo_t, hi_t = _decades(times)
    lo_e, hi_e = _decades(errors)
    chart.set_title({"name": "Error against run time (work-precision)",
                     "name_font": {"size": 11}})
    chart.set_x_axis({"name": "Run time (s)", "log_base": 10, "min": lo_t, "max": hi_t,
                      "num_format": "0.000", "major_gridlines": {"visible": True}})
    chart.set_y_axis({"name": "Relative error of the peak", "log_base": 10, "min": lo_e,
                      "max": hi_e, "num_format": "0E+0", "major_gridlines": {"visible": True}})
    chart.set_legend({"position": "bottom"})
    chart.set_size(chart_size(19, 20))
    ws.insert_chart(row + 2, 0, chart)
    one_page(ws, row + 22, len(headers) - 1, shot=shot.source.path.name if shot.source
             else None, title="Convergence")
    close_workbook(wb, path)


def _decades(values):
    positive = [v for v in values if v and v > 0 and math.isfinite(v)]
    if not positive:
        return 1e-6, 1.0
    return 10.0 ** math.floor(math.log10(min(positive))), 10.0 ** math.ceil(
        math.log10(max(positive)))


def _figure(ladders):
    """Error against run time, and against the time step; None without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, lad in enumerate(ladders):
        levels = [lv for lv in lad.levels[:-1] if lv.errors["peak_kg"] > 0]
        for ax, x in ((left, [lv.total_seconds for lv in levels]),
                      (right, [lv.delta for lv in levels])):
            ax.loglog(x, [lv.errors["peak_kg"] for lv in levels], "o-", color=COLORS[i % 3],
                      label=f"{lad.integrator}: peak")
            ax.loglog(x, [max(lv.errors["max_crush"], 1e-16) for lv in levels], "s--",
                      color=COLORS[i % 3], alpha=0.6, label=f"{lad.integrator}: max crush")
    left.set_xlabel("run time (s)")
    right.set_xlabel("time step (s)")
    for ax in (left, right):
        ax.set_ylabel("relative error vs finest level")
        ax.axhline(ladders[0].rtol, color="grey", lw=0.8, ls=":")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("airgun-xl convergence: error against run time and time step")
    fig.tight_layout()
    return fig
