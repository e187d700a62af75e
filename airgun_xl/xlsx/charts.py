"""Native scatter charts of a shot: the report's figures (Figs. 12, 14-15, 16, 17, 19).

Each chart is a :class:`ChartSpec`; its series name the data they plot by key (see
:func:`series_data`). The writer decides where each series' cells are: on the sheet that holds
them already, or, when that sheet is not written at full resolution or the series is longer
than :data:`POINT_BUDGET`, as a peak-keeping decimated copy on the ChartData sheet.
"""
import math
from dataclasses import dataclass

import numpy as np

from ..engine.summary import KG, PEAK_MIN_HZ, SPECTRUM_MAX_HZ
from . import report
from .report import one_page

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
    y2: bool = False  # on the secondary (right) axis
    dash: bool = False  # dashed, drawn over the others (a comparison or a mark)
    style: str = "solid"  # the line's dash type, to tell apart curves of one chart


@dataclass(frozen=True)
class ChartSpec:
    key: str
    title: str
    x_title: str
    y_title: str
    series: tuple
    x_range: tuple | None = None  # (min, max); None: the run's time span
    y2_title: str | None = None
    y_format: str | None = None  # the y axis's number format (None: by its span)
    x_format: str | None = None  # the x axis's ("0.0," shows Hz as kHz)


#: Lowest frequency the spectrum chart shows: below it the pulse's own content (4.2 kG at 0 Hz
#: for shot A) would swamp the OBR modes that Figs. 14-15 show.
SPECTRUM_MIN_HZ = PEAK_MIN_HZ

CHARTS = (
    ChartSpec("accel", "Test-item acceleration (Fig. 12)", "Time (ms)", "Acceleration (kG's)",
              (Series("accel_kg", "Acceleration"),
               Series("filtered_kg", "Filtered samples", markers=True),
               Series("compared_kg", "Other model", dash=True))),
    ChartSpec("spectrum", "FFT of the test-item acceleration (Figs. 14-15), from the end of "
              "the pulse's own lobe", "Frequency (kHz)", "Amplitude (kG)",
              (Series("spectrum", "Amplitude"),
               Series("dominant", "Dominant frequencies (the Summary's)", markers=True),
               Series("natural", "OBR chain natural frequencies (initial masses)",
                      dash=True)),
              (SPECTRUM_MIN_HZ, SPECTRUM_MAX_HZ), x_format="0.0,"),
    ChartSpec("force", "Mitigator force (Fig. 16)", "Time (ms)", "Force (kN)",
              (Series("force", "Mitigator force"),), y_format="#,##0,"),
    ChartSpec("crush", "Mitigator deflection and plastic wave front (Fig. 17)", "Time (ms)",
              "Deflection (m)", (Series("deflection", "Mitigator deflection"),
                                 Series("x_plastic", "Plastic wave front"))),
    ChartSpec("velocity", "OBR velocity (Fig. 19)", "Time (ms)", "Velocity (m/s)",
              (Series("v31", "OBR front plate"), Series("v1", "MEM"))),
    ChartSpec("displacements", "Displacements; Y32, Y33 relative to Y31 (right axis)",
              "Time (ms)", "Displacement (m)",
              (Series("y1", "Y1 (MEM)"), Series("y31", "Y31 (OBR Front Plate)"),
               Series("y32_rel", "Y32 - Y31 (mm)", y2=True),
               Series("y33_rel", "Y33 - Y31 (mm)", y2=True, style="round_dot")),
              y2_title="Relative to Y31 (mm)"),
)


def natural_marks(frequencies, top):
    """(x, y) of vertical marks from 0 to ``top`` at each frequency, NaN between them (empty
    cells: the chart's line breaks there)."""
    x, y = [], []
    for f in frequencies:
        x += [f, f, np.nan]
        y += [0.0, top, np.nan]
    return np.array(x[:-1], dtype=float), np.array(y[:-1], dtype=float)


