"""A recorder's time base as it is: a clock fitted to time stamps that jitter (issue 62).

A real recorder stamps blocks of samples: within a block the samples come at its ADC's even
rate, while the block time codes jitter at the boundaries (enDAQ's files: steps 0.75 to 1.07
of the median) and the clock runs a little off its nominal rate, wandering with temperature
over a long recording. Checked step by step, such a recording is refused as uneven; judged on
its stamps as they are, every figure that takes a time step would be off.

:func:`fit_clock` fits a rate and an offset (a straight line through the stamps against the
sample's number) over the continuous stretch that holds the recording's largest excursion,
and places the samples on that even base when no stamp lies more than :data:`JITTER_STEPS`
of a step from it. Over a long recording whose clock wanders past that, the line is fitted
over a shorter window centred on the excursion, halved until it fits, down to
:data:`MIN_WINDOW_SECONDS`; the rest of the recording is then not read, and the notes say so.

A *true gap* (missing samples: a step over :data:`GAP_STEPS` times the median) ends a
stretch. One within :data:`GAP_MARGIN_SECONDS` of the largest excursion lies inside the window
a pulse is judged over (its rest before, its pulse, its tail) and is refused, naming where; one
further away is said in the notes, and the stretch beyond it is not read.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import WorkbookError

#: The largest distance of a stamp from the fitted clock, in steps, at which the samples are
#: placed on the even base. Half a step: no sample is moved past the midpoint to its
#: neighbour, so the order of the samples and the sample nearest any instant stay as stamped,
#: and a duration or an instant measured on the even base moves by at most half a step,
#: within the one-step resolution a sampled pulse has anyway. (Block time codes that jitter
#: by 40 % of a step, as enDAQ's do at their boundaries, are inside it.)
JITTER_STEPS = 0.5

#: A step longer than this many median steps is a true gap (missing samples): one missing
#: sample doubles a step, while a block boundary's jitter is seen to reach 1.07.
GAP_STEPS = 1.5

#: A true gap this close [s] to the largest excursion lies inside what a pulse is judged
#: over (the rest before an air gun pulse, the pulse of milliseconds and its tail): refused.
GAP_MARGIN_SECONDS = 0.025

#: The shortest window [s] the clock is fitted over around the largest excursion: twice the
#: gap margin, so that a pulse and its rest on each side are on one fitted clock.
MIN_WINDOW_SECONDS = 2 * GAP_MARGIN_SECONDS

#: How far [-] the clock fitted around the excursion may run from the rate of the recording's
#: median step. A recorder's quartz keeps within 100 ppm (the real files here: within 84
#: ppm); a window whose stamps run 1.4 % fast (an enDAQ recording's first block, stamped
#: apart from the rest) is no clock's, and a duration measured on it would be 1.4 % off.
RATE_TOLERANCE = 0.005

#: Samples at the start of a recording whose median is its rest level, as the long-channel
#: scan takes it (:data:`airgun_xl.readers.formats.channels.REST_SAMPLES`).
REST_SAMPLES = 10_000


@dataclass(frozen=True)
class ClockFit:
    """The samples ``first`` to ``stop`` (from 0, ``stop`` excluded) placed on an even time
    base: ``time`` [s], at the fitted step ``dt`` [s]; ``notes`` say the clock's rate against
    the median step's, the largest jitter, and what was not read."""

    first: int
    stop: int
    time: np.ndarray
    dt: float
    notes: tuple[str, ...]


def _line(time: np.ndarray, first: int, stop: int) -> tuple[float, float, float]:
    """(offset [s] at sample ``first``, step [s], largest distance of a stamp from the line
    [steps]) of the least-squares line through ``time[first:stop]`` against the sample's
    number."""
    k = np.arange(stop - first, dtype=float)
    t = time[first:stop] - time[first]
    k_mean, t_mean = k.mean(), t.mean()
    dk = k - k_mean
    # numpy's pairwise sums, not BLAS's dot, whose kernel (and rounding) depends on the CPU:
    # the same stamps give the same clock on every machine
    step = float(np.sum(dk * (t - t_mean)) / np.sum(dk * dk))
    offset = float(t_mean - step * k_mean)
    worst = float(np.max(np.abs(t - (offset + step * k)))) / step
    return float(time[first]) + offset, step, worst


