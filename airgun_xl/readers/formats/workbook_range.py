"""A workbook's column range, ``trace.xlsx:Sheet1!A:B``: time and acceleration with a header
row, read from the workbook's cells (its extent checked before calamine reads it dense). The
"path" is the text naming the range, not a file: :func:`claims` tells it."""
from __future__ import annotations

import io
import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import AirgunXlError, OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, Table

NAME = "workbook range"
SUFFIXES: tuple[str, ...] = ()
#: ``FILE:SHEET!COL:COL``: a column range of a workbook.
RANGE = re.compile(r"^(?P<file>.+\.(?:xlsx|xlsm|xls)):(?P<sheet>[^!]+)!(?P<a>[A-Za-z]{1,3})"
                   r"(?:\d*)?:(?P<b>[A-Za-z]{1,3})(?:\d*)?$", re.IGNORECASE)

EXPECTED = EXPECTED_RANGE = ("expected a column range of time and acceleration with a header row, "
                  "e.g. trace.xlsx:Sheet1!A:B")


#: One channel a range: ``--channel`` is refused.
SEVERAL = False


def claims(text: str | Path) -> bool:
    """Whether ``text`` names a workbook's column range (and no file of that name exists)."""
    return RANGE.match(str(text)) is not None and not Path(str(text)).exists()


def sniff(head: bytes) -> bool:
    """Never: a range is told by its text (:func:`claims`), not by a file's content."""
    return False


def named(path: str | Path) -> bool:
    return claims(path)


def load(text: str | Path) -> re.Match[str]:
    """The range's parts (``file``, ``sheet``, ``a``, ``b``); the workbook is read by
    :func:`read`."""
    found = RANGE.match(str(text))
    assert found is not None, text  # claims() chose this format
    return found


def read(text: str | Path, data: Any, channel: str | None) -> Table:
    """The range's two columns; ``channel`` refused (a range is one)."""
    if channel is not None:
        raise OptionError("--channel: found with a workbook range, expected it only with a "
                          "file of several channels (TDMS, MATLAB .mat, MDF, IDE, UFF, MME)")
    return Table(*range_table(data))


def channels(text: str | Path, data: Any) -> list[ChannelInfo]:
    """Its one channel (:func:`.delimited.one_channel`)."""
    from .delimited import one_channel

    _shown, header, values = range_table(data)
    return [one_channel(header, values)]


def _column(letters):
    n = 0
    for ch in letters.upper():
        n = n * 26 + ord(ch) - 64
    return n - 1


def range_table(found):
    from .. import guard

    path = Path(found["file"])
    shown = f"{display(path)}:{found['sheet']}!{found['a'].upper()}:{found['b'].upper()}"
    data, kind = guard.read_input(path)
    if kind == "zip":
        zf = guard.open_zip(path, data)  # sizes, ratios and entities, before any parser
        member = guard.sheet_member(path, zf, found["sheet"])
        if member is not None:  # its extent, before calamine makes it dense (issue 23.1)
            rows, columns = guard.sheet_extent(path, zf, member, cap=limits.MAX_DIFF_CELLS,
                                               what=f"sheet {found['sheet']!r}")
            guard.check_extent(path, f"sheet {found['sheet']!r}", rows, columns,
                               limits.MAX_DIFF_CELLS)
        zf.close()
    else:
        for k, (rows, columns) in enumerate(guard.xls_extents(path, data)):
            guard.check_extent(path, f"sheet {k + 1}", rows, columns, limits.MAX_XLS_CELLS)
    a, b = _column(found["a"]), _column(found["b"])
    if a == b:
        raise OptionError(f"{shown}: names one column, {EXPECTED_RANGE}")
    try:
        from python_calamine import CalamineWorkbook

        wb = CalamineWorkbook.from_filelike(io.BytesIO(data))
        if found["sheet"] not in wb.sheet_names:
            raise WorkbookError(f"{shown}: has no sheet {found['sheet']!r} (it has "
                                f"{', '.join(map(repr, wb.sheet_names[:5]))}), "
                                f"{EXPECTED_RANGE}")
        rows = wb.get_sheet_by_name(found["sheet"]).to_python(skip_empty_area=False)
    except AirgunXlError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes: one line
        raise WorkbookError(f"{shown}: is not a readable workbook ({type(exc).__name__}), "
                            f"{EXPECTED_RANGE}") from None
    rows = [r for r in rows if len(r) > max(a, b) and (r[a] != "" or r[b] != "")]
    if len(rows) < 2:
        raise WorkbookError(f"{shown}: holds {len(rows)} rows, {EXPECTED_RANGE}")
    header = [str(rows[0][a]), str(rows[0][b])]
    values = np.empty((len(rows) - 1, 2))
    for i, row in enumerate(rows[1:], start=2):
        cells = (row[a], row[b])
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in cells) \
                or not all(math.isfinite(v) for v in cells):
            raise WorkbookError(f"{shown}: row {i} holds {list(cells)!r}, expected two finite "
                                "numbers (time, acceleration)")
        values[i - 2] = cells
    return shown, header, values
