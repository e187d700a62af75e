"""Recording formats a recorder or analyser exports, one module each behind one interface
(:class:`RecordingFormat`), in one registry (:data:`FORMATS`): the binary formats told by
content or name, a workbook's column range told by its text, and CSV, which a file no
other format claims is read as (:func:`detect`).

A format module holds:

- ``NAME``: how messages name the format;
- ``SUFFIXES``: the file name endings that choose it when its content does not (a MATLAB v4
  file has no header);
- ``sniff(head)``: whether the file's first :data:`HEAD` bytes are this format's (magic
  bytes, structure);
- ``channels(path, data)``: the file's channels as :class:`ChannelInfo`, read from its
  metadata, no samples;
- ``read(path, data, channel)``: the chosen channel as a :class:`Table` (how messages name
  it, the header naming the units as the file states them, ``time [s]``, ``acceleration [g]``,
  the (n, 2) array of time and the scaled (physical) acceleration, and the reading's notes);
- ``named(path)``: whether the file's name is this format's, where its content did not
  tell (its suffix; an MME channel file's ``TEST.001``; a workbook range's text);
- ``SEVERAL``: whether a file holds several channels (``--channel`` chooses one; CSV and a
  workbook range refuse it);
- ``WINDOWED`` (optional, True): the format reads a file past
  :data:`airgun_xl.limits.MAX_INPUT_BYTES` without reading it whole;
- ``load(path)`` (optional): what its reader is given, where not the file's capped bytes
  (a workbook range: its parts).

The file's bytes come from :func:`airgun_xl.readers.guard.read_bytes` (a regular file, its
size capped before it is read), so a reader parses bytes in memory and never opens a path; a
``WINDOWED`` format is given a larger file as a :class:`~airgun_xl.readers.guard.LargeFile`
instead (:func:`source`), which it opens only through
:func:`~airgun_xl.readers.guard.open_large`. A channel's declared length is checked against
:data:`airgun_xl.limits.MAX_SAMPLES` before its samples are read, and a ``WINDOWED`` format
reads the stretch of a longer channel around its pulse (:func:`.channels.pulse_window`).
Every fault is one :class:`~airgun_xl.errors.WorkbookError` (the file) or
:class:`~airgun_xl.errors.OptionError` (``--channel``) line.

``--channel`` names a channel the same way in every format: its name as the file gives it
(:attr:`ChannelInfo.name`), or its number in the file's list (1 for the first).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

from ... import limits
from ..guard import LargeFile, large_file, read_bytes
from . import delimited, ide, mat, mdf, mme, tdms, uff, workbook_range
from .channels import ChannelInfo, Table, choose


class RecordingFormat(Protocol):
    """The interface every format module offers (a module is its implementation)."""

    @property
    def NAME(self) -> str: ...  # noqa: N802 (a module's constant)

    @property
    def SUFFIXES(self) -> tuple[str, ...]: ...  # noqa: N802

    @property
    def EXPECTED(self) -> str: ...  # noqa: N802

    @property
    def SEVERAL(self) -> bool: ...  # noqa: N802

    def sniff(self, head: bytes) -> bool: ...

    def named(self, path: str | Path) -> bool: ...

    def channels(self, path: str | Path, data: Any) -> list[ChannelInfo]: ...

    def read(self, path: str | Path, data: Any, channel: str | None) -> Table: ...


#: Bytes read to tell a format by its content (a MATLAB v7.3 file's HDF5 signature is at 512).
HEAD = 1024

#: Every format but the fallback, in the order they are tried: by content first, then by
#: name (a workbook range is told by its text before any file is opened).
FORMATS: tuple[RecordingFormat, ...] = (tdms, mat, mdf, ide, uff, mme)

#: What a file no format claims is read as.
FALLBACK: RecordingFormat = delimited

EXPECTED_RECORDING = ("expected a recording (CSV, TDMS, MATLAB .mat, MDF, enDAQ IDE, UFF 58 or "
                      "ISO 13499 MME)")


def detect(path: str | Path) -> RecordingFormat:
    """The format of the recording ``path`` names: a workbook's column range by its text;
    a file by its content, else by its name (:data:`FORMATS`), else CSV (:data:`FALLBACK`)."""
    if workbook_range.claims(path):
        return workbook_range
    head = read_bytes(path, EXPECTED_RECORDING, "recording", head=HEAD)
    for fmt in FORMATS:
        if fmt.sniff(head):
            return fmt
    return next((fmt for fmt in FORMATS if fmt.named(path)), FALLBACK)


def source(fmt: RecordingFormat, path: str | Path) -> Any:
    """What ``fmt``'s reader is given of the recording ``path`` names: the format's own
    ``load`` where it has one; else the file's bytes (at most
    :data:`~airgun_xl.limits.MAX_INPUT_BYTES`), or, for a ``WINDOWED`` format, a larger file
    (up to :data:`~airgun_xl.limits.MAX_WINDOWED_BYTES`) as a :class:`LargeFile`."""
    load = getattr(fmt, "load", None)
    if load is not None:
        return load(path)
    if getattr(fmt, "WINDOWED", False):
        large = large_file(path, fmt.EXPECTED, "recording", limits.MAX_WINDOWED_BYTES)
        if large is not None:
            return large
    return read_bytes(path, fmt.EXPECTED, "recording")


__all__ = ["EXPECTED_RECORDING", "FALLBACK", "FORMATS", "HEAD", "ChannelInfo", "LargeFile",
           "RecordingFormat", "Table", "choose", "detect", "source"]
