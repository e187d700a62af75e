"""Did a pulse meet its specification? Criteria, margins and a verdict (issues 25 and 31).

One judge serves the recording (``accept``), the prediction (``fill``'s Summary) and every
shot of a Monte Carlo (``design --confidence``): :func:`judge_rows` takes a block of pulses on
one time grid and gives each criterion's value per pulse, with numpy over the block, so a
single pulse and ten thousand are judged by the same lines; :func:`judge_record` prepares a
recorded or predicted pulse the one way (its sampling, clipping and glitches checked, the
record judged made) and judges it.

Definitions (each verdict prints them, with every convention and where it came from):

- **record judged**: the one the specification names (unfiltered, or SAE J211 CFC N), or by
  default the tool's low-pass record: a 4-pole Bessel low-pass run both ways (no overshoot, no
  phase) at :data:`LOWPASS_PER_D` / D, D the nominal duration (the measured one without),
  which changes an ideal pulse's peak and duration by under 1 %. The rule depends on the
  specification and the record's rate only, never on one record's noise: a prediction and a
  recording of the same shot are judged on the same record (issue 60). Judged from rest; a
  single-sample glitch is taken out of the default record.
- **peak**: the largest sample of the record judged [kG].
- **duration** (``duration_def``): ``base``, each shape's own D: a half-sine's or a
  trapezoid's base, from the two crossings of 10 % of the peak (linearly interpolated)
  divided by the shape's width there (half-sine 1 - 2 asin(0.1)/pi = 0.9362, trapezoid with
  10 % ramps 0.98, none 1); a terminal-peak sawtooth's rise:
  its peak over the slope of a least-squares line through its rise from 10 % to 90 % (its
  decay does not count). ``width@10%``: the width between the 10 % crossings.
- **velocity change**: the trapezoidal integral of the acceleration [m/s] from ``dv_window``
  before the ideal pulse's start to ``dv_window`` after its end (without a shape: round the
  10 % crossings). A half-sine gives 2 A T / pi.
- **corridor**: the ideal pulse of the nominal peak and duration, placed over the record by
  least squares or with its peak on the record's; the limits are the ideal's largest and
  smallest values within ± the time slack (a sawtooth's upper one with its decay allowance,
  its lower one with none), plus and minus the band; before and after the pulse, over the
  ``monitor`` window, ± the band. A named shape is always judged: with no band given, the
  tool's ±20 % applies. The margin is the least distance to a limit, a fraction of the
  nominal peak.
- **SRS**: on the record as recorded by default (the default low-pass would take out what a
  spectrum measures), on the named record otherwise: the maximax absolute-acceleration SRS
  at the requirement's frequencies and Q; its
  margin at each is 20 log10(SRS / required) dB, inside [lower, upper]; up to the allowed
  fraction of frequencies may fall outside.

Limits are inclusive: a value on its limit is within it, to :data:`LIMIT_ULPS` units in the
last place of the limit (12 kG x 1.2 is 14.399999999999999 in binary). Margins are positive
inside the tolerance and negative outside: a fraction of the nominal for the figures and the
corridor, dB for the SRS.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import OptionError
from ..specification import Specification, shown_unit
from ..units import KG_MS2
from .recording_quality import Expected, RecordingQuality

#: Crossing level of the duration, a fraction of the peak (and the sawtooth rise's top).
DURATION_LEVEL = 0.10
RISE_TOP = 0.90

#: The trapezoid's rise and fall, each a fraction of its base.
TRAPEZOID_RAMP = 0.10

#: Samples over the nominal duration on which the ideal pulse is placed by least squares.
PLACEMENT_SAMPLES = 400

#: The default record's low-pass cut-off times the nominal duration, by shape: its fastest
#: feature sets it (a half-sine's whole base; a trapezoid's 10 % ramps; a sawtooth's decay).
#: Each keeps an ideal pulse's peak and duration within 1 % (tests/test_verdict_sign.py).
LOWPASS_PER_D = {"half-sine": 6.0, "none": 6.0, "trapezoid": 20.0, "sawtooth": 40.0}
LOWPASS_ORDER = 4

#: Above this fraction of the sample rate a cut-off would not filter: the record is judged as
#: it is, and the verdict says so.
LOWPASS_MAX_RATE = 0.4

#: Samples of rest prepended before a filter's start (REST_BEFORE) past which a fast record
#: gets only ten periods of the filter's cut-off (a 1 GHz record would take 2 million).
MAX_PAD = 20_000

#: A prediction's raw peak and its judged record's peak further apart than this fraction are
#: both shown, named (issue 60).
RAW_APART = 1e-3

#: A value on a limit is within it to this many units in the last place of the limit.
LIMIT_ULPS = 16

#: Fewest samples across the nominal duration: below it a verdict is refused; below
#: :data:`FEW_SAMPLES` it is warned, with the duration's resolution.
MIN_SAMPLES, FEW_SAMPLES = 3, 20

#: A single sample that stands out of both its neighbours, the same way, by this fraction of
#: the peak (and :data:`GLITCH_SIGMAS` of the noise) is a glitch.
GLITCH_FRACTION, GLITCH_SIGMAS = 0.1, 8.0

#: Samples at exactly the record's largest value, in a row, that mark it clipped.
CLIPPED_RUN = 3

#: A criterion within this many of its noise-induced standard deviations of a limit could be
#: moved across it by the pre-trigger noise: the verdict warns.
NOISE_FLIP_SIGMAS = 2.0

#: The coverage factor of a figure's expanded uncertainty U = k u (about 95 % of a normal's;
#: GUM, ILAC-G8). The same as :data:`NOISE_FLIP_SIGMAS`: a value within U of a limit is one
#: the noise could move across it.
COVERAGE_K = 2.0

#: The decision rules a verdict applies (ILAC-G8): ``simple`` acceptance (a value on or
#: inside its limits passes, its U stated) or ``guarded`` (a value passes only when it lies
#: inside its limits by at least U: a guard band of U).
DECISION_RULES = ("simple", "guarded")


def ideal(shape: str | None, t: np.ndarray, amplitude: float, duration: float,
          decay: float = 0.0) -> np.ndarray:
    """The ideal pulse [kG] at times ``t`` [s] from its start; a sawtooth rises over
    ``duration`` and falls to zero over ``decay`` x ``duration`` (0: at once)."""
    x = np.asarray(t, dtype=float) / duration
    if shape == "half-sine":
        y = np.where((x >= 0) & (x <= 1), np.sin(np.pi * np.clip(x, 0, 1)), 0.0)
    elif shape == "sawtooth":
        rise = np.where((x >= 0) & (x <= 1), np.clip(x, 0, 1), 0.0)
        fall = (1 - (x - 1) / decay) if decay > 0 else np.zeros_like(x)
        y = np.where((x > 1) & (x <= 1 + decay), fall, rise)
    elif shape == "trapezoid":
        y = np.where((x >= 0) & (x <= 1), np.clip(np.minimum(x, 1 - x) / TRAPEZOID_RAMP, 0,
                                                     1), 0.0)
    else:
        raise ValueError(f"no ideal pulse for the shape {shape!r}")
    return amplitude * y


def width_fraction(shape: str | None) -> float:
    """The shape's width at :data:`DURATION_LEVEL` of its peak, a fraction of its base (a
    sawtooth's without a decay)."""
    return {"half-sine": 1 - 2 * math.asin(DURATION_LEVEL) / math.pi,
            "sawtooth": 1 - DURATION_LEVEL,
            "trapezoid": 1 - 2 * TRAPEZOID_RAMP * DURATION_LEVEL}.get(shape or "none", 1.0)


def peak_offset(shape: str | None) -> float:
    """Time from the ideal's start to its peak, a fraction of its base."""
    return 1.0 if shape == "sawtooth" else 0.5


def duration_definition(shape: str | None, definition: str | None = "base") -> str:
    """How the duration is measured, in words, for a verdict."""
    if definition == "width@10%" or shape in (None, "none"):
        return f"the width between the crossings of {DURATION_LEVEL:.0%} of the peak"
    if shape == "sawtooth":
        return (f"the sawtooth's rise: its peak over the slope of a least-squares line through"
                f" its rise from {DURATION_LEVEL:.0%} to {RISE_TOP:.0%} of it (its decay does "
                "not count)")
    return (f"the {shape}'s base: the width between the crossings of {DURATION_LEVEL:.0%} "
            f"of the peak / {width_fraction(shape):.4f}")


