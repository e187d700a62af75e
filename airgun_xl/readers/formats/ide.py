"""enDAQ IDE (the drop and transport shock recorders' own format, EBML of DocType ``mide``), by
idelib (the ``ide`` extra, MIT): each subchannel of each channel is a channel, named
``CHANNEL/SUBCHANNEL`` as the file names them (``Acceleration/X``), its unit the one the file
states, its values the physical ones (the file's calibration polynomials applied, as idelib
gives them), its time the file's block time codes [s from the recording's start], evened out
of idelib's microsecond truncation (:func:`_even`).

A file must describe itself (its recording properties): a file without them is refused, not
read with idelib's built-in guess of an old recorder's channels. idelib and ebmlite are pure
Python: the file is parsed in this process, its warnings and logging silenced, any failure
one line. The samples of a channel are counted from its blocks before they are read.
"""
from __future__ import annotations

import io
import logging
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, Table, check_finite, choose

NAME = "enDAQ IDE"
SUFFIXES = (".ide",)
EXPECTED = "expected an enDAQ IDE recording with a channel of acceleration"

#: An EBML document's first bytes; an IDE file's DocType follows in its header.
EBML_MAGIC = b"\x1a\x45\xdf\xa3"

#: idelib holds each block's start and end times in whole microseconds (truncated) and spaces
#: the block's samples evenly between them, so a sample's time is off by up to this [s].
TIME_RESOLUTION = 2e-6

#: idelib's stand-in channels for a file without recording properties: none.
_NO_DEFAULTS: dict[str, Any] = {"sensors": {}, "channels": {}, "warnings": []}


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix."""
    return Path(path).suffix.lower() in SUFFIXES


def sniff(head: bytes) -> bool:
    """An EBML header whose DocType is ``mide``."""
    return head.startswith(EBML_MAGIC) and b"\x42\x82\x84mide" in head[:64]


def _quiet() -> None:
    """idelib and ebmlite warn and log as they parse: none of it reaches the terminal."""
    for name in ("idelib", "ebmlite"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _subchannels(path: str | Path, data: bytes) -> tuple[str, list[tuple[str, Any]]]:
    """The file opened, and its (name, subchannel) pairs in the file's order."""
    try:
        from idelib import importer
    except ImportError:
        raise OptionError(f"{display(Path(path))}: reading IDE needs idelib, expected it "
                          "installed: pip install 'airgun-xl[ide]'") from None
    _quiet()
    shown = display(Path(path))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            doc = importer.openFile(io.BytesIO(data), defaults=_NO_DEFAULTS, quiet=True)
            described = bool(doc.channels)
            if described:
                importer.readData(doc)
            subs = [(f"{ch.name}/{sub.name}", sub)
                    for ch in doc.channels.values() for sub in ch.subchannels]
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes: one line
        raise WorkbookError(f"{shown}: is not a readable IDE file ({type(exc).__name__}), "
                            f"{EXPECTED}") from None
    if not described:
        raise WorkbookError(f"{shown}: has no recording properties (no channel described; a "
                            f"recorder's old firmware?), {EXPECTED}")
    return shown, subs


def _samples(shown: str, name: str, sub: Any) -> tuple[np.ndarray, np.ndarray]:
    """A subchannel's times [s] and physical values, its length checked first."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            session = sub.getSession()
            n = len(session)
            if n > limits.MAX_SAMPLES:  # counted from the blocks, before they are read
                raise WorkbookError(f"{shown}: channel {name!r} holds {n:,} samples, expected "
                                    f"at most {limits.MAX_SAMPLES:,} samples")
            block = np.asarray(session.arraySlice(), dtype=float)
    except WorkbookError:
        raise
    except Exception as exc:  # noqa: BLE001 - any failure on untrusted bytes: one line
        raise WorkbookError(f"{shown}: channel {name!r} cannot be read "
                            f"({type(exc).__name__}), {EXPECTED}") from None
    if block.ndim != 2 or block.shape[0] != 2:
        raise WorkbookError(f"{shown}: channel {name!r} came back as an array of shape "
                            f"{block.shape}, expected times and one value each, {EXPECTED}")
    return block[0] * 1e-6, block[1]  # idelib's times are microseconds


def _even(name: str, time: np.ndarray, declared: float | None) -> tuple[np.ndarray, str]:
    """The samples' times without idelib's microsecond truncation: from the first, at the
    rate the file declares when every time lies within :data:`TIME_RESOLUTION` of it, else
    at the rate measured over the record (its ends) when they lie within it of that (a note
    says the rates differ), else idelib's times as they are: the block time codes of a real
    recorder, which jitter, and whose clock the recording's reader fits
    (:mod:`airgun_xl.readers.time_base`)."""
    n = len(time)
    if n < 2 or not time[-1] > time[0]:
        return time, ""
    measured = (n - 1) / (time[-1] - time[0])
    for rate in ((declared,) if declared else ()) + (measured,):
        if rate is None or not (np.isfinite(rate) and rate > 0):
            continue
        even = time[0] + np.arange(n) / rate
        if float(np.max(np.abs(time - even))) <= TIME_RESOLUTION:
            note = ("" if rate == declared or not declared else
                    f"channel {name!r}: its samples come at {measured:.6g} Hz, not the "
                    f"{declared:.6g} Hz the file declares: the measured rate is used")
            return even, note
    return time, ""


def _unit(sub: Any) -> str:
    units = getattr(sub, "units", None)
    return str(units[1]) if isinstance(units, tuple) and len(units) > 1 and units[1] else ""


def channels(path: str | Path, data: bytes) -> list[ChannelInfo]:
    """The file's subchannels, each with its measured rate (its times' span)."""
    shown, subs = _subchannels(path, data)
    out = []
    for name, sub in subs:
        time, _values = _samples(shown, name, sub)
        time, _note = _even(name, time, _declared(sub))
        rate = ((len(time) - 1) / (time[-1] - time[0])
                if len(time) > 1 and time[-1] > time[0] else None)
        out.append(ChannelInfo(name, _unit(sub), rate, len(time),
                               float(time[0]) if len(time) else None))
    return out


def read(path: str | Path, data: bytes, channel: str | None) -> Table:
    """The chosen subchannel (the first by default): its physical values on its times."""
    shown, subs = _subchannels(path, data)
    if not subs:
        raise WorkbookError(f"{shown}: has no subchannel, {EXPECTED}")
    name, sub = subs[choose(channel, [n for n, _ in subs])]
    time, values = _samples(shown, name, sub)
    check_finite(shown, ((f"channel {name!r}", values), ("its time", time)))
    time, note = _even(name, time, _declared(sub))
    unit = _unit(sub)
    header = ["time [s]", f"acceleration [{unit}]" if unit else "acceleration"]
    return Table(f"{shown} ({name})", header, np.column_stack([time, values]),
                 (f"{shown}: {note}",) if note else ())


def _declared(sub: Any) -> float | None:
    """The sample rate the file declares for the subchannel's channel [Hz], if any."""
    try:
        rate = float(sub.parent.sampleRate)
    except (AttributeError, TypeError, ValueError):
        return None
    return rate if np.isfinite(rate) and rate > 0 else None
