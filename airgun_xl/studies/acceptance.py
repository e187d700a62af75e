"""Did a pulse meet its specification? Criteria, margins and a verdict (issue 25).

One judge serves the recording (``accept``), the prediction (``fill``'s Summary) and every
shot of a Monte Carlo (``design --confidence``): :func:`judge_rows` takes a block of pulses on
one time grid and gives each criterion's value per pulse, with numpy over the block, so a
single pulse and ten thousand are judged by the same lines.

Definitions (each verdict prints them):

- **peak**: the largest sample of the record judged [kG].
- **duration**: the base width of the nominal shape, from the two crossings of 10 % of the
  peak (linearly interpolated) divided by that shape's width at 10 % (half-sine
  1 - 2 asin(0.1)/pi = 0.9362; terminal-peak sawtooth 0.9; trapezoid with 10 % ramps 0.98;
  none 1: the width at 10 % itself). An ideal pulse of duration T measures T.
- **velocity change**: the trapezoidal integral of the acceleration [m/s] over the pulse and
  its monitoring windows: from ``window`` before the ideal pulse's start to ``window`` after
  its end (without a shape: round the 10 % crossings). A half-sine gives 2 A T / pi.
- **corridor**: the ideal pulse of the nominal peak and duration, placed over the record by
  least squares (its cross-correlation's best lag, refined to a fraction of a sample) or with
  its peak on the record's; the limits are the ideal's largest and smallest values within
  ± the time slack, plus and minus the corridor's half-width; before and after the pulse, for
  the window, the limits are ± the half-width. The margin is the least distance to a limit
  over the window, a fraction of the nominal peak.
- **SRS**: the maximax absolute-acceleration SRS at the requirement's frequencies and Q; its
  margin at each is 20 log10(SRS / required) dB, inside [lower, upper]; up to the allowed
  fraction of frequencies may fall outside.

Margins are positive inside the tolerance and negative outside: a fraction of the nominal
for the figures and the corridor, dB for the SRS.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..specification import Specification
from ..units import KG_MS2

#: Crossing level of the duration, a fraction of the peak.
DURATION_LEVEL = 0.10

#: The trapezoid's rise and fall, each a fraction of its base.
TRAPEZOID_RAMP = 0.10

#: Samples over the nominal duration on which the ideal pulse is placed by least squares.
PLACEMENT_SAMPLES = 400


def ideal(shape: str | None, t: np.ndarray, amplitude: float, duration: float) -> np.ndarray:
    """The ideal pulse [kG] at times ``t`` [s] from its start."""
    x = np.asarray(t, dtype=float) / duration
    inside = (x >= 0) & (x <= 1)
    if shape == "half-sine":
        y = np.sin(np.pi * np.clip(x, 0, 1))
    elif shape == "sawtooth":
        y = np.clip(x, 0, 1)
    elif shape == "trapezoid":
        y = np.clip(np.minimum(x, 1 - x) / TRAPEZOID_RAMP, 0, 1)
    else:
        raise ValueError(f"no ideal pulse for the shape {shape!r}")
    return amplitude * np.where(inside, y, 0.0)


def width_fraction(shape: str | None) -> float:
    """The shape's width at :data:`DURATION_LEVEL` of its peak, a fraction of its base."""
    return {"half-sine": 1 - 2 * math.asin(DURATION_LEVEL) / math.pi,
            "sawtooth": 1 - DURATION_LEVEL,
            "trapezoid": 1 - 2 * TRAPEZOID_RAMP * DURATION_LEVEL}.get(shape or "none", 1.0)


def peak_offset(shape: str | None) -> float:
    """Time from the ideal's start to its peak, a fraction of its base."""
    return 1.0 if shape == "sawtooth" else 0.5


def duration_definition(shape: str | None) -> str:
    """How the duration is measured, in words, for a verdict."""
    f = width_fraction(shape)
    if shape in (None, "none"):
        return f"the width between the crossings of {DURATION_LEVEL:.0%} of the peak"
    return (f"the {shape}'s base: the width between the crossings of {DURATION_LEVEL:.0%} "
            f"of the peak / {f:.4f}")


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