def base_duration(spec: Specification) -> float:
    """The nominal D the ideal pulse is drawn with [s]: the nominal duration, or with
    ``width@10%`` the base whose width at 10 % it is."""
    nominal = _nominals(spec)[1]
    return nominal / width_fraction(spec.shape) if spec.duration_def == "width@10%" \
        else nominal


@dataclass
class Criterion:
    """One line of a verdict."""

    name: str
    value: float  # in ``unit``
    unit: str
    low: float | None  # limits in ``unit`` (None: open)
    high: float | None
    margin: float  # positive inside; in ``margin_unit``
    margin_unit: str  # "%" (of the nominal) or "dB"
    passed: bool
    detail: str = ""
    #: False when the record cannot show it (not measurable, and not shown outside its
    #: limits either): the verdict is NOT JUDGED unless another criterion failed
    judged: bool = True
    #: its standard uncertainty u [its unit] from what the recording shows (the noise at
    #: rest through the record's filter, the quantisation step, the sampling; NaN: not
    #: stated, a prediction's); its expanded one is :data:`COVERAGE_K` x u
    uncertainty: float = math.nan

    @property
    def expanded(self) -> float:
        """U = k u [its unit] (NaN where no uncertainty is stated)."""
        return COVERAGE_K * self.uncertainty

    def gap(self) -> float:
        """The distance [its unit] from its value to its nearest limit (the corridor's
        margin itself), NaN where it has none."""
        if self.name == "corridor":
            return abs(self.value)
        gaps = [abs(self.value - lim) for lim in (self.low, self.high) if lim is not None]
        return min(gaps) if gaps else math.nan

    @property
    def word(self) -> str:
        """PASS, FAIL or NOT JUDGED, as the verdict's line shows it."""
        return "PASS" if self.passed else "FAIL" if self.judged else "NOT JUDGED"


@dataclass
class Verdict:
    """The criteria judged, PASS when every one passed; what was used, and why not trusted."""

    criteria: list[Criterion]
    spec: Specification
    definitions: list[str]
    warnings: list[str] = field(default_factory=list)
    onset: float | None = None  # [s], the ideal pulse's start where placed
    window: tuple[float, float] | None = None  # [s], the span monitored
    record: tuple[np.ndarray, np.ndarray] | None = None  # (t [s], kg) of the record judged
    #: (t [s], kg) the SRS is computed on: the record judged where one is named; by default
    #: the record as recorded (the default low-pass would take out what a spectrum measures)
    srs_record: tuple[np.ndarray, np.ndarray] | None = None
    span: tuple[float, float] = (math.nan, math.nan)  # [s], the velocity change's window
    quality: RecordingQuality | None = None  # a recording's, as read before it was judged
    #: the test it is of (airgun_xl.identification: field -> text, those given)
    test: dict[str, str] = field(default_factory=dict)
    #: the decision rule applied (:data:`DECISION_RULES`; "" before one is)
    decision_rule: str = ""

    @property
    def passed(self) -> bool:
        """Every criterion judged and passed (False for NOT JUDGED too)."""
        return all(c.passed for c in self.criteria)

    @property
    def failed(self) -> bool:
        """A criterion judged and failed: FAIL, whatever the others."""
        return any(c.judged and not c.passed for c in self.criteria)

    @property
    def word(self) -> str:
        """PASS (every criterion passed), FAIL (one judged failed) or NOT JUDGED (none
        failed, and the record cannot show one: re-record or re-test; issue 63)."""
        return "PASS" if self.passed else "FAIL" if self.failed else "NOT JUDGED"

    def sources(self) -> list[str]:
        """Where each field of the specification came from, the defaults it used, and what a
        source gave that was not judged: a line each (:meth:`Specification.provenance`)."""
        from ..specification import unjudged

        return self.spec.provenance() + unjudged(self.spec)

    def tolerances(self) -> list[str]:
        """The tolerances used, one line each, as every verdict prints them."""
        return [f"{c.name}: {limits_text(c)}" for c in self.criteria]


def limits_text(c: Criterion) -> str:
    """A criterion's limits in words: ``9.6 to 14.4 kG``; a corridor's as its band."""
    if c.name == "corridor":
        return "the record inside the band (margin 0 % or more)"
    lo = "-inf" if c.low is None else f"{c.low:.5g}"
    hi = "+inf" if c.high is None else f"{c.high:.5g}"
    return f"{lo} to {hi} {c.unit}".strip()


def within(value, low, high):
    """``low <= value <= high`` with the limits widened by :data:`LIMIT_ULPS` units in their
    last place: a value on a limit, computed either side of it, is within it."""
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    slack = LIMIT_ULPS * np.spacing(np.maximum(np.abs(low), np.abs(high)))
    return (value >= low - slack) & (value <= high + slack)


