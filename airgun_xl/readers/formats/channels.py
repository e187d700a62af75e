"""What every recording format says of a channel (:class:`ChannelInfo`), and how
``--channel`` chooses one (:func:`choose`): the same in every format."""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ...errors import OptionError, WorkbookError


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
