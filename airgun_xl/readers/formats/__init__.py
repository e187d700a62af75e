"""Recording formats a recorder or analyser exports, one module each behind one interface.

A format module holds:

- ``NAME``: how messages name the format;
- ``SUFFIXES``: the file name endings that choose it when its content does not (a MATLAB v4
  file has no header);
- ``sniff(head)``: whether the file's first :data:`HEAD` bytes are this format's (magic
  bytes, structure);
- ``channels(path, data)``: the file's channels as :class:`ChannelInfo`, read from its
  metadata, no samples;
- ``read(path, data, channel)``: the chosen channel as ``(shown, header, values)``, the
  header naming the units as the file states them (``time [s]``, ``acceleration [g]``) and
  ``values`` the (n, 2) array of time and the scaled (physical) acceleration.

The file's bytes come from :func:`airgun_xl.readers.guard.read_bytes` (a regular file, its
size capped before it is read), so a reader parses bytes in memory and never opens a path. A
channel's declared length is checked against :data:`airgun_xl.limits.MAX_SAMPLES` before its
samples are read. Every fault is one :class:`~airgun_xl.errors.WorkbookError` (the file) or
:class:`~airgun_xl.errors.OptionError` (``--channel``) line.

``--channel`` names a channel the same way in every format: its name as the file gives it
(:attr:`ChannelInfo.name`), or its number in the file's list (1 for the first).
"""
from __future__ import annotations

from pathlib import Path
from types import ModuleType

from ..guard import read_bytes
from . import mat, mdf, mme, tdms, uff
from .channels import ChannelInfo, choose

#: Bytes read to tell a format by its content (a MATLAB v7.3 file's HDF5 signature is at 512).
HEAD = 1024

#: The formats told by content, in the order they are tried; a file none of them claims is
#: read as CSV.
FORMATS: tuple[ModuleType, ...] = (tdms, mat, mdf, uff, mme)

EXPECTED_RECORDING = ("expected a recording (CSV, TDMS, MATLAB .mat, MDF, UFF 58 or ISO 13499 "
                      "MME)")


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


__all__ = ["EXPECTED_RECORDING", "FORMATS", "HEAD", "ChannelInfo", "choose", "detect"]
