"""LabVIEW TDMS (npTDMS, the ``tdms`` extra): a waveform channel (``wf_increment``), named
``GROUP/CHANNEL``, its unit from ``unit_string`` and its start from ``wf_start_offset``.

The file is opened in npTDMS's streaming mode: its metadata is read, and only the samples of
the chosen channel that are wanted. A file past :data:`airgun_xl.limits.MAX_INPUT_BYTES` is
opened through :func:`~airgun_xl.readers.guard.open_large`, and a channel longer than
:data:`airgun_xl.limits.MAX_SAMPLES` is scanned a chunk at a time and read around its pulse
(:func:`~.channels.pulse_window`)."""
from __future__ import annotations

import io
import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from ..guard import LargeFile, open_large
from .channels import ChannelInfo, Table, choose, pulse_window

NAME = "LabVIEW TDMS"
SUFFIXES = (".tdms",)
EXPECTED = "expected a LabVIEW TDMS file with a waveform channel of acceleration"

#: A file past :data:`airgun_xl.limits.MAX_INPUT_BYTES` is opened by the reader, not read whole.
WINDOWED = True


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix."""
    return Path(path).suffix.lower() in SUFFIXES


def sniff(head: bytes) -> bool:
    """A TDMS segment starts with its lead-in tag."""
    return head[:4] == b"TDSm"


@contextmanager
def _waves(path: str | Path, data: bytes | LargeFile
           ) -> Iterator[tuple[str, list[Any], list[str]]]:
    """The file opened (streaming: its metadata read, no samples), its waveform channels and
    their names, while the ``with`` lasts."""
    try:
        from nptdms import TdmsFile
    except ImportError:
        raise OptionError(f"{display(Path(path))}: reading TDMS needs npTDMS, expected it "
                          "installed: pip install 'airgun-xl[tdms]'") from None
    import logging

    from nptdms.log import log_manager

    # npTDMS gives each of its modules a logger of its own level and a console handler: its
    # lines would come before our one (23.23, 32.17); all of them, and any made later, quiet
    log_manager.set_level(logging.CRITICAL + 1)
    logging.getLogger("nptdms").setLevel(logging.CRITICAL + 1)
    shown = display(Path(path))
    with (open_large(data) if isinstance(data, LargeFile) else io.BytesIO(data)) as source:
        try:
            tdms = TdmsFile.open(source)
            channels = [c for g in tdms.groups() for c in g.channels()]
        except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes
            raise WorkbookError(f"{shown}: is not a readable TDMS file "
                                f"({type(exc).__name__}), {EXPECTED}") from None
        waves = [c for c in channels if "wf_increment" in c.properties]
        yield shown, waves, [f"{c.group_name}/{c.name}" for c in waves]


def _samples(shown: str, chosen: Any, offset: int, count: int) -> np.ndarray:
    """``count`` samples of a waveform from ``offset``, as floats: a string, a timestamp or a
    complex channel, or data segments that do not parse, are the file's fault: one line."""
    try:
        raw = np.asarray(chosen.read_data(offset, count))
        if not np.issubdtype(raw.dtype, np.number) or np.iscomplexobj(raw):
            raise TypeError(f"{raw.dtype} samples")
        return raw.astype(float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise WorkbookError(f"{shown}: channel {chosen.name!r} is not a waveform of numbers "
                            f"({exc}), {EXPECTED}") from None
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes
        raise WorkbookError(f"{shown}: is not a readable TDMS file ({type(exc).__name__}), "
                            f"{EXPECTED}") from None


def _step(shown: str, chosen: Any) -> tuple[float, float]:
    """The waveform's step and start [s]: properties stored as numbers (a text that reads as
    one is the file's fault, not a step)."""
    try:
        for name in ("wf_increment", "wf_start_offset"):
            value = chosen.properties.get(name, 0.0)
            if isinstance(value, (str, bytes, bool)) or not isinstance(value, (int, float,
                                                                              np.number)):
                raise TypeError(f"{name} stored as {type(value).__name__}, not a number")
        dt = float(chosen.properties["wf_increment"])
        start = float(chosen.properties.get("wf_start_offset", 0.0))
    except (TypeError, ValueError, OverflowError) as exc:
        raise WorkbookError(f"{shown}: channel {chosen.name!r} is not a waveform of numbers "
                            f"({exc}), {EXPECTED}") from None
    if not (math.isfinite(dt) and dt > 0):
        raise WorkbookError(f"{shown}: channel {chosen.name!r} has wf_increment {dt!r}, "
                            "expected a positive sample step [s]")
    return dt, start


def channels(path: str | Path, data: bytes | LargeFile) -> list[Any]:
    """The file's waveform channels."""
    with _waves(path, data) as (shown, waves, names):
        out = []
        for c, name in zip(waves, names, strict=True):
            dt, start = _step(shown, c)
            out.append(ChannelInfo(name, str(c.properties.get("unit_string", "")), 1.0 / dt,
                                   len(c), start))
    return out


def read(path: str | Path, data: bytes | LargeFile, channel: str | None) -> Table:
    """The chosen waveform channel (the first by default; the stretch around its pulse of one
    past :data:`~airgun_xl.limits.MAX_SAMPLES`)."""
    with _waves(path, data) as (shown, waves, names):
        if not waves:
            raise WorkbookError(f"{shown}: has no waveform channel (wf_increment), {EXPECTED}")
        chosen = waves[choose(channel, names, "waveform channel")]
        dt, start = _step(shown, chosen)
        first, count = 0, len(chosen)
        notes: tuple[str, ...] = ()
        if count > limits.MAX_SAMPLES:  # scanned a chunk at a time, its pulse's stretch read
            try:
                window = pulse_window(
                    chosen.name, count, lambda k, n: _samples(shown, chosen, k, n),
                    lambda k, n: start + dt * (k + np.arange(n)), limits.MAX_SAMPLES)
            except ValueError as exc:
                raise WorkbookError(f"{shown}: {exc}") from None
            first, count, notes = window.first, window.count, (f"{shown}: {window.note}",)
        accel = _samples(shown, chosen, first, count)
    bad = ~np.isfinite(accel)
    if bad.any():
        k = int(np.argmax(bad))
        raise WorkbookError(f"{shown}: channel {chosen.name!r} sample {first + k + 1:,} is "
                            f"{accel[k]}, expected finite numbers (no NaN or inf)")
    unit = str(chosen.properties.get("unit_string", ""))
    # the header is built for the unit alone: a channel named 'accel (z)' or 'accel [z]' must
    # not lend its brackets to the unit parser
    header = ["time [s]", f"acceleration [{unit}]" if unit else "acceleration"]
    time = start + dt * (first + np.arange(len(accel)))
    # named with its channel, as every other format's (the verdict's lines name it)
    return Table(f"{shown} ({chosen.group_name}/{chosen.name})", header,
                 np.column_stack([time, accel]), notes)