def spectrum_range(spectrum):
    """(min, max) [Hz] of the spectrum chart's axis: from the whole kHz below the end of the
    pulse's own lobe (its ticks on round kHz; its curve starts at the lobe's end) to
    :data:`SPECTRUM_MAX_HZ`."""
    return float(np.floor(spectrum.band_start / 1000) * 1000), SPECTRUM_MAX_HZ


def series_data(result, spectrum, compared=None, natural=()):
    """Full-resolution ``(x, y)`` arrays of every chart series key.

    ``natural`` are the OBR chain's natural frequencies [Hz], marked on the spectrum chart.
    """
    h = result.history
    t = h.time * 1e3  # [ms], as the Summary
    f_rows = result.filtered.rows[result.filtered.rows < len(t)]
    f_vals = result.filtered.values[result.filtered.rows < len(t)]
    data = {
        "accel_kg": (t, result.accel_kg),
        # below one row AB holds no acceleration (the sub-row filter quirk): not charted
        "filtered_kg": ((t[f_rows], f_vals / KG) if result.params.samplerate >= 1 else
                        (t[:0], f_vals[:0])),
        # from the end of the pulse's own lobe (its axis starts at the whole kHz below)
        "spectrum": (spectrum.frequency[spectrum.frequency >= spectrum.band_start],
                     spectrum.amplitude[spectrum.frequency >= spectrum.band_start]),
        "y1": (t, h.y1), "y31": (t, h.y31),
        "y32_rel": (t, (h.y32 - h.y31) * 1e3), "y33_rel": (t, (h.y33 - h.y31) * 1e3),
    }
    lo = spectrum.band_start
    shown = (spectrum.frequency >= lo) & (spectrum.frequency <= SPECTRUM_MAX_HZ)
    marks = [f for f in natural if lo <= f <= SPECTRUM_MAX_HZ]
    if spectrum.peaks:  # the Summary's dominant frequencies, marked where they are
        at = np.searchsorted(spectrum.frequency, spectrum.peaks)
        data["dominant"] = (spectrum.frequency[at], spectrum.amplitude[at])
    if marks and shown.any():
        data["natural"] = natural_marks(marks, float(np.max(spectrum.amplitude[shown])))
    if compared is not None:
        data["compared_kg"] = (compared.history.time * 1e3, compared.accel_kg)
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
    # 12 digits drop the binary noise of k * step (0.6000000000000001 -> 0.6)
    return (float(f"{math.floor(lo / step) * step:.12g}"),
            float(f"{math.ceil(hi / step) * step:.12g}"))


def titled(chart, title, x_axis, y_axis, height=400, legend="bottom"):
    """Set a chart's title, both axes (dicts for xlsxwriter: explicit limits), legend and
    size (720 px wide); returns the chart."""
    chart.set_title({"name": title})
    chart.set_x_axis(x_axis)
    chart.set_y_axis(y_axis)
    chart.set_legend({"position": legend} if legend else {"none": True})
    chart.set_size({"width": 720, "height": height})
    return chart


def log_axis(name, values, gridlines=False):
    """An xlsxwriter log axis over whole decades around ``values`` (positive)."""
    v = np.asarray(values, dtype=float)
    axis = {"name": name, "log_base": 10,
            "min": 10.0 ** np.floor(np.log10(max(float(v.min()), 1e-12))),
            "max": 10.0 ** np.ceil(np.log10(max(float(v.max()), 1e-12)))}
    if gridlines:
        axis["major_gridlines"] = {"visible": True}
    return axis


def line_series(chart, sheet, name, first, last, x_col, y_col, color, dash=None):
    """A line (no markers) of ``sheet``'s rows ``first..last`` (0-based), x from ``x_col``."""
    line = {"color": color, "width": 1.25}
    if dash:
        line["dash_type"] = dash
    chart.add_series({"name": name, "categories": [sheet, first, x_col, last, x_col],
                      "values": [sheet, first, y_col, last, y_col], "line": line,
                      "marker": {"type": "none"}})


