"""The report layer: how every report sheet of every workbook shows its numbers and prints.

Every writer (fill, diff, sweep, Monte Carlo, Sobol, convergence, srs, compare-measured,
calibrate) goes through this module:

- :data:`QUANTITIES` is the one table of shown units: a value's quantity code names its unit,
  the factor from the unit the writer holds it in, and its number format (kG or g, ms, kHz,
  MPa, %). :class:`Style` makes the formats once per workbook and writes numbers with them.
- :func:`one_page` prints a report sheet on one landscape A4 page with a header naming the
  shot, the input file, the version and the print date, and groups it with the workbook's
  other report pages. :func:`data_pages` prints a data sheet by itself: all its rows, one
  page wide, its header row repeated on every page and each page numbered. Every workbook
  puts its report pages first and its data sheets after them, so a print of the whole
  workbook (LibreOffice's PDF export prints every sheet) starts with the report.
- The default print is the report: the report pages are the workbook's selected (grouped)
  sheets and it opens on one of them (:meth:`~airgun_xl.xlsx.workbook.new_workbook`'s close).
  Excel's default print ("Print Active Sheets") and LibreOffice's ("Print only selected
  sheets", on unless a user turned it off) print the selected sheets, so Ctrl+P gives the
  report pages and no data; a click on a data sheet's tab ends the group and prints that
  sheet alone.
- :func:`axis` gives a chart axis its explicit limits and the number format of its quantity;
  :func:`chart_size` sizes a chart to the printed columns.

The header carries the print date as a field (``&D``), so a workbook's bytes depend on the
run alone (the same run gives the same file).
"""
import contextlib
from dataclasses import dataclass

from ..version import __version__

#: A4 in xlsxwriter's paper codes; Letter printers scale it.
A4 = 9

@dataclass(frozen=True)
class Quantity:
    """How a quantity is shown: ``unit``, the ``factor`` from the unit its value is held in,
    and an Excel number ``fmt`` (which never shows more than 7 significant digits)."""

    unit: str
    factor: float
    fmt: str


#: Quantity code -> how it is shown. The code names the unit the value is held in.
QUANTITIES = {
    "kG": Quantity("kG", 1.0, "0.000"),  # the macro's kG (9,800 m/s^2)
    "g": Quantity("g", 1.0, "#,##0.0"),  # standard g (9.80665 m/s^2), as shock labs work
    "s": Quantity("ms", 1e3, "0.0000"),
    "ms": Quantity("ms", 1.0, "0.0000"),
    "Hz": Quantity("kHz", 1e-3, "0.00"),
    "Hz-plain": Quantity("Hz", 1.0, "#,##0"),
    "Pa": Quantity("MPa", 1e-6, "0.000"),
    "N": Quantity("kN", 1e-3, "#,##0.0"),
    "m": Quantity("m", 1.0, "0.0000"),
    "mm": Quantity("mm", 1.0, "0.000"),
    "kg": Quantity("kg", 1.0, "0.000"),
    "m/s": Quantity("m/s", 1.0, "0.00"),
    "step": Quantity("µs", 1e6, "0.000"),
    "runtime": Quantity("s", 1.0, "0.00"),
    "runtime-fine": Quantity("s", 1.0, "0.0000"),  # a kernel's milliseconds
    "ratio": Quantity("", 1.0, "0.000"),
    "fraction": Quantity("", 1.0, "0.0000"),  # a rating, a correlation, an index, 0..1
    "%": Quantity("%", 1.0, "0.00%"),  # held as a fraction, shown as a percentage
    "count": Quantity("", 1.0, "#,##0"),
    "sci": Quantity("", 1.0, "0.000E+00"),  # any other number: 4 significant digits
}


def number_format(code):
    """The number format of quantity ``code`` (:data:`QUANTITIES`)."""
    return QUANTITIES[code].fmt


def shown(value, code):
    """``value`` in the shown unit of ``code``."""
    return value * QUANTITIES[code].factor


