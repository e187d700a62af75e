"""What a recording says about itself, read before it is judged (issue 42).

A recording is evidence, not truth. Every command that reads one (``accept``,
``compare-measured``, ``calibrate``) runs it through :func:`assess` once, which reads from the
record itself:

- **its rest and noise** (:func:`baseline`): the stretch at rest before the pulse ends where
  the pulse provably has not yet left the noise (eq. 1 below), not a fixed guard before it;
  its noise (1 sigma) and colour (lag-1 autocorrelation); else the stretch at rest after it;
- **its quantisation step** (the common step of the values at its top) and, where a top held
  flat shows it, its **range**;
- **the samples across its pulse**, and a **start or end inside the pulse**;
- **clipping**: a top held within ``h`` of its largest value (eq. 2) for longer than a smooth
  peak can be at this rate, step and noise (eq. 3), or longer than its noise lets it be
  (eq. 4): dither within the noise does not hide it;
- **dropouts**: a run of one value inside the pulse entered or left by a jump no smooth
  signal makes there (eq. 5), or longer than the noise lets it be (eq. 4);
- **units that cannot be right**: a peak, duration or velocity change off what was expected
  (the shot's prediction, the specification's nominal) by a unit's factor.

The rules, each with its reason (docs/trust.md gives them with their thresholds):

1. The pulse leaves the noise at ``j``: the sample after the last one before its first
   crossing of :data:`PULSE_EDGE` of the excursion that lies within :data:`LEAVE_SIGMAS`
   robust standard deviations of the rest's level. The rest ends ``max(MIN_GUARD, k - j)``
   samples before ``j`` (``k`` the crossing): a foot that rises from the noise to the
   crossing in ``k - j`` samples, concave or convex, is back under a small fraction of the
   noise within as many again. Iterated until it holds.
2. ``h = max(LSB / 2, TOP_FLOOR x peak, noise / 4)``: the same code, or a dither within a
   quarter of the noise.
3. A smooth top of curvature ``c`` stays within ``d`` of its maximum for ``2 sqrt(2 d / c)``;
   ``d = h + LSB + 4 noise`` (the step, and the noise lifting a lower sample), ``c`` the
   curvature of a half-sine as wide as the pulse at 50 % or at 10 % of its peak, whichever
   is wider (the gentler). Allowed: :data:`CLIP_MARGIN` times that, plus two samples.
4. Noise of one-step prediction error ``e`` (from an autoregression of the rest, so a
   coloured noise is not taken for a white one) keeps ``n`` samples within a band ``2h``
   with probability at most ``p^(n-1)``, ``p = 2h / (e sqrt(2 pi))``; a run with that below
   :data:`CHANCE` is not the noise's. Only where the noise at rest exceeds an LSB: below it,
   whether a quiet converter's codes flip depends on where the level sits between them.
5. A run of one value (within ``LSB / 2``) of :data:`MIN_RUN` samples or more, inside the
   pulse and not its top, entered or left by a step larger than ``max(4 LSB, 8 noise
   steps)`` and :data:`JUMP_RATIO` times the largest of the signal's own
   :data:`JUMP_SPAN` steps beyond it: a smooth signal (or a corner) held within one step
   leaves it on its own path; a dropout's signal resumes elsewhere.
6. A top held within ``d`` of its largest value for ``n`` samples that falls on both sides,
   over the two samples past the run, by more than :data:`CORNER_MARGIN` ``x 8 d / (n - 2)``
   plus an LSB and :data:`CORNER_SIGMAS` of the noise's step is a corner: a parabola held
   ``n`` samples within ``d`` has the curvature ``8 d / n^2`` and falls about ``8 d / n``
   over the two samples past the run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..units import KG_MS2, G

#: The pulse's edge, a fraction of its excursion: the crossing rule 1 walks back from.
PULSE_EDGE = 0.25

#: Rule 1: a sample within this many robust standard deviations of the rest's level is in
#: the noise (4: a white sample outside by chance 6 times in 100,000).
LEAVE_SIGMAS = 4.0

#: Rule 1: the fewest samples between the rest and where the pulse leaves the noise.
MIN_GUARD = 2

#: Fewest samples at rest that give a baseline and a noise level.
MIN_PRE_SAMPLES = 16

#: A stretch is at rest when a line through it rises by no more than this fraction of the
#: pulse's excursion, or than :data:`REST_SIGMAS` standard errors of such a line through its
#: own noise (a pulse's rise or tail is not a baseline).
REST_DRIFT, REST_SIGMAS = 0.02, 4.0

#: After the pulse, a stretch is at rest only if its spread is noise, not the item ringing:
#: within this factor of its sample-to-sample noise.
REST_WHITE = 2.0

#: Rules 2 and 3: the smallest band round the top, a fraction of the peak (a converter of
#: 20 bits resolves 1e-6 of its range; a float record none coarser).
TOP_FLOOR = 1e-6

#: Rule 3: the level, a fraction of the peak, whose width gives a top's curvature.
TOP_LEVEL = 0.8

#: Rule 3: the allowance over a smooth top's time within its band.
CLIP_MARGIN = 1.5

#: Rule 6: a top held within ``d`` for ``n`` samples that falls on both sides, over the two
#: samples past the run, by more than CORNER_MARGIN x 8 d / (n - 2) + LSB + CORNER_SIGMAS x
#: the noise's step is a corner (a smooth parabola falls about 8 d / n there): a pulse cut
#: flat, not a peak.
CORNER_MARGIN, CORNER_SIGMAS = 2.0, 6.0

#: Rule 4: a run the noise makes with a probability below this is not the noise's (one in a
#: billion: a 10,000-sample record has it by chance once in 100,000 records).
CHANCE = 1e-9

#: Rule 5: fewest samples of one value that make a dropout.
MIN_RUN = 3

#: Rule 5: a run entered or left by a step this many times the largest of the signal's own
#: :data:`JUMP_SPAN` steps beyond it is off the signal's path (a hold of n samples on a ramp
#: resumes n steps on; a corner into a ramp, one).
JUMP_RATIO, JUMP_SPAN = 3.0, 4

#: A record whose first (last) :data:`EDGE_SAMPLES` samples average above
#: :data:`INSIDE_FRACTION` of its peak, and their noise by :data:`INSIDE_SIGMAS`, starts (ends)
#: inside the pulse: the duration's 10 % crossing was not recorded.
INSIDE_SIGMAS, INSIDE_FRACTION, EDGE_SAMPLES = 5.0, 0.10, 5

#: Factors that a wrong unit multiplies a figure by, and the units it mistakes: a figure
#: within :data:`UNIT_BAND` of one of them (off what was expected) is a probable unit error.
PEAK_FACTORS = ((1 / G, "g read as m/s^2"), (G, "m/s^2 read as g"),
                (KG_MS2 / G, "g read as kG"), (G / KG_MS2, "kG read as g"),
                (KG_MS2, "m/s^2 read as kG"), (1 / KG_MS2, "kG read as m/s^2"))
TIME_FACTORS = ((1000.0, "ms read as s, or us as ms"), (1 / 1000.0, "s read as ms, or ms as us"),
                (1e6, "us read as s"), (1e-6, "s read as us"))
UNIT_BAND = 2.0


@dataclass
class Baseline:
    """The recording's zero and noise, from where it is at rest: before the pulse, or (with
    no quiet pre-trigger) after it.

    Attributes
    ----------
    offset : float
        Median of the samples at rest [kG], removed from the recording (0 without any).
    noise : float
        Their standard deviation about it [kG] (NaN without a record at rest).
    samples : int
        Samples at rest used.
    where : str
        "before" or "after" the pulse, or "none".
    start : int
        Index of the first of them.
    colour : float
        Lag-1 autocorrelation of the noise at rest [-] (NaN without it): 0 white, towards 1
        correlated from sample to sample.
    step_noise : float
        The noise's one-step prediction error [kG] (rule 4): what is left of it once its
        correlation with the samples before is used (the noise itself when white).
    """

    offset: float
    noise: float
    samples: int
    where: str = "before"
    start: int = 0
    colour: float = math.nan
    step_noise: float = math.nan

    def words(self) -> str:
        """The baseline as a verdict or a comparison prints it."""
        if self.where == "none":
            return ("no record at rest before or after the pulse: offset taken as 0, noise "
                    "unknown")
        return (f"{self.offset:.4g} kG removed, noise {self.noise:.3g} kG (1 sigma): "
                f"{self.samples:,} samples at rest {self.where} the pulse")


def _at_rest(segment: np.ndarray, excursion: float, white: bool = False) -> int:
    """How many samples of ``segment`` from its start (``segment`` reversed: from its end)
    are at rest: the stretch is cut by a fifth until a line through it stays flat
    (:data:`REST_DRIFT`, :data:`REST_SIGMAS`) and, with ``white``, its spread is its
    sample-to-sample noise (:data:`REST_WHITE`)."""
    n = len(segment)
    while n >= MIN_PRE_SAMPLES:
        part = segment[:n]
        x = np.arange(n, dtype=float)
        slope, intercept = np.polyfit(x, part, 1)
        resid = float(np.std(part - (slope * x + intercept)))
        rise = abs(slope) * (n - 1)
        flat = rise <= max(REST_DRIFT * excursion, REST_SIGMAS * resid * math.sqrt(12.0 / n))
        if flat and (not white or resid <= REST_WHITE * _sample_noise(part)):
            return n
        n = int(n * 0.8)
    return 0


def _sample_noise(part: np.ndarray) -> float:
    """The sample-to-sample noise of a stretch (1 sigma): its second differences' median
    absolute deviation, scaled for white noise (their variance is 6 sigma^2)."""
    d2 = np.diff(part, 2)
    return 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)


def _robust_spread(values: np.ndarray) -> float:
    """1.4826 x the median absolute deviation: a standard deviation that a few samples of a
    pulse's foot do not lift."""
    return 1.4826 * float(np.median(np.abs(values - np.median(values))))


