"""Read a shot from a workbook in the report's layout.

The macro reads the active sheet; like the legacy runner, we read the first sheet. Its parameter
block (columns A..G, :data:`airgun_xl.cells.PARAMETER_COLUMNS`) is kept with formulas and values,
so the writer can copy it as it was. Result columns (H on) of an old workbook are ignored: they
are recomputed.

.xlsx and .xlsm are read with openpyxl (formulas and cached values); .xls with python-calamine
(cached values only, which Excel wrote and which are trusted).
"""
import hashlib
import io
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from ..cells import CELLS, PARAMETER_COLUMNS, TIME_HEADER
from ..errors import CellError, WorkbookError
from ..params import Found, ShotParams, describe
from .formula_eval import Evaluator, FormulaFailure, SheetView

ZIP_MAGIC = b"PK\x03\x04"
CFB_MAGIC = bytes.fromhex("D0CF11E0A1B11AE1")  # OLE compound file: .xls, or an encrypted .xlsx
ENCRYPTED_STREAM = "EncryptedPackage".encode("utf-16-le")

#: Relative difference above which a cached formula value "disagrees" with its evaluation.
CACHE_RTOL = 1e-12


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
    """

    path: Path
    sha256: str
    sheet_title: str
    block: dict
    other_sheets: dict = field(default_factory=dict)

    @property
    def outputs_block(self):
        """Cells of the workbook's Outputs sheet, if it has one."""
        return self.other_sheets.get("OUTPUTS", {})

    def view(self, extra_columns=None):
        """A :class:`SheetView` over the parameter sheet and the other sheets."""
        sheets = dict(self.other_sheets)
        sheets[self.sheet_title.upper()] = self.block
        if extra_columns is None:  # only the block was read: references beyond it must fail
            return SheetView(sheets, self.sheet_title.upper(), {},
                             {self.sheet_title.upper(): PARAMETER_COLUMNS})
        return SheetView(sheets, self.sheet_title.upper(), extra_columns)


def _sniff(path):
    path = Path(path)
    if not path.exists():
        raise WorkbookError(f"{path}: no such file, expected a workbook (.xlsx, .xlsm or .xls)")
    if path.is_dir():
        raise WorkbookError(f"{path}: is a folder, expected a workbook (.xlsx, .xlsm or .xls)")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise WorkbookError(f"{path}: cannot be read ({exc.strerror})") from None
    if data.startswith(ZIP_MAGIC):
        return data, "zip"
    if data.startswith(CFB_MAGIC):
        if ENCRYPTED_STREAM in data:
            raise WorkbookError(f"{path}: is password-protected, expected an unprotected workbook "
                                "(save a copy without a password)")
        return data, "xls"
    raise WorkbookError(f"{path}: is not a workbook, expected an .xlsx, .xlsm or .xls file")


def _read_zip(path, data):
    import openpyxl
    from openpyxl.utils.exceptions import InvalidFileException

    try:
        wb_f = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=False)
        wb_v = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=True)
    except (zipfile.BadZipFile, InvalidFileException, KeyError, OSError, ValueError) as exc:
        raise WorkbookError(f"{path}: is not a readable .xlsx workbook ({exc})") from None
    try:
        sheets = {}
        last = _block_extent(data)  # openpyxl need not parse an old workbook's result rows
        wanted = None  # after the first sheet: the other sheets its formulas name, and Outputs
        for ws_f, ws_v in zip(wb_f.worksheets, wb_v.worksheets):
            first = not sheets
            if not first and ws_f.title.upper() not in wanted:
                continue  # e.g. the Tracked or ChartData sheets of a filled workbook
            cells = {}
            max_col = PARAMETER_COLUMNS if first else None
            max_row = last if first else None
            for row_f, row_v in zip(ws_f.iter_rows(max_row=max_row, max_col=max_col),
                                    ws_v.iter_rows(max_row=max_row, max_col=max_col)):
                for cf, cv in zip(row_f, row_v):
                    if cf.value is None or not hasattr(cf, "column"):
                        continue
                    formula = _formula_text(cf.value)
                    cells[(cf.row, cf.column)] = (cv.value, formula)
            if first:
                h1 = next(ws_v.iter_rows(min_row=1, max_row=1, min_col=8, max_col=8,
                                         values_only=True), (None,))[0]
                if h1 is not None:
                    cells[(1, 8)] = (h1, None)
            sheets[ws_f.title] = cells
            if first:
                text = " ".join(f for _, f in cells.values() if f).upper()
                wanted = {t.upper() for t in wb_f.sheetnames[1:]
                          if t.upper() in text or t.upper() == "OUTPUTS"}
    except (zipfile.BadZipFile, KeyError, OSError, ValueError) as exc:
        raise WorkbookError(f"{path}: is not a readable .xlsx workbook ({exc})") from None
    finally:
        wb_f.close()
        wb_v.close()
    if not sheets:
        raise WorkbookError(f"{path}: has no worksheet, expected the report's parameter sheet")
    return sheets


