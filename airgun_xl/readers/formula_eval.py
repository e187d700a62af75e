"""Evaluate cell formulas with the ``formulas`` package, one cell and its precedents at a time.

Each formula is parsed and compiled by ``formulas``; its inputs (cells and ranges) are resolved
recursively through a :class:`SheetView`, so only the cells a parameter depends on are computed.
Whole-column ranges such as ``I:I`` are cut to the sheet's used rows.

``formulas`` takes 0.1-0.2 s to import and compile, more than the rest of reading a shot. The
template's formulas are all sums, differences, products and quotients of numbers and cells on
the same sheet (``=A2+E25``, ``=1/A11``, ``=-B6``), so those are computed here by
:func:`arithmetic`, a short version tested against ``formulas`` itself
(``tests/test_formula_arithmetic.py``). Anything else, and any case whose result the short
version cannot vouch for (a text, logical or error operand, a division by zero, an overflow),
goes to ``formulas``.
"""
import logging
import math
import re
from contextlib import contextmanager
from functools import lru_cache

import numpy as np
from openpyxl.utils.cell import range_boundaries


class FormulaFailure(Exception):
    """A formula could not be evaluated (unsupported function, bad reference, a cycle)."""


class SheetView:
    """Read access to the cells of a workbook for the evaluator.

    Parameters
    ----------
    sheets : dict
        Upper-cased sheet name -> ``{(row, col): (value, formula)}``; ``formula`` is the formula
        text (starting with ``=``) or None.
    default : str
        Upper-cased name of the sheet that unqualified references point to.
    columns : dict, optional
        ``{(sheet, col): sequence}`` of whole columns given as values for rows 1..n, e.g. the
        result columns of a run; they take precedence over ``sheets``.
    limits : dict, optional
        ``{sheet: (max_row, max_col)}``: references beyond the rows and columns that were read
        fail rather than read as blank.
    """

    def __init__(self, sheets, default, columns=None, limits=None):
        self.sheets = sheets
        self.default = default
        self.columns = columns if columns is not None else {}
        self.limits = limits or {}
        self.max_row = {name: max((r for r, _ in cells), default=1)
                        for name, cells in sheets.items()}
        self.max_col = {name: max((c for _, c in cells), default=1)
                        for name, cells in sheets.items()}
        for (name, col), values in self.columns.items():
            self.max_row[name] = max(self.max_row.get(name, 1), len(values))
            self.max_col[name] = max(self.max_col.get(name, 1), col)

    def cell(self, sheet, row, col):
        """``(value, formula)`` of a cell."""
        column = self.columns.get((sheet, col))
        if column is not None:
            return (column[row - 1] if row <= len(column) else None), None
        limit = self.limits.get(sheet)
        if limit is not None and (row > limit[0] or col > limit[1]) and (
                (row, col) not in self.sheets.get(sheet, {})):
            from openpyxl.utils.cell import get_column_letter

            block = "the parameter block" if sheet == self.default else f"the cells read of {sheet}"
            raise FormulaFailure(f"refers to a cell outside {block} (rows 1-{limit[0]}, columns "
                                 f"A-{get_column_letter(min(limit[1], 16_384))})")
        return self.sheets.get(sheet, {}).get((row, col), (None, None))


def _reason(exc):
    """One short line for why ``formulas`` failed."""
    if "NotImplemented" in repr(exc):
        return "unsupported function"
    text = str(exc).splitlines()[0].rstrip(": ") if str(exc).strip() else type(exc).__name__
    return text.lower()


@contextmanager
def _quiet():
    """Silence schedula, which logs a traceback for every unsupported function."""
    log = logging.getLogger("schedula")
    level = log.level
    log.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        log.setLevel(level)


#: Excel's longest formula (8,192 characters): a longer one is refused before it is parsed
#: (a 100,000-character formula took 67-85 s and 1.5 GB to fail, issue 23.4).
MAX_FORMULA = 8192


def shown_formula(formula, limit=80):
    """A formula as a message quotes it: cut to ``limit`` characters."""
    return formula if len(formula) <= limit else f"{formula[:limit - 3]}... ({len(formula):,} " \
                                                  "characters)"


