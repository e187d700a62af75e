"""Text from an untrusted workbook, made safe to write into a new one.

Text stays text: every worksheet airgun-xl writes is a :class:`SafeWorksheet`, whose
``write_string`` is the only way a string reaches a cell, and the workbooks are opened with
xlsxwriter's ``strings_to_formulas``, ``strings_to_urls`` and ``strings_to_numbers`` off, so
``write()`` of ``"=HYPERLINK(...)"`` writes those characters. Only a formula cell of the input
(``<f>``) is written as a formula, through :func:`copyable_formula`.

Text also has to survive XML: characters XML 1.0 cannot hold (lone surrogates from an
undecodable file name, U+FFFE) become ``\\x`` escapes, and a cell keeps at most Excel's 32,767
characters.
"""
import re

from xlsxwriter.utility import xl_cell_to_rowcol
from xlsxwriter.worksheet import Worksheet

#: Excel's longest cell text.
MAX_CELL_CHARS = 32_767

#: Options of every xlsxwriter Workbook airgun-xl opens.
WORKBOOK_OPTIONS = {"nan_inf_to_errors": True, "strings_to_formulas": False,
                    "strings_to_urls": False, "strings_to_numbers": False}

_NOT_XML = re.compile("[\ud800-\udfff\ufffe\uffff]")
_SHEET_BAD = re.compile(r"[\[\]:*?/\\\x00-\x1f]")


def cell_text(value):
    """``value`` as text a cell can hold: XML-safe and at most 32,767 characters."""
    text = value if isinstance(value, str) else str(value)
    if _NOT_XML.search(text):
        text = text.encode("utf-8", "backslashreplace").decode("utf-8")  # lone surrogates
        text = text.replace("\ufffe", "\\ufffe").replace("\uffff", "\\uffff")
    return text[:MAX_CELL_CHARS]


def sheet_title(title, taken=()):
    """A valid sheet name from an input's title: Excel's forbidden characters ``[]:*?/\\``
    become ``_``, no apostrophe at either end, at most 31 characters, not ``History``
    (reserved by Excel), and not one of ``taken`` (compared without case)."""
    text = _SHEET_BAD.sub("_", cell_text(title)).strip().strip("'").strip()[:31] or "Sheet1"
    if text.lower() == "history":
        text = "History_"
    base, n = text, 2
    while text.lower() in {t.lower() for t in taken}:
        suffix = f" ({n})"
        text = base[:31 - len(suffix)] + suffix
        n += 1
    return text


_CALLS_OUT = re.compile(r"\||\[|\b(?:WEBSERVICE|FILTERXML|HYPERLINK|CALL|REGISTER|EXEC|DDE)\s*\(",
                        re.IGNORECASE)


def copyable_formula(formula):
    """Whether an input's formula may be copied as a formula: not one that reaches outside the
    workbook (DDE ``app|topic``, another file ``[book]``, a web or program call)."""
    return not _CALLS_OUT.search(_without_strings(formula))


def _without_strings(formula):
    return re.sub(r'"(?:[^"]|"")*"', '""', formula)


def _cell_args(args):
    if args and isinstance(args[0], str):  # "A1" notation, as xlsxwriter allows
        return (*xl_cell_to_rowcol(args[0]), *args[1:])
    return args


#: Number format of a boolean cell: LibreOffice shows an .xlsx boolean as 1 or 0 without it;
#: Excel shows TRUE/FALSE either way.
BOOLEAN_FORMAT = '"TRUE";"TRUE";"FALSE"'


class SafeWorksheet(Worksheet):
    """A worksheet whose strings are always text: see the module docstring. Booleans read
    TRUE/FALSE in LibreOffice too (``boolean_format``, set by the workbook)."""

    boolean_format = None

    def write_string(self, *args):
        row, col, string, *rest = _cell_args(args)
        return super().write_string(row, col, cell_text(string), *rest)

    def write_formula(self, *args):
        row, col, formula, *rest = _cell_args(args)
        if len(rest) > 1 and isinstance(rest[1], str):
            rest[1] = cell_text(rest[1])  # the cached value
        return super().write_formula(row, col, cell_text(formula), *rest)

    # write(), write_row() and write_column() reach a string through this xlsxwriter internal
    # rather than write_string(); cleaning text twice is harmless.
    def _write_string(self, row, col, string, cell_format=None):
        return super()._write_string(row, col, cell_text(string), cell_format)

    def _write_boolean(self, row, col, boolean, cell_format=None):
        return super()._write_boolean(row, col, boolean, cell_format or self.boolean_format)
