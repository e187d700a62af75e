"""The sheets beyond the macro's: Tracked, Spectrum, Summary and ChartData.

Each writer returns the :class:`Ref` of the series it holds, so charts can point at cells that
are already written instead of copying them.
"""
import datetime
import math
from dataclasses import dataclass

import numpy as np

from ..cells import address
from ..crush_law import speeds_text
from ..engine.decimate import minmax_indices
from ..engine.summary import PULSE_FRACTION, SPECTRUM_MAX_HZ
from ..errors import OutputError
from .charts import COPY_POINTS, POINT_BUDGET
from .report import Style, data_pages, general_format, one_page, shown


@dataclass(frozen=True)
class Ref:
    """Where a chart series' cells are: a sheet, x and y columns, rows (0-based, inclusive)."""

    sheet: str
    x_col: int
    y_col: int
    first_row: int
    last_row: int
    total: int  # points of the full-resolution series
    x_sheet: str | None = None  # the x values on another sheet (None: on ``sheet``) ...
    x_first_row: int | None = None  # ... from this row, as many as the y values

    @property
    def points(self):
        return self.last_row - self.first_row + 1

    def x_range(self):
        sheet = self.x_sheet or self.sheet
        first = self.first_row if self.x_first_row is None else self.x_first_row
        return [sheet, first, self.x_col, first + self.points - 1, self.x_col]

    def y_range(self):
        return [self.sheet, self.first_row, self.y_col, self.last_row, self.y_col]


def write_about(ws, about, bold):
    """Label and text lines at the head of a sheet (rows 0..), the labels bold; returns the
    first row after them."""
    for r, (label, text) in enumerate(about):
        ws.write_string(r, 0, label, bold)
        ws.write_string(r, 1, text)
    return len(about)


#: Significant digits a data sheet shows of its numbers (the cells hold all 17).
DATA_DIGITS = 7


def data_format(values):
    """The number format of a data column: whole numbers as such (a count, a flag),
    otherwise :data:`DATA_DIGITS` significant digits of the largest magnitude, or scientific
    notation past 1e6 or below 1e-3 (:func:`~airgun_xl.xlsx.report.general_format`)."""
    finite = values[np.isfinite(values)]
    if len(finite) and np.all(finite == np.round(finite)) and np.abs(finite).max() < 1e15:
        return "#,##0"
    return general_format(finite.tolist(), DATA_DIGITS)


def write_number_columns(ws, first_row, columns, style=None):
    """Write ``{col: array}`` down from ``first_row``; NaN cells are left empty. With
    ``style`` (a :class:`~airgun_xl.xlsx.report.Style`), each column is shown in a format
    of :data:`DATA_DIGITS` significant digits of its largest value, or in scientific
    notation, never as General."""
    for col, given in columns.items():
        values = np.asarray(given, dtype=float)
        fmt = None if style is None else style.get(num_format=data_format(values))
        finite = np.concatenate(([False], np.isfinite(values), [False]))
        edges = np.flatnonzero(np.diff(finite.astype(np.int8)))
        for start, stop in zip(edges[0::2].tolist(), edges[1::2].tolist(), strict=True):
            if ws.write_number_column(first_row + start, col, values[start:stop], fmt) == -1:
                raise OutputError(f"{ws.get_name()}: {stop - start:,} rows from row "
                                  f"{first_row + start + 1:,} pass the sheet's last row; "
                                  "expected fewer rows on the sheet (a larger row stride: every)")


#: A data sheet's column width [characters]: the widest figure :func:`write_number_columns`
#: shows, a sign, a point and its digits, prints whole.
DATA_WIDTH = 16


def write_data_sheet(ws, headers, columns, style, shot=None, width=DATA_WIDTH):
    """A data sheet: ``headers`` in row 1, the ``{col: array}`` columns under them (see
    :func:`write_number_columns`), printed by itself (:func:`~airgun_xl.xlsx.report.data_pages`)."""
    ws.set_column(0, len(headers) - 1, width)
    ws.write_row(0, 0, headers, style.header)
    write_number_columns(ws, 1, columns, style)
    rows = max((len(v) for v in columns.values()), default=0)
    data_pages(ws, rows, len(headers) - 1, shot=shot)


