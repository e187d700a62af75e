"""What every recording format says of a channel (:class:`ChannelInfo`), how
``--channel`` chooses one (:func:`choose`), which stretch of a long channel is read
(:func:`pulse_window`), and the units a file's header may state (:func:`stated`, the
``FILE_*_UNITS`` tables): the same in every format."""
from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ... import units
from ...errors import OptionError, WorkbookError

#: Time units [s per unit]: the one table's (:data:`airgun_xl.units.TIME_UNITS`).
TIME_UNITS = {unit: float(scale) for unit, scale in units.TIME_UNITS.items()}

#: Acceleration units [kG per unit], the one table's (:data:`airgun_xl.units.PEAK_UNITS`): a
#: recorder's g is standard gravity (units.G, 9.80665 m/s^2); the kG is the macro's, 9800
#: m/s^2 (its Acceleration (kG's) column), so 1 g is 1.000679e-3 kG. The macro's 9800
#: applies to the macro's columns only.
ACCEL_UNITS = dict(units.PEAK_UNITS)

#: Spellings a recorder's file may state that the options do not take [kG per unit]: ``G``
#: (a recorder's g, as shock labs write it; as an option it would sit a case away from kG),
#: ``mm/ms^2`` (1,000 m/s^2), and ``**`` or ``sec`` for ``^`` and ``s``.
FILE_ACCEL_UNITS = {**ACCEL_UNITS, "G": ACCEL_UNITS["g"],
                    "mm/ms^2": 1e3 * ACCEL_UNITS["m/s^2"], "mm/ms**2": 1e3 * ACCEL_UNITS["m/s^2"],
                    "m/s**2": ACCEL_UNITS["m/s^2"], "m/sec^2": ACCEL_UNITS["m/s^2"],
                    "m/sec**2": ACCEL_UNITS["m/s^2"]}
#: The time units a file may state [s per unit]: the options' and ``sec``, ``msec``.
FILE_TIME_UNITS = {**TIME_UNITS, "sec": 1.0, "msec": 1e-3}


def stated(header: str) -> str:
    """The unit a header names in brackets or parentheses (``time [ms]`` -> ``ms``; '' for
    none)."""
    found = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]", header)
    return (found.group(1) if found else "").strip()


@dataclass(frozen=True)
class ChannelInfo:
    """A channel as the file declares it.

    Attributes
    ----------
    name : str
        As the file gives it; ``--channel`` takes it.
    unit : str
        The unit of its values as the file states it ('' when it states none).
    rate : float or None
        Samples a second [Hz]: the measured rate (from its time vector) when it has one.
    samples : int
        Its length.
    start : float or None
        Its first sample's time [s] (a trigger before the pulse reads negative).
    """

    name: str
    unit: str
    rate: float | None
    samples: int
    start: float | None


class Table(NamedTuple):
    """A channel as a format reads it: how messages name it, the header naming its units as
    the file states them (``time [s]``, ``acceleration [g]``), the (n, 2) array of its times
    and physical values, and what the reading did that the user should know (its notes)."""

    shown: str
    header: list[str]
    values: np.ndarray
    notes: tuple[str, ...] = ()


def choose(channel: str | None, names: list[str], kind: str = "channel") -> int:
    """The index of the channel ``--channel`` names in ``names``: its name, else its number
    (1 for the first); the first by default."""
    if not names:
        raise ValueError("no channels")
    if channel is None:
        return 0
    if channel in names:
        return names.index(channel)
    text = channel.strip()
    if text.isdigit() and 1 <= int(text) <= len(names):
        return int(text) - 1
    shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "")
    raise OptionError(f"--channel: found {channel!r}, expected one of the file's {kind}s: "
                      f"{shown} (or its number, 1 to {len(names)})")


def check_finite(shown: str, columns: Iterable[tuple[str, np.ndarray]],
                 item: str = "sample") -> None:
    """One line for the first NaN or infinity of any of ``columns`` ((what, values) pairs),
    counting its ``item`` from 1."""
    for what, column in columns:
        bad = ~np.isfinite(column)
        if bad.any():
            k = int(np.argmax(bad))
            raise WorkbookError(f"{shown}: {what} {item} {k + 1} is {column[k]}, expected "
                                "finite numbers (no NaN or inf)")


#: Seconds read on each side of a long channel's largest excursion (:func:`pulse_window`):
#: an air gun pulse lasts milliseconds, and its rest before and after is what the recording
#: checks need; a channel of at most :data:`airgun_xl.limits.MAX_SAMPLES` samples is read
#: whole.
WINDOW_SECONDS = 0.5

#: Samples a long channel is scanned by: 8 MB of float64 at a time.
SCAN_CHUNK = 1_000_000

#: Samples at the start of a long channel whose median is its rest level for the scan.
REST_SAMPLES = 10_000


@dataclass(frozen=True)
class Window:
    """The samples ``first`` to ``first + count`` (from 0) of a channel of ``samples``, read
    around its largest excursion from rest, at sample ``peak``; ``note`` says so."""

    first: int
    count: int
    samples: int
    peak: int
    note: str


def pulse_window(name: str, samples: int, values: Callable[[int, int], np.ndarray],
                 times: Callable[[int, int], np.ndarray], max_samples: int) -> Window:
    """Where to read a channel longer than ``max_samples``: :data:`WINDOW_SECONDS` on each
    side of its largest excursion from its rest level (the median of its first
    :data:`REST_SAMPLES`), at most ``max_samples`` in all. ``values(offset, count)`` and
    ``times(offset, count)`` read a stretch of the channel's physical values and times [s];
    the scan holds one :data:`SCAN_CHUNK` at a time.

    Raises
    ------
    ValueError
        Naming the first sample that is not finite (the caller names the file).
    """
    def finite(chunk: np.ndarray, offset: int) -> np.ndarray:
        if not np.isfinite(chunk).all():
            k = int(np.argmax(~np.isfinite(chunk)))
            raise ValueError(f"channel {name!r} sample {offset + k + 1:,} is not finite, "
                             "expected finite numbers (no NaN or inf)")
        return chunk

    rest = float(np.median(finite(values(0, min(samples, REST_SAMPLES)), 0)))
    peak, height = 0, -1.0
    for offset in range(0, samples, SCAN_CHUNK):
        chunk = np.abs(finite(values(offset, min(SCAN_CHUNK, samples - offset)), offset) - rest)
        k = int(np.argmax(chunk))
        if chunk[k] > height:
            peak, height = offset + k, float(chunk[k])
    ends = times(0, 1), times(samples - 1, 1)
    duration = float(ends[1][0] - ends[0][0])
    rate = (samples - 1) / duration if duration > 0 else math.inf
    half = int(min(round(WINDOW_SECONDS * rate), (max_samples - 1) // 2))
    first = max(0, peak - half)
    count = min(samples, peak + half + 1) - first
    note = (f"channel {name!r} holds {samples:,} samples ({duration:.4g} s), more than the "
            f"{max_samples:,} read whole: read the {count:,} samples around its largest "
            f"excursion from rest (sample {peak + 1:,}), {first + 1:,} to {first + count:,}; "
            "a pulse elsewhere in the channel is not looked at")
    return Window(first, count, samples, peak, note)