def _crossing_before(t, kg, peak_index, level):
    """Each row's last crossing of ``level`` (per row) before its peak, interpolated (NaN
    where the record starts above it)."""
    m, n = kg.shape
    below = kg < level[:, None]
    before = below & (np.arange(n)[None, :] < peak_index[:, None])
    has = before.any(axis=1)
    i0 = np.minimum(n - 1 - np.argmax(before[:, ::-1], axis=1), n - 2)
    rows = np.arange(m)
    a0, a1 = kg[rows, i0], kg[rows, i0 + 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        start = t[i0] + (level - a0) / (a1 - a0) * (t[i0 + 1] - t[i0])
    return np.where(has, start, np.nan)


def _crossings(t: np.ndarray, kg: np.ndarray, peak_index: np.ndarray, peak: np.ndarray):
    """(start, end) [s] of each row's crossings of :data:`DURATION_LEVEL` x its peak round its
    peak, linearly interpolated (NaN where the record starts or ends above the level)."""
    m, n = kg.shape
    level = DURATION_LEVEL * peak
    start = _crossing_before(t, kg, peak_index, level)
    after = (kg < level[:, None]) & (np.arange(n)[None, :] > peak_index[:, None])
    has_after = after.any(axis=1)
    i1 = np.maximum(np.argmax(after, axis=1), 1)
    rows = np.arange(m)
    b0, b1 = kg[rows, i1 - 1], kg[rows, i1]
    with np.errstate(invalid="ignore", divide="ignore"):
        end = t[i1 - 1] + (b0 - level) / (b0 - b1) * (t[i1] - t[i1 - 1])
    return start, np.where(has_after, end, np.nan)


def _placement(t: np.ndarray, kg: np.ndarray, spec: Specification, peak_index: np.ndarray,
               refine: bool = False):
    """Each row's ideal pulse start [s]: least squares (the cross-correlation's best lag,
    refined by a parabola through its neighbours, and with ``refine`` to the minimum over
    every sample) or the peak rule."""
    dt = t[1] - t[0]
    amplitude, duration = _nominals(spec)[0], base_duration(spec)
    if spec.placement == "peak":
        return t[peak_index] - peak_offset(spec.shape) * duration
    if spec.shape == "sawtooth":
        return _rise_fits(t, kg, peak_index)[0]
    from scipy.signal import fftconvolve

    # on every q-th sample, q keeping PLACEMENT_SAMPLES over the pulse (a prediction at 0.5 us
    # has 10,000 over a 5 ms pulse); the parabola below places it to a fraction of q samples
    q = max(1, int(duration / dt) // PLACEMENT_SAMPLES)
    template = ideal(spec.shape, np.arange(0.0, duration + dt / 2, q * dt), amplitude,
                     duration)
    # minimising sum (a - ideal(t - t0))^2 over t0 is maximising sum a ideal(t - t0) while
    # the ideal lies inside the record
    corr = fftconvolve(kg[:, ::q], template[::-1][None, :], mode="valid", axes=1)
    k = np.argmax(corr, axis=1)
    rows = np.arange(len(k))
    km, kp = np.maximum(k - 1, 0), np.minimum(k + 1, corr.shape[1] - 1)
    c0, cm, cp = corr[rows, k], corr[rows, km], corr[rows, kp]
    denom = cm - 2 * c0 + cp
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where((denom < 0) & (km < k) & (kp > k), 0.5 * (cm - cp) / denom, 0.0)
    onset = t[0] + (k + np.clip(frac, -0.5, 0.5)) * q * dt
    if refine:  # a verdict's: to the least squares of every sample
        onset = np.array([_least_squares_onset(t, row, spec, t0, q * dt)
                          for row, t0 in zip(kg, onset, strict=True)])
    return onset


def _least_squares_onset(t: np.ndarray, a: np.ndarray, spec: Specification, t0: float,
                         reach: float) -> float:
    """The start within ``reach`` [s] of ``t0`` that minimises sum (a - ideal(t - start))^2
    over every sample (Newton steps on its exact derivative, each kept only where it lowers
    the sum): the decimated cross-correlation's parabola leaves up to a few samples."""
    amplitude, duration = _nominals(spec)[0], base_duration(spec)
    dt = float(t[1] - t[0])
    inside = (t >= t0 - 2 * reach - dt) & (t <= t0 + duration + 2 * reach + dt)
    ts, ys = t[inside], a[inside]

    def cost(start):
        return float(np.sum((ys - ideal(spec.shape, ts - start, amplitude, duration)) ** 2))

    best, best_cost = t0, cost(t0)
    h = dt / 4
    for _ in range(8):
        tau = ts - best
        i = ideal(spec.shape, tau, amplitude, duration)
        slope = (ideal(spec.shape, tau + h, amplitude, duration) -
                 ideal(spec.shape, tau - h, amplitude, duration)) / (2 * h)
        curvature = float(np.sum(slope ** 2))
        if curvature <= 0:
            break
        step = float(np.clip(-np.sum((ys - i) * slope) / curvature, -reach, reach))
        trial = float(np.clip(best + step, t0 - reach, t0 + reach))
        trial_cost = cost(trial)
        if trial_cost >= best_cost:
            break
        best, best_cost = trial, trial_cost
        if abs(step) < 1e-6 * dt:
            break
    return best


def _rise_fits(t: np.ndarray, kg: np.ndarray, peak_index: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Each row's sawtooth start [s] and rise slope [kG/s]: a least-squares line through its
    rise (the samples from 10 % to 90 % of its peak, before it), its start where it meets
    zero. Its decay, anywhere in the allowance, does not pull it as a whole-pulse fit would,
    and noise moves it less than two crossings."""
    onsets = np.full(len(kg), np.nan)
    slopes = np.full(len(kg), np.nan)
    for k, row in enumerate(kg):
        p = int(peak_index[k])
        peak = row[p]
        rising = np.flatnonzero(row[:p + 1] < DURATION_LEVEL * peak)
        first = int(rising[-1]) + 1 if len(rising) else 0
        part = slice(first, p + 1)
        keep = row[part] <= RISE_TOP * peak
        x, y = t[part][keep], row[part][keep]
        if len(x) >= 2 and np.ptp(x) > 0:
            slope, intercept = np.polyfit(x, y, 1)
            if slope > 0:
                onsets[k], slopes[k] = -intercept / slope, slope
    return onsets, slopes


def _nominals(spec: Specification) -> tuple[float, float]:
    """The nominal peak [kG] and duration [s] the ideal pulse is drawn from."""
    if spec.peak is None or spec.duration is None:
        raise ValueError("an ideal pulse needs a nominal peak and duration")
    return spec.peak.nominal, spec.duration.nominal


def corridor_limits(spec: Specification, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower limits [kG] at times ``tau`` [s] from the ideal's start: its largest
    and smallest values within ± the time slack, ± the band; a sawtooth's upper limit with
    its decay allowance, its lower one with none (the band admits any decay between).

    Every shape rises to its peak and then falls, so over a window [tau - s, tau + s] its
    largest value is the peak where the window holds the peak's time, else the larger end,
    and its smallest value is the smaller end: two evaluations, not a search.
    """
    spec = spec.resolved()
    assert spec.time_slack is not None  # resolved
    amplitude, duration = _nominals(spec)[0], base_duration(spec)
    slack = spec.time_slack * duration
    decay = spec.decay or 0.0
    early = ideal(spec.shape, tau - slack, amplitude, duration, decay)
    late = ideal(spec.shape, tau + slack, amplitude, duration, decay)
    low_early = ideal(spec.shape, tau - slack, amplitude, duration)
    low_late = ideal(spec.shape, tau + slack, amplitude, duration)
    t_peak = peak_offset(spec.shape) * duration
    holds_peak = (tau - slack <= t_peak) & (tau + slack >= t_peak)
    band = (spec.corridor or 0.0) * amplitude
    upper = np.where(holds_peak, amplitude, np.maximum(early, late))
    return upper + band, np.minimum(low_early, low_late) - band


def _window_seconds(window: tuple, reference) -> tuple:
    """A window's (before, after) [s]: a side in D times ``reference`` [s]."""
    return tuple(value * reference if unit == "D" else value for value, unit in window)


def judge_rows(t: np.ndarray, kg: np.ndarray, spec: Specification, refine: bool = False,
               recorded: tuple[float, float] | None = None) -> dict[str, np.ndarray]:
    """Each criterion's value for each row of ``kg`` (pulses [kG] on the grid ``t`` [s]);
    with ``refine`` (a verdict's, not a Monte Carlo's blocks) the least-squares placement is
    the minimum over every sample, not the decimated correlation's estimate.

    No figure rests on what was not recorded: ``recorded`` is the span [s] the samples were
    recorded over (the rest of ``t`` padding a filter's start; default all of it). A
    criterion that needs samples outside it is NaN (not measurable): a duration whose 10 %
    crossings (a sawtooth's rise) are not both inside; a velocity change or a corridor whose
    placed pulse is not, or whose window reaches past it by more than a sample. A window the
    specification did not give (the tool's default) is cut to the span round a recorded
    pulse instead, and ``span`` and ``monitored`` say where it was.

    Returns
    -------
    dict
        ``peak`` [kG], ``duration`` [s], ``velocity change`` [m/s], ``corridor`` (least
        margin, a fraction of the nominal peak; only with a corridor), ``onset`` [s],
        ``span`` (start and end [s] of the velocity change's window) and ``monitored`` (of
        the corridor's, as judged).
    """
    spec = spec.resolved()
    t = np.asarray(t, dtype=float)
    kg = np.atleast_2d(np.asarray(kg, dtype=float))
    dt = t[1] - t[0]
    lo_t, hi_t = (float(t[0]), float(t[-1])) if recorded is None else recorded
    peak_index = np.argmax(kg, axis=1)
    peak = kg[np.arange(len(kg)), peak_index]
    peak = np.where((t[peak_index] >= lo_t) & (t[peak_index] <= hi_t), peak, np.nan)
    start, end = _crossings(t, kg, peak_index, peak)
    # a crossing interpolated from a sample that was not recorded is not measured
    start = np.where(start > lo_t, start, np.nan)
    end = np.where(end < hi_t, end, np.nan)
    width = end - start
    if spec.duration_def == "width@10%":
        duration = width
    elif spec.shape == "sawtooth":  # its rise, from a recorded 10 % crossing
        duration = np.where(np.isfinite(start), peak / _rise_fits(t, kg, peak_index)[1],
                            np.nan)
    else:
        duration = width / width_fraction(spec.shape)
    out = {"peak": peak, "duration": duration}
    placed = spec.shape != "none" and spec.peak is not None and spec.duration is not None
    if placed:
        onset = _placement(t, kg, spec, peak_index, refine)
        length = np.full(len(kg), base_duration(spec))
        reference = spec.duration.nominal if spec.duration is not None else length
    else:
        length = width / width_fraction(spec.shape)
        onset = start - (1 - width_fraction(spec.shape)) / 2 * length
        reference = (spec.duration.nominal if spec.duration is not None else
                     np.nan_to_num(duration))
    decay = (spec.decay or 0.0) if spec.shape == "sawtooth" else 0.0
    ending = length * (1 + decay)
    assert spec.dv_window is not None and spec.monitor is not None  # resolved
    before, after = _window_seconds(spec.dv_window, reference)
    lo, hi = onset - before, onset + ending + after
    # the pulse itself must be recorded; a window the specification did not give (the
    # tool's default) is cut to the record round it, one it gave is judged whole or not at all
    pulse_in = (onset >= lo_t - dt) & (onset + ending <= hi_t + dt)
    if spec.origin("dv_window") == "default":
        lo, hi = np.maximum(lo, lo_t), np.minimum(hi, hi_t)
    out["onset"] = onset
    out["span"] = np.stack([lo, hi], axis=1)
    # the trapezoidal rule over the samples inside the span [lo, hi], row by row: partial
    # sums of the intervals, differenced at the span's first and last sample
    first = np.clip(np.searchsorted(t, lo, side="left"), 0, len(t) - 1)
    last = np.clip(np.searchsorted(t, hi, side="right") - 1, 0, len(t) - 1)
    sums = np.zeros((len(kg), len(t)))
    np.cumsum(0.5 * (kg[:, 1:] + kg[:, :-1]), axis=1, out=sums[:, 1:])
    rows = np.arange(len(kg))
    dv = np.where(last > first, sums[rows, last] - sums[rows, np.minimum(first, last)],
                  0.0) * dt * KG_MS2
    recorded_dv = pulse_in & (lo >= lo_t - dt) & (hi <= hi_t + dt)  # to within a sample
    out["velocity change"] = np.where(recorded_dv, dv, np.nan)
    m_before, m_after = _window_seconds(spec.monitor, reference)
    m_lo, m_hi = onset - m_before, onset + ending + m_after
    given = spec.origin("monitor") != "default"
    if not given:  # the tool's default window: what the record holds of it
        m_lo, m_hi = np.maximum(m_lo, lo_t), np.minimum(m_hi, hi_t)
    out["monitored"] = np.stack([m_lo, m_hi], axis=1)
    if spec.corridor is not None and placed:
        inside = (t[None, :] >= m_lo[:, None]) & (t[None, :] <= m_hi[:, None])
        upper, lower = corridor_limits(spec, t[None, :] - onset[:, None])
        room = np.minimum(upper - kg, kg - lower)
        where = np.where(inside, room, np.inf)
        worst = np.argmin(where, axis=1)
        margin = where[np.arange(len(worst)), worst] / _nominals(spec)[0]
        judged = pulse_in & (m_lo >= lo_t - dt) & (m_hi <= hi_t + dt)
        out["corridor"] = np.where(judged, margin, np.nan)
        # where the record comes nearest a limit (or passes it furthest), and which: +1 the
        # upper, -1 the lower (a failure located, issue 63)
        ahead = (np.broadcast_to(upper - kg, room.shape)[np.arange(len(worst)), worst]
                 <= np.broadcast_to(kg - lower, room.shape)[np.arange(len(worst)), worst])
        out["corridor at"] = np.where(judged, np.broadcast_to(t, room.shape)[
            np.arange(len(worst)), worst], np.nan)
        out["corridor side"] = np.where(ahead, 1.0, -1.0)
    return out


def _figure(name: str, value: float, tol, unit: str, scale: float) -> Criterion:
    lo, hi = tol.limits
    margin = min(value - lo, hi - value) / tol.nominal if math.isfinite(value) else -math.inf
    passed = bool(within(value, lo, hi)) if math.isfinite(value) else False
    return Criterion(name, float(value) * scale, unit, lo * scale, hi * scale,
                     float(100 * margin) if not passed or margin >= 0 else 0.0, "%", passed)


def srs_criterion(t: np.ndarray, kg: np.ndarray, spec: Specification) -> tuple[Criterion,
                                                                             np.ndarray]:
    """The SRS criterion and the margin at each required frequency [dB]."""
    from .shock import srs

    spec = spec.resolved()
    r = spec.srs
    if r is None or spec.srs_q is None or spec.srs_lower_db is None or \
            spec.srs_upper_db is None or spec.srs_outside is None:
        raise ValueError("the specification has no SRS requirement")
    q, lower_db, upper_db = spec.srs_q, spec.srs_lower_db, spec.srs_upper_db
    dt = float(t[1] - t[0])
    top = max(r.frequencies)
    named = dict(spec.places).get("srs", f"the SRS requirement ({spec.source or 'options'})")
    if top > 0.1 / dt:
        raise OptionError(f"{named}: found a row at "
                          f"{top:,.0f} Hz, above a tenth of the record's {1 / dt:,.0f} "
                          f"samples a second, where the SRS is not computed; expected "
                          f"requirement rows up to {0.1 / dt:,.0f} Hz, or a faster record")
    low, length = min(r.frequencies), float(t[-1] - t[0])
    if low * length < 1:  # below one cycle over the record: not resolved, and costly
        # as many digits as tell the two apart (9.98 ms resolves 100.2 Hz, not "100")
        digits = next((d for d in range(3, 17) if f"{low:.{d}g}" != f"{1 / length:.{d}g}"),
                      17)
        least = f"{1 / length:,.{digits}g}"
        raise OptionError(f"{named}: found a row at {low:.{digits}g} Hz, below the {least} "
                          f"Hz the record's {length * 1e3:,.4g} ms can resolve (one cycle "
                          f"over it); expected rows from {least} Hz, or a longer record")
    from .. import limits
    from .shock import decimated_for

    def cost(samples, step):  # the record and srs()'s rest after it, a filter step each
        return len(r.frequencies) * (samples + 1.5 / (low * step))

    values, step, factor = np.asarray(kg, dtype=float), dt, 1
    steps = cost(len(kg), dt)
    if steps > limits.MAX_SRS_STEPS:  # a fast record: on what its frequencies need
        values, step, factor = decimated_for(values, dt, top)
    if cost(len(values), step) > limits.MAX_SRS_STEPS:  # estimated before any is run
        raise OptionError(f"{named}: found {len(r.frequencies):,} rows over the record's "
                          f"{len(kg):,} samples ({steps:.2g} filter steps with the rest after "
                          f"it), expected at most {limits.MAX_SRS_STEPS:.2g}: fewer rows, or a "
                          "shorter record")
    levels = srs(values, step, np.array(r.frequencies), q)
    with np.errstate(divide="ignore"):
        margins = 20 * np.log10(levels / np.array(r.levels_kg))
    inside = within(margins, lower_db, upper_db)
    room = np.minimum(margins - lower_db, upper_db - margins)
    room = np.where(inside, np.maximum(room, 0.0), room)
    allowed = int(math.floor(spec.srs_outside * len(margins) + 1e-9))
    passed = int((~inside).sum()) <= allowed
    # the margin of the verdict: the (allowed + 1)-th smallest room, so that letting some
    # frequencies out shows
    margin = float(np.sort(room)[min(allowed, len(room) - 1)])
    names = ", ".join(f"{f:,.0f} Hz ({m:+.2f} dB)" for f, m in
                      zip(np.array(r.frequencies)[~inside], margins[~inside], strict=True))
    detail = (f"{int((~inside).sum())} of {len(margins)} frequencies outside (allowed "
              f"{allowed})" + (f": {names}" if names else "") + (
        f"; on the record decimated 1 in {factor:,} ({1 / step:,.0f} samples a second)"
        if factor > 1 else ""))
    worst = float(margins[np.argmin(room)])
    return Criterion("SRS", worst, "dB", lower_db, upper_db, margin, "dB", passed,
                     detail + f"; Q {q:g}"), margins


def _shown_peak(spec: Specification) -> str:
    unit, factor = shown_unit(spec, "peak")
    return f"{_nominals(spec)[0] * factor:.4g} {unit}"


def _window_words(window: tuple) -> str:
    from ..specification import show_window

    before, after = show_window(window).split(",")
    return f"{before} before, {after} after"


def judge(t: np.ndarray, kg: np.ndarray, spec: Specification,
          warnings: list[str] | None = None, record: str | None = None,
          recorded: tuple[float, float] | None = None,
          srs_record: tuple[np.ndarray, np.ndarray] | None = None) -> Verdict:
    """The verdict on one pulse ``kg`` [kG] sampled at ``t`` [s] (the record judged: already
    zeroed and filtered as the specification asks; ``record`` says how, in words; ``recorded``
    the span [s] its samples were recorded over, :func:`judge_rows`); the SRS on
    ``srs_record`` (t, kg) where given, else on the record judged."""
    spec = spec.resolved()
    values = judge_rows(t, kg, spec, refine=True, recorded=recorded)
    row = {k: v[0] for k, v in values.items()}
    lo_t, hi_t = (float(t[0]), float(t[-1])) if recorded is None else recorded
    criteria = []
    assert spec.dv_window is not None and spec.monitor is not None  # resolved
    definitions = [f"record judged: {record or describe_record(spec)}",
                   f"duration: {duration_definition(spec.shape, spec.duration_def)}"]
    if spec.peak is not None:  # in the units the specification gave
        criteria.append(_figure("peak", row["peak"], spec.peak, *shown_unit(spec, "peak")))
    if spec.duration is not None:
        criteria.append(_figure("duration", row["duration"], spec.duration,
                                *shown_unit(spec, "duration")))
    if spec.velocity_change is not None:
        criteria.append(_figure("velocity change", row["velocity change"],
                                spec.velocity_change, "m/s", 1.0))
    lo, hi = row["span"]
    definitions.append(f"velocity change: integrated from {lo * 1e3:.4f} to {hi * 1e3:.4f} ms"
                       f" ({_window_words(spec.dv_window)} the pulse)")
    m_lo, m_hi = row["monitored"]
    if "corridor" in row:
        margin = float(row["corridor"])
        decay = (f", decay allowed 0 to {spec.decay:.0%} of D" if spec.shape == "sawtooth"
                 else "")
        at = float(row["corridor at"])
        side = "upper" if row["corridor side"] > 0 else "lower"
        located = ("" if not math.isfinite(at) else
                   f"; {'outside' if margin < 0 else 'nearest'} its {side} limit at "
                   f"{at * 1e3:.4f} ms, by {abs(margin):.2%} of the nominal peak")
        criteria.append(Criterion("corridor", 100 * margin, "%", 0.0, None,
                                  100 * margin, "%", margin >= 0,
                                  f"±{spec.corridor:.0%} of {_shown_peak(spec)}, time "
                                  f"slack ±{spec.time_slack:.0%}, placed by "
                                  f"{spec.placement}{decay}{located}"))
        definitions.append(f"corridor: the ideal {spec.shape} starts at "
                           f"{row['onset'] * 1e3:.4f} ms ({spec.placement}); monitored from "
                           f"{m_lo * 1e3:.4f} to {m_hi * 1e3:.4f} ms "
                           f"({_window_words(spec.monitor)} the pulse)")
    elif spec.shape == "none":
        definitions.append("shape: none, so the limits only: no corridor judged")
    if spec.srs is not None:
        ts, ks = srs_record if srs_record is not None else (t, kg)
        criteria.append(srs_criterion(np.asarray(ts), np.asarray(ks), spec)[0])
        if srs_record is not None:
            definitions.append("SRS: on the record as recorded (the default record's "
                               "low-pass would take out what a spectrum measures)")
    verdict = Verdict(criteria, spec, definitions, list(warnings or []),
                      float(row["onset"]) if math.isfinite(row["onset"]) else None,
                      (float(m_lo), float(m_hi)) if math.isfinite(m_lo) and math.isfinite(m_hi)
                      else None)
    verdict.span = (float(lo), float(hi))
    verdict.definitions += verdict.sources()
    if not criteria:
        verdict.warnings.append("the specification gives no criterion: nothing was judged")
    reference = spec.duration.nominal if spec.duration else (
        row["duration"] if math.isfinite(row["duration"]) else 0.0)
    ending = (base_duration(spec) if "corridor" in row or spec.shape not in (None, "none")
              and spec.peak is not None and spec.duration is not None
              else reference) * (1 + ((spec.decay or 0.0) if spec.shape == "sawtooth" else 0.0))
    for key, name, (a, b) in (("dv_window", "velocity change", (lo, hi)),
                              ("monitor", "corridor", (m_lo, m_hi))):
        judged = "corridor" in row if name == "corridor" else spec.velocity_change is not None
        if spec.origin(key) != "default" or not judged or not (
                math.isfinite(a) and math.isfinite(b)):
            continue
        wanted = _window_seconds(getattr(spec, key), reference)
        start, stop = row["onset"] - wanted[0], row["onset"] + ending + wanted[1]
        if a > start + 1e-12 or b < stop - 1e-12:
            option = "--dv-window" if key == "dv_window" else "--monitor"
            verdict.warnings.append(
                f"{name}: {'integrated' if key == 'dv_window' else 'monitored'} from "
                f"{a * 1e3:.4f} to {b * 1e3:.4f} ms only, what the record holds of the tool's "
                f"default window ({start * 1e3:.4f} to {stop * 1e3:.4f} ms, "
                f"{_window_words(getattr(spec, key))} the pulse): give {option} to judge a "
                "window of your own")
    reasons = _unmeasured(row, spec, (lo_t, hi_t))
    for c in criteria:
        if not math.isfinite(c.value):
            unmeasurable(verdict, c, reasons.get(c.name, "it could not be measured on this "
                                                 "pulse"),
                         _outlasts(t, kg, c) if c.name == "duration" else None)
    return verdict


def _outlasts(t: np.ndarray, kg: np.ndarray, c: Criterion) -> str | None:
    """Of a duration the record cannot measure because the pulse outlasts it (its start at
    10 % recorded, the record ending above 10 % of the peak): the words saying it is longer
    than its upper limit all the same, when the record already shows that; else None."""
    if c.high is None or not len(kg):
        return None
    top = int(np.argmax(kg))
    level = DURATION_LEVEL * float(kg[top])
    below = np.flatnonzero(kg[:top] < level)
    if not len(below) or kg[-1] < level or float(kg[top]) <= 0:
        return None
    from ..units import SHOWN_UNITS

    scale = dict(SHOWN_UNITS["duration"].values()).get(c.unit, math.nan)  # unit per second
    least = (float(t[-1]) - float(t[below[-1] + 1])) * scale
    if not least > c.high:
        return None
    return (f"the pulse outlasts the record, which shows it at least {least:.5g} {c.unit} "
            f"long, past its upper limit of {c.high:.5g} {c.unit}")


#: What to change so that a criterion the record cannot show can be judged.
REMEDY = {"peak": "record the whole pulse (a longer record, an earlier trigger)",
          "duration": "record the pulse's start and end (more pre-trigger, a longer record)",
          "velocity change": "a pre-trigger and a record after the pulse as long as its "
                             "window, or a shorter --dv-window",
          "corridor": "more pre-trigger and a longer record, or a shorter --monitor",
          "SRS": "record the whole pulse and its rest"}


def unmeasurable(verdict: Verdict, c: Criterion, why: str, proven: str | None = None,
                 say: bool = True) -> None:
    """``c`` cannot be measured on the record (``why``): NOT JUDGED, its remedy said, unless
    the record shows it outside its limits all the same (``proven``, in words): FAIL.
    ``say`` False where a warning of the recording's already says it."""
    c.passed, c.value, c.margin, c.judged = False, math.nan, -math.inf, proven is not None
    c.detail = f"not measurable: {why}" + (f"; {c.detail}" if c.detail else "")
    if not say:
        return
    if proven is not None:
        verdict.warnings.append(f"{c.name}: not measurable: {why}; {proven}: judged FAIL")
    else:
        verdict.warnings.append(
            f"{c.name}: not measurable: {why}: NOT JUDGED (the record cannot show it; to "
            f"judge it, {REMEDY.get(c.name, 'record it whole')})")


def _span_words(lo: float, hi: float) -> str:
    return f"{lo * 1e3:.4f} to {hi * 1e3:.4f} ms"


def _unmeasured(row: dict, spec: Specification, recorded: tuple[float, float]
                ) -> dict[str, str]:
    """Why each criterion :func:`judge_rows` left NaN was not measured, in words."""
    lo_t, hi_t = recorded
    span = (f"the record, {_span_words(lo_t, hi_t)}" if math.isfinite(lo_t) else
            f"the run, which ends at {hi_t * 1e3:.4f} ms")
    level = f"{DURATION_LEVEL:.0%}"
    out = {"peak": f"the record's largest sample lies outside {span}",
           "duration": f"a {level} crossing of the pulse is not inside {span} (it starts or "
                       f"ends above {level} of its peak)"}
    lo, hi = row["span"]
    if math.isfinite(lo) and math.isfinite(hi):
        out["velocity change"] = (f"its window, {_span_words(lo, hi)}, reaches past {span}")
    else:
        out["velocity change"] = "its window could not be placed (no pulse start recorded)"
    onset = row["onset"]
    m_lo, m_hi = row["monitored"]
    if not math.isfinite(onset):
        out["corridor"] = "the ideal pulse could not be placed"
    else:
        out["corridor"] = (f"the ideal pulse placed from {onset * 1e3:.4f} ms or the monitored "
                           f"window, {_span_words(m_lo, m_hi)}, reaches past {span}")
    return out


# -- the record judged ---------------------------------------------------------------------------

def lowpass_hz(spec: Specification, duration: float) -> float:
    """The default record's cut-off [Hz] for a pulse of ``duration`` [s]."""
    return LOWPASS_PER_D.get(spec.shape or "none", LOWPASS_PER_D["none"]) / duration


def describe_record(spec: Specification, duration: float | None = None,
                    dt: float | None = None) -> str:
    """The record judged, in words, as the verdict prints it."""
    if spec.judged.cfc:
        return f"CFC {spec.judged.cfc} (SAE J211), both ways"
    if spec.judged.is_unfiltered:
        return "unfiltered"
    per_d = LOWPASS_PER_D.get(spec.shape or "none", LOWPASS_PER_D["none"])
    if duration is None or not math.isfinite(duration) or duration <= 0:
        return (f"the tool's default: a {LOWPASS_ORDER}-pole Bessel low-pass at {per_d:g}/D, "
                "both ways (no record named)")
    hz = per_d / duration
    which = "nominal" if spec.duration is not None else "measured"
    if dt is not None and hz > LOWPASS_MAX_RATE / dt:
        return (f"unfiltered: the tool's default low-pass ({per_d:g}/D = {hz:,.0f} Hz, D the "
                f"{which} duration) lies above {LOWPASS_MAX_RATE:g} of the rate")
    return (f"the tool's default: a {LOWPASS_ORDER}-pole Bessel low-pass at {hz:,.0f} Hz "
            f"({per_d:g}/D, D the {which} {duration * 1e3:.4g} ms), both ways (no record "
            "named)")


def _reference_duration(t: np.ndarray, kg: np.ndarray, spec: Specification) -> np.ndarray:
    """Each row's D for the default low-pass: the nominal duration, else the measured one."""
    if spec.duration is not None:
        return np.full(len(kg), spec.duration.nominal)
    return np.nan_to_num(judge_rows(t, kg, spec.resolved())["duration"], nan=0.0)


def judged_record(t: np.ndarray, kg: np.ndarray, spec: Specification
                  ) -> tuple[np.ndarray, np.ndarray, str]:
    """A pulse (or a block of them, a row each) as the specification judges it, from rest
    (:data:`~airgun_xl.studies.measured.REST_BEFORE` of it prepended, for a phaseless
    filter's lead): through its CFC, unchanged (unfiltered), or by default through the
    low-pass of :func:`lowpass_hz` (unfiltered where that cut-off lies above
    :data:`LOWPASS_MAX_RATE` of the rate); and the record in words. The rule is the
    specification's and the rate's alone: a prediction and a recording go through the same
    one, whatever their noise."""
    from .measured import REST_BEFORE
    from .shock import cfc_filter

    kg = np.asarray(kg, dtype=float)
    record = spec.judged
    if record.is_unfiltered:  # the record as it is
        return t, kg, describe_record(spec)
    dt = float(t[1] - t[0])
    rows = np.atleast_2d(kg)
    durations = _reference_duration(t, rows, spec) if not record.cfc else None
    n = int(round(REST_BEFORE / dt))
    if n > MAX_PAD:  # a fast record: ten periods of the filter's cut-off lead it in
        longest = float(np.max(durations)) if durations is not None else 0.0
        hz = record.cfc * 1.65 if record.cfc else lowpass_hz(spec, longest or math.inf)
        n = min(n, max(MAX_PAD, int(math.ceil(10 / (hz * dt)))) if hz > 0 else n)
    t = np.concatenate([t[0] - dt * np.arange(n, 0, -1), t])
    padded = np.concatenate([np.zeros(kg.shape[:-1] + (n,)), kg], axis=-1)
    if record.cfc:
        return t, cfc_filter(padded, dt, record.cfc), describe_record(spec)
    from scipy.signal import bessel, sosfiltfilt

    assert durations is not None
    out = np.atleast_2d(padded).copy()
    cutoffs = np.array([lowpass_hz(spec, d) if d > 0 else math.inf for d in durations])
    # the rows of one cut-off (every row, where the specification gives the nominal D)
    # through one filter designed once, all at once: each row's numbers are those of its
    # own pass (sosfiltfilt filters along the last axis, row by row)
    for hz in dict.fromkeys(cutoffs.tolist()):
        if hz <= LOWPASS_MAX_RATE / dt:
            rows_of = np.flatnonzero(cutoffs == hz)
            sos = bessel(LOWPASS_ORDER, hz, fs=1 / dt, output="sos", norm="mag")
            out[rows_of] = sosfiltfilt(sos, out[rows_of], axis=-1)
    words = describe_record(spec, float(durations[0]), dt)
    return t, (out if kg.ndim > 1 else out[0]), words


def sampling_checks(dt: float, spec: Specification, what: str, t: np.ndarray | None = None,
                    kg: np.ndarray | None = None) -> list[str]:
    """Refuse a record with fewer than :data:`MIN_SAMPLES` samples across the nominal
    duration (naming a probable unit error of its time column where the pulse in ``t``,
    ``kg`` is as much wider than the nominal as a unit makes it); warn below
    :data:`FEW_SAMPLES`, stating the duration's resolution."""
    if spec.duration is None:
        return []
    d = spec.duration.nominal
    n = d / dt
    if n < MIN_SAMPLES:
        hint = ""
        if t is not None and kg is not None:
            from .recording_quality import TIME_FACTORS, UNIT_BAND

            body = np.flatnonzero(kg >= DURATION_LEVEL * np.max(kg))
            width = float(t[body[-1]] - t[body[0]]) if len(body) > 1 else 0.0
            for factor, words in TIME_FACTORS if width > 0 else ():
                if abs(math.log(width / d / factor)) < math.log(UNIT_BAND):
                    hint = (f"; its pulse is {width * 1e3:.4g} ms wide, {width / d:.4g} times "
                            f"the nominal: a probable unit error of the time column "
                            f"({words}): check its header or give --time-unit")
                    break
        raise OptionError(f"{what}: found {1 / dt:,.0f} samples a second, {n:.2g} across the "
                          f"nominal duration {d * 1e3:.4g} ms, expected at least "
                          f"{MIN_SAMPLES} (a rate of {MIN_SAMPLES / d:,.0f} or more){hint}")
    if n < FEW_SAMPLES:
        return [f"{what}: {n:.3g} samples across the nominal duration {d * 1e3:.4g} ms "
                f"({1 / dt:,.0f} a second), fewer than {FEW_SAMPLES}: its crossings are "
                f"placed to about ±{dt * 1e3 / 2:.3g} ms each, so the duration is resolved to "
                f"about ±{dt * 1e3:.3g} ms ({100 * dt / d:.0f} % of D); the peak may fall "
                "between samples"]
    return []


def glitches(kg: np.ndarray, noise: float) -> np.ndarray:
    """Indices of single samples that stand out of both neighbours the same way by more than
    :data:`GLITCH_FRACTION` of the peak and :data:`GLITCH_SIGMAS` x the noise."""
    kg = np.asarray(kg, dtype=float)
    if len(kg) < 3:
        return np.array([], dtype=int)
    left, right = kg[1:-1] - kg[:-2], kg[1:-1] - kg[2:]
    noise = noise if math.isfinite(noise) else 0.0
    floor = max(GLITCH_FRACTION * float(np.max(np.abs(kg))), GLITCH_SIGMAS * noise)
    out = (np.sign(left) == np.sign(right)) & (np.minimum(np.abs(left), np.abs(right)) > floor)
    return np.flatnonzero(out) + 1


def judge_record(t: np.ndarray, kg: np.ndarray, spec: Specification, what: str,
                 noise: float = math.nan, warnings: list[str] | None = None,
                 quality: RecordingQuality | None = None, prediction: bool = False
                 ) -> Verdict:
    """The verdict on a recorded or predicted pulse ``kg`` [kG] (zeroed, unfiltered) at
    ``t`` [s], named ``what`` in messages; ``noise`` is its rest's standard deviation [kG]
    (NaN: unknown). The sampling is checked, single-sample glitches are taken out of the
    default record (and warned either way), a criterion the noise could move across its
    limit is warned, and no figure rests on samples that were not recorded (the padding a
    filter starts from; before a ``prediction``'s first sample it is at rest, known).

    ``quality`` (a recording's, :func:`~.recording_quality.assess`; its findings are
    already among ``warnings``): a clipped record or one with a dropout inside the pulse
    measures no criterion (each FAIL, not measurable); one that starts or ends inside the
    pulse measures no SRS (the spectrum of a pulse cut short)."""
    spec = spec.resolved()
    t = np.asarray(t, dtype=float)
    kg = np.asarray(kg, dtype=float)
    dt = float(t[1] - t[0])
    recorded = (-math.inf if prediction else float(t[0]), float(t[-1]))
    said = list(warnings or []) + sampling_checks(dt, spec, what, t, kg)
    spikes = glitches(kg, noise)
    if len(spikes):
        shown = ", ".join(f"{t[i] * 1e3:.4f} ms ({kg[i]:.4g} kG)" for i in spikes[:5])
        more = f" and {len(spikes) - 5} more" if len(spikes) > 5 else ""
        if spec.judged.is_default:  # taken out, each by its neighbours' mean
            kg = kg.copy()
            kg[spikes] = 0.5 * (kg[spikes - 1] + kg[np.minimum(spikes + 1, len(kg) - 1)])
            said.append(f"{what}: {len(spikes)} single-sample glitch"
                        f"{'es' * (len(spikes) != 1)} at {shown}{more}, taken out of the "
                        "record judged (each replaced by its neighbours' mean)")
        else:
            said.append(f"{what}: {len(spikes)} single-sample glitch"
                        f"{'es' * (len(spikes) != 1)} at {shown}{more}, kept in the record "
                        f"judged ({describe_record(spec)}, as the specification names it): "
                        "it may lift the peak")
    if not math.isfinite(noise):
        said.append(f"{what}: its noise is unknown (no record at rest before or after the "
                    "pulse): whether noise could move a criterion across its limit was not "
                    "checked")
    tj, kj, words = judged_record(t, kg, spec)
    spectral = (t, kg) if spec.judged.is_default else (tj, kj)
    verdict = judge(tj, kj, spec, said, record=words, recorded=recorded,
                    srs_record=spectral if spec.judged.is_default else None)
    if prediction:  # at rest before its first sample by construction: the lead is the model's
        verdict.record = (tj, kj)
    else:  # the filter's lead over samples never recorded is not data: never shown as such
        kept = tj >= t[0] - 0.5 * dt
        verdict.record = (tj[kept], kj[kept])
    verdict.srs_record = spectral
    verdict.quality = quality
    damaged = quality.damaged if quality is not None else None
    cut = quality is not None and (quality.starts_inside or quality.ends_inside)
    for c in verdict.criteria:
        why = damaged or ("the record starts or ends inside the pulse: the spectrum of a "
                          "pulse cut short" if cut and c.name == "SRS" else None)
        if why and math.isfinite(c.value):
            # a clipped record shows the pulse reached the recorder's range: FAIL (issue
            # 63); a dropout or a spectrum cut short shows nothing: NOT JUDGED
            clipped = quality is not None and quality.clip is not None and why == damaged
            unmeasurable(verdict, c, why, "the pulse reached the recorder's range"
                         if clipped else None, say=why != damaged)
    if math.isfinite(noise) and noise > 0 and not prediction:
        lsb = quality.lsb if quality is not None and math.isfinite(quality.lsb) else 0.0
        u = standard_uncertainties(verdict, tj, kj, spec, noise, lsb)
        for c in verdict.criteria:
            if c.name in u and math.isfinite(c.value):
                c.uncertainty = u[c.name]
        verdict.warnings += noise_could_flip(verdict, spec, noise, what)
    return verdict


def standard_uncertainties(verdict: Verdict, t: np.ndarray, kg: np.ndarray,
                           spec: Specification, noise: float, lsb: float = 0.0
                           ) -> dict[str, float]:
    """Each criterion's standard uncertainty [its unit] from what the recording shows, on the
    record judged ``kg`` [kG] at ``t`` [s]: the noise at rest (``noise`` [kG], 1 sigma,
    unfiltered) through the record's filter (:func:`noise_gain`, exact for white noise),
    the quantisation step ``lsb`` [kG] (uniform: lsb / sqrt(12)), and
    for the peak the sampling (the crest between samples: up to c dt^2 / 8 below it, c the
    curvature there; uniform); the duration's two crossings move by that noise over the
    record's slope at 10 % (its linear interpolation errs by a second-order term, under 1e-4
    of D at 20 samples across D: left out); the velocity change by the noise integrated over
    its window. docs/acceptance.md gives the derivation and its Monte Carlo check."""
    dt = float(t[1] - t[0])
    peak = float(np.max(kg))
    duration = float(_reference_duration(t, np.atleast_2d(kg), spec)[0])
    sigma = math.hypot(noise * noise_gain(spec, dt, duration), lsb / math.sqrt(12.0))
    top = int(np.argmax(kg))
    curvature = abs(float(kg[top - 1] - 2 * kg[top] + kg[top + 1])) / dt ** 2 \
        if 0 < top < len(kg) - 1 else 0.0
    sampling = curvature * dt ** 2 / 8 / math.sqrt(3.0)
    slope = np.abs(np.gradient(kg, dt))
    level = DURATION_LEVEL * peak
    near = np.abs(kg - level) < 0.05 * peak
    steep = float(np.median(slope[near])) if near.any() else math.inf
    lo, hi = verdict.span  # the velocity change's window, as judged
    n_dv = max(1, int(round((hi - lo) / dt))) if math.isfinite(hi - lo) else len(kg)
    return {"peak": math.hypot(sigma, sampling) * shown_unit(spec, "peak")[1],
            "duration": (math.sqrt(2) * sigma / steep * shown_unit(spec, "duration")[1]
                         if steep > 0 else math.inf),
            "velocity change": math.hypot(noise * math.sqrt(n_dv), lsb / math.sqrt(12.0))
            * dt * KG_MS2,
            "corridor": 100 * sigma / (spec.peak.nominal if spec.peak else peak)}


def noise_gain(spec: Specification, dt: float, duration: float) -> float:
    """The share [-] of a white noise's standard deviation the record's filter (both ways,
    at the step ``dt`` [s]; the default low-pass's cut-off from ``duration`` [s]) leaves:
    sqrt(sum h^2) of its impulse response, the filter run on a unit impulse (exact for
    white noise; 1 for the unfiltered record)."""
    from scipy.signal import bessel, sosfiltfilt

    from .shock import cfc_filter

    record = spec.judged
    if record.is_unfiltered:
        return 1.0
    # J211's -3 dB point is 1.65 x its class; the low-pass's is its cut-off
    # a duration unknown (0) leaves the default record unfiltered, as judged_record does
    hz = record.cfc * 1.65 if record.cfc else (
        lowpass_hz(spec, duration) if duration > 0 else math.inf)
    if not record.cfc and not hz <= LOWPASS_MAX_RATE / dt:
        return 1.0  # the default record unfiltered at this rate
    n = int(min(200_000, max(256, math.ceil(40 / (hz * dt)))))  # 40 periods each side
    impulse = np.zeros(2 * n + 1)
    impulse[n] = 1.0
    out = cfc_filter(impulse, dt, record.cfc) if record.cfc else sosfiltfilt(
        bessel(LOWPASS_ORDER, hz, fs=1 / dt, output="sos", norm="mag"), impulse)
    return float(np.sqrt(np.sum(out ** 2)))


def noise_could_flip(verdict: Verdict, spec: Specification, noise: float, what: str
                     ) -> list[str]:
    """Warnings for the criteria that the rest's noise (``noise`` [kG], 1 sigma, unfiltered)
    could move across a limit: within :data:`NOISE_FLIP_SIGMAS` of their uncertainty."""
    said = []
    for c in verdict.criteria:
        effect = c.uncertainty
        if not (math.isfinite(effect) and math.isfinite(c.value)):
            continue
        gap = c.gap()
        if gap <= NOISE_FLIP_SIGMAS * effect:
            said.append(f"{what}: the noise at rest ({noise:.3g} kG, 1 sigma; about "
                        f"{effect:.3g} {c.unit} on the {c.name} of the record judged) could "
                        f"move the {c.name} across its limit: it is {gap:.3g} {c.unit} from "
                        f"it; the {c.name}'s {'PASS' if c.passed else 'FAIL'} is not sure")
    return said


def apply_decision_rule(verdict: Verdict, rule: str = "simple") -> None:
    """Apply ``rule`` (:data:`DECISION_RULES`) and state it: under ``guarded`` a criterion
    passed within its U of a limit is not accepted (FAIL, said); under ``simple`` it stands,
    marked. The rule and the coverage factor are a line of the verdict's definitions."""
    verdict.decision_rule = rule
    verdict.definitions.append(
        "decision rule: " + ("simple acceptance (ILAC-G8): a value on or inside its limits "
                             "passes; each figure's expanded uncertainty U (k = 2, about 95 %) "
                             "is stated beside it" if rule == "simple" else
                             "guarded acceptance (ILAC-G8): a value passes only inside its "
                             "limits by its expanded uncertainty U (k = 2, about 95 %), a "
                             "guard band of U"))
    for c in verdict.criteria:
        u = c.expanded
        if not (math.isfinite(u) and math.isfinite(c.value) and c.judged):
            continue
        if c.gap() < u:
            within = f"within its U ({u:.3g} {c.unit}) of a limit"
            if rule == "guarded" and c.passed:
                c.passed = False
                c.detail = (f"{within}: not accepted (guarded acceptance)"
                            + (f"; {c.detail}" if c.detail else ""))
            else:
                c.detail = (f"{within}: judged as measured (simple acceptance)"
                            + (f"; {c.detail}" if c.detail else ""))


def predicted_verdict(result, spec: Specification) -> Verdict:
    """The verdict on a run's predicted pulse (the test item's acceleration, at rest before
    the impact), judged as a recording is (:func:`judge_record`)."""
    from .shock import check_cfc

    spec = spec.resolved()
    ok = np.isfinite(result.accel_kg)
    t, kg = result.history.time[ok], result.accel_kg[ok]
    warnings: list[str] = []
    if spec.judged.cfc:
        try:
            warnings += check_cfc(spec.judged.cfc, float(t[1] - t[0]))
        except OptionError as exc:
            raise OptionError(f"the specification's record (CFC {spec.judged.cfc}): {exc}"
                              ) from None
    verdict = judge_record(t, kg, spec, "the predicted pulse", noise=0.0, warnings=warnings,
                           prediction=True)
    verdict.definitions.insert(0, "judged: the predicted pulse (the test item's acceleration)")
    raw = float(np.max(kg)) if kg.size else math.nan
    judged = next((c.value for c in verdict.criteria if c.name == "peak"), math.nan)
    if math.isfinite(raw) and math.isfinite(judged) and abs(raw - judged) > RAW_APART * raw:
        verdict.definitions.insert(1, (
            f"the model's raw pulse peaks at {raw:.4g} kG (the Summary's raw peak); the "
            f"verdict's {judged:.4g} kG is the record judged, as a recording of this shot "
            "would be judged: the raw peak is the model's, not a verdict"))
    return verdict


#: accept runs the shot's prediction, to tell a recording's unit error, up to this many rows
#: (about a second); past it the specification's nominals alone are its reference.
PREDICTION_ROWS = 2_000_000


def expectations(shot, spec: Specification) -> tuple[list[Expected], list[str]]:
    """What a recording judged against ``spec`` for ``shot`` is expected to show (to tell a
    probable unit error): the specification's nominals, and the shot's prediction where it
    runs in :data:`PREDICTION_ROWS` rows or fewer; and a note for what was not used."""
    out, notes = [], []
    if not spec.empty:
        out.append(Expected(spec.peak.nominal if spec.peak else None,
                            spec.duration.nominal if spec.duration else None,
                            spec.velocity_change.nominal if spec.velocity_change else None,
                            "the specification's nominal"))
    rows = shot.params.rows
    if rows <= PREDICTION_ROWS:
        result = shot.run(track=())
        out.append(Expected.of_pulse(result.history.time, result.accel_kg))
    else:
        notes.append(f"the shot's prediction was not run to check the recording's units "
                     f"({rows:,} rows, over {PREDICTION_ROWS:,}): the specification's "
                     "nominals alone were")
    return out, notes


def pass_flags(values: dict[str, np.ndarray], spec: Specification) -> dict[str, np.ndarray]:
    """Each criterion's PASS per row of :func:`judge_rows`' values (the SRS is not among
    them: it is judged on single pulses)."""
    flags = {}
    for name, tol in (("peak", spec.peak), ("duration", spec.duration),
                      ("velocity change", spec.velocity_change)):
        if tol is not None:
            lo, hi = tol.limits
            flags[name] = within(values[name], lo, hi)
    if "corridor" in values:
        flags["corridor"] = values["corridor"] >= 0
    return flags


#: The columns of :class:`BlockJudge`'s values.
BLOCK_VALUES = ("peak", "duration", "velocity change", "corridor")


@dataclass(frozen=True)
class BlockJudge:
    """``run_batch``'s ``extra``: each shot's :data:`BLOCK_VALUES`, judged as
    :func:`predicted_verdict` judges one shot (picklable, for Dask workers)."""

    spec: Specification
    width: int = len(BLOCK_VALUES)

    def __call__(self, t: np.ndarray, kg: np.ndarray) -> np.ndarray:
        spec = self.spec.resolved()
        last = float(t[-1])  # a prediction: at rest before its first sample, known
        t, kg, _ = judged_record(t, kg, spec)
        values = judge_rows(t, kg, spec, recorded=(-math.inf, last))
        return np.column_stack([values.get(name, np.full(len(kg), np.nan))
                                for name in BLOCK_VALUES])


def flags_of(values: np.ndarray, spec: Specification) -> dict[str, np.ndarray]:
    """:func:`pass_flags` of a :class:`BlockJudge`'s columns; a diverged shot (NaN) fails
    every criterion."""
    spec = spec.resolved()
    named = {name: values[:, k] for k, name in enumerate(BLOCK_VALUES)}
    if spec.corridor is None or spec.shape in (None, "none"):
        named.pop("corridor")
    return pass_flags(named, spec)


def wilson_interval(passes: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """The Wilson score interval of a proportion (95 % by default)."""
    if n == 0:
        return 0.0, 1.0
    p = passes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def pseudo_velocity(frequencies: np.ndarray, srs_kg: np.ndarray) -> np.ndarray:
    """The pseudo-velocity shock spectrum [m/s] from the absolute-acceleration SRS [kG]:
    PV = SRS / (2 pi f), exact for an undamped oscillator (the absolute acceleration is then
    omega^2 times the relative displacement), within the damping's share 1/(2Q) otherwise."""
    return np.asarray(srs_kg) * KG_MS2 / (2 * np.pi * np.asarray(frequencies))


def equivalent_half_sine(t: np.ndarray, kg: np.ndarray, frequencies: np.ndarray,
                         q: float = 10.0, durations: np.ndarray | None = None):
    """The smallest half-sine whose SRS envelops the pulse's at every frequency.

    For each candidate duration T the least peak that envelops is max over f of SRS(f) /
    SRS_unit(f; T) (the SRS is linear in the peak); the smallest such peak wins.

    Returns
    -------
    (peak [kG], duration [s], governing frequency [Hz])
    """
    from scipy.optimize import minimize_scalar

    from .shock import srs

    dt = t[1] - t[0]
    target = srs(np.asarray(kg, dtype=float), dt, frequencies, q)

    def least_peak(duration):
        n = int(math.ceil(duration / dt)) + 1
        unit = ideal("half-sine", np.arange(n) * dt, 1.0, duration)
        response = srs(unit, dt, frequencies, q)
        with np.errstate(divide="ignore", invalid="ignore"):  # a half-sine between samples
            ratio = np.where(response > 0, target / response, np.inf)
        k = int(np.argmax(ratio))
        return float(ratio[k]), float(frequencies[k])

    if durations is None:  # round the pulse's own duration (its 10 % crossings round its
        # peak: noise elsewhere above 10 % would put the grid off the pulse)
        row = np.atleast_2d(np.asarray(kg, dtype=float))
        k = np.argmax(row, axis=1)
        start, end = _crossings(np.asarray(t, dtype=float), row, k, row[0, k])
        width = float(end[0] - start[0])
        base = width / width_fraction("half-sine") if math.isfinite(width) and width > 0 \
            else 1e-3
        durations = base * np.geomspace(0.1, 10.0, 49)
    durations = np.asarray(durations, dtype=float)
    durations = durations[durations >= 2 * dt] if np.any(durations >= 2 * dt) else \
        np.array([2 * dt])  # a half-sine the record's samples can draw
    peaks = [least_peak(d)[0] for d in durations]
    k = int(np.argmin(peaks))
    lo, hi = durations[max(k - 1, 0)], durations[min(k + 1, len(durations) - 1)]
    if hi > lo:  # refined between the grid's neighbours
        found = minimize_scalar(lambda d: least_peak(d)[0], bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-4 * lo})
        if found.fun < peaks[k]:
            peak, governing = least_peak(float(found.x))
            return peak, float(found.x), governing
    peak, governing = least_peak(float(durations[k]))
    return peak, float(durations[k]), governing
