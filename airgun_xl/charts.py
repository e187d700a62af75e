"""Native scatter charts of a shot: the report's figures (Figs. 12, 14-15, 16, 17, 19).

Each chart is a :class:`ChartSpec`; its series name the data they plot by key (see
:func:`series_data`). The writer decides where each series' cells are: on the sheet that holds
them already, or, when that sheet is not written at full resolution or the series is longer
than :data:`POINT_BUDGET`, as a peak-keeping decimated copy on the ChartData sheet.
"""
import math
from dataclasses import dataclass

import numpy as np

from .engine.summary import KG, SPECTRUM_MAX_HZ

#: Most points a chart series references; spreadsheet apps slow down well before 100,000.
POINT_BUDGET = 20_000

#: Points of a decimated copy: 4,000 buckets' min and max, several per pixel of any chart.
COPY_POINTS = 8_000

LINE = {"type": "scatter", "subtype": "straight"}
COLORS = ("#1f4e79", "#c00000", "#548235", "#7f6000")


@dataclass(frozen=True)
class Series:
    key: str
    name: str
    markers: bool = False


@dataclass(frozen=True)
class ChartSpec:
    key: str
    title: str
    x_title: str
    y_title: str
    series: tuple
    x_range: tuple = None  # (min, max); None: the run's time span


CHARTS = (
    ChartSpec("accel", "Test-item acceleration (Fig. 12)", "Time (s)", "Acceleration (kG's)",
              (Series("accel_kg", "Acceleration"),
               Series("filtered_kg", "Filtered samples", markers=True),
               Series("compared_kg", "Other model (--compare-models)"))),
    ChartSpec("spectrum", "FFT of the test-item acceleration (Figs. 14-15)", "Frequency (Hz)",
              "Amplitude (kG)", (Series("spectrum", "Amplitude"),), (0.0, SPECTRUM_MAX_HZ)),
    ChartSpec("force", "Mitigator force (Fig. 16)", "Time (s)", "Force (N)",
              (Series("force", "Mitigator force"),)),
    ChartSpec("crush", "Mitigator deflection and plastic wave front (Fig. 17)", "Time (s)",
              "Deflection (m)", (Series("deflection", "Mitigator deflection"),
                                 Series("x_plastic", "Plastic wave front"))),
    ChartSpec("velocity", "OBR velocity (Fig. 19)", "Time (s)", "Velocity (m/s)",
              (Series("v31", "OBR front plate"), Series("v1", "MEM"))),
    ChartSpec("displacements", "Displacements", "Time (s)", "Displacement (m)",
              (Series("y1", "Y1 (MEM)"), Series("y31", "Y31 (OBR Front Plate)"),
               Series("y32", "Y32 (OBR Back Plate)"), Series("y33", "Y33 (Test Item)"))),
)


def series_data(result, spectrum, compared=None):
    """Full-resolution ``(x, y)`` arrays of every chart series key."""
    h = result.history
    t = h.time
    f_rows = result.filtered.rows[result.filtered.rows < len(t)]
    f_vals = result.filtered.values[result.filtered.rows < len(t)]
    data = {
        "accel_kg": (t, result.accel_kg),
        "filtered_kg": (t[f_rows], f_vals / KG),
        "spectrum": (spectrum.frequency, spectrum.amplitude),
        "y1": (t, h.y1), "y31": (t, h.y31), "y32": (t, h.y32), "y33": (t, h.y33),
    }
    if compared is not None:
        data["compared_kg"] = (compared.history.time, compared.accel_kg)
    for key in ("force", "deflection", "x_plastic", "v31", "v1"):
        values = getattr(h, key)
        if values is not None:
            data[key] = (t, values)
    return {k: v for k, v in data.items() if np.isfinite(v[1]).any()}


def nice_range(values, include_zero=False):
    """(min, max) rounded outward to a round step, with a little headroom."""
    finite = np.asarray(values)[np.isfinite(values)]
    if not len(finite):
        return 0.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    if include_zero:
        lo, hi = min(lo, 0.0), max(hi, 0.0)
    if hi == lo:
        hi, lo = hi + 1.0, lo - 1.0
    span = hi - lo
    step = 10 ** math.floor(math.log10(span / 5))
    for factor in (1, 2, 5, 10):
        if span / (factor * step) <= 8:
            step *= factor
            break
    return math.floor(lo / step) * step, math.ceil(hi / step) * step


def add_charts(workbook, sheet, refs, data, max_time, labels=None):
    """Insert the charts on ``sheet``, two a row.

    Parameters
    ----------
    workbook : xlsxwriter.Workbook
    sheet : xlsxwriter worksheet
    refs : dict
        Series key -> :class:`airgun_xl.workbook.sheets.Ref` (where its cells are).
    data : dict
        Series key -> full-resolution (x, y), for the axis ranges.
    max_time : float
        End of the time axis [s].
    labels : dict, optional
        Series key -> legend name, overriding the chart's own.
    """
    sheet.write_string(0, 0, "Charts of this shot; the figure numbers are those of ARL-TR-3559.")
    sheet.set_landscape()
    sheet.fit_to_pages(1, 0)  # printed (and rendered to PDF) one page wide
    placed = 0
    for spec in CHARTS:
        present = [s for s in spec.series if s.key in refs]
        if not present:
            continue
        chart = workbook.add_chart(LINE)
        decimated = []
        for i, s in enumerate(present):
            ref = refs[s.key]
            name = (labels or {}).get(s.key, s.name)
            options = {"name": name, "categories": ref.x_range(), "values": ref.y_range()}
            color = COLORS[i % len(COLORS)]
            if s.markers:
                options["marker"] = {"type": "circle", "size": 5,
                                     "border": {"color": color}, "fill": {"color": color}}
                options["line"] = {"none": True}
            else:
                options["line"] = {"color": color, "width": 1.25}
                options["marker"] = {"type": "none"}
            chart.add_series(options)
            if ref.points < ref.total:
                decimated.append(f"{ref.points:,} of {ref.total:,} points")
        title = spec.title
        if decimated:
            title += f"\n(decimated to {decimated[0]}, peaks kept)"
        chart.set_title({"name": title, "name_font": {"size": 11}})
        ys = np.concatenate([data[s.key][1] for s in present])
        xlo, xhi = spec.x_range or (0.0, max_time)
        ylo, yhi = nice_range(ys, include_zero=True)
        chart.set_x_axis({"name": spec.x_title, "min": xlo, "max": xhi,
                          "major_gridlines": {"visible": True, "line": {"color": "#d9d9d9"}},
                          "num_format": "General"})
        chart.set_y_axis({"name": spec.y_title, "min": ylo, "max": yhi,
                          "major_gridlines": {"visible": True, "line": {"color": "#d9d9d9"}},
                          "num_format": "0.0E+0" if max(abs(ylo), abs(yhi)) >= 1e5
                          else "General"})
        chart.set_legend({"position": "bottom"} if len(present) > 1 else {"none": True})
        chart.set_size({"width": 640, "height": 360})
        row, col = 2 + (placed // 2) * 19, (placed % 2) * 10
        sheet.insert_chart(row, col, chart)
        placed += 1
    return placed
