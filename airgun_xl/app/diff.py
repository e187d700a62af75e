"""Compare two workbooks in the macro's layout: parameters first, then every result column.

Workbooks are read with python-calamine (cached values; .xlsx, .xlsm and .xls). Columns are
matched by the macro's position and header; rows by time. A column is compared where both
files hold numbers in it: the legacy macro writes only the header of column O, so O is "only
in new" rather than a column of differences.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import limits
from ..cells import CELLS
from ..errors import OptionError, WorkbookError
from ..readers import guard
from . import declared

if TYPE_CHECKING:  # numpy loads with a comparison, not with the command's parser
    import numpy as np

#: Default tolerance: Calc and Excel keep 15 significant digits.
DEFAULT_RTOL = 1e-12

FIRST_RESULT_COL = 7  # column H, 0-based


def _letter(col: Any) -> str:
    from xlsxwriter.utility import xl_col_to_name

    return xl_col_to_name(col)


@dataclass
class ResultSheet:
    """The first sheet of a workbook in the macro's layout, as numbers."""

    path: Path
    params: dict  # address -> raw value
    headers: dict  # 0-based col -> header text
    data: dict  # 0-based col -> float array over the data rows (NaN where empty)
    time: np.ndarray
    finals: tuple  # (final M1, final m31) below column I, NaN when absent


def _number(v: object) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return math.nan
    return float(v)


def _first_sheet(path: str | Path) -> Any:
    """The first sheet's values as a float grid, its text cells, and the raw bytes; every cap
    of :mod:`airgun_xl.readers.guard` is checked before python-calamine runs."""
    import io

    import numpy as np
    from python_calamine import CalamineWorkbook

    data, kind = guard.read_input(path)
    if kind == "zip":
        zf = guard.open_zip(path, data)
        rows, columns = guard.sheet_extent(path, zf, guard.first_sheet_member(path, zf),
                                           cap=limits.MAX_DIFF_CELLS)
    else:
        extents = guard.xls_extents(path, data)
        rows, columns = extents[0] if extents else (0, 0)
    guard.check_extent(path, "its first sheet", rows, columns, limits.MAX_DIFF_CELLS)
    grid = np.full((max(rows, 1), max(columns, 1)), np.nan)
    text = {}  # (row, col) -> str, for headers, labels and parameter cells
    try:
        sheet = CalamineWorkbook.from_filelike(io.BytesIO(data)).get_sheet_by_index(0)
        r0, c0 = sheet.start if sheet.start is not None else (0, 0)
        for r, row in enumerate(sheet.iter_rows(), start=r0):
            for c, v in enumerate(row, start=c0):
                if isinstance(v, float) or (isinstance(v, int) and not isinstance(v, bool)):
                    grid[r, c] = v
                elif v != "" and v is not None:
                    text[(r, c)] = v
    except IndexError:
        raise WorkbookError(f"{guard.display(path)}: holds cells outside the extent its XML "
                            "declares, expected a consistent workbook") from None
    except Exception as exc:  # noqa: BLE001 - calamine raises its own types
        raise WorkbookError(f"{guard.display(path)}: is not a readable workbook "
                            f"({type(exc).__name__}: {str(exc)[:120]})") from None
    return grid, text, data


