"""The shocks a recording holds (issue 62): a drop or air gun session recorded continuously,
a recorder left running between shots, holds several; each is an *event*.

The rule (:func:`find_events`), on a channel's samples as the file holds them:

1. **Rest**: the median of the recording's first tenth (at most :data:`REST_SAMPLES`
   samples, at least 16): a recorder is started, or pre-triggered, before a shock, and a
   recording that is mostly pulse still starts at rest. **Noise**: 1.4826 times the median
   absolute deviation from rest over the same samples (the standard deviation of Gaussian
   noise, unmoved by a spike).
2. **Threshold**: the larger of :data:`EVENT_SIGMAS` times the noise (Gaussian noise passes
   8 sigma once in about 10^15 samples: no event is noise) and :data:`EVENT_SHARE` of the
   recording's largest excursion from rest (a pulse's ringing and tail stay in its event).
3. **Events**: the samples past the threshold, grouped; two groups closer than
   :data:`HOLD_SECONDS`, or than the earlier one lasts, are one event (a pulse and its
   rebound, a shock's ringing). An event touching the recording's first or last sample is
   *cut* (no rest before or after it).
4. Each event's **peak** is its largest excursion from rest, with its sign; its **duration**
   the run of samples round the peak at 10 % of it or more, same sign (to a sample step);
   its **start** that run's first sample.

A recording of several events is judged on one: the *stretch* from the middle of the rest
before it to the middle of the rest after it (:func:`stretch`), cut to 50 ms plus the event's
own length on each side of it (:func:`judged_span`), by default the largest (one
the recording cuts is said to be cut: its rest before or after is missing). A recording
whose samples never pass 8 sigma of its noise holds no event: it is judged whole, as
before, and the reading says so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Samples at most whose median is the rest level (those at a recording's start).
REST_SAMPLES = 10_000

#: Times the noise at rest a sample must pass to belong to an event.
EVENT_SIGMAS = 8.0

#: Share of the recording's largest excursion a sample must pass to belong to an event.
EVENT_SHARE = 0.10

#: Groups of samples past the threshold closer than this [s] are one event: an air gun or
#: drop pulse lasts milliseconds, its rebound and ringing follow within tens; shots of a
#: session come seconds apart. Twice the clock fit's margin round a pulse
#: (:data:`airgun_xl.readers.time_base.GAP_MARGIN_SECONDS`): each event's stretch holds at
#: least 25 ms of rest on each side.
HOLD_SECONDS = 0.05

#: The share of an event's peak at which its duration and start are read.
DURATION_SHARE = 0.10


@dataclass(frozen=True)
class Event:
    """One shock: samples ``first`` to ``last`` (from 0) pass the threshold; ``peak`` the
    sample of its largest excursion, ``height`` that excursion from rest (signed, in the
    file's unit); ``start`` [s] and ``duration`` [s] the run round the peak at 10 % of it;
    ``cut`` when it touches the recording's first or last sample."""

    number: int
    first: int
    last: int
    peak: int
    height: float
    start: float
    duration: float
    cut: bool


@dataclass(frozen=True)
class Events:
    """The recording's ``rest`` and ``noise`` [file's unit], the ``threshold`` its events
    passed, and the ``events`` in time order (numbered from 1)."""

    rest: float
    noise: float
    threshold: float
    events: tuple[Event, ...]

    def largest(self) -> Event | None:
        """The largest event (the first of equals), or None when it holds none."""
        return max(self.events, key=lambda e: abs(e.height)) if self.events else None


def rest_samples(count: int) -> int:
    """How many of a recording's first samples its rest is read from."""
    return max(16, min(REST_SAMPLES, count // 10))


def find_events(time: np.ndarray, values: np.ndarray) -> Events:
    """The events of a channel: its times ``time`` [s] (increasing) and its finite
    ``values`` (see the module's rule).

    Returns
    -------
    Events
    """
    head = values[:rest_samples(len(values))]
    rest = float(np.median(head))
    noise = 1.4826 * float(np.median(np.abs(head - rest)))
    away = np.abs(values - rest)
    largest = float(np.max(away)) if len(away) else 0.0
    threshold = max(EVENT_SIGMAS * noise, EVENT_SHARE * largest)
    past = np.flatnonzero(away >= threshold) if largest > 0 else np.zeros(0, int)
    groups: list[list[int]] = []
    if len(past):
        # candidate breaks: a hold of rest between two samples past the threshold
        breaks = np.flatnonzero(np.diff(time[past]) > HOLD_SECONDS)
        starts = np.concatenate([[0], breaks + 1])
        ends = np.concatenate([breaks, [len(past) - 1]])
        for s, e in zip(starts, ends, strict=True):
            first, last = int(past[s]), int(past[e])
            if groups:
                a, b = groups[-1]
                if time[first] - time[b] <= time[b] - time[a]:  # closer than it lasts
                    groups[-1][1] = last
                    continue
            groups.append([first, last])
    events = []
    for number, (first, last) in enumerate(groups, start=1):
        peak = first + int(np.argmax(away[first:last + 1]))
        height = float(values[peak] - rest)
        sign = 1.0 if height >= 0 else -1.0
        low = sign * (values - rest) < DURATION_SHARE * abs(height)
        before = np.flatnonzero(low[:peak])
        after = np.flatnonzero(low[peak:])
        a = int(before[-1]) + 1 if len(before) else 0
        b = peak + int(after[0]) - 1 if len(after) else len(values) - 1
        events.append(Event(number, first, last, peak, height, float(time[a]),
                            float(time[b] - time[a]), first == 0 or last == len(values) - 1))
    return Events(rest, noise, threshold, tuple(events))


def judged_span(found: Events, event: Event, time: np.ndarray) -> tuple[int, int]:
    """The samples (``first``, ``stop``) of ``event``'s :func:`stretch` that are judged: at
    most :data:`HOLD_SECONDS` plus the event's own length before its first sample past the
    threshold and as much after its last (at least 25 ms of rest each side, as the stretch
    holds; the judge's windows, of a few D, lie well inside), so that a long rest between
    shots is not filtered, scanned and charted for nothing."""
    first, stop = stretch(found, event, len(time))
    span = HOLD_SECONDS + float(time[event.last] - time[event.first])
    lo = int(np.searchsorted(time, time[event.first] - span, side="left"))
    hi = int(np.searchsorted(time, time[event.last] + span, side="right"))
    return max(first, lo), min(stop, hi)


def stretch(found: Events, event: Event, count: int) -> tuple[int, int]:
    """The samples (``first``, ``stop``, from 0, ``stop`` excluded) of a recording of
    ``count`` samples that hold ``event`` and the rest round it: from the middle of the rest
    before it (or the first sample) to the middle of the rest after it (or the last)."""
    k = event.number - 1
    events = found.events
    first = 0 if k == 0 else (events[k - 1].last + event.first) // 2 + 1
    stop = count if k == len(events) - 1 else (event.last + events[k + 1].first) // 2 + 1
    return first, stop