def _axis(title, lo, hi, gridlines=True, num_format=None):
    return report.axis(title, lo, hi, gridlines=gridlines, num_format=num_format)


def _in_range(x, y, x_range):
    """The y values whose x lies in ``x_range`` (all of them for None)."""
    if x_range is None:
        return y
    return y[(x >= x_range[0]) & (x <= x_range[1])]


#: Charts on the Charts sheet: two a row, each this many rows tall.
CHART_ROWS, CHART_COLS = 19, 10


def add_charts(workbook, sheet, refs, data, max_time, labels=None, x_ranges=None, shot=None):
    """Insert the charts on ``sheet``, two a row; the sheet prints as one landscape page.

    Parameters
    ----------
    workbook : xlsxwriter.Workbook
    sheet : xlsxwriter worksheet
    refs : dict
        Series key -> :class:`airgun_xl.xlsx.sheets.Ref` (where its cells are).
    data : dict
        Series key -> full-resolution (x, y), for the axis ranges.
    max_time : float
        End of the time axis [ms].
    labels : dict, optional
        Series key -> legend name, overriding the chart's own.
    x_ranges : dict, optional
        Chart key -> (min, max) of its x axis, overriding the chart's own (the spectrum's
        band starts where the pulse's own lobe ends).
    shot : str, optional
        The input file's name, for the page header.

    Returns
    -------
    int
        Charts placed.
    """
    sheet.write_string(0, 0, "Charts of this shot; the figure numbers are those of ARL-TR-3559.")
    placed = 0
    for spec in CHARTS:
        present = [s for s in spec.series if s.key in refs]
        if not present:
            continue
        chart = workbook.add_chart(LINE)
        decimated = []
        # dashed series (a comparison, marks) last, so they are drawn over the others
        for i, s in enumerate(sorted(present, key=lambda s: s.dash)):
            ref = refs[s.key]
            name = (labels or {}).get(s.key, s.name)
            options = {"name": name, "categories": ref.x_range(), "values": ref.y_range(),
                       "y2_axis": s.y2}
            color = COLORS[i % len(COLORS)]
            if s.markers:
                options["marker"] = {"type": "circle", "size": 5,
                                     "border": {"color": color}, "fill": {"color": color}}
                options["line"] = {"none": True}
            else:
                options["line"] = {"color": color, "width": 2.0 if s.dash else 1.25,
                                   "dash_type": "dash" if s.dash else s.style}
                options["marker"] = {"type": "none"}
            chart.add_series(options)
            if ref.points < ref.total:
                decimated.append(f"{ref.points:,} of {ref.total:,} points")
        title = spec.title
        if decimated:
            title += f"\n(decimated to {decimated[0]}, peaks kept)"
        chart.set_title({"name": title, "name_font": {"size": 11}})
        x_range = (x_ranges or {}).get(spec.key, spec.x_range)
        xlo, xhi = x_range or (0.0, max_time)
        chart.set_x_axis(_axis(spec.x_title, xlo, xhi, num_format=spec.x_format))
        for secondary in (False, True):
            on_axis = [s for s in present if s.y2 == secondary]
            if not on_axis:
                continue
            ys = np.concatenate([_in_range(data[s.key][0], data[s.key][1], x_range)
                                 for s in on_axis])
            ylo, yhi = nice_range(ys, include_zero=True)
            if secondary:
                chart.set_y2_axis(_axis(spec.y2_title, ylo, yhi, gridlines=False))
            else:
                chart.set_y_axis(_axis(spec.y_title, ylo, yhi, num_format=spec.y_format))
        chart.set_legend({"position": "bottom"} if len(present) > 1 else {"none": True})
        chart.set_size({"width": 640, "height": 360})
        row, col = 2 + (placed // 2) * CHART_ROWS, (placed % 2) * CHART_COLS
        sheet.insert_chart(row, col, chart)
        placed += 1
    last_row = 2 + -(-placed // 2) * CHART_ROWS
    one_page(sheet, last_row, 2 * CHART_COLS - 1, shot=shot, title="Charts")
    return placed
