"""Universal File Format dataset 58, ASCII and binary (58b), by pyuff (the ``uff`` extra):
each time response (function type 1) is a channel, named by its first ID line (or its node and
direction when that line is empty), its values' unit the ordinate's axis units label, its time
from the abscissa (even: its minimum and increment; uneven: its values) in the abscissa's
units label.

pyuff reads a file by its name: it is given a private copy of the bytes already read and
capped (:func:`airgun_xl.readers.guard.read_bytes`), so the file it parses is the one checked.
A dataset's declared point count must match the values it holds.
"""
from __future__ import annotations

import math
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ... import limits
from ...errors import OptionError, WorkbookError
from ...transaction import display
from .channels import ChannelInfo, Table, check_finite, choose

NAME = "UFF dataset 58"
SUFFIXES = (".uff", ".unv")
EXPECTED = ("expected a Universal File (UFF) with a dataset 58 time response of acceleration "
            "(ASCII or binary 58b)")

#: Function type 1: a time response.
TIME_RESPONSE = 1


#: A file of several channels: ``--channel`` chooses one.
SEVERAL = True


def named(path: str | Path) -> bool:
    """Whether the file's name is this format's: its suffix."""
    return Path(path).suffix.lower() in SUFFIXES


def sniff(head: bytes) -> bool:
    """A universal file starts with a ``-1`` delimiter line, then the dataset's number."""
    lines = head.lstrip(b"\r\n").splitlines()
    return (len(lines) >= 2 and lines[0].strip() == b"-1"
            and lines[1][:6].strip().isdigit())


def _datasets(path: str | Path, data: bytes) -> tuple[str, list[dict[str, Any]]]:
    """The file's dataset-58 time responses, as pyuff reads them."""
    shown = display(Path(path))
    try:
        import pyuff
    except ImportError:
        raise OptionError(f"{shown}: reading a universal file needs pyuff, expected it "
                          "installed: pip install 'airgun-xl[uff]'") from None
    try:
        with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pyuff's own warnings: our checks follow
            copy = Path(folder) / "recording.uff"
            copy.write_bytes(data)
            uff = pyuff.UFF(str(copy))
            types = [int(t) for t in uff.get_set_types()]
            picked = [k for k, t in enumerate(types) if t == 58]
            sets = uff.read_sets(picked) if picked else []
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes
        raise WorkbookError(f"{shown}: is not a readable universal file "
                            f"({type(exc).__name__}), {EXPECTED}") from None
    if isinstance(sets, dict):
        sets = [sets]
    return shown, [s for s in sets if int(s.get("func_type", -1)) == TIME_RESPONSE]


def _name(dataset: dict[str, Any]) -> str:
    name = str(dataset.get("id1", "")).strip()
    return name or f"node {dataset.get('rsp_node', '?')} dir {dataset.get('rsp_dir', '?')}"


def _units(dataset: dict[str, Any]) -> tuple[str, str]:
    return (str(dataset.get("abscissa_axis_units_lab", "")).strip(),
            str(dataset.get("ordinate_axis_units_lab", "")).strip())


def _seconds(unit: str) -> float | None:
    from ...units import TIME_UNITS

    return float(TIME_UNITS[unit]) if unit in TIME_UNITS else None


def channels(path: str | Path, data: bytes) -> list[ChannelInfo]:
    """The file's time responses (a file of none: the listing refuses it)."""
    shown, sets = _datasets(path, data)
    out = []
    for dataset in sets:
        t_unit, unit = _units(dataset)
        scale = _seconds(t_unit)
        x = np.asarray(dataset.get("x", []), dtype=float)
        rate = start = None
        if scale is not None and len(x) > 1 and x[-1] > x[0]:
            rate = (len(x) - 1) / ((x[-1] - x[0]) * scale)
            start = float(x[0]) * scale
        out.append(ChannelInfo(_name(dataset), unit, rate, len(x), start))
    return out


def read(path: str | Path, data: bytes, channel: str | None) -> Table:
    """The chosen time response (the first by default)."""
    shown, sets = _datasets(path, data)
    if not sets:
        raise WorkbookError(f"{shown}: has no dataset 58 time response (function type 1), "
                            f"{EXPECTED}")
    names = [_name(s) for s in sets]
    dataset = sets[choose(channel, names, "time response")]
    name = _name(dataset)
    try:
        values = np.asarray(dataset["data"])
        x = np.asarray(dataset["x"], dtype=float)
        declared = int(dataset["num_pts"])
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise WorkbookError(f"{shown}: time response {name!r} is not readable ({exc}), "
                            f"{EXPECTED}") from None
    if np.iscomplexobj(values) or not np.issubdtype(values.dtype, np.number):
        raise WorkbookError(f"{shown}: time response {name!r} holds {values.dtype} values, "
                            f"expected real numbers, {EXPECTED}")
    if declared != len(values) or len(x) != len(values):
        raise WorkbookError(f"{shown}: time response {name!r} declares {declared:,} points "
                            f"and holds {len(values):,}, {EXPECTED}")
    if declared > limits.MAX_SAMPLES:
        raise WorkbookError(f"{shown}: time response {name!r} holds {declared:,} samples, "
                            f"expected at most {limits.MAX_SAMPLES:,} samples")
    accel = values.astype(float)
    check_finite(shown, ((f"time response {name!r}", accel), ("its time", x)), "point")
    t_unit, unit = _units(dataset)
    if not t_unit and int(dataset.get("abscissa_spec_data_type", 0)) == 17:
        t_unit = "s"  # the abscissa is time (type 17), in the SI unit the format defaults to
    header = [f"time [{t_unit}]" if t_unit else "time",
              f"acceleration [{unit}]" if unit else "acceleration"]
    if not math.isfinite(float(x[0])):
        raise WorkbookError(f"{shown}: time response {name!r} starts at {x[0]}, {EXPECTED}")
    return Table(f"{shown} ({name})", header, np.column_stack([x, accel]))
