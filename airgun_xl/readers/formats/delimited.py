"""CSV: a data-acquisition export of time and acceleration (or any two columns, a required
spectrum's too), the format a file no other claims is read as; one channel, its second
column, its units in the header. Every row is checked: one line names the first that is not
two finite numbers."""
from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from ..guard import read_bytes
from .channels import FILE_TIME_UNITS, ChannelInfo, Table, stated

NAME = "CSV"
SUFFIXES = (".csv", ".txt")
EXPECTED = "expected a CSV of time and acceleration (two columns, a header row)"
#: One channel a file: ``--channel`` is refused.
SEVERAL = False


def sniff(head: bytes) -> bool:
    """Never: a CSV is what a file no other format claims is read as (:data:`.FALLBACK`)."""
    return False


def named(path: str | Path) -> bool:
    """Never by name alone, for the same reason."""
    return False


def load(path: str | Path) -> bytes:
    """The file's bytes, capped (:func:`~airgun_xl.readers.guard.read_bytes`)."""
    return read_bytes(path, EXPECTED, "CSV")


def read(path: str | Path, data: Any, channel: str | None) -> Table:
    """The file's two columns (:func:`table`); ``channel`` refused (a CSV holds one)."""
    if channel is not None:
        raise OptionError("--channel: found with a CSV file, expected it only with a file of "
                          "several channels (TDMS, MATLAB .mat, MDF, IDE, UFF, MME)")
    return Table(*table(path, EXPECTED, ("time", "acceleration"), data))


def channels(path: str | Path, data: Any) -> list[ChannelInfo]:
    """Its one channel: the second column, its unit, rate and start from the time column."""
    shown, header, values = table(path, EXPECTED, ("time", "acceleration"), data)
    return [one_channel(header, values)]


def one_channel(header: list[str], values: np.ndarray) -> ChannelInfo:
    """The channel of a two-column table: its header's name and unit, the rate and start of
    its time column (in the header's unit)."""
    scale = FILE_TIME_UNITS.get(stated(header[0]))
    time = values[:, 0]
    rate = ((len(time) - 1) / ((time[-1] - time[0]) * scale)
            if scale and len(time) > 1 and time[-1] > time[0] else None)
    return ChannelInfo(header[1], stated(header[1]), rate, len(values),
                       float(time[0]) * scale if scale else None)


def _number(text, decimal_comma):
    text = text.strip()
    return float(text.replace(",", ".") if decimal_comma else text)


def _is_pair(row, decimal_comma):
    """Whether a row starts with two numbers."""
    if len(row) < 2:
        return False
    try:
        _number(row[0], decimal_comma)
        _number(row[1], decimal_comma)
    except ValueError:
        return False
    return True


def _looks_like_data(row):
    """A row that starts with a number: data, where the header should have been followed by
    two numbers."""
    try:
        float(row[0].strip().replace(",", "."))
    except (ValueError, IndexError):
        return False
    return True


def _body(raw, delimiter, comma):
    """The data lines (UTF-8 bytes) as an n x 2 float array by pandas' C parser (no Python
    list a row), or None when a line is not two numbers (the slow path then names it)."""
    import pandas as pd

    try:
        frame = pd.read_csv(io.BytesIO(raw), sep=delimiter, header=None, usecols=[0, 1],
                            decimal="," if comma else ".", dtype=float, engine="c",
                            comment="#", skip_blank_lines=True, skipinitialspace=True)
    except (ValueError, IndexError, pd.errors.ParserError, pd.errors.EmptyDataError):
        return None
    return frame.to_numpy(dtype=float)


def _find_bad_line(shown, text, first, delimiter, comma, columns):
    """Raise the one line naming the first data line that is not two finite numbers."""
    for number, line in enumerate(text.splitlines(), start=first):
        try:
            row = next(csv.reader([line], delimiter=delimiter), [])
        except csv.Error as exc:
            raise WorkbookError(f"{shown}: line {number} is not readable CSV ({exc})") from None
        if not any(cell.strip() for cell in row) or row[0].lstrip().startswith("#"):
            continue
        try:
            a, b = _number(row[0], comma), _number(row[1], comma)
        except (ValueError, IndexError):
            raise WorkbookError(f"{shown}: line {number} holds {row[:2]!r}, expected two "
                                f"numbers ({columns[0]}, {columns[1]})") from None
        if not (math.isfinite(a) and math.isfinite(b)):
            raise WorkbookError(f"{shown}: line {number} holds {row[0].strip()}, "
                                f"{row[1].strip()}, expected finite numbers (no NaN or inf)")
    raise WorkbookError(f"{shown}: is not a readable CSV of two numbers a line")