@dataclass
class Verdict:
    """The criteria judged, PASS when every one passed; what was used, and why not trusted."""

    criteria: list[Criterion]
    spec: Specification
    definitions: list[str]
    warnings: list[str] = field(default_factory=list)
    onset: float | None = None  # [s], the ideal pulse's start where placed
    window: tuple[float, float] | None = None  # [s], the span judged

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria)

    @property
    def word(self) -> str:
        return "PASS" if self.passed else "FAIL"

    def sources(self) -> list[str]:
        """Where each field of the specification came from, the defaults it used, and what a
        source gave that was not judged: a line each (:meth:`Specification.provenance`)."""
        from ..specification import unjudged

        return self.spec.provenance() + unjudged(self.spec)

    def tolerances(self) -> list[str]:
        """The tolerances used, one line each, as every verdict prints them."""
        return [f"{c.name}: {_limits_text(c)}" for c in self.criteria]


def _limits_text(c: Criterion) -> str:
    lo = "-inf" if c.low is None else f"{c.low:.5g}"
    hi = "+inf" if c.high is None else f"{c.high:.5g}"
    return f"{lo} to {hi} {c.unit}".strip()


def _crossings(t: np.ndarray, kg: np.ndarray, peak_index: np.ndarray, peak: np.ndarray):
    """(start, end) [s] of each row's crossings of :data:`DURATION_LEVEL` x its peak round its
    peak, linearly interpolated (NaN where the record starts or ends above the level)."""
    m, n = kg.shape
    level = (DURATION_LEVEL * peak)[:, None]
    below = kg < level
    idx = np.arange(n)[None, :]
    before = below & (idx < peak_index[:, None])
    after = below & (idx > peak_index[:, None])
    has_before, has_after = before.any(axis=1), after.any(axis=1)
    i0 = n - 1 - np.argmax(before[:, ::-1], axis=1)  # last sample below, before the peak
    i1 = np.argmax(after, axis=1)  # first sample below, after the peak
    rows = np.arange(m)
    i0c, i1c = np.minimum(i0, n - 2), np.maximum(i1, 1)
    a0, a1 = kg[rows, i0c], kg[rows, i0c + 1]
    b0, b1 = kg[rows, i1c - 1], kg[rows, i1c]
    lv = level[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        start = t[i0c] + (lv - a0) / (a1 - a0) * (t[i0c + 1] - t[i0c])
        end = t[i1c - 1] + (b0 - lv) / (b0 - b1) * (t[i1c] - t[i1c - 1])
    return np.where(has_before, start, np.nan), np.where(has_after, end, np.nan)


def _placement(t: np.ndarray, kg: np.ndarray, spec: Specification, peak_index: np.ndarray):
    """Each row's ideal pulse start [s]: least squares (the cross-correlation's best lag,
    refined by a parabola through its neighbours) or the peak rule."""
    dt = t[1] - t[0]
    amplitude, duration = _nominals(spec)
    if spec.placement == "peak":
        return t[peak_index] - peak_offset(spec.shape) * duration
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
    return t[0] + (k + np.clip(frac, -0.5, 0.5)) * q * dt


def _nominals(spec: Specification) -> tuple[float, float]:
    """The nominal peak [kG] and duration [s] the ideal pulse is drawn from."""
    if spec.peak is None or spec.duration is None:
        raise ValueError("an ideal pulse needs a nominal peak and duration")
    return spec.peak.nominal, spec.duration.nominal


def corridor_limits(spec: Specification, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower limits [kG] at times ``tau`` [s] from the ideal's start: its largest
    and smallest values within ± the time slack, ± the half-width.

    Every shape rises to its peak and then falls, so over a window [tau - s, tau + s] its
    largest value is the peak where the window holds the peak's time, else the larger end,
    and its smallest value is the smaller end: two evaluations, not a search.
    """
    spec = spec.resolved()
    assert spec.time_slack is not None  # resolved
    amplitude, duration = _nominals(spec)
    slack = spec.time_slack * duration
    early = ideal(spec.shape, tau - slack, amplitude, duration)
    late = ideal(spec.shape, tau + slack, amplitude, duration)
    t_peak = peak_offset(spec.shape) * duration
    holds_peak = (tau - slack <= t_peak) & (tau + slack >= t_peak)
    band = (spec.corridor or 0.0) * amplitude
    upper = np.where(holds_peak, amplitude, np.maximum(early, late))
    return upper + band, np.minimum(early, late) - band


def judge_rows(t: np.ndarray, kg: np.ndarray, spec: Specification) -> dict[str, np.ndarray]:
    """Each criterion's value for each row of ``kg`` (pulses [kG] on the grid ``t`` [s]).

    Returns
    -------
    dict
        ``peak`` [kG], ``duration`` [s], ``velocity change`` [m/s], ``corridor`` (least
        margin, a fraction of the nominal peak; only with a corridor), ``onset`` [s] and
        ``span`` (start and end [s] of the span judged).
    """
    spec = spec.resolved()
    t = np.asarray(t, dtype=float)
    kg = np.atleast_2d(np.asarray(kg, dtype=float))
    dt = t[1] - t[0]
    peak_index = np.argmax(kg, axis=1)
    peak = kg[np.arange(len(kg)), peak_index]
    start, end = _crossings(t, kg, peak_index, peak)
    out = {"peak": peak, "duration": (end - start) / width_fraction(spec.shape)}
    placed = spec.shape != "none" and spec.peak is not None and spec.duration is not None
    if placed:
        onset = _placement(t, kg, spec, peak_index)
        length = _nominals(spec)[1]
    else:
        length = out["duration"]
        onset = start - (1 - width_fraction(spec.shape)) / 2 * length
    window = spec.window if spec.window is not None else 0.5 * (
        spec.duration.nominal if spec.duration is not None else np.nan_to_num(length))
    lo, hi = onset - window, onset + length + window
    out["onset"] = onset
    out["span"] = np.stack([lo, hi], axis=1)
    # the trapezoidal rule over the samples inside the span [lo, hi], row by row: partial
    # sums of the intervals, differenced at the span's first and last sample
    first = np.clip(np.searchsorted(t, lo, side="left"), 0, len(t) - 1)
    last = np.clip(np.searchsorted(t, hi, side="right") - 1, 0, len(t) - 1)
    sums = np.zeros((len(kg), len(t)))
    np.cumsum(0.5 * (kg[:, 1:] + kg[:, :-1]), axis=1, out=sums[:, 1:])
    rows = np.arange(len(kg))
    out["velocity change"] = np.where(
        last > first, sums[rows, last] - sums[rows, np.minimum(first, last)], 0.0) * dt * KG_MS2
    if spec.corridor is not None and placed:
        inside = (t[None, :] >= lo[:, None]) & (t[None, :] <= hi[:, None])
        upper, lower = corridor_limits(spec, t[None, :] - onset[:, None])
        room = np.minimum(upper - kg, kg - lower)
        out["corridor"] = np.min(np.where(inside, room, np.inf), axis=1) / _nominals(spec)[0]
    return out


def _figure(name: str, value: float, tol, unit: str, scale: float) -> Criterion:
    lo, hi = tol.limits
    margin = min(value - lo, hi - value) / tol.nominal if math.isfinite(value) else -math.inf
    return Criterion(name, float(value) * scale, unit, lo * scale, hi * scale,
                     float(100 * margin), "%",
                     bool(lo <= value <= hi))


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
    if top > 0.1 / dt:
        from ..errors import OptionError

        raise OptionError(f"the SRS requirement ({spec.source or 'options'}): found a row at "
                          f"{top:,.0f} Hz, above a tenth of the record's {1 / dt:,.0f} "
                          f"samples a second, where the SRS is not computed; expected "
                          f"requirement rows up to {0.1 / dt:,.0f} Hz, or a faster record")
    levels = srs(np.asarray(kg, dtype=float), dt, np.array(r.frequencies), q)
    with np.errstate(divide="ignore"):
        margins = 20 * np.log10(levels / np.array(r.levels_kg))
    outside = (margins < lower_db) | (margins > upper_db)
    room = np.minimum(margins - lower_db, upper_db - margins)
    allowed = int(math.floor(spec.srs_outside * len(margins) + 1e-9))
    passed = int(outside.sum()) <= allowed
    # the margin of the verdict: the (allowed + 1)-th smallest room, so that letting some
    # frequencies out shows
    margin = float(np.sort(room)[min(allowed, len(room) - 1)])
    names = ", ".join(f"{f:,.0f} Hz ({m:+.2f} dB)" for f, m in
                      zip(np.array(r.frequencies)[outside], margins[outside], strict=True))
    detail = (f"{int(outside.sum())} of {len(margins)} frequencies outside (allowed "
              f"{allowed})" + (f": {names}" if names else ""))
    worst = float(margins[np.argmin(room)])
    return Criterion("SRS", worst, "dB", lower_db, upper_db, margin, "dB", passed,
                     detail + f"; Q {q:g}"), margins


def judge(t: np.ndarray, kg: np.ndarray, spec: Specification,
          warnings: list[str] | None = None) -> Verdict:
    """The verdict on one pulse ``kg`` [kG] sampled at ``t`` [s] (the record judged: already
    zeroed and filtered as the specification asks)."""
    spec = spec.resolved()
    values = judge_rows(t, kg, spec)
    row = {k: v[0] for k, v in values.items()}
    criteria = []
    definitions = [f"record judged: {'CFC %d' % spec.cfc if spec.cfc else 'unfiltered'}",
                   f"duration: {duration_definition(spec.shape)}"]
    if spec.peak is not None:
        criteria.append(_figure("peak", row["peak"], spec.peak, "kG", 1.0))
    if spec.duration is not None:
        criteria.append(_figure("duration", row["duration"], spec.duration, "ms", 1e3))
    if spec.velocity_change is not None:
        criteria.append(_figure("velocity change", row["velocity change"],
                                spec.velocity_change, "m/s", 1.0))
    lo, hi = row["span"]
    definitions.append(f"velocity change: integrated from {lo * 1e3:.4f} to {hi * 1e3:.4f} ms")
    if "corridor" in row:
        margin = float(row["corridor"])
        criteria.append(Criterion("corridor", 100 * margin, "%", 0.0, None,
                                  100 * margin, "%", margin >= 0,
                                  f"±{spec.corridor:.0%} of {_nominals(spec)[0]:.4g} kG, time "
                                  f"slack ±{spec.time_slack:.0%}, placed by "
                                  f"{spec.placement}"))
        definitions.append(f"corridor: the ideal {spec.shape} starts at "
                           f"{row['onset'] * 1e3:.4f} ms ({spec.placement})")
    if spec.srs is not None:
        criteria.append(srs_criterion(np.asarray(t), np.asarray(kg), spec)[0])
    verdict = Verdict(criteria, spec, definitions, list(warnings or []),
                      float(row["onset"]) if math.isfinite(row["onset"]) else None,
                      (float(lo), float(hi)) if math.isfinite(lo) and math.isfinite(hi)
                      else None)
    verdict.definitions += verdict.sources()
    if not criteria:
        verdict.warnings.append("the specification gives no criterion: nothing was judged")
    for c in criteria:
        if not math.isfinite(c.value):
            verdict.warnings.append(f"{c.name}: could not be measured on this pulse (it starts"
                                    " or ends above 10 % of its peak): judged FAIL")
            c.passed = False
    return verdict


def pass_flags(values: dict[str, np.ndarray], spec: Specification) -> dict[str, np.ndarray]:
    """Each criterion's PASS per row of :func:`judge_rows`' values (the SRS is not among
    them: it is judged on single pulses)."""
    flags = {}
    for name, tol in (("peak", spec.peak), ("duration", spec.duration),
                      ("velocity change", spec.velocity_change)):
        if tol is not None:
            lo, hi = tol.limits
            v = values[name]
            flags[name] = (v >= lo) & (v <= hi)
    if "corridor" in values:
        flags["corridor"] = values["corridor"] >= 0
    return flags


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
        ratio = target / srs(unit, dt, frequencies, q)
        k = int(np.argmax(ratio))
        return float(ratio[k]), float(frequencies[k])

    if durations is None:
        above = np.flatnonzero(np.asarray(kg) >= DURATION_LEVEL * np.max(kg))
        base = ((above[-1] - above[0] + 1) * dt / width_fraction("half-sine") if len(above)
                else 1e-3)
        durations = base * np.geomspace(0.25, 4.0, 33)
    durations = np.asarray(durations, dtype=float)
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


def predicted_verdict(result, spec: Specification) -> Verdict:
    """The verdict on a run's predicted pulse (the test item's acceleration, at rest before
    the impact, through the specification's CFC filter when it names one)."""
    from ..errors import OptionError
    from .shock import check_cfc

    ok = np.isfinite(result.accel_kg)
    t, kg = result.history.time[ok], result.accel_kg[ok]
    warnings: list[str] = []
    if spec.cfc:
        try:
            warnings += check_cfc(spec.cfc, float(t[1] - t[0]))
        except OptionError as exc:
            raise OptionError(f"the specification's record (CFC {spec.cfc}): {exc}") from None
    t, kg = judged_record(t, kg, spec.cfc)
    verdict = judge(t, kg, spec, warnings)
    verdict.definitions.insert(0, "judged: the predicted pulse (the test item's acceleration)")
    return verdict


def judged_record(t: np.ndarray, kg: np.ndarray, cfc: int | None):
    """A predicted pulse (or a block of them, a row each) as the specification judges it:
    through CFC ``cfc`` from rest (:data:`~airgun_xl.studies.measured.REST_BEFORE` of it
    before the impact, for the phaseless filter's lead), or unchanged."""
    from .measured import REST_BEFORE
    from .shock import cfc_filter

    kg = np.asarray(kg, dtype=float)
    if not cfc:  # unfiltered: the record as it is (a run starts at rest)
        return t, kg
    dt = float(t[1] - t[0])
    n = int(round(REST_BEFORE / dt))
    t = np.concatenate([t[0] - dt * np.arange(n, 0, -1), t])
    rest = np.zeros(kg.shape[:-1] + (n,))
    kg = np.concatenate([rest, kg], axis=-1)
    return t, (cfc_filter(kg, dt, cfc) if cfc else kg)


#: The columns of :class:`BlockJudge`'s values.
BLOCK_VALUES = ("peak", "duration", "velocity change", "corridor")


@dataclass(frozen=True)
class BlockJudge:
    """``run_batch``'s ``extra``: each shot's :data:`BLOCK_VALUES`, judged as
    :func:`predicted_verdict` judges one shot (picklable, for Dask workers)."""

    spec: Specification
    width: int = len(BLOCK_VALUES)

    def __call__(self, t: np.ndarray, kg: np.ndarray) -> np.ndarray:
        t, kg = judged_record(t, kg, self.spec.cfc)
        values = judge_rows(t, kg, self.spec)
        return np.column_stack([values.get(name, np.full(len(kg), np.nan))
                                for name in BLOCK_VALUES])


def flags_of(values: np.ndarray, spec: Specification) -> dict[str, np.ndarray]:
    """:func:`pass_flags` of a :class:`BlockJudge`'s columns; a diverged shot (NaN) fails
    every criterion."""
    named = {name: values[:, k] for k, name in enumerate(BLOCK_VALUES)}
    if spec.corridor is None or spec.shape in (None, "none"):
        named.pop("corridor")
    return pass_flags(named, spec)
