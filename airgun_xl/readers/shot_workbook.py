"""Read a shot from a workbook in the report's layout.

The macro reads the active sheet; like the legacy runner, we read the first sheet. Its parameter
block (columns A..G, :data:`airgun_xl.cells.PARAMETER_COLUMNS`) is kept with formulas and values,
so the writer can copy it as it was. Result columns (H on) of an old workbook are ignored: they
are recomputed.

.xlsx and .xlsm are read with openpyxl (formulas and cached values); .xls with python-calamine
(cached values only, which Excel wrote and which are trusted).

A workbook may come from anyone: :mod:`airgun_xl.readers.guard` checks the file and the zip
before a parser runs, only the first :data:`~airgun_xl.limits.BLOCK_ROWS` rows are read, and
only real formula cells (``<f>``) are formulas: a text cell that starts with ``=`` is text.
"""
import hashlib
import io
from dataclasses import dataclass, field
from pathlib import Path

from openpyxl.utils.cell import get_column_letter

from .. import limits
from ..cells import BY_ADDRESS, CELLS, PARAMETER_COLUMNS, TIME_HEADER, UNUSED_K1
from ..errors import AirgunXlError, CellError, WorkbookError
from ..params import Found, ShotParams, describe
from . import guard
from .formula_eval import MAX_FORMULA, Evaluator, FormulaFailure, SheetView, shown_formula
from .law_sheet import KEY as LAW_KEY
from .law_sheet import SHEET_NAME as LAW_SHEET
from .law_sheet import law_from_cells
from .spec_sheet import KEY as SPEC_KEY
from .spec_sheet import LAST_ROW as SPEC_LAST_ROW
from .spec_sheet import SHEET_NAME as SPEC_SHEET
from .spec_sheet import SRS_COLUMNS, spec_from_cells, test_from_cells

#: Columns read from a sheet other than the parameter sheet (Outputs, or one a formula names).
OTHER_COLUMNS = 26

#: Relative difference above which a cached formula value "disagrees" with its evaluation.
CACHE_RTOL = 1e-12


def rows_read(title):
    """How many rows of a sheet are read: the block's, or the Specification sheet's to the
    end of its SRS rows (:data:`~airgun_xl.readers.spec_sheet.LAST_ROW`)."""
    return SPEC_LAST_ROW if title.upper() == SPEC_KEY else limits.BLOCK_ROWS


def _kept(title, row, col):
    """Whether a cell of a sheet is kept: within the rows read, or (on the Specification
    sheet) a cell of its SRS columns past them, kept so that it is refused, not dropped."""
    return row <= rows_read(title) or (title.upper() == SPEC_KEY and col in SRS_COLUMNS)


@dataclass
class Source:
    """Where a shot came from, and its parameter sheet as read.

    Attributes
    ----------
    path : pathlib.Path
    sha256 : str
        Hash of the input file's bytes.
    sheet_title : str
        Title of the parameter sheet.
    block : dict
        ``{(row, col): (value, formula)}`` for columns A..G and H1 of the parameter sheet;
        ``value`` is the cached value, ``formula`` the formula text or None.
    other_sheets : dict
        Upper-cased title -> cells, like ``block``, for formulas that point to other sheets.
    percent_cells : frozenset
        (row, col) of the Specification sheet's cells formatted as a percentage: a cell
        typed "10%" holds 0.1 (.xlsx and .xlsm; an .xls is read without its formats).
    """

    path: Path
    sha256: str
    sheet_title: str
    block: dict
    other_sheets: dict = field(default_factory=dict)
    percent_cells: frozenset = frozenset()

    @property
    def outputs_block(self):
        """Cells of the workbook's Outputs sheet, if it has one."""
        return self.other_sheets.get("OUTPUTS", {})

    @property
    def law_block(self):
        """Cells of the workbook's Crush law sheet, if it has one."""
        return self.other_sheets.get(LAW_KEY)

    @property
    def spec_block(self):
        """Cells of the workbook's Specification sheet, if it has one."""
        return self.other_sheets.get(SPEC_KEY)

    def view(self, extra_columns=None):
        """A :class:`SheetView` over the parameter sheet and the other sheets."""
        sheets = dict(self.other_sheets)
        sheets[self.sheet_title.upper()] = self.block
        bounds = {name: (rows_read(name), OTHER_COLUMNS) for name in sheets}
        if extra_columns is None:  # only the block was read: references beyond it must fail
            bounds[self.sheet_title.upper()] = (limits.BLOCK_ROWS, PARAMETER_COLUMNS)
            return SheetView(sheets, self.sheet_title.upper(), {}, bounds)
        # the run's result columns extend the first sheet to the right, not down its block
        bounds[self.sheet_title.upper()] = (limits.BLOCK_ROWS, 16_384)
        return SheetView(sheets, self.sheet_title.upper(), extra_columns, bounds)