TRACKED_COLUMNS = (
    ("Time (s)", "time"), ("Mitigator force (N)", "force"),
    ("Plastic wave front x_p (m)", "x_plastic"), ("Mitigator deflection (m)", "deflection"),
    ("M1 (kg)", "m1"), ("m31 (kg)", "m31"), ("OBR front plate velocity (m/s)", "v31"),
    ("MEM velocity (m/s)", "v1"),
)


def write_tracked(wb, result, keep, sheet_class, name="Tracked", shot=None):
    """The Tracked sheet: step values the kernel recorded, every kept row."""
    ws = wb.add_worksheet(name, worksheet_class=sheet_class)
    ws.set_column(0, len(TRACKED_COLUMNS) - 1, 16)
    style = Style(wb)
    h = result.history
    columns = {}
    for col, (header, key) in enumerate(TRACKED_COLUMNS):
        ws.write_string(0, col, header, style.header)
        values = getattr(h, key)
        if values is not None:
            columns[col] = values[keep]
    write_number_columns(ws, 1, columns, style)
    data_pages(ws, len(keep), len(TRACKED_COLUMNS) - 1, shot=shot)
    full = len(keep) == result.rows
    refs = {}
    for col, (_, key) in enumerate(TRACKED_COLUMNS[1:], start=1):
        if col in columns and full:
            refs[key] = Ref(ws.get_name(), 0, col, 1, len(keep), len(keep))
    return refs


def write_spectrum(wb, spectrum, sheet_class, name="Spectrum", shot=None):
    ws = wb.add_worksheet(name, worksheet_class=sheet_class)
    style = Style(wb)
    ws.set_column(0, 1, 16)
    ws.set_column(3, 3, 60, style.wrap)
    ws.write_string(0, 0, "Frequency (Hz)", style.header)
    ws.write_string(0, 1, "Amplitude (kG)", style.header)
    ws.write_string(0, 3, f"Single-sided amplitude spectrum 2|FFT|/N (numpy.fft.rfft) of the "
                          f"test-item acceleration in kG, 0-{SPECTRUM_MAX_HZ:,.0f} Hz")
    write_number_columns(ws, 1, {0: spectrum.frequency, 1: spectrum.amplitude}, style)
    n = len(spectrum.frequency)
    data_pages(ws, n, 3, shot=shot)
    return {"spectrum": Ref(ws.get_name(), 0, 1, 1, n, n)} if n else {}


def write_chart_data(wb, data, refs, sheet_class, name="ChartData", budget=POINT_BUDGET,
                     time_ms=None, shot=None):
    """Copies on ChartData of the series that have no usable home; decimated past the budget.

    ``budget`` lowers the budget (the rows a ``--every N`` run keeps on its sheets): a longer
    series is cut to that many points, the min and max of each bucket. ``time_ms`` is the kept
    rows' time [ms]: a series charted from its home (whose time column is in s) takes its x
    from a copy of it here, so every chart's time axis is in ms, as the Summary. Returns the
    refs of all chart series, homes and copies.
    """
    import dataclasses

    ws = wb.add_worksheet(name, worksheet_class=sheet_class)
    style = Style(wb)
    limit = max(2, min(budget, POINT_BUDGET))
    ws.write_string(0, 0, f"Chart series not on another sheet at full resolution; a series "
                          f"longer than {limit:,} points is cut to {min(COPY_POINTS, limit):,}, "
                          "the min and max of each bucket of consecutive points.")
    out = {}
    col = 0
    time_col = None
    for key, (x, y) in data.items():
        home = refs.get(key)
        if home is not None and home.points <= limit:
            if key in TIME_SERIES and time_ms is not None:
                if time_col is None:  # the kept rows' time in ms, once, for every home
                    time_col = col
                    ws.write_string(1, col, "Time (ms)", style.header)
                    write_number_columns(ws, 2, {col: time_ms[:limit]}, style)
                    col += 1
                home = dataclasses.replace(home, x_sheet=ws.get_name(), x_col=time_col,
                                           x_first_row=home.first_row + 1)
            out[key] = home
            continue
        index = minmax_indices(y, min(COPY_POINTS, limit) if len(y) > limit else limit)
        ws.write_string(1, col, f"{key} x", style.header)
        ws.write_string(1, col + 1, key, style.header)
        write_number_columns(ws, 2, {col: x[index], col + 1: y[index]}, style)
        out[key] = Ref(ws.get_name(), col, col + 1, 2, 1 + len(index), len(y))
        col += 2
    longest = max((r.last_row for r in out.values() if r.sheet == ws.get_name()), default=1)
    if time_col is not None:
        longest = max(longest, 1 + len(time_ms[:limit]))
    # as wide as the other data sheets' columns: at the default width a six-decimal time or a
    # negative figure printed as "###" (seen on design --confidence's PDF)
    ws.set_column(0, max(col - 1, 0), DATA_WIDTH)
    data_pages(ws, max(longest, 1), max(col - 1, 0), header_rows=2, shot=shot)
    return out


