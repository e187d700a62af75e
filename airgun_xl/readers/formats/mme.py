"""ISO/TS 13499 MME (the crash-test data exchange format), read by airgun-xl itself: it is
plain text, and its one Python library pins old numpy, pandas and scipy.

A test is a folder: ``TEST.mme`` (the test's description), ``Channel/TEST.chn`` (the channel
list) and a file per channel, ``Channel/TEST.001``, ``.002``... A channel file is a header of
``Name :value`` lines, then its samples, one per line, the time implicit (from ``Time of
first sample`` and ``Sampling interval``) or explicit (``Reference channel :explicit``: the
values of the test's channel that ``Reference channel name`` names, by name or code, in its
own unit), or two per line, time and value. The fields read: ``Name of the channel``,
``Channel code``, ``Unit``, ``Time of first sample``, ``Sampling interval``, ``Number of
samples``, ``Reference channel`` and ``Reference channel name``; ``NOVALUE`` is the format's
word for a field not given. The text's encoding is UTF-8 (with or without a byte-order
mark), else Windows-1252, else Latin-1.

Given the ``.mme`` file, its channels are the numbered files of its ``Channel`` folder, each
read like any input (a regular file, not a symlink, its size capped), and ``--channel`` takes
a channel's name, its channel code or its number; given one channel file, that channel.
"""
from __future__ import annotations

import math
import os
import re
import stat
from pathlib import Path

import numpy as np

from ... import limits
from ...errors import WorkbookError
from ...transaction import display
from ..guard import read_bytes
from .channels import ChannelInfo, Table, choose

NAME = "ISO 13499 MME"
SUFFIXES = (".mme",)
EXPECTED = ("expected an ISO 13499 MME test (its .mme file, with its Channel folder) or one of "
            "its channel files")

#: The fields a channel file's header is read for (lower case, spaces single).
NAME_FIELD, CODE, UNIT = "name of the channel", "channel code", "unit"
FIRST, STEP, COUNT = "time of first sample", "sampling interval", "number of samples"
REFERENCE, REFERENCE_NAME = "reference channel", "reference channel name"

#: The format's word for a field not given.
NOVALUE = "NOVALUE"

#: The most channel files a test's folder is read for.
MAX_CHANNELS = 999

_HEADER_LINE = re.compile(r"^([A-Za-z][^:]{0,80}?)\s*:(.*)$")
_CHANNEL_FILE = re.compile(r"\.\d{3}$")


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix, or an MME channel file's
    ``TEST.001``."""
    return Path(path).suffix.lower() in SUFFIXES or channel_file(path)


def sniff(head: bytes) -> bool:
    """An MME file or channel file starts with one of the format's header lines (an NHTSA
    export's test file with ``Data format``, its channel files with ``Channel code``)."""
    text = _decode(head).lstrip("\ufeff").lstrip()
    first = text.split("\n", 1)[0].strip().lower()
    return re.match(r"^(data format( edition number)?|instrumentation standard|channel code)"
                    r"\s*:", first) is not None


def channel_file(path: str | Path) -> bool:
    """Whether ``path`` is named as an MME channel file (``TEST.001``)."""
    return _CHANNEL_FILE.search(Path(path).name) is not None


def _is_channel(data: bytes) -> bool:
    """Whether the file's header is a channel's (it names a channel, or its samples' step),
    whatever the file is called; a test's ``.mme`` file names neither."""
    fields, _ = _header(_decode(data[:HEADER_BYTES]))
    return any(key in fields for key in (NAME_FIELD, CODE, STEP))


def _decode(data: bytes) -> str:
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:].decode("utf-8", "replace")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        pass
    try:
        return data.decode("cp1252")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _header(text: str) -> tuple[dict[str, str], list[str]]:
    """The header's fields (lower-case names) and the lines after it."""
    fields: dict[str, str] = {}
    lines = text.splitlines()
    for k, line in enumerate(lines):
        found = _HEADER_LINE.match(line.strip())
        if found is None:
            return fields, lines[k:]
        fields.setdefault(" ".join(found.group(1).lower().split()), found.group(2).strip())
    return fields, []


def _given(fields: dict[str, str], name: str) -> str | None:
    value = fields.get(name)
    return None if value is None or value.strip().upper() == NOVALUE or not value.strip() \
        else value.strip()


