"""MATLAB .mat files: v5, v6 and v7 by :mod:`.mat5` (scipy.io's reader crashes on damaged
files); v7.3 (HDF5) by h5py, the ``mat`` extra. A v4 file (no header) is refused by name.

A .mat file has no standard layout for a recording, so the file's variables are read as a
recorder's export writes them (docs/recordings.md):

- a **channel** is a real numeric vector (n x 1, 1 x n) of at least 2 samples, named as the
  variable is; its unit is the text variable ``<name>_unit`` when there is one;
- its **time** is the vector ``time`` or ``t`` of the same length (unit ``time_unit``), or
  the scalars ``fs`` (samples a second [Hz]) or ``dt`` (the step, in ``time_unit``), with
  ``t0`` the first sample's time when given;
- a variable's declared size is read (``whosmat``, an HDF5 dataset's shape) and checked
  before any of its samples is; only the chosen channel and its time are loaded.

A v7.3 file is HDF5, whose library reads data from other files when the file asks it to: a
dataset's external storage (its raw samples in a named file), a virtual dataset (mapped from
other files' datasets) and an external link (a variable that is another file's object). So
before any variable is listed or read, every top-level link is looked at without being
followed and every dataset's storage is vetted (:func:`_vet`): only hard links, and only
datasets whose samples are in the file itself, through HDF5's built-in filters (a filter it
would look for as a plugin library is refused too). MATLAB writes nothing else.
"""
from __future__ import annotations

import io
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, Table, check_finite, choose
from .mat5 import Mat5, MatError

NAME = "MATLAB .mat"
SUFFIXES = (".mat",)
EXPECTED = ("expected a MATLAB .mat file of a recording (a numeric vector of acceleration, "
            "and a time vector or fs or dt)")

#: Variables that hold the time base, not a channel (lower case).
TIME_NAMES = ("time", "t")
#: Scalars of the time base (lower case): the rate [Hz], the step and the start.
RATE, STEP, START, TIME_UNIT = "fs", "dt", "t0", "time_unit"

#: MATLAB's numeric classes (a logical, char, cell, struct or object is not a channel).
NUMERIC = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
           "uint64"}

#: The HDF5 signature, at byte 512 of a v7.3 file (after MATLAB's 512-byte user block).
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix."""
    return Path(path).suffix.lower() in SUFFIXES


def sniff(head: bytes) -> bool:
    """A v5/v7/v7.3 file starts with MATLAB's 116-byte text header (a v4 file has none: it
    is told by its suffix)."""
    return head[:6] == b"MATLAB" and head[10:19] == b" MAT-file"


class _Variables:
    """The file's variables: name -> (length, MATLAB class), and a loader of named ones."""

    def __init__(self, path: str | Path, data: bytes) -> None:
        self.shown = display(Path(path))
        self.v73 = len(data) > 520 and data[512:520] == HDF5_SIGNATURE
        self.data = data
        self.sizes: dict[str, tuple[tuple[int, ...], str]] = {}
        try:
            with warnings.catch_warnings():  # scipy's MatReadWarning: our checks follow
                warnings.simplefilter("ignore")
                self._list()
        except (OptionError, WorkbookError):
            raise
        except MatError as exc:
            raise WorkbookError(f"{self.shown}: is not a readable MATLAB file ({exc}), "
                                f"{EXPECTED}") from None
        except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes
            raise WorkbookError(f"{self.shown}: is not a readable MATLAB file "
                                f"({type(exc).__name__}), {EXPECTED}") from None

    def _list(self) -> None:
        if not self.v73:  # not scipy.io: a damaged file crashes its reader (mat5's notes)
            self._v5 = Mat5(self.data, limits.MAX_SAMPLES)
            for name, v in self._v5.variables.items():
                self.sizes[name] = (v.shape, v.kind)
            return
        self._h5 = self._open_h5()
        for name in list(self._h5.keys()):  # keys only: items() would follow the links
            item = _vet(self.shown, self._h5, name)
            if item is not None:  # a dataset, not a group
                kind = item.attrs.get("MATLAB_class", b"")
                kind = kind.decode("ascii", "replace") if isinstance(kind, bytes) else str(kind)
                self.sizes[name] = (tuple(int(n) for n in item.shape), kind)

    def _open_h5(self) -> Any:
        try:
            import h5py
        except ImportError:
            raise OptionError(f"{self.shown}: is a MATLAB v7.3 file (HDF5), which needs h5py, "
                              "expected it installed: pip install 'airgun-xl[mat]'") from None
        return h5py.File(io.BytesIO(self.data), "r")

    def load(self, names: list[str]) -> dict[str, np.ndarray]:
        """The named variables' values, as arrays (a text as a 0-d array of str)."""
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return self._load(names)
        except MatError as exc:
            raise WorkbookError(f"{self.shown}: {exc}, {EXPECTED}") from None
        except Exception as exc:  # noqa: BLE001 - a variable whose bytes lie: one line
            raise WorkbookError(f"{self.shown}: variable {names[0]!r} cannot be read "
                                f"({type(exc).__name__}), {EXPECTED}") from None

    def _load(self, names: list[str]) -> dict[str, np.ndarray]:
        if not self.v73:
            return {name: self._v5.values(name) for name in names}
        out = {}
        for name in names:
            raw = np.asarray(self._h5[name][()])
            if self.sizes[name][1] == "char":  # MATLAB's text: UTF-16 code units
                raw = np.asarray("".join(chr(int(c)) for c in raw.ravel()))
            out[name] = raw
        return out

    def length(self, name: str) -> int | None:
        """A real vector's length (None for anything else)."""
        shape, kind = self.sizes[name]
        if kind not in NUMERIC or len(shape) > 2 or math.prod(shape) < 2:
            return None
        if len(shape) == 2 and min(shape) != 1:
            return None
        return math.prod(shape)

    def find(self, lowered: str) -> str | None:
        return next((n for n in self.sizes if n.lower() == lowered), None)

    def text(self, name: str | None) -> str:
        """A text variable's value ('' when there is none or it is not text)."""
        if name is None or self.sizes[name][1] != "char" or math.prod(self.sizes[name][0]) > 64:
            return ""
        return str(self.load([name])[name]).strip()

    def scalar(self, name: str | None) -> float | None:
        if name is None or self.sizes[name][1] not in NUMERIC \
                or math.prod(self.sizes[name][0]) != 1:
            return None
        value = self.load([name])[name]
        if np.iscomplexobj(value) or not np.issubdtype(value.dtype, np.number):
            return None
        return float(value.ravel()[0])


