"""The convergence workbook (table and a log-log chart) and its PNG."""
import math

from ..errors import OutputError
from ..studies.convergence import QUANTITIES
from ..transaction import Publication, display
from .writer import close_workbook, new_workbook

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


def _render(ladders, tmp, path, shot):
    """The workbook, into the temp file ``tmp`` (``path`` names it in messages)."""
    wb = new_workbook(tmp)
    ws = wb.add_worksheet("Convergence")
    bold = wb.add_format({"bold": True})
    sci = wb.add_format({"num_format": "0.00E+00"})
    headers = ["Integrator", "Time step (s)", "Rows", "Kernel time (s)", "Total time (s)"]
    for _, label, unit in QUANTITIES:
        headers += [f"{label} ({unit})", f"{label}: relative error", f"{label}: order"]
    ws.write_row(0, 0, headers, bold)
    ws.set_column(0, len(headers), 14)
    row = 1
    spans = []
    for lad in ladders:
        first = row
        for lv in lad.levels:
            values = [lv.integrator, lv.delta, lv.rows, lv.kernel_seconds,
                      lv.total_seconds]
            for q, _, _ in QUANTITIES:
                values += [lv.figures[q], lv.errors[q], lv.order.get(q)]
            for col, value in enumerate(values):
                if isinstance(value, str):
                    ws.write_string(row, col, value)
                elif value is not None and math.isfinite(value):
                    ws.write_number(row, col, value, sci if col in (1, 3, 4) else None)
            row += 1
        spans.append((lad, first, row - 2))  # the finest level is the reference
        ws.write_string(row, 0, f"{lad.integrator}: Richardson extrapolation", bold)
        for i, (q, _, _) in enumerate(QUANTITIES):
            if math.isfinite(lad.richardson[q]):
                ws.write_number(row, 5 + 3 * i, lad.richardson[q])
        row += 1
        ws.write_string(row, 0, f"{lad.integrator}: coarsest time step with the raw peak "
                                f"within {lad.rtol:.2%} of the finest level (s)", bold)
        if lad.recommended == lad.recommended:
            ws.write_number(row, 5, lad.recommended)
        else:
            ws.write_string(row, 5, "none")
        row += 2
    ws.write_string(row, 0, f"Shot: {shot.source.path if shot.source else 'API'}; errors "
                            "are relative to the finest level of the same integrator.")
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
    chart.set_title({"name": "Error against run time (work-precision)"})
    chart.set_x_axis({"name": "Run time (s)", "log_base": 10, "min": lo_t, "max": hi_t})
    chart.set_y_axis({"name": "Relative error of the peak", "log_base": 10, "min": lo_e,
                      "max": hi_e, "num_format": "0E+0"})
    chart.set_size({"width": 720, "height": 420})
    ws.insert_chart(row + 2, 0, chart)
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