def general_format(values, digits=4):
    """A number format for values of no fixed quantity: fixed decimals to ``digits``
    significant digits of the largest, or scientific past 1e6 or below 1e-3."""
    import math

    finite = [abs(float(v)) for v in values if v is not None and math.isfinite(float(v))]
    top = max(finite, default=0.0)
    if top == 0.0:
        return "0"
    if top >= 1e6 or top < 1e-3:
        return "0." + "0" * (digits - 1) + "E+00"
    decimals = max(0, digits - 1 - math.floor(math.log10(top)))
    return "#,##0" + ("." + "0" * decimals if decimals else "")


#: Characters of a column that shows :func:`value_format`'s widest text (-1.2346E+08).
VALUE_COLUMN_CHARS = 12


def value_format(value, digits=7):
    """A number format that shows ``value`` in at most ``digits`` significant digits, with
    no trailing zeros: ``0`` for a whole number below 10^digits, decimals as needed from
    1e-3, scientific notation past them with 5 (a copied input cell, whose quantity is not
    known; at most :data:`VALUE_COLUMN_CHARS` characters)."""
    import math

    x = abs(float(value))
    if not math.isfinite(x) or x == 0.0 or (x == round(x) and x < 10.0 ** digits):
        return "0"
    if 1e-3 <= x < 10.0 ** digits:
        decimals = max(1, digits - 1 - math.floor(math.log10(x)))
        return "0." + "#" * decimals
    return "0.####E+00"


class Style:
    """The formats of one workbook's report sheets, made once (xlsxwriter formats belong to
    their workbook)."""

    def __init__(self, wb):
        self.wb = wb
        self._cache = {}
        self.bold = self.get(bold=True)
        self.title = self.get(bold=True, font_size=13)
        self.wrap = self.get(text_wrap=True, valign="top")
        self.header = self.get(bold=True, text_wrap=True, valign="bottom", bottom=1)

    def get(self, **props):
        """The format with ``props`` (cached)."""
        key = tuple(sorted(props.items()))
        if key not in self._cache:
            self._cache[key] = self.wb.add_format(props)
        return self._cache[key]

    def of(self, code, flagged=False, **props):
        """The format of quantity ``code``; ``flagged``: red, for a doubted figure."""
        if flagged:
            props.update(bg_color="#FFC7CE", font_color="#9C0006")
        return self.get(num_format=number_format(code), **props)

    def fmt(self, num_format, **props):
        return self.get(num_format=num_format, **props)

    def number(self, ws, row, col, value, code, flagged=False):
        """Write ``value`` (held in the unit ``code`` names) in its shown unit and format;
        None or a non-finite value leaves the cell empty."""
        import math

        if value is None or not math.isfinite(float(value)):
            return
        ws.write_number(row, col, float(value) * QUANTITIES[code].factor,
                        self.of(code, flagged))

    def unit(self, code):
        return QUANTITIES[code].unit


#: Characters of the shot's name the header keeps (Excel allows 255 for the whole header).
HEADER_NAME_CHARS = 60


def _header_text(text):
    text = str(text).encode("utf-8", "backslashreplace").decode("utf-8")  # an undecodable name
    if len(text) > HEADER_NAME_CHARS:
        text = text[:HEADER_NAME_CHARS - 1] + "…"
    return text.replace("&", "&&")


#: The lines of a report's signature block, to fill by hand (the accept workbook's Verdict
#: sheet and the PDF report: a verdict a client signs).
SIGNATURE_LINES = ("Name", "Signature", "Date")


def one_page(ws, last_row, last_col, first_row=0, first_col=0, landscape=True, shot=None,
             title=None, report=True):
    """Print ``ws``'s range (0-based, inclusive) on one A4 page: a header with ``shot`` (the
    input file's name), ``title`` (the sheet's name by default), the version and the print
    date; the file and sheet names in the footer. A ``report`` page is selected, so the
    workbook's default print gives it (the module's notes); ``report=False`` keeps a page
    that prints on its own out of that print (sheet 1's raw parameter block)."""
    if report:
        ws.select()
    ws.print_area(first_row, first_col, last_row, last_col)
    if landscape:
        ws.set_landscape()
    else:
        ws.set_portrait()
    ws.set_paper(A4)
    ws.fit_to_pages(1, 1)
    ws.set_margins(left=0.5, right=0.5, top=0.75, bottom=0.6)
    left = _header_text(shot) if shot else "&F"
    centre = _header_text(title) if title else "&A"
    ws.set_header(f"&L{left}&C&B{centre}&Rairgun-xl {__version__}, printed &D")
    ws.set_footer("&L&F&R&A")