def _read_zip(path, data):
    import openpyxl

    zf = guard.open_zip(path, data)  # before any parser: sizes, ratios, DTDs and entities
    zf.close()
    shown = guard.display(path)
    wb_f = wb_v = None
    try:
        wb_f = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=False,
                                      keep_links=False)
        wb_v = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=True,
                                      keep_links=False)
        sheets: dict = {}
        percent: set = set()
        wanted: set = set()  # after the first sheet: the sheets its formulas name, Outputs
        for ws_f, ws_v in zip(wb_f.worksheets, wb_v.worksheets, strict=True):
            first = not sheets
            if not first and ws_f.title.upper() not in wanted:
                continue  # e.g. the Tracked or ChartData sheets of a filled workbook
            cells = {}
            max_col = PARAMETER_COLUMNS if first else OTHER_COLUMNS
            # the Specification sheet to its end (the guard has capped its size), so that a
            # cell past its last SRS row is refused, not dropped
            max_row = None if ws_f.title.upper() == SPEC_KEY else limits.BLOCK_ROWS
            for row_f, row_v in zip(ws_f.iter_rows(max_row=max_row, max_col=max_col),
                                    ws_v.iter_rows(max_row=max_row, max_col=max_col),
                                    strict=True):
                for cf, cv in zip(row_f, row_v, strict=True):
                    if cf.value is None or not hasattr(cf, "column") or not _kept(
                            ws_f.title, cf.row, cf.column):
                        continue
                    cells[(cf.row, cf.column)] = (cv.value, _formula_text(cf))
                    if ws_f.title.upper() == SPEC_KEY and "%" in str(
                            getattr(cf, "number_format", "")):
                        percent.add((cf.row, cf.column))
            if first:
                h1 = next(ws_v.iter_rows(min_row=1, max_row=1, min_col=8, max_col=8,
                                         values_only=True), (None,))[0]
                if h1 is not None:
                    cells[(1, 8)] = (h1, None)
            sheets[ws_f.title] = cells
            if first:
                text = " ".join(f for _, f in cells.values() if f).upper()
                wanted = {t.upper() for t in wb_f.sheetnames[1:]
                          if t.upper() in text or t.upper() in ("OUTPUTS", LAW_KEY, SPEC_KEY)}
    except AirgunXlError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes is one line
        raise WorkbookError(f"{shown}: is not a readable .xlsx workbook "
                            f"({_reason(exc)})") from None
    finally:
        for wb in (wb_f, wb_v):
            if wb is not None:
                wb.close()
    if not sheets:
        raise WorkbookError(f"{shown}: has no worksheet, expected the report's parameter sheet")
    return sheets, frozenset(percent)


def _reason(exc):
    """A parser's exception as a short phrase."""
    text = str(exc).splitlines()[0].strip() if str(exc).strip() else ""
    return f"{type(exc).__name__}: {text[:120]}" if text else type(exc).__name__


def _formula_text(cell):
    """The formula of a real formula cell (``<f>``), else None: text is never a formula."""
    if getattr(cell, "data_type", None) != "f":
        return None
    value = cell.value
    if isinstance(value, str) and value.startswith("=") and len(value) > 1:
        return value
    text = getattr(value, "text", None)  # openpyxl ArrayFormula
    return text if isinstance(text, str) and text.startswith("=") else None