@lru_cache(maxsize=256)
def _compile(formula):
    if len(formula) > MAX_FORMULA:
        raise FormulaFailure(f"cannot evaluate a formula of {len(formula):,} characters, over "
                             f"Excel's {MAX_FORMULA:,}")
    import formulas  # heavy import, only when a workbook holds a formula

    with _quiet():  # compiling a formula without inputs already evaluates it
        try:
            return formulas.Parser().ast(formula)[1].compile()
        except Exception as exc:  # noqa: BLE001 - formulas raises its own types for bad syntax
            raise FormulaFailure(f"cannot evaluate {shown_formula(formula)}: "
                                 f"{_reason(exc)}") from None


#: One token of the arithmetic subset: a number, a same-sheet cell, an operator or a bracket.
#: An exponent has its sign (``1E+3``, as Excel stores it): ``formulas`` refuses ``1e3``.
_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][-+]\d+)?)"
                    r"|(?P<ref>\$?(?P<col>[A-Za-z]{1,3})\$?(?P<row>[1-9]\d{0,6})(?![\w.!:(]))"
                    r"|(?P<op>[-+*/()]))")

#: Excel's last column (XFD) and row.
_MAX_COL, _MAX_ROW = 16_384, 1_048_576


class _NotArithmetic(Exception):
    """The short version cannot vouch for this formula or its operands: use ``formulas``."""


def _column_number(letters):
    n = 0
    for ch in letters.upper():
        n = n * 26 + ord(ch) - 64
    return n


@lru_cache(maxsize=256)
def arithmetic(formula):
    """The formula as a postfix program if it is arithmetic on numbers and same-sheet cells
    (``+ - * /``, unary signs, brackets), else None.

    The program is a tuple of ``("num", x)``, ``("ref", row, col)``, ``("neg",)`` and
    ``("bin", op)`` steps; :meth:`Evaluator.evaluate` runs it.
    """
    text = formula[1:] if formula.startswith("=") else None
    if not text or len(text) > MAX_FORMULA:
        return None
    tokens: list[tuple] = []
    pos = 0
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None or match.end() == pos:
            if text[pos:].strip():
                return None
            break
        pos = match.end()
        if match["num"]:
            tokens.append(("num", float(match["num"])))
        elif match["ref"]:
            col, row = _column_number(match["col"]), int(match["row"])
            if col > _MAX_COL or row > _MAX_ROW:
                return None
            tokens.append(("ref", row, col))
        else:
            tokens.append(("op", match["op"]))
    program: list = []
    try:
        end = _expression(tokens, 0, program)
    except _NotArithmetic:
        return None
    return tuple(program) if end == len(tokens) else None


def _expression(tokens, i, program):
    """expression := term (("+" | "-") term)*; returns the index after it."""
    i = _term(tokens, i, program)
    while i < len(tokens) and tokens[i] in (("op", "+"), ("op", "-")):
        op = tokens[i][1]
        i = _term(tokens, i + 1, program)
        program.append(("bin", op))
    return i


def _term(tokens, i, program):
    """term := factor (("*" | "/") factor)*."""
    i = _factor(tokens, i, program)
    while i < len(tokens) and tokens[i] in (("op", "*"), ("op", "/")):
        op = tokens[i][1]
        i = _factor(tokens, i + 1, program)
        program.append(("bin", op))
    return i


def _factor(tokens, i, program):
    """factor := ("-" | "+") factor | number | cell | "(" expression ")"."""
    if i >= len(tokens):
        raise _NotArithmetic
    token = tokens[i]
    if token in (("op", "-"), ("op", "+")):
        i = _factor(tokens, i + 1, program)
        if token[1] == "-":
            program.append(("neg",))
        return i
    if token[0] in ("num", "ref"):
        program.append(token)
        return i + 1
    if token == ("op", "("):
        i = _expression(tokens, i + 1, program)
        if i < len(tokens) and tokens[i] == ("op", ")"):
            return i + 1
    raise _NotArithmetic


def _run(program, operand):
    """Run an :func:`arithmetic` program; ``operand(row, col)`` gives a cell's number."""
    stack: list = []
    for step in program:
        if step[0] == "num":
            stack.append(step[1])
        elif step[0] == "ref":
            stack.append(operand(step[1], step[2]))
        elif step[0] == "neg":
            stack.append(-stack.pop())
        else:
            b, a = stack.pop(), stack.pop()
            if step[1] == "/" and b == 0:
                raise _NotArithmetic  # #DIV/0!: the library's word
            stack.append(a + b if step[1] == "+" else a - b if step[1] == "-" else
                         a * b if step[1] == "*" else a / b)
    value = stack.pop()
    if not math.isfinite(value):
        raise _NotArithmetic  # an overflow: #NUM! in the library
    return value + 0.0  # -0.0 shows as 0


