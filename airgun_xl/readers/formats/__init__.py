"""Recording formats a recorder or analyser exports, one module each behind one interface.

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
- ``WINDOWED`` (optional, True): the format reads a file past
  :data:`airgun_xl.limits.MAX_INPUT_BYTES` without reading it whole.

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
from types import ModuleType

from ... import limits
from ..guard import LargeFile, large_file, read_bytes
from . import ide, mat, mdf, mme, tdms, uff
from .channels import ChannelInfo, Table, choose

#: Bytes read to tell a format by its content (a MATLAB v7.3 file's HDF5 signature is at 512).
HEAD = 1024

#: The formats told by content, in the order they are tried; a file none of them claims is
#: read as CSV.
FORMATS: tuple[ModuleType, ...] = (tdms, mat, mdf, ide, uff, mme)

EXPECTED_RECORDING = ("expected a recording (CSV, TDMS, MATLAB .mat, MDF, enDAQ IDE, UFF 58 or "
                      "ISO 13499 MME)")


def detect(path: str | Path) -> ModuleType | None:
    """The format module of the file at ``path``: by its content, else by its suffix; None
    for a file no format claims (read as CSV)."""
    head = read_bytes(path, EXPECTED_RECORDING, "recording", head=HEAD)
    for fmt in FORMATS:
        if fmt.sniff(head):
            return fmt
    suffix = Path(path).suffix.lower()
    if mme.channel_file(path):
        return mme
    return next((fmt for fmt in FORMATS if suffix in fmt.SUFFIXES), None)


def source(fmt: ModuleType, path: str | Path) -> bytes | LargeFile:
    """What ``fmt``'s reader is given of the file at ``path``: its bytes (at most
    :data:`~airgun_xl.limits.MAX_INPUT_BYTES`), or, for a ``WINDOWED`` format, a larger file
    (up to :data:`~airgun_xl.limits.MAX_WINDOWED_BYTES`) as a :class:`LargeFile`."""
    if getattr(fmt, "WINDOWED", False):
        large = large_file(path, fmt.EXPECTED, "recording", limits.MAX_WINDOWED_BYTES)
        if large is not None:
            return large
    return read_bytes(path, fmt.EXPECTED, "recording")


__all__ = ["EXPECTED_RECORDING", "FORMATS", "HEAD", "ChannelInfo", "LargeFile", "Table",
           "choose", "detect", "source"]