def _dialect(lines):
    """(delimiter, decimal comma) of a data-acquisition export's data lines: ``;`` or a tab
    with a decimal comma (``1,5;0,25``), or a comma, semicolon or tab with a point."""
    sample = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    sample = sample[-50:]  # data lines, past any metadata and the header
    for delimiter in (";", "\t", ","):
        if sample and all(line.count(delimiter) >= 1 for line in sample):
            comma = delimiter != "," and any("," in line for line in sample)
            return delimiter, comma
    return ",", False


def table(path, expected, columns, data=None):
    """(shown name, header, n x 2 values) of a two-column CSV (its bytes ``data``, read here
    when None); every row checked.

    Data-acquisition exports are read as they come: ``#`` comment lines and other metadata
    lines above the header are skipped (the header is the row above the first row of two
    numbers); ``,``, ``;`` or tab delimiters; a decimal comma with ``;`` or tabs."""
    shown = display(Path(path))
    if data is None:
        data = read_bytes(path, expected, "CSV")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise WorkbookError(f"{shown}: is not UTF-8 text (byte {exc.start}), {expected}") \
            from None
    count = text.count("\n") + 1
    if count > limits.MAX_SAMPLES + 1000:  # counted before any parsing: a bounded read
        raise WorkbookError(f"{shown}: holds {count:,} lines, expected at most "
                            f"{limits.MAX_SAMPLES:,} samples")
    delimiter, comma = _dialect(text[-20_000:].splitlines()[-50:])
    header, start, numbered = None, None, []  # the lines above the data, parsed one by one
    offset, number = 0, 0
    while offset <= len(text) and start is None:
        end = text.find("\n", offset)
        end = len(text) if end < 0 else end
        number += 1
        line = text[offset:end].rstrip("\r")
        try:
            row = next(csv.reader([line], delimiter=delimiter), [])
        except csv.Error as exc:  # a field past csv's limit, a stray quote
            raise WorkbookError(f"{shown}: line {number} is not readable CSV ({exc}), "
                                f"{expected}") from None
        if any(cell.strip() for cell in row) and not row[0].lstrip().startswith("#"):
            if _is_pair(row, comma):
                start = (offset, number)
                break
            numbered.append((number, row))
            if len(numbered) >= 2 and not _is_pair(numbered[-2][1], comma) and \
                    _looks_like_data(numbered[-1][1]):
                line_no, bad = numbered[-1]  # a header, then a row that is not two numbers
                raise WorkbookError(f"{shown}: line {line_no} holds {bad[:2]!r}, expected two "
                                    f"numbers ({columns[0]}, {columns[1]})")
        offset = end + 1
    if start is None or not numbered:
        got = numbered[0] if numbered else (number, [])
        raise WorkbookError(f"{shown}: line {got[0]} holds {got[1][:3]!r}, {expected}; found "
                            + ("no header row above the numbers" if start is not None else
                               f"no row of two numbers ({delimiter!r}-delimited"
                               + (", decimal comma" if comma else "") + ")"))
    header_line, header = numbered[-1]
    if len(header) < 2:
        raise WorkbookError(f"{shown}: line {header_line} (the header) holds {header!r}, "
                            f"{expected}")
    # the data from their first line, as bytes: pandas reads them without a str copy a row
    head = len(text[:start[0]].encode("utf-8")) + (3 if data.startswith(b"\xef\xbb\xbf") else 0)
    values = _body(data[head:], delimiter, comma)
    if values is None or not np.isfinite(values).all():
        _find_bad_line(shown, text[start[0]:], start[1], delimiter, comma, columns)
    if len(values) > limits.MAX_SAMPLES:
        raise WorkbookError(f"{shown}: holds {len(values):,} rows, expected at most "
                            f"{limits.MAX_SAMPLES:,} samples")
    return shown, header, values
