"""LabVIEW TDMS (npTDMS, the ``tdms`` extra): a waveform channel (``wf_increment``), named
``GROUP/CHANNEL``, its unit from ``unit_string`` and its start from ``wf_start_offset``."""
from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, Table, choose

NAME = "LabVIEW TDMS"
SUFFIXES = (".tdms",)
EXPECTED = "expected a LabVIEW TDMS file with a waveform channel of acceleration"


def sniff(head: bytes) -> bool:
    """A TDMS segment starts with its lead-in tag."""
    return head[:4] == b"TDSm"


def _waves(path: str | Path, data: bytes) -> tuple[str, list[Any], list[str]]:
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
    try:
        tdms = TdmsFile.read(io.BytesIO(data))
        channels = [c for g in tdms.groups() for c in g.channels()]
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes: one line
        raise WorkbookError(f"{shown}: is not a readable TDMS file ({type(exc).__name__}), "
                            f"{EXPECTED}") from None
    waves = [c for c in channels if "wf_increment" in c.properties]
    return shown, waves, [f"{c.group_name}/{c.name}" for c in waves]


def _step(shown: str, chosen: Any) -> tuple[float, float]:
    try:
        dt = float(chosen.properties["wf_increment"])
        start = float(chosen.properties.get("wf_start_offset", 0.0))
    except (TypeError, ValueError, OverflowError) as exc:
        raise WorkbookError(f"{shown}: channel {chosen.name!r} is not a waveform of numbers "
                            f"({exc}), {EXPECTED}") from None
    if not (math.isfinite(dt) and dt > 0):
        raise WorkbookError(f"{shown}: channel {chosen.name!r} has wf_increment {dt!r}, "
                            "expected a positive sample step [s]")
    return dt, start


def channels(path: str | Path, data: bytes) -> list[Any]:
    """The file's waveform channels."""
    shown, waves, names = _waves(path, data)
    out = []
    for c, name in zip(waves, names, strict=True):
        dt, start = _step(shown, c)
        out.append(ChannelInfo(name, str(c.properties.get("unit_string", "")), 1.0 / dt,
                               len(c), start))
    return out


def read(path: str | Path, data: bytes, channel: str | None) -> Table:
    """The chosen waveform channel (the first by default)."""
    shown, waves, names = _waves(path, data)
    if not waves:
        raise WorkbookError(f"{shown}: has no waveform channel (wf_increment), {EXPECTED}")
    chosen = waves[choose(channel, names, "waveform channel")]
    if len(chosen) > limits.MAX_SAMPLES:  # before the samples are read
        raise WorkbookError(f"{shown}: channel {chosen.name!r} holds {len(chosen):,} samples, "
                            f"expected at most {limits.MAX_SAMPLES:,} samples")
    try:  # a string, a timestamp or a complex channel is the file's fault: one line
        raw = np.asarray(chosen[:])
        if not np.issubdtype(raw.dtype, np.number) or np.iscomplexobj(raw):
            raise TypeError(f"{raw.dtype} samples")
        accel = raw.astype(float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise WorkbookError(f"{shown}: channel {chosen.name!r} is not a waveform of numbers "
                            f"({exc}), {EXPECTED}") from None
    dt, start = _step(shown, chosen)
    bad = ~np.isfinite(accel)
    if bad.any():
        k = int(np.argmax(bad))
        raise WorkbookError(f"{shown}: channel {chosen.name!r} sample {k} is {accel[k]}, "
                            "expected finite numbers (no NaN or inf)")
    unit = str(chosen.properties.get("unit_string", ""))
    # the header is built for the unit alone: a channel named 'accel (z)' or 'accel [z]' must
    # not lend its brackets to the unit parser
    header = ["time [s]", f"acceleration [{unit}]" if unit else "acceleration"]
    return Table(shown, header, np.column_stack([start + dt * np.arange(len(accel)), accel]))