#: Chart series against time (the rest are against frequency).
TIME_SERIES = ("accel_kg", "filtered_kg", "compared_kg", "y1", "y31", "y32_rel", "y33_rel",
               "force", "deflection", "x_plastic", "v31", "v1")


def variant_name(result):
    """How a compared run is named: its model, or its unloading force."""
    if result.params.unloading == "continuous":
        return "continuous unloading"
    return f"{result.model} model"


def summary_rows(result, summary, prov):
    """(label, value in SI, quantity code of :data:`~airgun_xl.xlsx.report.QUANTITIES`
    or "" for text, definition) per Summary row."""
    p = result.params
    s = summary
    rows = [
        ("Peak acceleration (raw)", s.peak_kg, "kG", "largest Acceleration (kG's), column U"),
        ("Time of peak", s.time_of_peak, "s", ""),
        ("Peak acceleration (filtered)", s.filtered_peak_kg, "kG",
         "largest Filtered Acceleration (column AB) / -9800"),
        ("Time of filtered peak", s.time_of_filtered_peak, "s", ""),
        ("Pulse duration", s.pulse_duration, "s",
         f"from the first to the last row with acceleration >= {PULSE_FRACTION:.0%} of its "
         "peak"),
        ("Pulse start", s.pulse_start, "s", ""),
        ("Pulse end", s.pulse_end, "s", ""),
        ("Maximum crush", s.max_crush, "m", "largest mitigator deflection Y31 - Y1"),
        ("Final mitigator length", s.final_length, "m", "E16 + E19 - maximum crush"),
        ("Final M1", s.final_m1, "kg", "MEM with the uncrushed mitigator, as the macro ends"),
        ("Final m31", s.final_m31, "kg", "OBR front plate with the crushed honeycomb"),
        ("OBR exit velocity", s.obr_exit_velocity, "m/s",
         "OBR front plate velocity at the end of the run"),
        ("MEM final velocity", s.mem_final_velocity, "m/s", ""),
    ]
    for i in range(3):
        value = s.spectrum.peaks[i] if i < len(s.spectrum.peaks) else None
        rows.append((f"Dominant frequency {i + 1}", value, "Hz",
                     "local maxima of the spectrum past the pulse's own lobe (from "
                     f"{s.spectrum.band_start:,.0f} Hz), most prominent first; marked on the "
                     "FFT chart" if i == 0 else ""))
    for label, freqs in (("initial", s.natural_initial), ("final", s.natural_final)):
        for i, f in enumerate(freqs):
            rows.append((f"OBR chain natural frequency {i + 1} ({label} masses)", f, "Hz",
                         "sqrt of the eigenvalues of M^-1 K of the bird's springs / 2 pi"
                         if i == 0 and label == "initial" else ""))
    compared = prov.compared
    if compared is not None:
        name = variant_name(compared)
        rows += [(f"Peak acceleration, {name}", compared.peak_kg, "kG",
                  "the same shot without the macro's unloading quirk (--unloading "
                  "continuous)" if compared.params.unloading == "continuous" else
                  "the same shot with the other model"),
                 (f"Time of peak, {name}", compared.time_of_peak, "s", "")]
    rows += [
        ("Model", p.model + (" - the rigid-body model" if result.model == "rigid" else ""),
         "", ""),
        ("Integrator", result.integrator, "", ""),
        ("Crush-factor law", "the macro's polynomial, Eq. (8)" if p.crush_law.is_legacy else
         f"fitted, {speeds_text(p.crush_law.v_range)}",
         "", "" if p.crush_law.is_legacy else
         f"the archive's law {p.crush_law.source} (calibrate --archive --name)"
         if p.crush_law.source else "the Crush law sheet (airgun-xl calibrate)"),
        ("Time step", p.delta, "step", address("delta")),
        ("Critical time step", prov.dt_crit, "step", "largest step stable for the OBR chain, "
         "the springs that always act (airgun-xl check)")
        if prov.dt_crit != float("inf") else
        ("Critical time step", "n/a", "", "none: the Newmark integrator is implicit in the "
         "OBR chain, so no step bounds it"),
        ("Critical time step, unloading", prov.dt_unloading, "step",
         "largest step stable while the mitigator unloads at full length"),
        ("Critical time step, compacted", prov.dt_compacted, "step",
         "largest step stable while the mitigator unloads fully compacted"),
        ("Time step / critical", prov.dt_ratio, "ratio",
         "above 1 the run diverges from its first steps")
        if prov.dt_crit != float("inf") else
        ("Time step / critical", "n/a", "", "no critical time step (Newmark)"),
        ("Rows", result.rows, "count", "time rows of the run"),
        ("Rows on the sheets", prov.sheet_rows, "count", ""),
        ("Every N-th row", prov.every, "count", "1: every row is on the sheets"),
        ("Engine version", prov.version, "", "airgun-xl"),
        ("Input file", prov.input, "", ""),
        ("Input SHA-256", prov.sha256, "", ""),
    ]
    if prov.kernel_seconds is not None:
        rows += [("Kernel run time", prov.kernel_seconds, "runtime-fine",
                  "time stepping alone"),
                 ("Run time", prov.run_seconds, "runtime",
                  "reading, stepping and post-processing, before writing")]
    return rows


