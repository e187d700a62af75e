"""The client's test report as a PDF (issue 46): the verdict's pages drawn directly, without a
spreadsheet application, by matplotlib's PDF backend (vector charts, text kept as text in
embedded TrueType fonts, so a PDF reader or ``pdftotext`` reads it back).

A report is a list of A4 pages. The first holds what the client is handed: the verdict, every
criterion with its value, limits and margin, the warnings, the recording's quality, where each
field of the specification came from, and a block for the test engineer's name and signature;
the text flows onto further pages when it is long. Then the charts: the pulse (with its
corridor or the peak's limits), its SRS and pseudo-velocity on log axes. Every page has a
header (the shot, the recording, the specification's source) and a footer (the tool's version,
the date, page n of m).

A fill's report (:func:`write_fill_pdf`) is its Summary (every figure with its unit and
definition, the figures the warnings put in doubt marked so), the predicted verdict when the
shot has a specification, the warnings, and the Charts page's six charts.

``reproducible`` leaves the date out of the footer and of the file's metadata: the same run
gives the same bytes.
"""
from __future__ import annotations

import datetime
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import OptionError
from ..version import __version__

#: A4 portrait [inch].
PAGE = (8.27, 11.69)

#: Margins [fraction of the page]: left, right, top (below the header), bottom (above the
#: footer).
LEFT, RIGHT, TOP, BOTTOM = 0.08, 0.92, 0.93, 0.07

#: Characters a full-width line of body text holds (9 pt DejaVu Sans on 0.84 of A4's width).
LINE_CHARS = 105

#: Line height of body text [fraction of the page's height].
LINE = 0.0135

#: Colours of the verdict's word.
PASS_COLOUR, FAIL_COLOUR = "#006100", "#9C0006"
#: NOT JUDGED (the record cannot show a criterion): neither the pass's nor the fail's colour.
NOT_JUDGED_COLOUR = "#9C5700"
#: Each word's colour.
WORD_COLOURS = {"PASS": PASS_COLOUR, "FAIL": FAIL_COLOUR, "NOT JUDGED": NOT_JUDGED_COLOUR}


#: The font every text is drawn in (matplotlib's own: on every platform matplotlib runs).
FONT = "DejaVu Sans"

_font: list[Any] = []


def drawable(text: str) -> str:
    """``text`` with each character the font has no glyph for written as its code point
    (``\\u6d4b``): a name in another script stays readable and exact, where the font would
    draw an empty box and matplotlib warn (a library's warning, on the user's terminal)."""
    if text.isascii():
        return text
    if not _font:
        from matplotlib import font_manager, ft2font

        _font.append(ft2font.FT2Font(font_manager.findfont(FONT)))
    return "".join(c if c.isascii() or _font[0].get_char_index(ord(c)) else
                   f"\\u{ord(c):04x}" for c in text)