def data_pages(ws, last_row, last_col, header_rows=1, shot=None, title=None):
    """Print data sheet ``ws``'s range (0-based, inclusive, from A1) by itself: as many A4
    pages as its rows need, one page wide, its first ``header_rows`` rows repeated on each,
    the gridlines printed, the header and footer of a report page (with the page number)."""
    ws.print_area(0, 0, max(last_row, 0), max(last_col, 0))
    if header_rows:
        ws.repeat_rows(0, header_rows - 1)
    ws.set_landscape() if last_col >= 6 else ws.set_portrait()
    ws.set_paper(A4)
    ws.fit_to_pages(1, 0)
    ws.hide_gridlines(0)  # shown and printed
    ws.set_margins(left=0.5, right=0.5, top=0.75, bottom=0.6)
    left = _header_text(shot) if shot else "&F"
    centre = _header_text(title) if title else "&A"
    ws.set_header(f"&L{left}&C&B{centre}&Rairgun-xl {__version__}, printed &D")
    ws.set_footer("&L&F&CPage &P of &N&R&A")


#: Pixels of a default column (8.43 characters) and of a default row (15 points).
COLUMN_PX, ROW_PX = 64, 20

#: Points of a line of the default font.
LINE_POINTS = 15


def fit_wrapped_row(ws, row, text, chars):
    """Size ``row`` to the lines wrapped ``text`` takes in a column (or merged range) of
    ``chars`` characters: the spreadsheet keeps a written row at one line's height, so a
    wrapped text taller than that would overprint the rows below it."""
    lines = max(1, -(-len(text) // chars))
    if lines > 1:
        ws.set_row(row, LINE_POINTS * lines)


def chart_size(columns, rows):
    """(width, height) [px] of a chart that covers ``columns`` default columns and ``rows``
    default rows: charts sized to the printed range."""
    return {"width": columns * COLUMN_PX, "height": rows * ROW_PX}


def axis(title, lo, hi, code=None, log=False, gridlines=True, num_format=None):
    """An xlsxwriter axis dict: explicit limits, gridlines, and the number format of quantity
    ``code`` (the values are plotted in the unit the code names, its factor applied already);
    ``num_format`` overrides it."""
    out = {"name": title, "min": lo, "max": hi,
           "major_gridlines": {"visible": gridlines, "line": {"color": "#d9d9d9"}}}
    fmt = num_format or (number_format(code) if code else general_format([lo, hi], digits=2))
    out["num_format"] = fmt
    if log:
        out["log_base"] = 10
        out["num_format"] = num_format or "#,##0.###"
        out["minor_gridlines"] = {"visible": gridlines, "line": {"color": "#eeeeee"}}
    return out


@contextlib.contextmanager
def report_workbook(path, force=False, inputs=(), publication=None):
    """The one way a command writes a workbook: refuse an output it may not write
    (:func:`~airgun_xl.transaction.check_output`), write into a temp file beside it, and
    publish it whole when the block ends without an error (nothing is left otherwise). With
    a ``publication``, the temp file is staged in it and published with its other files at
    the caller's commit.

    Yields
    ------
    xlsxwriter.Workbook
        With the project's options and fixed properties
        (:func:`~airgun_xl.xlsx.workbook.new_workbook`).
    """
    from ..transaction import atomic_path, check_output
    from .workbook import close_workbook, new_workbook

    check_output(path, force, inputs=inputs)
    if publication is not None:
        wb = new_workbook(publication.stage(path))
        yield wb
        close_workbook(wb, path)
        return
    with atomic_path(path, force) as tmp:
        wb = new_workbook(tmp)
        yield wb
        close_workbook(wb, path)