def write_predicted_verdict(wb, ws, verdict, row, style, doubted=()):
    """The prediction judged by the shot's specification, from ``row``: the verdict, then a
    row a criterion (value, unit, limits, margin, PASS/FAIL); the next free row. ``doubted``:
    the cells whose warnings put the pulse's figures in doubt, and so the verdict."""
    from ..studies.acceptance import limits_text

    good = wb.add_format({"bold": True, "font_color": "#006100", "bg_color": "#C6EFCE"})
    bad = wb.add_format({"bold": True, "font_color": "#9C0006", "bg_color": "#FFC7CE"})
    number = wb.add_format({"num_format": "0.000", "align": "right"})
    ws.write_string(row, 0, "Specification: predicted verdict", style.bold)
    ws.write_string(row, 1, verdict.word, good if verdict.passed else bad)
    doubt = f"DOUBTED: see the warnings on {', '.join(doubted)}; " if doubted else ""
    ws.write_string(row, 3, f"{doubt}the specification from {verdict.spec.source or 'options'}")
    row += 1
    for c in verdict.criteria:
        ws.write_string(row, 0, f"Specification: {c.name}")
        if np.isfinite(c.value):
            ws.write_number(row, 1, c.value, number)
        ws.write_string(row, 2, c.unit)
        ws.write_string(row, 3, f"{c.word}: limits {limits_text(c)}"
                        f", margin {c.margin:+.2f} {c.margin_unit}"
                        + (f"; {c.detail}" if c.detail else ""))
        row += 1
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    for line in verdict.definitions[1:] + [f"note: {n}" for n in verdict.spec.notes]:
        write_definition(ws, row, line, wrap)
        row += 1
    return row