def fit_clock(shown: str, time: np.ndarray, values: np.ndarray, centre: int | None = None,
              named: bool = False) -> ClockFit:
    """The recording ``shown`` (its stamps ``time`` [s], increasing, and its raw ``values``)
    on one fitted clock around its largest excursion, or the sample ``centre`` (the peak of
    the event judged, :mod:`airgun_xl.readers.events`; ``named`` when the user named it: the
    messages say so; see the module's notes).

    Raises
    ------
    WorkbookError
        A true gap within :data:`GAP_MARGIN_SECONDS` of the largest excursion, or stamps that
        stray over :data:`JITTER_STEPS` from one clock even over :data:`MIN_WINDOW_SECONDS`
        around it, naming where.
    """
    steps = np.diff(time)
    median = float(np.median(steps))
    rest = float(np.median(values[:REST_SAMPLES]))
    peak = int(np.argmax(np.abs(values - rest))) if centre is None else centre
    what = "the peak of the event judged" if named else "its largest excursion"
    gaps = np.flatnonzero(steps > GAP_STEPS * median)  # a gap after sample g
    before, after = gaps[gaps < peak], gaps[gaps >= peak]
    first = int(before[-1]) + 1 if len(before) else 0
    stop = int(after[0]) + 1 if len(after) else len(time)
    for g, edge in ((before[-1] if len(before) else None, first),
                    (after[0] if len(after) else None, stop - 1)):
        if g is not None and abs(float(time[peak] - time[edge])) < GAP_MARGIN_SECONDS:
            raise WorkbookError(
                f"{shown}: a gap of {float(steps[g]):.4g} s ({float(steps[g]) / median:.1f} "
                f"steps) in its time after {float(time[g]):.6g} s, "
                f"{abs(float(time[edge] - time[peak])) * 1e3:.3g} ms from {what} at "
                f"{float(time[peak]):.6g} s, expected no missing samples within "
                f"{GAP_MARGIN_SECONDS * 1e3:g} ms of the pulse (its rest, the pulse and its "
                "tail are judged there)")
    lo, hi = first, stop
    start, step, worst = _line(time, lo, hi)
    shortest = max(int(math.ceil(MIN_WINDOW_SECONDS / median)), 16)
    half = (hi - lo) // 2
    while worst > JITTER_STEPS:
        half //= 2
        if 2 * half < shortest:
            raise WorkbookError(
                f"{shown}: its time stamps stray up to {worst:.2g} of a step from one clock "
                f"even over the {(time[hi - 1] - time[lo]) * 1e3:.3g} ms around {what} at "
                f"{float(time[peak]):.6g} s, expected a recorder's time base: "
                f"a rate and an offset that every stamp lies within {JITTER_STEPS:g} of a "
                "step of (a changed rate or a damaged time column?)")
        lo, hi = max(first, peak - half), min(stop, peak + half + 1)
        start, step, worst = _line(time, lo, hi)
    if abs(median / step - 1) > RATE_TOLERANCE:
        raise WorkbookError(
            f"{shown}: its time stamps around {what} at {float(time[peak]):.6g} s "
            f"({float(time[lo]):.6g} to {float(time[hi - 1]):.6g} s) run at {1 / step:.6g} "
            f"Hz, {(median / step - 1):+.2%} from the {1 / median:.6g} Hz of its median step, "
            f"expected one clock within {RATE_TOLERANCE:.1%} (a block stamped apart from the "
            "others, as a recorder's first often is): its time there cannot be trusted")
    off = steps[lo:hi - 1]
    jittered = int(np.sum(np.abs(off - median) > 0.01 * median))
    largest = float(np.max(np.abs(off - median))) / median if len(off) else 0.0
    notes = [f"{shown}: its time stamps jitter ({jittered:,} steps off the median by over "
             f"1 %, the largest by {largest:.0%} of a step): the clock fitted over "
             f"{float(time[lo]):.6g} to {float(time[hi - 1]):.6g} s ({hi - lo:,} samples) "
             f"runs at {1 / step:.6g} Hz, {(median / step - 1) * 1e6:+.0f} ppm from the "
             f"median step's {1 / median:.6g} Hz; its samples are placed on that even base, "
             f"none moved more than {worst:.2f} of a step (at most {JITTER_STEPS:g})"]
    if (lo, hi) != (first, stop):
        notes.append(f"{shown}: its clock wanders more than {JITTER_STEPS:g} of a step from "
                     f"one rate over the whole recording: only the {hi - lo:,} samples around "
                     f"{what}, {float(time[lo]):.6g} to "
                     f"{float(time[hi - 1]):.6g} s, are read")
    if len(gaps):
        notes.append(f"{shown}: {len(gaps)} gap{'s' * (len(gaps) > 1)} in its time (missing "
                     f"samples; the first after {float(time[gaps[0]]):.6g} s), none within "
                     f"{GAP_MARGIN_SECONDS * 1e3:g} ms of {what}: the "
                     f"stretch from {float(time[first]):.6g} to {float(time[stop - 1]):.6g} s "
                     "that holds it is read")
    return ClockFit(lo, hi, start + step * np.arange(hi - lo, dtype=float), step,
                    tuple(notes))