def read_results(path: str | Path) -> ResultSheet:
    """Read a filled workbook.

    Raises
    ------
    WorkbookError
        When the file cannot be read, passes a cap of :mod:`airgun_xl.limits`, or is not in
        the macro's layout (no "Time" in H1 and time values below it).
    """
    import numpy as np

    path = Path(path)
    grid, text, data = _first_sheet(path)
    height, width = grid.shape

    def cell(r: int, c: int) -> Any:
        if r >= height or c >= width:
            return ""
        v = grid[r, c]
        return float(v) if not math.isnan(v) else text.get((r, c), "")

    h1 = cell(0, FIRST_RESULT_COL)
    if str(h1).strip() != "Time":
        raise WorkbookError(f"{guard.display(path)}: H1 holds {h1!r}, expected 'Time' (not a "
                            "workbook in the macro's layout)")
    column = grid[1:, FIRST_RESULT_COL] if width > FIRST_RESULT_COL else np.array([])
    gaps = np.flatnonzero(np.isnan(column))
    n = int(gaps[0]) if len(gaps) else len(column)
    if n == 0:
        raise WorkbookError(f"{guard.display(path)}: no time values below H1, expected the "
                            "macro's result columns (fill the workbook first)")
    from openpyxl.utils.cell import coordinate_to_tuple

    params = {}
    for c in CELLS:
        r, col = coordinate_to_tuple(c.address)
        params[c.address] = cell(r - 1, col - 1)
    blank = [a for a, v in params.items() if v == ""]
    if blank and data[:2] == b"PK":
        params.update(_error_cells(data, blank))
    headers, columns = {}, {}
    for col in range(FIRST_RESULT_COL, width):
        header = text.get((0, col), "" if math.isnan(grid[0, col]) else grid[0, col])
        last = height if col == 27 else n + 1  # AB may run past the last time row
        values = grid[1:last, col].copy()
        if col == 8:
            values = values[:n]
        if header != "" or np.isfinite(values).any():
            headers[col] = str(header)
            columns[col] = values
    finals = (_number(cell(n + 2, 8)), _number(cell(n + 3, 8)))
    return ResultSheet(path, params, headers, columns, column[:n].copy(), finals)


def _error_cells(data: bytes, addresses: Any) -> dict[str, str]:
    """calamine reads an error cell as blank; openpyxl keeps its text (#DIV/0!, ...)."""
    import io

    import openpyxl

    try:
        wb = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=True,
                                    keep_links=False)
        ws = wb.worksheets[0]
        found = {}
        for row in ws.iter_rows(min_row=1, max_row=43, max_col=5):
            for c in row:
                if getattr(c, "coordinate", None) in addresses and c.value is not None:
                    found[c.coordinate] = c.value
        wb.close()
        return found
    except Exception:  # noqa: BLE001 - the blank calamine gave stays
        return {}


@dataclass
class ColumnDiff:
    """How one column of NEW differs from LEGACY."""

    column: str
    header: str
    rows_legacy: int
    rows_new: int
    max_abs: float
    max_rel: float
    outside: int
    first_outside: dict | None = None  # row (sheet), time, legacy, new


@dataclass
class DiffReport:
    legacy: str
    new: str
    rows: tuple
    inputs: list  # (cell, label, legacy, new) of differing parameter cells
    columns: list
    only_legacy: list
    only_new: list
    rtol: float
    atol: float
    notes: list = field(default_factory=list)
    #: How the two sides are named; archived runs are named by entry, not LEGACY and NEW.
    labels: tuple = ("LEGACY", "NEW")
    #: Whether the parameter cells were compared here (archived runs: by the caller).
    inputs_compared: bool = True
    #: The column furthest apart, for --report: (name, time, legacy values, new values).
    worst: tuple | None = None

    @property
    def same(self) -> bool:
        return (not self.inputs and self.rows[0] == self.rows[1]
                and all(c.outside == 0 for c in self.columns))

    def as_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out.pop("worst", None)  # arrays, for the report workbook only
        out["same"] = self.same
        return out


def _same_param(a: object, b: object) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))
    return a == b