#: Characters a line of the Summary's Definition column (D, 100 wide) holds.
DEFINITION_CHARS = 110


def write_definition(ws, row, line, wrap):
    """``line`` in the Summary's Definition column at ``row``, wrapped (``wrap``: a text-wrap
    format) and the row made tall enough for its lines: a long line printed in one cell runs
    past the page's right edge and prints cut."""
    ws.write_string(row, 3, line, wrap)
    if len(line) > DEFINITION_CHARS:
        ws.set_row(row, 15 * math.ceil(len(line) / DEFINITION_CHARS))


def write_summary(wb, result, summary, prov, name="Summary"):
    """The Summary sheet: one labelled cell per figure (label A, value B in the unit of C, with
    a number format fit for it, definition D); printed as one landscape page."""
    ws = wb.add_worksheet(name)
    style = Style(wb)
    ws.set_column(0, 0, 44)
    ws.set_column(1, 1, 16)
    ws.set_column(2, 2, 6)
    ws.set_column(3, 3, 100)
    text = style.get(align="left")
    for col, heading in enumerate(("Quantity", "Value", "Unit", "Definition")):
        ws.write_string(0, col, heading, style.bold)
    rows = summary_rows(result, summary, prov)
    flags = flagged_figures(list(prov.warnings))
    for row, (label, value, code, definition) in enumerate(rows, 1):
        ws.write_string(row, 0, label)
        note = definition
        if label in flags:  # a figure the warnings below put in doubt, flagged where shown
            note = f"DOUBTED: see the warnings on {', '.join(flags[label])}" + (
                f"; {definition}" if definition else "")
        if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(value,
                                                                                         bool):
            ws.write_number(row, 1, shown(float(value), code),
                            style.of(code, label in flags, align="right"))
        elif isinstance(value, datetime.datetime):
            ws.write_string(row, 1, value.isoformat(), text)
        elif value is not None:
            ws.write_string(row, 1, str(value), text)
        if code and style.unit(code):
            ws.write_string(row, 2, style.unit(code))
        if note:
            ws.write_string(row, 3, note)
    row = len(rows) + 2
    if prov.verdict is not None:
        row = write_predicted_verdict(wb, ws, prov.verdict, row, style,
                                      flags.get("Peak acceleration (raw)", [])) + 1
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    for note in prov.study_notes:
        ws.write_string(row, 0, "Design", style.get(bold=True, valign="top"))
        write_definition(ws, row, note, wrap)
        row += 1
    last = write_warnings(wb, ws, row, list(prov.warnings), 3)
    one_page(ws, last, 3, shot=prov.shot, title="Summary")
    ws.freeze_panes(1, 0)
    return ws


#: The Summary's figures each warning puts in doubt, by the cell the warning names: the crush
#: and the masses for the mitigator's own cells; every acceleration figure for the rest (the
#: crush law's range, the unloading quirk, the step, an implausible input).
_CRUSH_FIGURES = ("Maximum crush", "Final mitigator length", "Final M1", "Final m31")
_PULSE_FIGURES = ("Peak acceleration (raw)", "Time of peak", "Peak acceleration (filtered)",
                  "Time of filtered peak", "Pulse duration", "Pulse start", "Pulse end")
_DOUBTED = {address("hcylinder"): _CRUSH_FIGURES, address("mmitigator"): _CRUSH_FIGURES[2:],
            address("filter_frequency"): ("Peak acceleration (filtered)", "Time of filtered peak")}


def flagged_figures(warnings):
    """{Summary label: [cells of the warnings that doubt it]} for a run's warnings (each
    starts with the cell it names, as ``E19 (...)``); a warning naming no cell doubts none."""
    out: dict = {}
    for text in warnings:
        cell = text.split(" ", 1)[0]
        if not (cell[:1].isalpha() and cell[1:].isdigit()):
            continue
        for label in _DOUBTED.get(cell, _PULSE_FIGURES + _CRUSH_FIGURES):
            out.setdefault(label, [])
            if cell not in out[label]:
                out[label].append(cell)
    return out


