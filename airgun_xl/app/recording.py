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
    events: bool = declared.option(
        False, "--events", kind="switch", read=declared.a_switch,
        help="also list the shocks (events) of one channel: each one's start, peak with its "
             "sign, the peak's time and its duration at 10 %%, numbered for --event")
    channel: str | None = declared.channel(
        "with --events: the channel whose events are listed, its name or number (default: "
        "the first acceleration channel)")
    time_unit: str | None = declared.time_unit()
    accel_unit: str | None = declared.accel_unit()

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("channel", "time_unit", "accel_unit"):
            if getattr(self, name) is not None and not self.events:
                raise declared.refusal("{0}: found it without {1}, expected {1} with it (the "
                                       "channel whose events are listed)", name, "events")


@dataclass(frozen=True)
class RecordingOutcome:
    """The file's ``format`` (its name in messages) and its ``channels``
    (:class:`airgun_xl.readers.formats.ChannelInfo`, in the file's order: ``--channel N`` is
    the N-th)."""

    path: Path
    format: str
    channels: tuple[Any, ...]
    #: with ``events``: (the channel's name as shown, its unit, its times [s],
    #: :class:`airgun_xl.readers.events.Events`)
    events: tuple[str, str, Any, Any] | None = None

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
        return out + self._event_lines()

    def _event_lines(self) -> list[str]:
        """The events' table (``--events``)."""
        from ..readers.events import EVENT_SHARE, EVENT_SIGMAS
        from ..untrusted_json import printable

        if self.events is None:
            return []
        shown, unit, time, found = self.events
        unit = printable(unit)
        count = len(found.events)
        out = [f"{printable(shown)}: {count} event{'' if count == 1 else 's'} (samples past "
               f"{found.threshold:.4g} {unit} from its rest of {found.rest:.4g} {unit}: the "
               f"larger of {EVENT_SIGMAS:g} x its noise at rest, {found.noise:.3g} {unit}, and "
               f"{EVENT_SHARE:.0%} of its largest excursion; a rest of 50 ms or more between "
               "two)"]
        if not count:
            return out
        largest = found.largest()
        out.append(f"{'#':>3}  {'start [s]':>12} {f'peak [{unit}]':>14} {'at [s]':>12} "
                   f"{'duration at 10% [ms]':>21}")
        for e in found.events:
            mark = ("  (judged by default)" if e is largest else "") + \
                ("  (cut by the recording)" if e.cut else "")
            out.append(f"{e.number:>3}  {e.start:>12.6g} {e.height:>+14.5g} "
                       f"{float(time[e.peak]):>12.6g} {e.duration * 1e3:>21.4g}{mark}")
        return out

    def to_json(self) -> str:
        """The listing as JSON (the channels' rates in Hz and starts in s; null unknown)."""
        from .documents import dumps

        listing: dict[str, Any] = {
            "file": self.path, "format": self.format, "channels": [
                {"number": k, "name": c.name, "unit": c.unit, "rate_hz": c.rate,
                 "samples": c.samples, "start_s": c.start}
                for k, c in enumerate(self.channels, start=1)]}
        if self.events is not None:
            shown, unit, time, found = self.events
            largest = found.largest()
            listing["events"] = {
                "channel": shown, "unit": unit, "rest": found.rest, "noise": found.noise,
                "threshold": found.threshold, "events": [
                    {"number": e.number, "start_s": e.start, "peak": e.height,
                     "peak_time_s": float(time[e.peak]), "duration_s": e.duration,
                     "cut": e.cut, "judged_by_default": e is largest}
                    for e in found.events]}
        return dumps(listing)


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
    events = None
    if request.events:
        from ..readers.recording import list_events

        events = list_events(path, request.channel, request.time_unit, request.accel_unit)
    return RecordingOutcome(Path(text), kind, channels, events)