def _align(a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    """Indices into a and b of rows with equal time (the grids may differ in length)."""
    import numpy as np

    if len(a.time) == len(b.time) and np.allclose(a.time, b.time, rtol=0,
                                                  atol=1e-9 * np.ptp(a.time) + 1e-300):
        idx = np.arange(len(a.time))
        return idx, idx
    step = np.median(np.diff(a.time)) if len(a.time) > 1 else 1.0
    j = np.clip(np.searchsorted(b.time, a.time), 0, len(b.time) - 1)
    j_prev = np.clip(j - 1, 0, len(b.time) - 1)
    best = np.where(np.abs(b.time[j_prev] - a.time) < np.abs(b.time[j] - a.time), j_prev, j)
    ok = np.abs(b.time[best] - a.time) <= 1e-6 * step
    return np.flatnonzero(ok), best[ok]


def _compare(col: Any, header: str, x: np.ndarray, y: np.ndarray, times: Any,
             rtol: float, atol: float) -> ColumnDiff:
    """Column diff of aligned arrays x (legacy) and y (new)."""
    import numpy as np

    scale = float(np.nanmax(np.abs(x))) if np.isfinite(x).any() else 0.0
    both = np.isfinite(x) & np.isfinite(y)
    diff = np.where(both, np.abs(x - y), 0.0)
    one_empty = np.isfinite(x) != np.isfinite(y)
    bad = (diff > atol + rtol * scale) | one_empty
    max_abs = float(diff.max()) if len(diff) else 0.0
    first = None
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        time = float(times[i]) if i < len(times) else math.nan
        first = {"row": i + 2, "time": None if math.isnan(time) else time,  # final masses: none
                 "legacy": None if math.isnan(x[i]) else float(x[i]),
                 "new": None if math.isnan(y[i]) else float(y[i])}
    return ColumnDiff(_letter(col), header, int(np.isfinite(x).sum()),
                      int(np.isfinite(y).sum()), max_abs, max_abs / scale if scale else max_abs,
                      int(bad.sum()), first)


def diff_workbooks(legacy_path: str | Path, new_path: str | Path, rtol: float = DEFAULT_RTOL,
                   atol: float = 0.0) -> DiffReport:
    """Compare two filled workbooks; see the module docstring: the parameter cells
    (:func:`_differing_inputs`), the result columns by time (:func:`_compare_columns`), the
    final masses (:func:`_compare_finals`), and the column furthest apart
    (:func:`_worst_column`).

    Returns
    -------
    DiffReport
    """
    a, b = read_results(legacy_path), read_results(new_path)
    ia, ib = _align(a, b)
    columns, only_legacy, only_new = _compare_columns(a, b, ia, ib, rtol, atol)
    columns += _compare_finals(a, b, rtol, atol)
    notes = []
    if len(ia) < max(len(a.time), len(b.time)):
        notes.append(f"only {len(ia):,} rows share a time; legacy has {len(a.time):,}, new "
                     f"{len(b.time):,}")
    return DiffReport(str(legacy_path), str(new_path), (len(a.time), len(b.time)),
                      _differing_inputs(a, b), columns, only_legacy, only_new, rtol, atol,
                      notes, worst=_worst_column(a, b, ia, ib))


def _differing_inputs(a: ResultSheet, b: ResultSheet) -> list[Any]:
    """(cell, label, legacy, new) of the parameter cells that differ."""
    labels = {c.address: c.label for c in CELLS}
    return [(addr, labels[addr], a.params[addr], b.params[addr]) for addr in a.params
            if not _same_param(a.params[addr], b.params[addr])]


def _compare_columns(a: ResultSheet, b: ResultSheet, ia: np.ndarray, ib: np.ndarray,
                     rtol: float, atol: float) -> Any:
    """Each result column both sheets fill under one header, compared on the shared times
    (AB by row: its rows may run past the time grid); and the columns only one side fills
    (or fills under another header)."""
    import numpy as np

    columns, only_legacy, only_new = [], [], []
    for col in sorted(set(a.data) | set(b.data)):
        xa: Any = a.data.get(col)
        xb: Any = b.data.get(col)
        ha, hb = a.headers.get(col, ""), b.headers.get(col, "")
        has_a = xa is not None and np.isfinite(xa).any()
        has_b = xb is not None and np.isfinite(xb).any()
        name = f"{_letter(col)} {ha or hb}"
        if has_a and has_b and ha == hb:
            if col == 27:  # AB: rows may run past the time grid, compare by row
                m = max(len(xa), len(xb))
                xa2 = np.concatenate((xa, np.full(m - len(xa), np.nan)))
                xb2 = np.concatenate((xb, np.full(m - len(xb), np.nan)))
                columns.append(_compare(col, ha, xa2, xb2, a.time, rtol, atol))
            else:
                columns.append(_compare(col, ha, xa[ia], xb[ib], a.time[ia], rtol, atol))
        elif has_a and not has_b:
            only_legacy.append(name + (" (new: header only)" if hb else ""))
        elif has_b and not has_a:
            only_new.append(name + (" (legacy: header only)" if ha else ""))
        elif has_a and has_b:
            only_legacy.append(f"{_letter(col)} {ha}")
            only_new.append(f"{_letter(col)} {hb}")
    return columns, only_legacy, only_new


def _compare_finals(a: ResultSheet, b: ResultSheet, rtol: float, atol: float) -> Any:
    """The final masses below column I, each compared as a one-row column."""
    import numpy as np

    out = []
    for k, label in enumerate(("Final M1", "Final m31")):
        x, y = np.array([a.finals[k]]), np.array([b.finals[k]])
        if np.isfinite(x).any() or np.isfinite(y).any():
            d = _compare(8, label, x, y, [math.nan], rtol, atol)
            d.column = f"I{len(a.time) + 3 + k}"
            d.first_outside = ({**d.first_outside, "row": len(a.time) + 3 + k}
                               if d.first_outside else None)
            out.append(d)
    return out


def _worst_column(a: ResultSheet, b: ResultSheet, ia: np.ndarray, ib: np.ndarray) -> Any:
    """(name, time, legacy, new) of the column whose largest difference is the largest
    fraction of its magnitude (AB and empty columns aside); None when there is none."""
    import numpy as np

    worst = None
    for col in sorted(set(a.data) & set(b.data)):
        x, y = a.data[col], b.data[col]
        if col == 27 or not (np.isfinite(x).any() and np.isfinite(y).any()):
            continue
        x, y = x[ia], y[ib]
        scale = np.nanmax(np.abs(x)) or 1.0
        err = np.nanmax(np.abs(x - y)) / scale if (np.isfinite(x) & np.isfinite(y)).any() else 0
        if worst is None or err > worst[0]:
            worst = (err, f"{_letter(col)} {a.headers[col]}", a.time[ia], x, y)
    return worst[1:] if worst else None


def diff_histories(name_a: str, a: dict[str, np.ndarray], name_b: str,
                   b: dict[str, np.ndarray], rtol: float = DEFAULT_RTOL,
                   atol: float = 0.0) -> DiffReport:
    """Compare two full time histories (``{column: array}`` with a ``time`` column), as
    :func:`diff_workbooks` compares sheet columns; for archived runs."""
    import numpy as np

    ta, tb = np.asarray(a["time"]), np.asarray(b["time"])
    sa = ResultSheet(Path(name_a), {}, {}, {}, ta, (np.nan, np.nan))
    sb = ResultSheet(Path(name_b), {}, {}, {}, tb, (np.nan, np.nan))
    ia, ib = _align(sa, sb)
    columns = []
    for name in [k for k in a if k in b and k != "time"]:
        columns.append(_compare(0, name, np.asarray(a[name])[ia], np.asarray(b[name])[ib],
                                ta[ia], rtol, atol))
        columns[-1].column = name
        columns[-1].header = ""
    only_a = [k for k in a if k not in b]
    only_b = [k for k in b if k not in a]
    return DiffReport(name_a, name_b, (len(ta), len(tb)), [], columns, only_a, only_b, rtol,
                      atol, labels=(name_a, name_b), inputs_compared=False)


def format_report(report: DiffReport) -> str:
    """The report as a readable table."""
    if report.labels == ("LEGACY", "NEW"):
        lines = [f"LEGACY {report.legacy} ({report.rows[0]:,} rows)",
                 f"NEW    {report.new} ({report.rows[1]:,} rows)"]
    else:
        lines = [f"rows: {report.rows[0]:,} in {report.labels[0]}, {report.rows[1]:,} in "
                 f"{report.labels[1]}"]
    if report.inputs_compared and report.inputs:
        lines.append("inputs differ (so the numbers may differ for that reason):")
        for addr, label, x, y in report.inputs:
            lines.append(f"  {addr} {label}: {x!r} vs {y!r}")
    elif report.inputs_compared:
        lines.append(f"inputs: the {len(CELLS)} parameter cells agree")
    lines.append(f"  {'column':<30} {'rows':>13} {'max abs':>10} {'max rel':>10} "
                 f"{'outside':>8}  first outside")
    for c in report.columns:
        first = ""
        if c.first_outside:
            f = c.first_outside
            when = "" if f["time"] is None else f" t={f['time']:.6g}"
            first = f"row {f['row']}{when}: {f['legacy']!r} vs {f['new']!r}"
        lines.append(f"  {(c.column + ' ' + c.header).strip()[:30]:<30} "
                     f"{c.rows_legacy:>6,}/{c.rows_new:<6,} {c.max_abs:>10.2e} "
                     f"{c.max_rel:>10.2e} {c.outside:>8,}  {first}")
    for label, names in (("only in legacy", report.only_legacy),
                         ("only in new", report.only_new)):
        if names:
            lines.append(f"{label}: {'; '.join(names)}")
    lines += report.notes
    verdict = "within tolerance" if report.same else "DIFFERENT"
    lines.append(f"{verdict} (rtol {report.rtol:g} of each column's largest magnitude, "
                 f"atol {report.atol:g})")
    return "\n".join(lines)


@dataclass(frozen=True)
class DiffOutcome:
    """The comparison (:class:`DiffReport`: the parameter cells, every column, the worst), and
    the files written."""

    report: DiffReport
    files: tuple[Path, ...]

    @property
    def same(self) -> bool:
        """Every column within tolerance (the CLI's exit 0; 1 otherwise)."""
        return bool(self.report.same)


#: The help of ``diff``'s tolerances.
RTOL_HELP = ("relative to each column's largest magnitude (default 1e-12: Calc and Excel keep "
             "15 digits)")
ATOL_HELP = "absolute tolerance (default 0)"


def a_tolerance(value: Any, who: str) -> float:
    """A tolerance: a number >= 0 [-], given as one or as text."""
    try:
        found = declared.a_number(value, who)
    except OptionError:
        found = -1.0
    if not found >= 0:
        raise OptionError(f"{who}: found {value!r}, expected a number >= 0")
    return found


@dataclass(frozen=True, kw_only=True)
class DiffRequest(declared.Checked):
    """The two workbooks, the tolerances [-] and where the report goes (None: none). Declared
    once (:mod:`.declared`): the command's options and the API's keywords."""

    legacy: Path = declared.positional("legacy", metavar="LEGACY", read=declared.a_path,
                                       help="the workbook the macro filled (the reference)")
    new: Path = declared.positional("new", metavar="NEW", read=declared.a_path,
                                    help="the workbook airgun-xl fill wrote")
    rtol: float = declared.option(DEFAULT_RTOL, "--rtol", help=RTOL_HELP, read=a_tolerance)
    atol: float = declared.option(0.0, "--atol", help=ATOL_HELP, read=a_tolerance)
    report: Path | None = declared.option(
        None, "--report", metavar="REPORT.xlsx", read=declared.a_path_or_none,
        help="also write a workbook: error table and the worst column's curves")
    force: bool = declared.force("REPORT.xlsx")


def run(request: DiffRequest) -> DiffOutcome:
    """Compare a legacy workbook with a new one; with a report, also write the error table
    and the worst column's curves there.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        A file that cannot be read, or a report that exists (without ``force``).
    """
    legacy, new, report = request.legacy, request.new, request.report
    if report is not None:
        check_report(report, request.force, [legacy, new])
    found = diff_workbooks(legacy, new, request.rtol, request.atol)
    files: tuple[Path, ...] = ()
    if report is not None:
        write_report(found, report, request.force)
        files = (Path(report),)
    return DiffOutcome(found, files)


def check_report(report: str | Path, force: bool, inputs: list[str | Path]) -> None:
    """Refuse a report workbook that exists (without ``force``) or is one of the inputs,
    before any work."""
    from ..transaction import check_output

    check_output(report, force, inputs=inputs)


def write_report(found: DiffReport, report: str | Path, force: bool = False) -> None:
    """The comparison's workbook: the error table and the worst column's curves."""
    from ..reports.diff_report import write_diff_report

    write_diff_report(found, report, force)