#: The filters built into HDF5 (deflate, shuffle, Fletcher32, szip, n-bit, scale-offset): any
#: other is looked for as a plugin library on HDF5's plugin path before a sample is read.
BUILT_IN_FILTERS = frozenset(range(1, 7))

#: The layout of a virtual dataset (H5D_VIRTUAL), whose samples are other files' datasets.
_VIRTUAL_LAYOUT = 3


def _vet(shown: str, root: Any, name: str) -> Any:
    """The top-level dataset ``name`` of the HDF5 file ``root`` once it is shown to keep its
    samples inside the file (None for a group); no sample is read and no link followed.

    Raises
    ------
    WorkbookError
        For a soft or external link, a virtual dataset, a dataset with external storage, or a
        filter that is not built into HDF5.
    """
    import h5py

    expected = "expected a recording whose data is inside the file"
    link = root.get(name, getlink=True)
    if isinstance(link, h5py.ExternalLink):
        raise WorkbookError(f"{shown}: variable {name!r} is an external link to "
                            f"{link.filename!r}, {expected}")
    if not isinstance(link, h5py.HardLink):  # a soft link may lead through an external one
        raise WorkbookError(f"{shown}: variable {name!r} is a {type(link).__name__}, "
                            f"{expected} (MATLAB writes every variable as a hard link)")
    item = root[name]
    if not isinstance(item, h5py.Dataset):
        return None
    plist = item.id.get_create_plist()
    if plist.get_layout() == _VIRTUAL_LAYOUT:
        raise WorkbookError(f"{shown}: variable {name!r} is a virtual dataset (mapped from "
                            f"other files' data), {expected}")
    if plist.get_external_count() > 0:
        outside = plist.get_external(0)[0].decode("utf-8", "replace")
        raise WorkbookError(f"{shown}: variable {name!r} keeps its samples in the outside "
                            f"file {outside!r} (HDF5 external storage), {expected}")
    for index in range(plist.get_nfilters()):
        code = int(plist.get_filter(index)[0])
        if code not in BUILT_IN_FILTERS:
            raise WorkbookError(f"{shown}: variable {name!r} is stored through HDF5 filter "
                                f"{code}, which HDF5 would load as a plugin library, "
                                "expected one of HDF5's built-in filters (deflate, shuffle, "
                                "Fletcher32, szip, n-bit, scale-offset)")
    return item


def _channels(variables: _Variables) -> list[str]:
    skip = {variables.find(n) for n in TIME_NAMES}
    return [n for n in variables.sizes if n not in skip and variables.length(n) is not None]


