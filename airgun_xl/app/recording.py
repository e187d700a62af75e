"""Recording: what a recording file holds, as the reading commands would read it (its format
and its channels, with their names, units, rates, lengths and starts); no samples judged.

:func:`run` takes a :class:`RecordingRequest` and returns a :class:`RecordingOutcome`; the
CLI (``airgun-xl recording``) and the Python API (:func:`airgun_xl.recording`) are both
this."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import declared


@dataclass(frozen=True, kw_only=True)
class RecordingRequest(declared.Checked):
    """The recording file (or a workbook's columns, as text). Declared once
    (:mod:`.declared`): the command's argument and the API's keyword."""

    path: str = declared.positional("path", help=declared.RECORDING_HELP, metavar="RECORDING",
                                    read=declared.a_recording)


@dataclass(frozen=True)
class RecordingOutcome:
    """The file's ``format`` (its name in messages) and its ``channels``
    (:class:`airgun_xl.readers.formats.ChannelInfo`, in the file's order: ``--channel N`` is
    the N-th)."""

    path: Path
    format: str
    channels: tuple[Any, ...]

    def lines(self) -> list[str]:
        """What ``recording`` prints: a line for the file, then a row per channel."""
        from ..transaction import display
        from ..untrusted_json import printable

        def number(x: float | None, fmt: str) -> str:
            return "unknown" if x is None or not math.isfinite(x) else format(x, fmt)

        count = len(self.channels)
        names = [printable(c.name) for c in self.channels]
        units = [printable(c.unit) or "-" for c in self.channels]
        # the columns as wide as their longest entry: a long name never runs into the unit
        wide, unit = max([24, *map(len, names)]), max([8, *map(len, units)])
        out = [f"{printable(display(self.path))}: {self.format}, {count} channel"
               f"{'' if count == 1 else 's'}",
               f"{'#':>3}  {'name':<{wide}} {'unit':<{unit}} {'rate [Hz]':>12} "
               f"{'samples':>12} {'start [s]':>12}"]
        for k, c in enumerate(self.channels, start=1):
            out.append(f"{k:>3}  {names[k - 1]:<{wide}} {units[k - 1]:<{unit}} "
                       f"{number(c.rate, ',.6g'):>12} {c.samples:>12,} "
                       f"{number(c.start, '.6g'):>12}")
        return out

    def to_json(self) -> str:
        """The listing as JSON (the channels' rates in Hz and starts in s; null unknown)."""
        from .documents import dumps

        return dumps({"file": self.path, "format": self.format, "channels": [
            {"number": k, "name": c.name, "unit": c.unit, "rate_hz": c.rate,
             "samples": c.samples, "start_s": c.start}
            for k, c in enumerate(self.channels, start=1)]})


def run(request: RecordingRequest) -> RecordingOutcome:
    """List the channels of the recording the request names.

    Raises
    ------
    airgun_xl.errors.WorkbookError
        The file is missing, not a regular file, too large, or not a readable recording.
    """
    from ..readers import formats
    from ..readers.recording import list_channels

    path = text = request.path
    kind = formats.detect(path).NAME
    channels = tuple(list_channels(path))
    if not channels:  # a UFF of no time response listed "0 channels" and exited 0
        from ..errors import WorkbookError
        from ..transaction import display

        raise WorkbookError(f"{display(Path(text))}: holds no channel of a recording (a time "
                            f"response), expected a {kind} file of at least one")
    return RecordingOutcome(Path(text), kind, channels)