def _rest_end(accel: np.ndarray, edge: int, top: float) -> int:
    """Where the rest before the pulse ends (rule 1): ``edge`` is the first sample at
    :data:`PULSE_EDGE` of the excursion ``top``."""
    end = edge
    for _ in range(8):
        if end < MIN_PRE_SAMPLES:
            return 0
        part = accel[:end]
        level = float(np.median(part))
        band = max(LEAVE_SIGMAS * _robust_spread(part), TOP_FLOOR * 1e-3 * top)
        inside = np.flatnonzero(np.abs(accel[:edge] - level) <= band)
        leave = int(inside[-1]) + 1 if len(inside) else 0
        new_end = leave - max(MIN_GUARD, edge - leave)
        if new_end >= end:
            break
        end = new_end
    return max(end, 0)


def _rest_start_after(accel: np.ndarray, edge: int, top: float) -> int:
    """Where the rest after the pulse may start: past the last sample after ``edge`` (its
    last sample at :data:`PULSE_EDGE`) outside the tail's noise, and :data:`MIN_GUARD`
    more."""
    tail = accel[edge + 1:]
    if len(tail) < MIN_PRE_SAMPLES:
        return len(accel)
    quiet = tail[len(tail) // 2:]
    level = float(np.median(quiet))
    band = max(LEAVE_SIGMAS * _robust_spread(quiet), TOP_FLOOR * 1e-3 * top)
    outside = np.flatnonzero(np.abs(tail - level) > band)
    back = int(outside[-1]) + 1 if len(outside) else 0
    return min(len(accel), edge + 1 + back + MIN_GUARD)


def _noise_of(rest: np.ndarray) -> tuple[float, float]:
    """(lag-1 autocorrelation, one-step prediction error [kG]) of a stretch at rest: the
    residuals of a line through it, and an autoregression of up to 8 lags fitted to them
    (Yule-Walker, scipy.linalg.solve_toeplitz)."""
    n = len(rest)
    x = np.arange(n, dtype=float)
    r = rest - np.polyval(np.polyfit(x, rest, 1), x)
    power = float(r @ r)
    if n < 4 or power == 0:
        return (math.nan, 0.0)
    lags = min(8, n // 8)
    acf = np.array([float(r[k:] @ r[:n - k]) for k in range(lags + 1)]) / power
    colour = float(acf[1]) if lags else 0.0
    variance = power / n
    if lags:
        from scipy.linalg import solve_toeplitz

        try:
            phi = solve_toeplitz(acf[:-1], acf[1:])
            left = float(1 - phi @ acf[1:])
        except np.linalg.LinAlgError:
            left = 1.0
        variance *= min(1.0, max(left, 1e-6))
    return colour, math.sqrt(variance)


def baseline(accel, dt) -> Baseline:
    """The :class:`Baseline` of a recording (``accel`` [kG] at step ``dt`` [s]): the samples
    at rest before its pulse (rule 1), else those after it; with neither, offset 0 and noise
    NaN."""
    accel = np.asarray(accel, dtype=float)
    # the level at rest: the median of the quieter end (a record may start in its pulse)
    m = max(MIN_PRE_SAMPLES, len(accel) // 10)
    ends = [accel[:m], accel[-m:]]
    opening = float(np.median(min(ends, key=lambda e: float(np.std(e)))))
    excursion = accel - opening
    top = float(np.max(np.abs(excursion))) if len(accel) else 0.0
    above = np.flatnonzero(np.abs(excursion) >= PULSE_EDGE * top) if top > 0 else \
        np.array([], dtype=int)
    if len(above) == 0:
        return Baseline(0.0, np.nan, 0, "none")
    end = _rest_end(accel, int(above[0]), top)
    quiet = _at_rest(accel[:end], top)
    if quiet >= MIN_PRE_SAMPLES:
        return _measured(accel[:quiet], "before", 0)
    start = _rest_start_after(accel, int(above[-1]), top)
    quiet = _at_rest(accel[start:][::-1], top, white=True)
    if quiet >= MIN_PRE_SAMPLES:
        return _measured(accel[len(accel) - quiet:], "after", len(accel) - quiet)
    return Baseline(0.0, np.nan, end, "none")


def _measured(rest: np.ndarray, where: str, start: int) -> Baseline:
    offset = float(np.median(rest))
    colour, step = _noise_of(rest)
    return Baseline(offset, float(np.std(rest - offset)), len(rest), where, start, colour,
                    step)


# -- the quantisation step ------------------------------------------------------------------------

def common_step(values: np.ndarray) -> float:
    """The common step of ``values`` [their unit]: the greatest step of which every value's
    distance from the smallest is a whole multiple (Euclid's algorithm, to 1e-9 of the
    largest value), or 0 where there is none coarser than 1e-8 of it (values not quantised,
    or fewer than three distinct ones)."""
    v = np.unique(np.asarray(values, dtype=float))
    v = v[np.isfinite(v)]
    if len(v) < 3:
        return 0.0
    scale = float(np.max(np.abs(v)))
    tol = 1e-9 * scale
    d = np.unique(np.diff(v))
    step = float(d[0])
    for gap in d[1:]:
        a, b = float(gap), step
        while b > tol:
            a, b = b, math.fmod(a, b)
            if b > tol and a - b <= tol:  # a remainder within the tolerance of the divisor
                b = 0.0
        step = a
        if step <= 1e-8 * scale:
            return 0.0
    # Euclid's step is good to its tolerance; refined over ever longer spans (each a hundred
    # times the last, so that the count of steps in it is never miscounted) it is good to
    # the values' own rounding, as a 24-bit converter's 16 million codes need
    offsets = v - v[0]
    span = 100 * step
    while True:
        k = int(np.searchsorted(offsets, span))
        j = min(k, len(v) - 1)
        count = round(offsets[j] / step)
        if count > 0:
            step = float(offsets[j]) / count
        if k >= len(v) - 1:
            break
        span *= 100
    ratio = offsets / step
    return step if bool(np.all(np.abs(ratio - np.round(ratio)) <= 1e-3)) else 0.0


# -- runs ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Run:
    """Samples ``start`` to ``stop - 1`` of a record, held at ``value`` [kG]."""

    start: int
    stop: int
    value: float

    @property
    def samples(self) -> int:
        return self.stop - self.start

    def words(self, time: np.ndarray) -> str:
        """``12 samples from 1.2340 to 1.4560 ms``."""
        return (f"{self.samples:,} samples from {time[self.start] * 1e3:.4f} to "
                f"{time[self.stop - 1] * 1e3:.4f} ms")


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """The runs of True in ``flags``: (start, stop) each."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], flags.astype(np.int8), [0]])))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _held(x: np.ndarray, level: float, band: float) -> tuple[int, int]:
    """The longest run of samples within ``band`` of ``level``: (start, stop)."""
    runs = _runs(np.abs(x - level) <= band)
    return max(runs, key=lambda r: r[1] - r[0]) if runs else (0, 0)


def _width(x: np.ndarray, level: float) -> float:
    """Samples from the first to the last at or above ``level`` (0 if none)."""
    above = np.flatnonzero(x >= level)
    return float(above[-1] - above[0] + 1) if len(above) else 0.0


def chance_run(band: float, step_noise: float) -> float:
    """Rule 4: the fewest samples the noise (one-step prediction error ``step_noise``) keeps
    within ``band`` with a probability below :data:`CHANCE` (inf where it cannot tell:
    no noise, or a band as wide as it)."""
    if not (step_noise > 0) or not math.isfinite(step_noise):
        return math.inf
    p = band / (step_noise * math.sqrt(2 * math.pi))
    if p >= 1:
        return math.inf
    return 1 + math.ceil(math.log(CHANCE) / math.log(p)) if p > 0 else 2.0


def smooth_top(x: np.ndarray, peak: float, depth: float) -> float:
    """Rule 3: the samples a smooth top of the pulse ``x`` (its peak ``peak``) spends within
    ``depth`` of its maximum: ``2 sqrt(2 depth / c)`` [samples], ``c = 8 (1 - l) peak / w^2``
    the curvature of the parabola as wide as the pulse at ``l`` = :data:`TOP_LEVEL` of its
    peak (``w`` samples; a half-sine's is 0.96 of its own pi^2 peak / D^2)."""
    width = _width(x, TOP_LEVEL * peak)
    if peak <= 0 or width <= 0:
        return math.inf
    curvature = 8 * (1 - TOP_LEVEL) * peak / width ** 2
    return 2 * math.sqrt(2 * depth / curvature)


@dataclass(frozen=True)
class Clip:
    """A top held flat (rule 3 or 4): the run, the samples a smooth top could hold there,
    and which rule found it."""

    run: Run
    allowed: float
    side: str  # "top" or "bottom"
    why: str


def find_clip(x: np.ndarray, base: Baseline, lsb: float, flat_expected: bool = False,
              side: str = "top") -> Clip | None:
    """A clipped top of ``x`` (zeroed [kG]; ``side`` "bottom": of ``-x``): rules 2-4, with
    the band of rule 2 tight (the same code) and, in a noisy record, loose (a dither within
    a quarter of its noise). ``flat_expected`` (a trapezoid named): a flat top is the
    shape's, so only the noise's rule (4) can tell a clip."""
    x = np.asarray(x, dtype=float)
    if side == "bottom":
        x = -x
    peak = float(np.max(x)) if len(x) else 0.0
    if peak <= 0:
        return None
    noise = base.noise if math.isfinite(base.noise) else 0.0
    tight = max(0.5 * lsb * (1 + 1e-9), TOP_FLOOR * peak)
    for band in (tight, 0.25 * noise) if 0.25 * noise > tight else (tight,):
        start, stop = _held(x, peak, band)
        n = stop - start
        if n < MIN_RUN:
            continue
        smooth = CLIP_MARGIN * smooth_top(x, peak, band + lsb + 4 * noise) + 2
        by_noise = chance_run(2 * band, base.step_noise) if noise > lsb else math.inf
        allowed = by_noise if flat_expected else min(smooth, by_noise)
        sign = -1.0 if side == "bottom" else 1.0
        if n > allowed:
            why = ("flatter than its noise lets a top be" if n > by_noise else
                   "held longer than a smooth peak can be")
            return Clip(Run(start, stop, sign * peak), allowed, side, why)
        if not flat_expected and 1 < start and stop < len(x) - 1:
            # rule 6: a smooth top held n samples within d falls about 8 d / n over the two
            # samples past either end of the run (a sample landing near the range on the way
            # down does not hide a corner)
            edge = min(x[start] - x[start - 2], x[stop - 1] - x[stop + 1])
            steps = base.step_noise if math.isfinite(base.step_noise) else 0.0
            smooth_edge = CORNER_MARGIN * 8 * (band + lsb) / max(n - 2, 1) + lsb + \
                CORNER_SIGMAS * steps
            if edge > smooth_edge:
                return Clip(Run(start, stop, sign * peak), allowed, side,
                            f"falling {edge:.3g} kG or more over the two samples past "
                            f"either end, where a smooth top held {n} samples falls at "
                            f"most {smooth_edge:.3g}")
    return None


def find_dropouts(x: np.ndarray, base: Baseline, lsb: float,
                  skip: tuple[int, int] | None = None) -> list[Run]:
    """Runs of one value inside the pulse of ``x`` (zeroed [kG]) that no smooth signal and
    no noise make (rules 4 and 5); ``skip``: a clipped top's (start, stop), clipping's
    business."""
    x = np.asarray(x, dtype=float)
    peak = float(np.max(x))
    if peak <= 0 or len(x) < MIN_RUN + 2:
        return []
    if skip is None:  # the top is clipping's business, clipped or not
        skip = _held(x, peak, max(0.5 * lsb * (1 + 1e-9), TOP_FLOOR * peak))
    body = np.flatnonzero(x >= PULSE_EDGE * peak)
    first, last = int(body[0]), int(body[-1])
    band = max(0.5 * lsb * (1 + 1e-9), TOP_FLOOR * 1e-3 * peak)
    same = np.abs(np.diff(x)) <= band
    noise = base.noise if math.isfinite(base.noise) else 0.0
    steps = float(np.std(np.diff(x[base.start:base.start + base.samples]))) \
        if base.samples > 2 else 0.0
    by_noise = chance_run(2 * band, base.step_noise) if noise > lsb else math.inf
    found = []
    for a, stop in _runs(same):  # samples a .. stop equal
        b = stop + 1
        if b - a < MIN_RUN or b <= first or a > last:
            continue
        if skip is not None and a < skip[1] and b > skip[0]:
            continue
        floor = max(4 * lsb, 8 * steps, TOP_FLOOR * peak)
        # each side's step against the signal's own steps beyond it: a dropout's value is
        # off the signal's path (the signal resumes elsewhere), a corner's is on it
        jumped = (a > 1 and abs(x[a - 1] - x[a]) > max(
            floor, JUMP_RATIO * _largest_step(x[max(0, a - 1 - JUMP_SPAN):a])))
        jumped |= (b < len(x) - 1 and abs(x[b] - x[b - 1]) > max(
            floor, JUMP_RATIO * _largest_step(x[b:b + 1 + JUMP_SPAN])))
        if jumped or (b - a) > by_noise:
            found.append(Run(a, b, float(x[a])))
    return found


def _largest_step(part: np.ndarray) -> float:
    """The largest step between neighbours of a stretch (0 for under two samples)."""
    return float(np.max(np.abs(np.diff(part)))) if len(part) >= 2 else 0.0


# -- the whole reading --------------------------------------------------------------------------

@dataclass(frozen=True)
class Expected:
    """What a recording is expected to show, to tell a unit error: its peak [kG], duration
    (the width at 10 % of the peak) [s] and velocity change [m/s] (each None where unknown),
    and from where (in words)."""

    peak: float | None = None
    duration: float | None = None
    velocity_change: float | None = None
    source: str = "the shot's prediction"

    @classmethod
    def of_pulse(cls, time, accel, source: str = "the shot's prediction") -> Expected:
        """What a pulse (``accel`` [kG] at ``time`` [s], from rest) shows."""
        from .integrals import trapezoid

        time = np.asarray(time, dtype=float)
        accel = np.asarray(accel, dtype=float)
        ok = np.isfinite(accel)
        time, accel = time[ok], accel[ok]
        if len(accel) < 2 or not np.max(accel) > 0:
            return cls(source=source)
        peak = float(np.max(accel))
        body = np.flatnonzero(accel >= 0.1 * peak)
        return cls(peak, float(time[body[-1]] - time[body[0]]) or None,
                   float(trapezoid(accel, time)) * KG_MS2, source)


@dataclass
class RecordingQuality:
    """What a recording says about itself (:func:`assess`).

    Attributes
    ----------
    name : str
        The recording, as messages name it.
    rate : float
        Samples a second [Hz].
    samples : int
        Samples recorded.
    base : Baseline
        Its rest: offset, noise and colour.
    lsb : float
        The quantisation step at its top [kG] (0: none seen).
    peak : float
        Its largest sample, zeroed [kG].
    width : float
        Its pulse's width at 10 % of its peak [s] (NaN where it starts or ends above).
    starts_inside, ends_inside : bool
        The record starts above its noise, or ends above 10 % of its peak: the pulse's start
        or end was not recorded.
    clip : Clip or None
        A top held flat, with the samples a smooth one could hold.
    dropouts : list of Run
        Runs of one value inside the pulse that the signal and its noise cannot make.
    units : list of str
        Probable unit errors, in words.
    warnings : list of str
        Each finding, a line each, as the run prints and carries them.
    """

    name: str
    rate: float
    samples: int
    base: Baseline
    lsb: float
    peak: float
    width: float
    starts_inside: bool
    ends_inside: bool
    clip: Clip | None = None
    dropouts: list[Run] = field(default_factory=list)
    units: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    time: np.ndarray | None = field(default=None, repr=False)
    first: float = math.nan  # the first sample, zeroed [kG]
    nominal: float | None = None  # the specification's D [s], the samples counted across it

    @property
    def damaged(self) -> str | None:
        """Why no criterion can be measured on this record (clipped, a dropout), or None."""
        if self.clip is not None:
            return f"the record is clipped ({self.clip.side})"
        if self.dropouts:
            return "the record has a dropout inside the pulse"
        return None

    def block(self, duration: float | None = None) -> list[tuple[str, str]]:
        """The "recording" block of a verdict: (label, text) rows; ``duration`` [s], the
        nominal D the samples are counted across (else the measured width)."""
        d = duration or self.nominal or self.width
        across = f"{d * self.rate:,.0f} across D ({d * 1e3:.4g} ms)" if d and \
            math.isfinite(d) else "the pulse's duration unknown"
        base = self.base
        if base.where == "none":
            noise = "unknown: no record at rest"
        else:
            colour = f"lag-1 correlation {base.colour:.2f}" if math.isfinite(base.colour) \
                else "colour unknown"
            share = f" ({100 * base.noise / self.peak:.3g} % of the peak)" if self.peak > 0 \
                else ""
            noise = (f"{base.noise:.3g} kG, 1 sigma{share}, {colour}; {base.samples:,} "
                     f"samples {base.where} the pulse")
        clip = "none seen" if self.clip is None else (
            f"{self.clip.side} held at {self.clip.run.value:.6g} kG for "
            f"{self.clip.run.samples:,} samples (a smooth one: at most "
            f"{self.clip.allowed:.3g}): {self.clip.why}")
        t = self.time if self.time is not None else np.arange(self.samples) / self.rate
        drops = "none seen" if not self.dropouts else "; ".join(
            f"{r.words(t)} at {r.value:.4g} kG" for r in self.dropouts[:3]) + (
            f" and {len(self.dropouts) - 3} more" if len(self.dropouts) > 3 else "")
        ends = ", ".join(w for w, flag in (("starts inside the pulse", self.starts_inside),
                                           ("ends inside the pulse", self.ends_inside))
                         if flag) or "the whole pulse recorded, from rest"
        return [("Rate", f"{self.rate:,.6g} samples a second, {self.samples:,} samples; "
                         + across),
                ("Quantisation", f"{self.lsb:.4g} kG a step at its top" if self.lsb else
                 "no common step seen"),
                ("Noise at rest", noise), ("Clipping", clip), ("Dropouts", drops),
                ("Start and end", ends)] + (
            [("Units", "; ".join(self.units))] if self.units else [])


def assess(time, accel, name: str, flat_top: bool = False,
           expected: Expected | list[Expected] | None = None,
           nominal_duration: float | None = None) -> RecordingQuality:
    """Read a recording (``accel`` [kG] at ``time`` [s], as recorded: offset not removed)
    before it is judged.

    Parameters
    ----------
    name : str
        The recording, as messages name it.
    flat_top : bool
        A flat top is expected (a trapezoid named): only its noise tells a clip.
    expected : Expected or list of Expected, optional
        What it should show (the shot's prediction, the specification's nominals), to tell
        a probable unit error: each figure off by a unit's factor is named once.
    nominal_duration : float, optional
        The specification's D [s], to count the samples across it.

    Returns
    -------
    RecordingQuality
    """
    time = np.asarray(time, dtype=float)
    raw = np.asarray(accel, dtype=float)
    dt = float(time[1] - time[0])
    base = baseline(raw, dt)
    x = raw - base.offset
    peak = float(np.max(x)) if len(x) else 0.0
    lsb = common_step(raw[x >= 0.5 * peak]) if peak > 0 else 0.0
    if lsb:  # a step coarser at the top (digits printed: 12.345 over 9.8765) is the top's
        top = np.unique(raw[x >= 0.95 * peak])
        coarse = common_step(top[top >= top[-1] - 0.02 * peak])
        if lsb < coarse <= 10.5 * lsb:
            lsb = coarse
    body = np.flatnonzero(x >= 0.1 * peak) if peak > 0 else np.array([], dtype=int)
    width = float((body[-1] - body[0]) * dt) if len(body) else math.nan
    noise = base.noise if math.isfinite(base.noise) else 0.0
    known = base.where != "none"  # without a rest, where the pulse starts is not known
    k = min(EDGE_SAMPLES, len(x))  # the first and last few, averaged against the noise
    above = INSIDE_FRACTION * peak + INSIDE_SIGMAS * noise / math.sqrt(max(k, 1))
    starts = bool(known and base.where != "before" and k and abs(np.mean(x[:k])) > above)
    ends = bool(known and k and np.mean(x[-k:]) > above)
    q = RecordingQuality(name, 1 / dt, len(x), base, lsb, peak, width, starts, ends,
                         time=time, first=float(x[0]) if len(x) else math.nan,
                         nominal=nominal_duration)
    q.clip = find_clip(x, base, lsb, flat_top)
    if q.clip is None and peak > 0 and -float(np.min(x)) > PULSE_EDGE * peak:
        q.clip = find_clip(x, base, lsb, side="bottom")
    skip = (q.clip.run.start, q.clip.run.stop) if q.clip is not None else None
    q.dropouts = find_dropouts(x, base, lsb, skip)
    for one in [expected] if isinstance(expected, Expected) else (expected or []):
        said = {u.split(",")[0] for u in q.units}  # a figure named once
        q.units += [u for u in unit_errors(q, x, dt, one) if u.split(",")[0] not in said]
    q.warnings = _warnings(q)
    return q


def unit_errors(q: RecordingQuality, x: np.ndarray, dt: float, expected: Expected
                ) -> list[str]:
    """Probable unit errors: the recording's figures off ``expected``'s by a unit's factor
    (within :data:`UNIT_BAND`). An acceleration unit (:data:`PEAK_FACTORS`) is told by the
    peak, or without one expected by the velocity change where the duration is not off; a
    time unit (:data:`TIME_FACTORS`) by the duration, or without one by the velocity change
    where the peak is not off."""
    from .integrals import trapezoid

    def ratio(value, wanted):
        ok = wanted is not None and wanted > 0 and value > 0 and math.isfinite(value)
        return value / wanted if ok else None

    def near(r, factor):
        return r is not None and abs(math.log(r / factor)) < math.log(UNIT_BAND)

    dv = float(trapezoid(x, dx=dt)) * KG_MS2
    shown = {"peak": (q.peak, expected.peak, "kG", 1.0),
             "duration": (q.width, expected.duration, "ms", 1e3),
             "velocity change": (dv, expected.velocity_change, "m/s", 1.0)}
    r = {k: ratio(v, w) for k, (v, w, _, _) in shown.items()}
    found = []
    for factors, direct, other in ((PEAK_FACTORS, "peak", "duration"),
                                   (TIME_FACTORS, "duration", "peak")):
        if r[direct] is not None:
            told = direct
        elif r["velocity change"] is not None and (r[other] is None or near(r[other], 1.0)):
            told = "velocity change"
        else:
            continue
        for factor, words in factors:
            if near(r[told], factor):
                value, wanted, unit, scale = shown[told]
                assert wanted is not None  # its ratio was taken
                found.append(f"its {told}, {value * scale:.4g} {unit}, is {r[told]:.4g} times "
                             f"{expected.source}'s {wanted * scale:.4g} {unit}: a probable unit "
                             f"error ({words}, a factor {factor:.6g}): check the header's "
                             f"units or give --{'accel' if factors is PEAK_FACTORS else 'time'}"
                             "-unit")
                break
    return found


def _warnings(q: RecordingQuality) -> list[str]:
    out = []
    t = q.time if q.time is not None else np.arange(q.samples) / q.rate
    if q.clip is not None:
        c = q.clip
        out.append(f"{q.name}: clipped: its {c.side} is held at {c.run.value:.6g} kG (zeroed) "
                   f"for {c.run.words(t)} ({c.why}: a smooth {c.side} holds there at most "
                   f"{c.allowed:.3g} samples at this rate, step and noise): the recorder's "
                   "range; every criterion is not measurable and judged FAIL")
    for r in q.dropouts:
        out.append(f"{q.name}: a dropout: {r.words(t)} hold one value, {r.value:.4g} kG "
                   "(zeroed), inside the pulse, which neither the signal nor its noise "
                   "makes: every criterion is not measurable: NOT JUDGED unless one fails "
                   "(record again)")
    if q.starts_inside:
        out.append(f"{q.name}: it starts inside the pulse (its first sample, zeroed, is "
                   f"{q.first:.4g} kG, above its noise and {INSIDE_FRACTION:.0%} of its "
                   "peak): the pulse's start was not recorded, so what needs it is not "
                   "measurable")
    if q.ends_inside:
        out.append(f"{q.name}: it ends inside the pulse (its last sample is above "
                   f"{INSIDE_FRACTION:.0%} of its peak): the pulse's end was not recorded, "
                   "so what needs it is not measurable")
    for words in q.units:
        out.append(f"{q.name}: {words}")
    return out