def _number(shown: str, fields: dict[str, str], name: str) -> float | None:
    value = _given(fields, name)
    if value is None:
        return None
    try:
        number = float(value.replace(",", "."))
    except ValueError:
        raise WorkbookError(f"{shown}: '{name}' is {value[:40]!r}, expected a number or "
                            f"{NOVALUE}") from None
    if not math.isfinite(number):
        raise WorkbookError(f"{shown}: '{name}' is {value[:40]!r}, expected a finite number")
    return number


def _channel_files(path: Path) -> list[Path]:
    """The numbered channel files of the test at ``path`` (its ``.mme`` file), in order;
    the Channel folder and each file must be what they say (no symlink)."""
    shown = display(path)
    folder = path.parent / "Channel"
    try:
        st = os.lstat(folder)
    except OSError:
        raise WorkbookError(f"{shown}: has no Channel folder beside it, {EXPECTED}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise WorkbookError(f"{shown}: its Channel folder is not a folder (a symlink or a "
                            f"file), {EXPECTED}")
    found = _numbered(folder, path.stem)
    if not found:
        raise WorkbookError(f"{shown}: its Channel folder holds no {path.stem}.001, "
                            f"{EXPECTED}")
    return found


def _numbered(folder: Path, stem: str) -> list[Path]:
    """``stem.001``, ``stem.002``... in ``folder``, up to the first missing; each must be a
    regular file (no symlink)."""
    found = []
    for k in range(1, MAX_CHANNELS + 1):
        candidate = folder / f"{stem}.{k:03d}"
        try:
            st = os.lstat(candidate)
        except OSError:
            break  # the channels are numbered from 001 without a gap
        if not stat.S_ISREG(st.st_mode):
            raise WorkbookError(f"{display(candidate)}: is not a regular file (a symlink or "
                                f"a device), {EXPECTED}")
        found.append(candidate)
    return found


class _Channel:
    """One channel file's header and samples."""

    def __init__(self, path: Path, data: bytes, complete: bool = True) -> None:
        self.complete = complete  # False: ``data`` is the file's head only
        self.shown = display(path)
        fields, self.body = _header(_decode(data))
        self.name = _given(fields, NAME_FIELD) or _given(fields, CODE) or path.name
        self.code = _given(fields, CODE) or ""
        self.unit = _given(fields, UNIT) or ""
        self.first = _number(self.shown, fields, FIRST)
        self.step = _number(self.shown, fields, STEP)
        count = _number(self.shown, fields, COUNT)
        if count is not None and (count < 0 or count != int(count)):
            raise WorkbookError(f"{self.shown}: '{COUNT}' is {count:g}, expected a whole "
                                "count")
        self.count = None if count is None else int(count)
        self.explicit = (_given(fields, REFERENCE) or "").lower() == "explicit"
        self.reference = _given(fields, REFERENCE_NAME)

    @property
    def info(self) -> ChannelInfo:
        rate = 1.0 / self.step if self.step and self.step > 0 else None
        samples = self.count if self.count is not None else (
            sum(1 for line in self.body if line.strip()) if self.complete else 0)
        return ChannelInfo(self.name, self.unit, rate, samples, self.first)

    def numbers(self) -> np.ndarray:
        """The sample lines' numbers, (n, 1) or (n, 2), every line checked."""
        if self.count is not None and self.count > limits.MAX_SAMPLES:  # before any parse
            raise WorkbookError(f"{self.shown}: channel {self.name!r} declares "
                                f"{self.count:,} samples, expected at most "
                                f"{limits.MAX_SAMPLES:,} samples")
        rows = [line.split() for line in self.body if line.strip()]
        if len(rows) > limits.MAX_SAMPLES:
            raise WorkbookError(f"{self.shown}: holds {len(rows):,} samples, expected at most "
                                f"{limits.MAX_SAMPLES:,} samples")
        if self.count is not None and self.count != len(rows):
            raise WorkbookError(f"{self.shown}: declares {self.count:,} samples and holds "
                                f"{len(rows):,}, {EXPECTED}")
        if not rows:
            raise WorkbookError(f"{self.shown}: holds no samples after its header, {EXPECTED}")
        widths = {len(r) for r in rows}
        if len(widths) > 1 or not widths <= {1, 2}:
            raise WorkbookError(f"{self.shown}: its sample lines hold {sorted(widths)} numbers, "
                                "expected one on every line (the time implicit) or two (time "
                                "and value)")
        try:
            values = np.array([[float(x.replace(",", ".")) for x in r] for r in rows],
                              dtype=float).reshape(len(rows), -1)
        except ValueError:
            bad = next(k for k, r in enumerate(rows) if not _all_numbers(r))
            raise WorkbookError(f"{self.shown}: sample {bad + 1} is {' '.join(rows[bad])[:40]!r}"
                                f", expected numbers") from None
        return values

    def samples(self, time: np.ndarray | None = None) -> np.ndarray:
        """(n, 2): time and value (the time in s, or ``time`` given: the explicit reference
        channel's values, which must be as many)."""
        values = self.numbers()
        if values.shape[1] == 2:
            return values
        if time is not None:
            if len(time) != len(values):
                raise WorkbookError(f"{self.shown}: holds {len(values):,} samples and its "
                                    f"reference channel {self.reference!r} {len(time):,} "
                                    f"times, expected one time a sample")
            return np.column_stack([time, values[:, 0]])
        if self.step is None or self.step <= 0:
            raise WorkbookError(f"{self.shown}: its samples have no time (one number a line) "
                                f"and '{STEP}' is not a positive number, {EXPECTED}")
        time = (self.first or 0.0) + self.step * np.arange(len(values))
        return np.column_stack([time, values[:, 0]])


def _all_numbers(row: list[str]) -> bool:
    try:
        [float(x.replace(",", ".")) for x in row]
    except ValueError:
        return False
    return True


#: Bytes of a channel file read for its header alone (a listing, the channel not chosen).
HEADER_BYTES = 1 << 16


def _test(path: str | Path, data: bytes) -> list[tuple[Path, bytes | None]]:
    """The channel files of the test or channel file at ``path``: (path, its bytes when
    already read, else None)."""
    path = Path(path)
    if channel_file(path) or _is_channel(data):
        return [(path, data)]
    return [(p, None) for p in _channel_files(path)]


def _headers(path: str | Path, data: bytes) -> list[tuple[Path, _Channel]]:
    """Each channel file's header, from its first :data:`HEADER_BYTES` (a test of many
    channels is listed without reading their samples)."""
    out = []
    for p, whole in _test(path, data):
        head = whole if whole is not None else read_bytes(p, EXPECTED, "MME channel",
                                                           head=HEADER_BYTES, follow=False)
        out.append((p, _Channel(p, head, whole is not None or len(head) < HEADER_BYTES)))
    return out


def channels(path: str | Path, data: bytes) -> list[ChannelInfo]:
    """The test's channels, from their headers (the samples of a channel whose count is not
    declared are counted only when its header and samples fit in :data:`HEADER_BYTES`: 0
    otherwise)."""
    return [c.info for _p, c in _headers(path, data)]


def read(path: str | Path, data: bytes, channel: str | None) -> Table:
    """The chosen channel (by name, channel code or number; the first by default)."""
    headers = _headers(path, data)
    names = [c.name for _p, c in headers]
    codes = {c.code: k for k, (_p, c) in enumerate(headers) if c.code}
    if channel is not None and channel not in names and channel in codes:
        where, _ = headers[codes[channel]]
    else:
        where, _ = headers[choose(channel, names)]
    whole = data if Path(path) == where else read_bytes(where, EXPECTED, "MME channel",
                                                        follow=False)  # linked meanwhile
    chosen = _Channel(where, whole)
    time_unit, time = "s", None
    if chosen.explicit and chosen.reference:  # the time is another channel's values
        reference = _reference(where, chosen, headers)
        time_unit, time = reference.unit or "s", reference.numbers()[:, -1]
    values = chosen.samples(time)
    header = [f"time [{time_unit}]",
              f"acceleration [{chosen.unit}]" if chosen.unit else "acceleration"]
    return Table(f"{chosen.shown} ({chosen.name})", header, values)


def _reference(where: Path, chosen: _Channel, headers: list[tuple[Path, _Channel]]
               ) -> _Channel:
    """The channel that ``chosen``'s ``Reference channel name`` names (by name or code):
    among the test's channels, or, for a channel file read alone, its numbered siblings."""
    pool = headers if len(headers) > 1 else [
        (p, _Channel(p, read_bytes(p, EXPECTED, "MME channel", head=HEADER_BYTES,
                                   follow=False), False))
        for p in _numbered(where.parent, where.stem)]
    for p, c in pool:
        if p != where and chosen.reference in (c.name, c.code):
            return _Channel(p, read_bytes(p, EXPECTED, "MME channel", follow=False))
    raise WorkbookError(f"{chosen.shown}: its time is explicit, in the reference channel "
                        f"{chosen.reference!r}, which the test does not hold, {EXPECTED}")