def _time_base(variables: _Variables, name: str, n: int) -> tuple[str | None, float | None,
                                                                  float | None, str]:
    """(time vector's name, step, start, time unit) of channel ``name`` of length ``n``."""
    unit = variables.text(variables.find(TIME_UNIT))
    for lowered in TIME_NAMES:
        found = variables.find(lowered)
        if found is not None and variables.length(found) == n:
            return found, None, None, unit
    start = variables.scalar(variables.find(START))
    rate = variables.scalar(variables.find(RATE))
    if rate is not None:
        if not (math.isfinite(rate) and rate > 0):
            raise WorkbookError(f"{variables.shown}: fs is {rate!r}, expected a positive rate "
                                "[Hz]")
        return None, 1.0 / rate, start, "s"
    step = variables.scalar(variables.find(STEP))
    if step is not None:
        if not (math.isfinite(step) and step > 0):
            raise WorkbookError(f"{variables.shown}: dt is {step!r}, expected a positive step")
        return None, step, start, unit
    raise WorkbookError(f"{variables.shown}: channel {name!r} has no time base (a vector "
                        f"'time' or 't' of its {n:,} samples, or a scalar fs or dt), "
                        f"{EXPECTED}")


def channels(path: str | Path, data: bytes) -> list[Any]:
    """The file's channels, from the variables' declared sizes (no samples read)."""
    variables = _Variables(path, data)
    out = []
    for name in _channels(variables):
        n = variables.length(name)
        assert n is not None
        unit = variables.text(variables.find(f"{name.lower()}_unit"))
        try:
            vector, step, start, t_unit = _time_base(variables, name, n)
        except WorkbookError:
            out.append(ChannelInfo(name, unit, None, n, None))
            continue
        scale = _seconds(t_unit)
        rate = None if step is None or scale is None else 1.0 / (step * scale)
        first = None if scale is None else (start or 0.0) * scale
        if vector is not None:
            if n > limits.MAX_SAMPLES:
                out.append(ChannelInfo(name, unit, None, n, None))
                continue
            t = _floats(variables, f"time {vector!r}", variables.load([vector])[vector])
            if scale is not None and len(t) == n and np.all(np.diff(t) > 0):
                rate = (n - 1) / ((t[-1] - t[0]) * scale)  # the measured rate
                first = float(t[0]) * scale
        out.append(ChannelInfo(name, unit, rate, n, first))
    return out


def _floats(variables: _Variables, what: str, values: np.ndarray) -> np.ndarray:
    """A vector's values as floats; one line for any that are not real numbers (a class the
    file claims is not proof of what its bytes hold)."""
    if np.iscomplexobj(values) or not np.issubdtype(values.dtype, np.number):
        raise WorkbookError(f"{variables.shown}: {what} holds {values.dtype} values, expected "
                            f"real numbers, {EXPECTED}")
    return values.astype(float).ravel()


def _seconds(unit: str) -> float | None:
    from ...units import TIME_UNITS

    return float(TIME_UNITS[unit]) if unit in TIME_UNITS else None


def read(path: str | Path, data: bytes, channel: str | None) -> Table:
    """The chosen channel (the first by default) and its time."""
    variables = _Variables(path, data)
    names = _channels(variables)
    if not names:
        raise WorkbookError(f"{variables.shown}: holds no numeric vector, {EXPECTED}")
    name = names[choose(channel, names)]
    n = variables.length(name)
    assert n is not None
    if n > limits.MAX_SAMPLES:  # declared, before a sample is read
        raise WorkbookError(f"{variables.shown}: channel {name!r} holds {n:,} samples, "
                            f"expected at most {limits.MAX_SAMPLES:,} samples")
    vector, step, start, t_unit = _time_base(variables, name, n)
    loaded = variables.load([name] + ([vector] if vector else []))
    accel = _floats(variables, f"channel {name!r}", loaded[name])
    if len(accel) != n:  # the bytes disagree with the declared size
        raise WorkbookError(f"{variables.shown}: channel {name!r} declares {n:,} samples and "
                            f"holds {len(accel):,}, {EXPECTED}")
    if vector is not None:
        time = _floats(variables, f"time {vector!r}", loaded[vector])
        if len(time) != n:
            raise WorkbookError(f"{variables.shown}: time vector {vector!r} declares {n:,} "
                                f"samples and holds {len(time):,}, {EXPECTED}")
    else:
        assert step is not None
        time = (start or 0.0) + step * np.arange(n)
    check_finite(variables.shown, ((f"channel {name!r}", accel), (f"time {vector!r}", time)))
    unit = variables.text(variables.find(f"{name.lower()}_unit"))
    header = [f"time [{t_unit}]" if t_unit else "time",
              f"acceleration [{unit}]" if unit else "acceleration"]
    return Table(f"{variables.shown} ({name})", header, np.column_stack([time, accel]))