def _scalar(result):
    """A Python value from a ``formulas`` result: float, str, bool, None, or '#ERR!' text."""
    cells = np.asarray(result, dtype=object)
    value = cells.reshape(-1)[0] if cells.size else None
    if value is None:
        return None
    if value is _empty():
        return 0.0  # a formula that points at a blank cell shows 0
    text = str(value)
    if text.startswith("#") and text.endswith(("!", "?", "A")):
        return text  # an Excel error such as #DIV/0!, #NAME?, #N/A
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, float, np.integer, np.floating)):
        return float(value)
    if type(value).__name__ == "_Empty" or text == "":
        return None
    return text


class Evaluator:
    """Evaluates formula cells of a :class:`SheetView`, memoising each cell's value."""

    def __init__(self, view):
        self.view = view
        self._values = {}
        self._active = set()

    def value(self, sheet, row, col):
        """The value of a cell: its constant, or its formula's result."""
        key = (sheet, row, col)
        if key in self._values:
            return self._values[key]
        value, formula = self.view.cell(sheet, row, col)
        if formula is not None:
            if key in self._active:
                raise FormulaFailure("circular reference")
            self._active.add(key)
            try:
                value = self.evaluate(formula, sheet)
            finally:
                self._active.discard(key)
        self._values[key] = value
        return value

    def evaluate(self, formula, sheet):
        """Evaluate formula text (``=...``) as if it stood on ``sheet``."""
        program = arithmetic(formula)
        if program is not None:
            try:
                return _run(program, lambda row, col: self._number(sheet, row, col))
            except _NotArithmetic:
                pass
        return self.library(formula, sheet)

    def library(self, formula, sheet):
        """Evaluate formula text with ``formulas`` alone (:meth:`evaluate` without the short
        version)."""
        func = _compile(formula)
        args = [self._resolve(ref, sheet) for ref in func.inputs]
        with _quiet():
            try:
                return _scalar(func(*args))
            except Exception as exc:  # noqa: BLE001 - any failure inside formulas
                raise FormulaFailure(f"cannot evaluate {shown_formula(formula)}: "
                                 f"{_reason(exc)}") from None

    def _number(self, sheet, row, col):
        """A cell's value as an operand of :func:`arithmetic`: a blank is 0, a number itself;
        anything else is left to ``formulas`` (Excel's rules for text and logicals)."""
        if sheet not in self.view.sheets:
            raise _NotArithmetic
        value = self.value(sheet, row, col)
        if value is None:
            return 0.0
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return float(value)
        raise _NotArithmetic

    def _resolve(self, ref, sheet):
        if "!" in ref:
            sheet, ref = ref.rsplit("!", 1)
            sheet = sheet.strip("'").upper()
        sheet = sheet or self.view.default
        if sheet not in self.view.sheets:
            raise FormulaFailure(f"unknown sheet in reference {ref}")
        try:
            min_col, min_row, max_col, max_row = range_boundaries(ref.replace("$", ""))
        except ValueError:
            raise FormulaFailure(f"unsupported reference {ref}") from None
        min_row = min_row or 1
        min_col = min_col or 1
        max_row = max_row or self.view.max_row[sheet]
        max_col = max_col or self.view.max_col[sheet]
        if min_row == max_row and min_col == max_col:
            value = self.value(sheet, min_row, min_col)
            return np.array([[_empty() if value is None else value]], dtype=object)
        column = self.view.columns.get((sheet, min_col))
        if column is not None and min_col == max_col:  # a result column: slice, not cell by cell
            part = np.full(max_row - min_row + 1, _empty(), dtype=object)
            values = column[min_row - 1:max_row]
            part[:len(values)] = values
            part[np.array([v is None for v in part], dtype=bool)] = _empty()
            return part.reshape(-1, 1)
        block = np.empty((max_row - min_row + 1, max_col - min_col + 1), dtype=object)
        for r in range(min_row, max_row + 1):
            for c in range(min_col, max_col + 1):
                v = self.value(sheet, r, c)
                block[r - min_row, c - min_col] = _empty() if v is None else v
        return block


def _empty():
    import schedula  # formulas' dependency; its EMPTY token marks a blank cell

    return schedula.EMPTY