def _read_xls(path, data):
    shown = guard.display(path)
    for k, (rows, columns) in enumerate(guard.xls_extents(path, data)):
        guard.check_extent(path, f"sheet {k + 1}", rows, columns, limits.MAX_XLS_CELLS)
    try:
        from python_calamine import CalamineWorkbook

        wb = CalamineWorkbook.from_filelike(io.BytesIO(data))
        names = list(wb.sheet_names)
        sheets: dict = {}
        for name in names[:1] + [n for n in names[1:] if n.upper() in ("OUTPUTS", LAW_KEY,
                                                                         SPEC_KEY)]:
            first = not sheets
            rows = wb.get_sheet_by_name(name).to_python(skip_empty_area=False)
            cells = {}
            for r, row in enumerate(rows, start=1):
                if r > limits.BLOCK_ROWS and name.upper() != SPEC_KEY:
                    break
                for c, value in enumerate(row, start=1):
                    if c > (PARAMETER_COLUMNS if first else OTHER_COLUMNS) and (r, c) != (1, 8):
                        continue
                    if not first and not _kept(name, r, c):
                        continue
                    if value is not None and value != "":
                        cells[(r, c)] = (value, None)
            sheets[name] = cells
    except AirgunXlError:
        raise
    except Exception as exc:  # noqa: BLE001 - calamine raises its own types for broken files
        raise WorkbookError(f"{shown}: is not a readable .xls workbook "
                            f"({_reason(exc)})") from None
    if not sheets:
        raise WorkbookError(f"{shown}: has no worksheet, expected the report's parameter sheet")
    return sheets


def _address(cell):
    """(row, column), 1-based, of a cell of the map."""
    from openpyxl.utils.cell import coordinate_to_tuple

    return coordinate_to_tuple(cell.address)


def read_source(path):
    """Read the first sheet's parameter block of a workbook.

    Raises
    ------
    WorkbookError
        When the file is missing, unreadable, not a workbook, or password-protected.
    """
    path = Path(path)
    data, kind = guard.read_input(path)
    sheets, percent = _read_zip(path, data) if kind == "zip" else (_read_xls(path, data),
                                                                    frozenset())
    title = next(iter(sheets))
    block = sheets.pop(title)
    return Source(path, hashlib.sha256(data).hexdigest(), title, block,
                  {name.upper(): cells for name, cells in sheets.items()}, percent)


def _disagrees(cached, value):
    if not isinstance(cached, (int, float)) or isinstance(cached, bool):
        return True
    if not isinstance(value, float):
        return True
    return abs(cached - value) > CACHE_RTOL * max(abs(cached), abs(value))


def cell_value(evaluator, sheet, pos, cell, where, label):
    """One cell's raw value, its formula evaluated; and the warning it raised (or None). The
    one reader of formula cells, for the parameter sheet and the Crush law sheet alike.

    A formula cell is evaluated with the ``formulas`` engine. Without a cached value the result
    is used as it is; when a cached value disagrees, a warning says so and the evaluated value
    is used (spreadsheet apps recalculate on open, so that is what the macro would read). When a
    formula cannot be evaluated (a circular reference, a function the engine does not know such
    as HYPERLINK), its cached number is used with a warning, and anything else is left as a
    :class:`Found` description for the caller to refuse, naming the cell.

    Parameters
    ----------
    cell : (object, str or None)
        The cell's (cached value, formula).
    where, label : str
        How messages name the cell (``E40``, ``'Crush law'!B5``) and its label.
    """
    cached, formula = cell
    if formula is None:
        return cached, None
    if len(formula) > MAX_FORMULA:  # refused, not run on its cached value (issue 30.7)
        return Found(f"a formula of {len(formula):,} characters, over Excel's "
                     f"{MAX_FORMULA:,}"), None
    try:
        value = evaluator.value(sheet, *pos)
    except FormulaFailure as exc:
        if isinstance(cached, (int, float)) and not isinstance(cached, bool):
            return cached, f"{where} ({label}): {exc}; using the cached value {cached!r}"
        return Found(f"the formula {shown_formula(formula)} ({exc})"), None
    warning = None
    if isinstance(value, float) and (cached is not None) and _disagrees(cached, value):
        warning = (f"{where} ({label}): the cached value {describe(cached)} disagrees with "
                   f"{shown_formula(formula)} = {value!r}; using the evaluated value")
    if isinstance(value, float):
        return value, warning
    return Found(f"{describe(value)} from {shown_formula(formula)}"), warning