#: Characters a line of a merged warning row holds, across the Summary's printed width.
WARNING_LINE_CHARS = 150


def write_warnings(wb, ws, row, warnings, last_col, line_chars=WARNING_LINE_CHARS,
                   heading="Warnings"):
    """The run's warnings from ``row`` down, each across columns 0..``last_col`` with its text
    wrapped (``line_chars`` to a line, for the row's height), under a bold heading that counts
    them; returns the last row written. Every warning the terminal showed is on the printed
    page."""
    bold = wb.add_format({"bold": True, "font_color": "#9C0006" if warnings else "#000000"})
    ws.write_string(row, 0, f"{heading} ({len(warnings)})" if warnings else
                    f"{heading}: none", bold)
    return write_wrapped(wb, ws, row + 1, warnings, last_col, line_chars) - 1


def write_wrapped(wb, ws, row, lines, last_col, line_chars=WARNING_LINE_CHARS):
    """``lines`` from ``row`` down, each across columns 0..``last_col`` with its text wrapped
    (``line_chars`` to a line, for the row's height): nothing cut at the page's edge. Returns
    the next free row."""
    wrap = wb.add_format({"text_wrap": True, "valign": "top"})
    for i, text in enumerate(lines):
        ws.merge_range(row + i, 0, row + i, last_col, "", wrap)
        ws.write_string(row + i, 0, text, wrap)
        ws.set_row(row + i, 15 * max(1, -(-len(text) // line_chars)))
    return row + len(lines)


def parameter_rows(params):
    """[(cell, quantity, value or None when blank, unit, meaning)] of every cell the macro
    reads (:data:`airgun_xl.cells.CELLS`), as the run used them: the Parameters sheet's
    rows and the fill's PDF's list of the shot's inputs."""
    from ..cells import CELLS

    rows = []
    for cell in CELLS:
        value = getattr(params, cell.name, None)
        number = (float(value) if isinstance(value, (int, float)) and not isinstance(value, bool)
                  else None)
        rows.append((cell.address, cell.label, number, cell.unit.replace("^3", "³") or "-",
                     cell.meaning))
    return rows


def write_parameters(wb, params, shot, name="Parameters"):
    """The Parameters sheet: every cell the macro reads (:data:`airgun_xl.cells.CELLS`), its
    quantity, the value the run used (exact, shown to 7 significant digits), its unit and
    meaning; printed as one landscape page. Sheet 1 keeps the input's layout as data."""
    ws = wb.add_worksheet(name)
    style = Style(wb)
    widths = (7, 30, 16, 8, 70)
    for col, width in enumerate(widths):
        ws.set_column(col, col, width)
    ws.write_string(0, 0, f"Parameters of {shot or 'the shot'}, as the run read them "
                          "(ARL-TR-3559's cells)", style.title)
    for col, heading in enumerate(("Cell", "Quantity", "Value", "Unit", "Meaning")):
        ws.write_string(2, col, heading, style.header)
    row = 3
    for address_, label, value, unit, meaning in parameter_rows(params):
        ws.write_string(row, 0, address_)
        ws.write_string(row, 1, label)
        if value is not None:
            ws.write_number(row, 2, value,
                            style.fmt(general_format([value], digits=7), align="right"))
        else:
            ws.write_string(row, 2, "blank", style.get(align="right"))
        ws.write_string(row, 3, unit)
        ws.write_string(row, 4, meaning)
        row += 1
    law = params.crush_law
    ws.write_string(row + 1, 1, "Crush-factor law")
    ws.write_string(row + 1, 2, "Eq. (8)" if law.is_legacy else "fitted")
    ws.write_string(row + 1, 4, "the macro's polynomial" if law.is_legacy else
                    f"from the Crush law sheet, valid {speeds_text(law.v_range)}")
    ws.write_string(row + 2, 1, "Model; unloading force")
    ws.write_string(row + 2, 2, f"{params.model}; {params.unloading}")
    one_page(ws, row + 2, len(widths) - 1, shot=shot, title="Parameters")
    return ws