def _block_extent(data):
    """Last row to read in columns A..G of the first sheet: the last one with a value there,
    found by python-calamine (fast), plus a margin of 200 rows for formulas whose cached
    value is "" (calamine shows those as empty); None when it cannot tell: read every row."""
    try:
        from python_calamine import CalamineWorkbook

        rows = CalamineWorkbook.from_filelike(io.BytesIO(data)).get_sheet_by_index(
            0).to_python(skip_empty_area=False)
    except Exception:  # noqa: BLE001 - openpyxl will report a broken file itself
        return None
    last = 1
    for r, row in enumerate(rows, start=1):
        if any(v not in ("", None) for v in row[:PARAMETER_COLUMNS]):
            last = r
    return last + 200


def _formula_text(value):
    if isinstance(value, str) and value.startswith("=") and len(value) > 1:
        return value
    text = getattr(value, "text", None)  # openpyxl ArrayFormula
    return text if isinstance(text, str) and text.startswith("=") else None


def _read_xls(path, data):
    try:
        from python_calamine import CalamineWorkbook

        wb = CalamineWorkbook.from_filelike(io.BytesIO(data))
        sheets = {}
        for name in wb.sheet_names:
            rows = wb.get_sheet_by_name(name).to_python(skip_empty_area=False)
            first = not sheets
            cells = {}
            for r, row in enumerate(rows, start=1):
                for c, value in enumerate(row, start=1):
                    if first and c > PARAMETER_COLUMNS and (r, c) != (1, 8):
                        continue
                    if value is not None and value != "":
                        cells[(r, c)] = (value, None)
            sheets[name] = cells
    except Exception as exc:  # noqa: BLE001 - calamine raises its own types for broken files
        raise WorkbookError(f"{path}: is not a readable .xls workbook ({exc})") from None
    if not sheets:
        raise WorkbookError(f"{path}: has no worksheet, expected the report's parameter sheet")
    return sheets


def _address(cell):
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
    data, kind = _sniff(path)
    sheets = _read_zip(path, data) if kind == "zip" else _read_xls(path, data)
    title = next(iter(sheets))
    block = sheets.pop(title)
    return Source(path, hashlib.sha256(data).hexdigest(), title, block,
                  {name.upper(): cells for name, cells in sheets.items()})


def _disagrees(cached, value):
    if not isinstance(cached, (int, float)) or isinstance(cached, bool):
        return True
    if not isinstance(value, float):
        return True
    return abs(cached - value) > CACHE_RTOL * max(abs(cached), abs(value))


def parameter_values(source):
    """Raw values of the parameter cells, evaluating formulas; and the warnings raised.

    A formula cell is evaluated with the ``formulas`` engine. Without a cached value the result
    is used as it is; when a cached value disagrees, a warning says so and the evaluated value
    is used (spreadsheet apps recalculate on open, so that is what the macro would read). When a
    formula cannot be evaluated, its cached value is used with a warning. Nothing is raised
    here: a bad value is left for :meth:`ShotParams.from_cells` to report, in cell order.

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
        cached, formula = source.block.get(pos, (None, None))
        if formula is None:
            raw[cell.address] = cached
            continue
        try:
            value = evaluator.value(sheet, *pos)
        except FormulaFailure as exc:
            if isinstance(cached, (int, float)) and not isinstance(cached, bool):
                warnings.append(f"{cell.address} ({cell.label}): {exc}; using the cached value "
                                f"{cached!r}")
                raw[cell.address] = cached
            else:
                raw[cell.address] = Found(f"the formula {formula} ({exc})")
            continue
        if isinstance(value, float) and (cached is not None) and _disagrees(cached, value):
            warnings.append(f"{cell.address} ({cell.label}): the cached value {describe(cached)} "
                            f"disagrees with {formula} = {value!r}; using the evaluated value")
        if isinstance(value, float):
            raw[cell.address] = value
        else:
            raw[cell.address] = Found(f"{describe(value)} from {formula}")
    return raw, warnings


def check_time_header(source):
    """H1 must be blank or hold "Time": the macro starts its result columns there."""
    value = source.block.get((1, 8), (None, None))[0]
    if value is not None and str(value).strip() != "Time":
        raise CellError(TIME_HEADER.address, TIME_HEADER.label, describe(value),
                        "'Time' or a blank cell (the result columns start at H1)")


def read_params(path):
    """Read and check a shot's parameters from a workbook.

    Returns
    -------
    params : ShotParams
    source : Source
    warnings : list of str
    """
    source = read_source(path)
    check_time_header(source)
    raw, warnings = parameter_values(source)
    return ShotParams.from_cells(raw), source, warnings