def parameter_values(source):
    """Raw values of the parameter cells, evaluating formulas (:func:`cell_value`); and the
    warnings raised. Nothing is raised here: a bad value is left for
    :meth:`ShotParams.from_cells` to report, in cell order.

    Returns
    -------
    raw : dict
        Address -> raw value (number, text, None, or a :class:`Found` description).
    warnings : list of str
    """
    evaluator = Evaluator(source.view())
    sheet = source.sheet_title.upper()
    raw, warnings = {}, []
    for cell in CELLS:
        pos = _address(cell)
        raw[cell.address], warning = cell_value(
            evaluator, sheet, pos, source.block.get(pos, (None, None)), cell.address,
            cell.label)
        if warning:
            warnings.append(warning)
    return raw, warnings


def sheet_values(source, key, title, label):
    """A sheet's cells (Crush law, Specification) with their formulas evaluated
    (:func:`cell_value`, as the parameter sheet's); and the warnings raised."""
    evaluator = Evaluator(source.view())
    cells, warnings = {}, []
    for pos, cell in source.other_sheets[key].items():
        where = f"'{title}'!{get_column_letter(pos[1])}{pos[0]}"
        value, warning = cell_value(evaluator, key, pos, cell, where, label)
        cells[pos] = (value, None)
        if warning:
            warnings.append(warning)
    return cells, warnings


def law_values(source):
    """The Crush law sheet's cells, evaluated (:func:`sheet_values`), for
    :func:`~airgun_xl.readers.law_sheet.law_from_cells`; and the warnings raised."""
    return sheet_values(source, LAW_KEY, LAW_SHEET, "crush law")


def read_spec(source):
    """The Specification sheet's specification (None when the sheet is missing or empty), its
    Test block's fields (:func:`~.spec_sheet.test_from_cells`), and the warnings its formulas
    raised."""
    if source is None or source.spec_block is None:
        return None, {}, []
    cells, warnings = sheet_values(source, SPEC_KEY, SPEC_SHEET, "specification")
    return spec_from_cells(cells, source.percent_cells), test_from_cells(cells), warnings


def check_time_header(source):
    """H1 must be blank or hold "Time": the macro starts its result columns there."""
    value = source.block.get((1, 8), (None, None))[0]
    if value is not None and str(value).strip() != "Time":
        raise CellError(TIME_HEADER.address, TIME_HEADER.label, describe(value),
                        "'Time' or a blank cell (the result columns start at H1)")


def read_params(path, read_law=True):
    """Read and check a shot's parameters from a workbook; with ``read_law`` False its Crush
    law sheet is not read (the macro's law runs, whatever the sheet holds).

    Returns
    -------
    params : ShotParams
    source : Source
    warnings : list of str
    """
    source = read_source(path)
    check_time_header(source)
    raw, warnings = parameter_values(source)
    k1 = source.block.get(_address(BY_ADDRESS[UNUSED_K1]), (None, None))
    if k1[0] not in (None, "") or k1[1] is not None:
        warnings.append(f"{UNUSED_K1} (K1): holds {describe(k1[0])}, which the macro never "
                        "reads (it computes k1 from E13, E31, E16 and E19): this value has no "
                        "effect on the run")
    params = ShotParams.from_cells(raw)
    if source.law_block is not None and read_law:
        cells, found = law_values(source)
        params = params.replace(crush_law=law_from_cells(cells))
        warnings += found
    return params, source, warnings