def require_matplotlib(option: str = "--pdf") -> None:
    """One line naming the option when matplotlib (the ``plots`` extra) is not installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise OptionError(f"{option}: needs matplotlib, expected it installed (pip install "
                          "'airgun-xl[plots]')") from None


def check_pdf(pdf: Path, force: bool, inputs: Sequence[Any] = (), beside: Path | None = None,
              force_word: str = "--force") -> None:
    """``--pdf``: refused before any work when matplotlib is missing, or when ``pdf`` is a
    file the command may not write (:func:`~airgun_xl.transaction.check_output`: an input,
    or ``beside``, the workbook written with it). Beside its workbook the two are published
    together; in another folder, after it (:func:`~airgun_xl.transaction.for_file`)."""
    from ..transaction import check_output

    require_matplotlib()
    check_output(pdf, force, inputs=[*inputs, *([beside] if beside is not None else [])],
                 suffixes=(".pdf",), force_word=force_word)


class _Pages:
    """Pages being written: text flows down the current page, and a new one starts when the
    next line would pass the bottom margin."""

    def __init__(self) -> None:
        self.figures: list[Any] = []
        self.y = 0.0
        self.new()

    def new(self) -> None:
        from matplotlib.figure import Figure  # no pyplot: the caller's backend is left alone

        self.figures.append(Figure(figsize=PAGE))
        self.y = TOP

    @property
    def figure(self) -> Any:
        return self.figures[-1]

    def room(self, height: float) -> None:
        if self.y - height < BOTTOM:
            self.new()

    def text(self, text: str, size: float = 9.0, bold: bool = False, colour: str = "black",
             indent: float = 0.0, width: int = LINE_CHARS) -> None:
        """``text`` wrapped to the page's width, line by line, a paragraph kept on one page
        (one that fits a page is never split by a page break)."""
        lines = textwrap.wrap(drawable(text), width - int(indent * 120)) or [""]
        height = LINE * size / 9.0
        if height * len(lines) < TOP - BOTTOM:
            self.room(height * len(lines))
        for line in lines:
            self.room(height)
            self.figure.text(LEFT + indent, self.y, line, fontsize=size, color=colour,
                             fontweight="bold" if bold else "normal", va="top", ha="left",
                             parse_math=False)
            self.y -= height

    def gap(self, lines: float = 0.6) -> None:
        self.y -= LINE * lines

    def table(self, header: list[str], rows: list[list[str]], columns: list[float],
              colours: list[str | None] | None = None) -> None:
        """A table of text: ``columns`` the left edge of each column [fraction of the
        page's width from the left margin]; a long cell is wrapped within its column."""
        edges = [*columns, RIGHT - LEFT]
        widths = [max(8, int((b - a) * 125)) for a, b in zip(edges[:-1], edges[1:],
                                                               strict=True)]
        for k, row in enumerate([header, *rows]):
            wrapped = [textwrap.wrap(drawable(cell), w) or [""]
                       for cell, w in zip(row, widths, strict=True)]
            height = LINE * max(len(w) for w in wrapped)
            self.room(height)
            for x, lines, col in zip(columns, wrapped, range(len(row)), strict=True):
                colour = (colours[k - 1] if colours and k and col == len(row) - 1
                          else None) or "black"
                for j, line in enumerate(lines):
                    self.figure.text(LEFT + x, self.y - j * LINE, line, fontsize=8.5,
                                     va="top", ha="left", color=colour,
                                     fontweight="bold" if k == 0 or colour != "black"
                                     else "normal", parse_math=False)
            self.y -= height + LINE * 0.25


def _criteria_rows(verdict: Any) -> tuple[list[list[str]], list[str | None]]:
    from ..studies.acceptance import limits_text

    rows: list[list[str]] = []
    colours: list[str | None] = []
    for c in verdict.criteria:
        value = f"{c.value:.5g}" if np.isfinite(c.value) else "n/a"
        if np.isfinite(c.value) and np.isfinite(c.expanded):  # U, k = 2
            value += f" ± {c.expanded:.2g}"
        margin = f"{c.margin:+.2f} {c.margin_unit}" if np.isfinite(c.margin) else "n/a"
        rows.append([c.name, value, c.unit, limits_text(c), margin,
                     c.word])
        colours.append(WORD_COLOURS[c.word])
    return rows, colours


def _test_table(pages: _Pages, test: Sequence[tuple[str, str]]) -> None:
    """The test's identification (:mod:`airgun_xl.identification`), two fields a row, a
    blank line each where none was given (issue 63)."""
    if not test:
        return
    cells = [[label, value] for label, value in test]
    pairs = [cells[k] + (cells[k + 1] if k + 1 < len(cells) else ["", ""])
             for k in range(0, len(cells), 2)]
    pages.table(["Test", "", "", ""], pairs, [0.0, 0.17, 0.5, 0.67])
    pages.gap(0.5)


def _text_pages(pages: _Pages, verdict: Any, about: list[tuple[str, str]],
                warnings: list[str]) -> None:
    """The verdict, the criteria, the warnings, the recording, the sources, the signature."""
    from matplotlib.lines import Line2D

    pages.text("Shock test report", size=16, bold=True)
    pages.gap(1.0)
    pages.text(f"Verdict: {verdict.word}", size=14, bold=True,
               colour=WORD_COLOURS[verdict.word])
    pages.gap()
    from ..identification import LABELS

    _test_table(pages, [(label, value) for label, value in about
                        if label in LABELS.values()])
    pages.table(["Item", "Value"], [[label, value] for label, value in about
                                    if label not in LABELS.values()], [0.0, 0.2])
    pages.gap()
    pages.text("Criteria", size=11, bold=True)
    rows, colours = _criteria_rows(verdict)
    pages.table(["Criterion", "Value", "Unit", "Limits", "Margin", "Result"], rows,
                [0.0, 0.17, 0.29, 0.37, 0.67, 0.80], colours)
    # where each was judged and, for a failure, where it failed: the SRS's frequencies
    # outside their band with their excess, the corridor's worst instant (as the terminal and
    # the workbook say it; the table alone gave only the worst figure)
    for c in verdict.criteria:
        if c.detail:
            pages.text(f"- {c.name}: {c.detail}", indent=0.02,
                       colour="black" if c.passed else WORD_COLOURS[c.word])
    pages.gap()
    pages.text(f"Warnings ({len(warnings)})" if warnings else "Warnings: none", size=11,
               bold=True, colour=FAIL_COLOUR if warnings else "black")
    for w in warnings:
        pages.text(f"- {w}", indent=0.02)
    if verdict.quality is not None:
        pages.gap()
        pages.text("The recording, before it was judged", size=11, bold=True)
        nominal = verdict.spec.duration.nominal if verdict.spec.duration else None
        for label, text in verdict.quality.block(nominal):
            pages.text(f"{label}: {text}", indent=0.02)
    pages.gap()
    pages.text("How it was judged", size=11, bold=True)
    sources = verdict.sources()
    for line in verdict.definitions:
        if line not in sources:  # said once, under the sources (issue 63)
            pages.text(f"- {line}", indent=0.02)
    pages.gap()
    pages.text("The specification's sources", size=11, bold=True)
    for line in sources:
        pages.text(f"- {line}", indent=0.02)
    pages.gap(1.5)
    if pages.y - LINE * 10 < BOTTOM:  # the block whole on one page: its title, three lines
        # never alone on a page (issue 63): the verdict's summary repeated above it
        pages.new()
        pages.text(f"Verdict: {verdict.word} (summary, repeated for the signature)",
                   size=14, bold=True, colour=WORD_COLOURS[verdict.word])
        pages.gap()
        identity = [f"{label}: {value}" for label, value in about
                    if label in ("Client", "Test number", "Test item", "Serial number",
                                 "Shot", "Recording")]
        for line in identity:
            pages.text(line)
        pages.gap()
        rows, colours = _criteria_rows(verdict)
        pages.table(["Criterion", "Value", "Unit", "Limits", "Margin", "Result"], rows,
                    [0.0, 0.17, 0.29, 0.37, 0.67, 0.80], colours)
        pages.gap(1.5)
    pages.text("Test engineer", size=11, bold=True)
    pages.gap(1.2)
    from ..xlsx.report import SIGNATURE_LINES

    for label in SIGNATURE_LINES:
        pages.room(LINE * 2.4)
        pages.figure.text(LEFT, pages.y, f"{label}:", fontsize=9, va="top",
                          parse_math=False)
        pages.figure.add_artist(Line2D([LEFT + 0.1, LEFT + 0.5],
                                                 [pages.y - LINE, pages.y - LINE],
                                                 color="black", linewidth=0.6))
        pages.y -= LINE * 2.4


def _two_and_five(value: float, _position: object) -> str:
    """A minor tick's label on a log axis: 2 and 5 times a power of ten, plainly."""
    if not value > 0:
        return ""
    mantissa = value / 10 ** np.floor(np.log10(value))
    return f"{value:g}" if any(abs(mantissa - m) < 1e-6 for m in (2.0, 5.0)) else ""


def chart_unit(spec: Any) -> tuple[str, float]:
    """(unit, factor from kG) the charts show accelerations in: the client's (issue 63): the
    unit the specification's peak was given in; g for an SRS requirement without a peak (its
    rows are read as the spectra a client writes, and the workbook's SRS chart is in g); kG
    when neither says."""
    from ..specification import shown_unit
    from ..units import G_PER_KG

    if dict(spec.units).get("peak"):
        return shown_unit(spec, "peak")
    if spec.srs is not None:
        return "g", G_PER_KG
    return "kG", 1.0


def _chart_page(pages: _Pages, verdict: Any, pulse: dict[str, Any],
                spectra: dict[str, Any]) -> None:
    """The pulse with its limits, the SRS and the pseudo-velocity: one page."""
    from matplotlib.ticker import FormatStrFormatter, FuncFormatter, NullFormatter

    pages.new()
    fig = pages.figure
    unit, factor = chart_unit(verdict.spec)
    t_ms = np.asarray(pulse["time"]) * 1e3
    ax = fig.add_axes((LEFT + 0.03, 0.62, RIGHT - LEFT - 0.03, 0.28))
    ax.plot(t_ms, np.asarray(pulse["kg"]) * factor, color="#1f4e79", linewidth=0.8,
            label="Record judged")
    if "upper" in pulse:
        ax.plot(t_ms, np.asarray(pulse["ideal"]) * factor, color="#7f7f7f", linewidth=0.8,
                linestyle="--", label="Ideal pulse")
        ax.plot(t_ms, np.asarray(pulse["upper"]) * factor, color=FAIL_COLOUR, linewidth=0.8,
                label="Corridor")
        ax.plot(t_ms, np.asarray(pulse["lower"]) * factor, color=FAIL_COLOUR, linewidth=0.8)
    elif verdict.spec.peak is not None:
        lo, hi = verdict.spec.peak.limits
        ax.axhspan(lo * factor, hi * factor, color="#c6efce", alpha=0.6,
                   label="Peak's limits")
    ax.set_xlabel("Time (ms)")
    ax.set_ylabel(f"Acceleration ({unit})")
    ax.set_title("The record judged", fontsize=10)
    ax.grid(True, color="#d9d9d9", linewidth=0.5)
    ax.legend(fontsize=7, loc="upper right")
    f = np.asarray(spectra["frequencies"])
    for k, (key, title, label, scale_by) in enumerate((
            ("srs", f"SRS (maximax, Q = {spectra['q']:g})", f"Acceleration ({unit})", factor),
            ("pv", "Pseudo-velocity", "Velocity (m/s)", 1.0))):
        ax = fig.add_axes((LEFT + 0.03, 0.36 - k * 0.27, RIGHT - LEFT - 0.03, 0.2))
        ax.loglog(f, np.asarray(spectra[key]) * scale_by, color="#1f4e79", linewidth=0.9,
                  label=title)
        if key == "srs" and "required" in spectra:
            ax.loglog(f, np.asarray(spectra["required"]) * factor, color="black",
                      linewidth=0.8, label="Required")
            ax.loglog(f, np.asarray(spectra["lower"]) * factor, color=FAIL_COLOUR,
                      linewidth=0.6, linestyle="--", label="Tolerance")
            ax.loglog(f, np.asarray(spectra["upper"]) * factor, color=FAIL_COLOUR,
                      linewidth=0.6, linestyle="--")
        ax.set_xlabel("Frequency (Hz)")
        ax.set_ylabel(label)
        for scale, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            # plain numbers (100, 1000), not powers of ten; over less than two decades the
            # minor ticks at 2 and 5 are labelled too, or the axis would show one number
            scale.set_major_formatter(FormatStrFormatter("%g"))
            narrow = lo > 0 and np.log10(hi / lo) < 2
            scale.set_minor_formatter(FuncFormatter(_two_and_five) if narrow
                                      else NullFormatter())
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", color="#e5e5e5", linewidth=0.4)
        ax.legend(fontsize=7, loc="lower right")


def excel_number(value: float, fmt: str) -> str:
    """``value`` as the spreadsheet shows it under number format ``fmt`` (the formats of
    :data:`airgun_xl.xlsx.report.QUANTITIES`: ``0.000``, ``#,##0.0``, ``0.00%``,
    ``0.000E+00``), so the PDF reads the workbook's figures."""
    decimals = len(fmt.split(".", 1)[1].rstrip("%").split("E")[0]) if "." in fmt else 0
    if fmt.endswith("%"):
        return f"{value:.{decimals}%}"
    if "E+" in fmt:
        return f"{value:.{decimals}E}"
    return f"{value:{',' if '#,##' in fmt else ''}.{decimals}f}"


def _save(path: str | Path, pages: _Pages, heading: tuple[str, str, str],
          date: datetime.datetime | None, title: str) -> None:
    """Every page's header and footer, then the pages into ``path``."""
    from matplotlib.backends.backend_pdf import PdfPages

    left, right, source = heading
    stamp = (f"printed {date:%Y-%m-%d %H:%M} UTC" if date is not None
             else "date left out (--reproducible)")
    total = len(pages.figures)
    for n, fig in enumerate(pages.figures, start=1):
        said = {"fontsize": 7.5, "parse_math": False}
        fig.text(LEFT, 0.975, drawable(left), va="top", **said)
        fig.text(RIGHT, 0.975, drawable(right), va="top", ha="right", **said)
        fig.text(LEFT, 0.962, textwrap.shorten(drawable(source), 150), va="top", **said)
        fig.text(LEFT, 0.03, f"airgun-xl {__version__}, {stamp}", **said)
        fig.text(RIGHT, 0.03, f"page {n} of {total}", ha="right", **said)
    metadata = {"Title": drawable(title), "Creator": "airgun-xl",
                "Producer": f"airgun-xl {__version__} (matplotlib)",
                "CreationDate": date, "ModDate": date}
    with PdfPages(path, metadata=metadata) as pdf:
        for fig in pages.figures:
            pdf.savefig(fig)


def summary_text(result: Any, summary: Any, info: Any) -> list[tuple[str, str, str, str]]:
    """The Summary sheet's rows as text (:func:`airgun_xl.xlsx.sheets.summary_rows`): each
    value in its shown unit and number format, a figure the warnings put in doubt marked as
    the sheet marks it."""
    import datetime as dt

    from ..xlsx.report import QUANTITIES, number_format
    from ..xlsx.report import shown as in_unit
    from ..xlsx.sheets import flagged_figures, summary_rows

    flags = flagged_figures(list(info.warnings))
    out = []
    for label, value, code, definition in summary_rows(result, summary, info):
        unit = QUANTITIES[code].unit if code in QUANTITIES else code
        if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(
                value, bool):
            text = (excel_number(in_unit(float(value), code), number_format(code))
                    if code in QUANTITIES and np.isfinite(value) else f"{value}")
        elif isinstance(value, dt.datetime):
            text = value.isoformat()
        else:
            text = "" if value is None else str(value)
        note = definition
        if label in flags:
            note = f"DOUBTED: see the warnings on {', '.join(flags[label])}" + (
                f"; {definition}" if definition else "")
        out.append((label, text, unit, note))
    return out


def _fill_charts(pages: _Pages, charts: list[tuple[Any, dict[str, Any], tuple[float, float]]]
                 ) -> None:
    """The fill's charts, two a row and three rows a page, as the Charts sheet draws them:
    each series present, its x range, its title and axes' names."""
    from ..xlsx.charts import nice_range

    colours = ("#1f4e79", "#c00000", "#548235", "#7f6000")
    for k, (spec, data, x_range) in enumerate(charts):
        if k % 6 == 0:
            pages.new()
        row, col = divmod(k % 6, 2)
        ax = pages.figure.add_axes((LEFT + 0.05 + col * 0.45, 0.68 - row * 0.3, 0.36, 0.2))
        twin = None
        x_factor = 1e-3 if (spec.x_format or "").endswith(",") else 1.0
        lo, hi = np.asarray(x_range) * x_factor
        shown: dict[bool, list[Any]] = {False: [], True: []}
        for m, series in enumerate(s for s in spec.series if s.key in data):
            x, y = data[series.key]
            # the sheet's "0.0," and "#,##0," show thousands: Hz as kHz, N as kN
            x = np.asarray(x) * x_factor
            y = np.asarray(y) * (1e-3 if (spec.y_format or "").endswith(",") else 1.0)
            shown[series.y2].append(y[(x >= lo) & (x <= hi)])
            target = ax
            if series.y2:
                twin = twin or ax.twinx()
                target = twin
            style = {"color": colours[m % len(colours)], "linewidth": 0.8,
                     "linestyle": "--" if series.dash else "-", "label": series.name}
            if series.markers:
                target.plot(x, y, marker="o", markersize=2.5, linestyle="none",
                            color=style["color"], label=series.name)
            else:
                target.plot(x, y, **style)
        ax.set_xlim(lo, hi)
        # the y range of what lies in the x range, as the sheet's chart sets it (the
        # spectrum's own lobe, left of its range, would flatten the rest)
        for axis, values in ((ax, shown[False]), (twin, shown[True])):
            if axis is not None and values:
                axis.set_ylim(*nice_range(np.concatenate(values), include_zero=True))
        ax.set_title(spec.title, fontsize=7.5, wrap=True)
        ax.set_xlabel(spec.x_title, fontsize=7)
        ax.set_ylabel(spec.y_title, fontsize=7)
        if twin is not None and spec.y2_title:
            twin.set_ylabel(spec.y2_title, fontsize=7)
            twin.tick_params(labelsize=6)
        ax.tick_params(labelsize=6)
        ax.grid(True, color="#d9d9d9", linewidth=0.4)
        if len([s for s in spec.series if s.key in data]) > 1:
            handles = [h for a in (ax, twin) if a is not None
                       for h in a.get_legend_handles_labels()[0]]
            ax.legend(handles=handles, fontsize=5.5, loc="best")


def write_fill_pdf(path: str | Path, rows: list[tuple[str, str, str, str]],
                   verdict: Any, warnings: list[str],
                   charts: list[tuple[Any, dict[str, Any], tuple[float, float]]],
                   heading: tuple[str, str, str], reproducible: bool = False,
                   notes: tuple[str, ...] = (), doubted: tuple[str, ...] = (),
                   inputs: Sequence[tuple[str, str, str, str]] = (),
                   test: Sequence[tuple[str, str]] = ()) -> None:
    """A fill's report at ``path``: ``rows`` the Summary's (quantity, value as shown, unit,
    definition), the predicted ``verdict`` (or None; ``doubted`` the cells whose warnings
    put it in doubt), what the study behind the shot found (``notes``: a design's, the
    closed loop's P(PASS)), the warnings, the shot's ``inputs`` (cell, quantity, value as
    shown, unit: the velocity, the masses, the mitigator; issue 63), the ``test`` it is (its
    identification's rows: label, text) and ``charts``
    (:class:`~airgun_xl.xlsx.charts.ChartSpec`, its series' data, its x range)."""
    import matplotlib

    date = None if reproducible else datetime.datetime.now(datetime.UTC)
    with matplotlib.rc_context({"pdf.fonttype": 42, "font.family": FONT,
                                "path.simplify": False}):
        pages = _Pages()
        pages.text("Shot report: the prediction", size=16, bold=True)
        pages.gap(1.0)
        _test_table(pages, test)
        if verdict is not None:
            pages.text(f"Predicted verdict: {verdict.word}", size=13, bold=True,
                       colour=WORD_COLOURS[verdict.word])
            if doubted:
                pages.text(f"DOUBTED: see the warnings on {', '.join(doubted)}",
                           bold=True, colour=FAIL_COLOUR)
            criteria, colours = _criteria_rows(verdict)
            pages.table(["Criterion", "Value", "Unit", "Limits", "Margin", "Result"],
                        criteria, [0.0, 0.17, 0.29, 0.37, 0.67, 0.80], colours)
            pages.gap()
        if notes:
            pages.text("The study behind this shot", size=11, bold=True)
            for note in notes:
                pages.text(f"- {note}", indent=0.02)
            pages.gap()
        pages.text(f"Warnings ({len(warnings)})" if warnings else "Warnings: none",
                   size=11, bold=True, colour=FAIL_COLOUR if warnings else "black")
        for w in warnings:
            pages.text(f"- {w}", indent=0.02)
        pages.gap()
        pages.text("Summary", size=11, bold=True)
        pages.table(["Quantity", "Value", "Unit", "Definition"],
                    [list(r) for r in rows], [0.0, 0.33, 0.47, 0.54])
        if inputs:
            pages.gap()
            pages.text("The shot's inputs (the cells the run read)", size=11, bold=True)
            pages.table(["Cell", "Quantity", "Value", "Unit"], [list(r) for r in inputs],
                        [0.0, 0.08, 0.5, 0.66])
        _fill_charts(pages, charts)
        _save(path, pages, heading, date, f"Shot report: {heading[0]}")


def write_verdict_pdf(path: str | Path, verdict: Any, about: list[tuple[str, str]],
                      pulse: dict[str, Any], spectra: dict[str, Any], warnings: list[str],
                      heading: tuple[str, str, str], reproducible: bool = False) -> None:
    """The verdict's report at ``path`` (written as it is: the caller publishes it whole).

    Parameters
    ----------
    about : list of (str, str)
        The shot, the recording and what was read of it, as the verdict workbook gives them.
    pulse, spectra : dict
        :func:`airgun_xl.app.accept.report_data`'s: time [s], acceleration [kG], the
        corridor's; frequencies [Hz], SRS [kG], pseudo-velocity [m/s].
    heading : (str, str, str)
        The shot, the recording and the specification's source, for every page's header.
    reproducible : bool
        No date in the footer or the metadata.
    """
    import matplotlib

    date = None if reproducible else datetime.datetime.now(datetime.UTC)
    with matplotlib.rc_context({"pdf.fonttype": 42, "font.family": FONT,
                                "path.simplify": False}):
        pages = _Pages()
        _text_pages(pages, verdict, about, warnings)
        _chart_page(pages, verdict, pulse, spectra)
        shot, recording, source = heading
        _save(path, pages, (f"Shot: {shot}", f"Recording: {recording}",
                            f"Specification: {source}"), date, f"Shock test report: {shot}")
