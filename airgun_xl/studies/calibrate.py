"""Calibration from measured shots: the crush-factor law by the report's iteration, and E40,
zeta and a crush-factor scale by least squares.

The law (ARL-TR-3559, section 3.2, Figs. 6-8). The mitigator's force on the bird is the bird's
mass, with the crushed mitigator transferred to it, times the measured deceleration; divided by
the static crush force sigma_y A it gives the crush factor X against the relative velocity V.
The report ran the simulation to get the masses, A and V, refitted X(V), and ran again until
the law moved less than 1 %. Here the simulated pulse is filtered, aligned and divided the same
way as the measured one, and each sample's factor is the current law's times the ratio of the
measured to the simulated force: X_new = X_old F_meas / F_sim. For a rigid bird and no filter
F_sim = sigma_y A X_old, so this is the report's F_meas / (sigma_y A) exactly; with the OBR's
springs and a CFC filter, the ringing and the filter's smearing are the same on both sides and
cancel. The samples of all shots are pooled into one polynomial, as the report combined its two
shots. Under a filter the pointwise ratio can settle short of the law that reproduces the
pulses (1.6 % off in the recovery test), so :func:`refine_law` finishes by least squares on the
law's values.

The least squares (scipy.optimize.least_squares) fits any of E40 (sigma_y), E43 (zeta) and a
scale of the whole law to the filtered pulses, on their difference (L2) or on the ISO/TS 18571
rating. sigma_y and the scale multiply the same force, so they cannot both be fitted.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..crush_law import DEGREE, CrushLaw
from ..errors import OptionError
from .measured import KG_MS2, on_measured_grid, threshold_shift
from .shock import cfc_filter

#: The iteration stops when the law moves less than this over the samples' velocities (the
#: report's 1 %).
LAW_TOLERANCE = 0.01

#: Most iterations of the law before it is reported as not converged.
MAX_ITERATIONS = 12

#: Samples whose simulated force is below this fraction of the peak carry no weight in the law
#: (the ratio of two small, noisy numbers).
FORCE_FLOOR = 0.2

#: Fit names (cells, or the law's scale): the field they move, and their bounds relative to the
#: start (None: zeta's absolute 0..0.5).
FIT_PARAMETERS = {"E40": ("sigmay", 0.25, 4.0), "E43": ("zeta", None, None),
                  "scale": ("scale", 0.25, 4.0)}
OBJECTIVES = ("l2", "iso18571")

TRACK = ("crush_factor", "m31", "force", "deflection", "v31", "v1")


@dataclass
class Aligned:
    """One shot's simulated and measured pulses on the measured grid, in the run's time."""

    time: np.ndarray  # [s], the measured samples in the run's time
    simulated_kg: np.ndarray  # filtered as the measurement
    measured_kg: np.ndarray
    shift: float  # [s] added to the measured time
    crush_factor: np.ndarray  # the run's, at the samples
    velocity: np.ndarray  # relative velocity V [m/s]
    loading: np.ndarray  # bool: the law acts (the crush front advancing)
    mass: np.ndarray  # bird mass with the transferred mitigator [kg]


@dataclass
class Iteration:
    number: int
    change: float  # largest relative move of the law over the samples' velocities
    rms_error: float  # RMS of simulated - measured over the pulse, relative to the peak
    samples: int


@dataclass
class LawCalibration:
    """The law the iteration converged on, and how it got there."""

    law: CrushLaw
    iterations: list = field(default_factory=list)
    converged: bool = False
    velocity: np.ndarray = None  # the last iteration's samples: V [m/s]
    factor: np.ndarray = None  # and X [-], the measured crush factor


@dataclass
class FitResult:
    """Fitted values, by name of :data:`FIT_PARAMETERS`, with the fit's figures."""

    values: dict
    start: dict
    cost: float
    evaluations: int
    params: list = field(default_factory=list)  # each shot's ShotParams, fitted


def _run(p, integrator):
    from ..shot import Shot

    return Shot(p).run(integrator=integrator, track=TRACK)


def align(result, trace, cfc=None):
    """The run's pulse on the measured trace's grid, both filtered alike (``cfc``) and aligned
    at the impact instant (where each first reaches
    :data:`~airgun_xl.studies.measured.IMPACT_FRACTION` of its peak).

    Every measured sample is kept (the run is at rest before it starts and holds its last
    value after), so the residuals of two runs have the same length."""
    h = result.history
    ok = np.isfinite(result.accel_kg)
    t_run, a_run = h.time[ok], result.accel_kg[ok]
    meas = cfc_filter(trace.accel_kg, trace.dt, cfc) if cfc else trace.accel_kg
    shift = threshold_shift(t_run, a_run, trace, meas, cfc)[0]
    t = trace.time + shift
    if ((t >= t_run[0]) & (t <= t_run[-1])).sum() < 16:
        raise OptionError("the aligned traces overlap in fewer than 16 samples, expected the "
                          "measured pulse to cover the simulated one")
    sim = on_measured_grid(t, t_run, a_run, trace.dt, cfc)
    rows = h.time[2:]
    cf = np.interp(t, rows, h.crush_factor[2:])
    prev = np.interp(t - result.params.delta, rows, h.deflection[2:])
    now = np.interp(t, rows, h.deflection[2:])
    force = np.interp(t, rows, h.force[2:], left=0.0, right=0.0)
    loading = (now > prev) & (force > 0) & (t >= rows[0]) & (t <= rows[-1])
    p = result.params
    mass = np.interp(t, rows, h.m31[2:]) + p.m32 + p.m33
    v = np.interp(t, h.time[1:-1], (h.v31 - h.v1)[1:-1])
    return Aligned(t, sim, meas, shift, cf, v, loading, mass)


def rms_error(a):
    """RMS of simulated - measured over the measured pulse, relative to the measured peak."""
    peak = np.max(a.measured_kg)
    window = a.measured_kg >= 0.1 * peak
    return float(np.sqrt(np.mean((a.simulated_kg - a.measured_kg)[window] ** 2)) / peak)


def law_change(new, old, v):
    """Largest relative move between two laws over velocities ``v`` [m/s]."""
    return float(np.max(np.abs(new(v) - old(v)) / old(v)))


def law_samples(a):
    """The corrected crush factor X and its velocity V at the samples where the law acts and
    the force is well above the noise. The force is mass x deceleration for both pulses; the
    mass (transfer included) is the run's, so it cancels in the ratio, but it is kept so the
    samples read as the report's F / (sigma_y A)."""
    f_meas = a.mass * a.measured_kg * KG_MS2
    f_sim = a.mass * a.simulated_kg * KG_MS2
    use = a.loading & (a.simulated_kg > FORCE_FLOOR * a.simulated_kg.max()) & (f_meas > 0)
    return a.velocity[use], a.crush_factor[use] * f_meas[use] / f_sim[use]


def fit_law(v, x, degree=DEGREE, v_range=None):
    """A polynomial crush-factor law through samples (V [m/s], X [-]) by least squares, valid
    over ``v_range`` (the samples' span by default)."""
    from numpy.polynomial import Polynomial

    if len(v) <= degree:
        raise OptionError(f"--degree: {len(v)} samples of the law, expected more than the "
                          f"degree ({degree}); a longer or less filtered pulse")
    poly = Polynomial.fit(v, x, degree).convert()
    span = v_range or (float(v.min()), float(v.max()))
    return CrushLaw(tuple(poly.coef), span, "fitted")


def shots_range(pairs, v):
    """The velocities the shots' pulses cover: from rest (or the least sample below it) to
    the highest impact speed (the first sample is already a step past the impact)."""
    impact = max(p.v31 - p.v1 for p, _ in pairs)
    return (min(0.0, float(v.min())), max(float(impact), float(v.max())))


def calibrate_law(pairs, cfc=None, degree=DEGREE, integrator="legacy",
                  tolerance=LAW_TOLERANCE, max_iterations=MAX_ITERATIONS):
    """Recover the crush-factor law from measured shots by the report's iteration.

    Parameters
    ----------
    pairs : list of (ShotParams, Trace)
        Each shot's parameters (its law the starting guess) and its measured pulse.
    cfc : int, optional
        SAE J211 class both pulses are filtered with.
    degree : int
        Of the fitted polynomial (6 as Eq. 8).
    tolerance : float
        Stop when the law moves less than this (relative) over the samples' velocities.

    Returns
    -------
    LawCalibration
    """
    law = pairs[0][0].crush_law
    out = LawCalibration(law)
    for number in range(1, max_iterations + 1):
        vs, xs, errors = [], [], []
        for p, trace in pairs:
            a = align(_run(p.replace(crush_law=law), integrator), trace, cfc)
            v, x = law_samples(a)
            vs.append(v)
            xs.append(x)
            errors.append(rms_error(a))
        v, x = np.concatenate(vs), np.concatenate(xs)
        new = fit_law(v, x, degree, shots_range(pairs, v))
        change = law_change(new, law, np.linspace(v.min(), v.max(), 101))
        out.iterations.append(Iteration(number, change, float(np.max(errors)), len(v)))
        out.law, out.velocity, out.factor = new, v, x
        law = new
        if change < tolerance:
            out.converged = True
            break
    return out


def _chebyshev_nodes(lo, hi, n):
    k = np.arange(n)
    return (lo + hi) / 2 + (hi - lo) / 2 * np.cos((2 * k + 1) * np.pi / (2 * n))[::-1]


def law_through(v_nodes, x_nodes, v_range):
    """The polynomial law through (V, X) nodes (degree len - 1)."""
    from numpy.polynomial import Polynomial

    poly = Polynomial.fit(v_nodes, x_nodes, len(v_nodes) - 1).convert()
    return CrushLaw(tuple(poly.coef), v_range, "fitted")


def refine_law(pairs, law, cfc=None, objective="l2", integrator="legacy", degree=DEGREE):
    """Least squares on the law itself: its values at ``degree + 1`` Chebyshev velocities of
    its range, moved until the filtered pulses agree (scipy.optimize.least_squares).

    The iteration's fixed point is where the samples' ratio is orthogonal to the polynomials;
    with a filter that smears the pulse's rise, that is not always where the pulses agree.
    This step finishes the job from the iteration's law.
    """
    from scipy.optimize import least_squares

    nodes = _chebyshev_nodes(*law.v_range, degree + 1)
    x0 = law.poly(nodes)
    evaluations = [0]

    def residuals(x):
        evaluations[0] += 1
        trial = law_through(nodes, x, law.v_range)
        aligned = [align(_run(p.replace(crush_law=trial), integrator), trace, cfc)
                   for p, trace in pairs]
        return _objective_residuals(aligned, objective)

    fit = least_squares(residuals, x0, x_scale=np.abs(x0), diff_step=1e-4, max_nfev=100)
    return law_through(nodes, fit.x, law.v_range), evaluations[0]


def _objective_residuals(aligned, objective):
    if objective == "iso18571":
        from .iso18571 import rating

        return np.array([1.0 - rating(a.time, a.measured_kg, a.simulated_kg).overall
                         for a in aligned])
    parts = []
    for a in aligned:
        peak = np.max(a.measured_kg)
        window = a.measured_kg >= 0.1 * peak
        parts.append((a.simulated_kg - a.measured_kg)[window] / peak
                     / np.sqrt(window.sum()))
    return np.concatenate(parts)


def check_fit(names, objective="l2"):
    """The fit's names, unique and in order; one line naming the fault otherwise."""
    names = list(dict.fromkeys(names))
    unknown = [n for n in names if n not in FIT_PARAMETERS]
    if unknown or not names:
        raise OptionError(f"--fit: found {','.join(unknown) or 'nothing'}, expected names "
                          f"from {', '.join(FIT_PARAMETERS)}")
    if "E40" in names and "scale" in names:
        raise OptionError("--fit: found both E40 and scale, expected one of them: the yield "
                          "stress and the law's scale multiply the same crush force, so no "
                          "pulse can tell them apart")
    if objective not in OBJECTIVES:
        raise OptionError(f"--objective: found {objective!r}, expected one of "
                          f"{', '.join(OBJECTIVES)}")
    return names


def fit_parameters(pairs, names, cfc=None, objective="l2", integrator="legacy"):
    """Fit E40, E43 and/or a law scale to measured shots by least squares.

    Parameters
    ----------
    pairs : list of (ShotParams, Trace)
    names : sequence of str
        From :data:`FIT_PARAMETERS`. E40 and the scale both multiply the crush force: only
        one of them.
    objective : {"l2", "iso18571"}
        The filtered pulses' difference over each measured pulse (10 % rule), or one minus
        each shot's ISO/TS 18571 overall rating.

    Returns
    -------
    FitResult
    """
    from scipy.optimize import least_squares

    names = check_fit(names, objective)
    p0 = pairs[0][0]
    start = {"E40": p0.sigmay, "E43": p0.zeta, "scale": 1.0}
    x0, lo, hi = [], [], []
    for n in names:
        _, low, high = FIT_PARAMETERS[n]
        x0.append(start[n])
        lo.append(start[n] * low if low else 0.0)
        hi.append(start[n] * high if high else 0.5)
    evaluations = [0]

    def shots(x):
        values = dict(zip(names, x))
        out = []
        for p, _ in pairs:
            changes = {}
            if "E40" in values:
                changes["sigmay"] = values["E40"]
            if "E43" in values:
                changes["zeta"] = values["E43"]
            if "scale" in values:
                changes["crush_law"] = p.crush_law.scaled(values["scale"])
            out.append(p.replace(**changes))
        return out

    def residuals(x):
        evaluations[0] += 1
        aligned = [align(_run(p, integrator), trace, cfc)
                   for p, (_, trace) in zip(shots(x), pairs)]
        return _objective_residuals(aligned, objective)

    x0 = np.clip(x0, lo, hi)
    scale = np.where(np.asarray(x0) > 0, np.abs(x0), 0.01)
    fit = least_squares(residuals, x0, bounds=(lo, hi), x_scale=scale, diff_step=1e-4,
                        xtol=1e-10, ftol=1e-10, gtol=1e-10, max_nfev=200)
    return FitResult(dict(zip(names, map(float, fit.x))), {n: start[n] for n in names},
                     float(fit.cost), evaluations[0], shots(fit.x))


@dataclass
class Score:
    rms: float  # RMS error over the measured pulse, relative to its peak
    iso: float  # ISO/TS 18571 overall rating


@dataclass
class Calibration:
    """What :func:`calibrate` found: each shot's fitted parameters, and the way there."""

    params: list
    law_calibration: LawCalibration | None
    fitted: dict
    start: dict
    before: list
    after: list
    aligned: list  # each shot's pulses after calibration
    runs: int = 0
    seconds: float = 0.0


def score(a):
    """RMS error and ISO/TS 18571 rating of an aligned pair, over the measured pulse widened by
    a tenth of its duration each side, from the impact on (as compare-measured rates it)."""
    from ..engine.summary import pulse
    from .iso18571 import rating

    start, end, duration = pulse(a.time, a.measured_kg)
    lo, hi = max(0.0, start - 0.1 * duration), min(a.time[-1], end + 0.1 * duration)
    return Score(rms_error(a), rating(a.time, a.measured_kg, a.simulated_kg, lo, hi).overall)


def calibrate(params, traces, law=True, fit=(), cfc=None, degree=DEGREE, objective="l2",
              integrator="legacy"):
    """Calibrate the model on measured shots: the crush-factor law (the report's iteration,
    then least squares on the law's values, :func:`refine_law`), then the named parameters
    (:func:`fit_parameters`).

    Parameters
    ----------
    params : list of ShotParams
    traces : list of Trace
        The measured pulse of each shot.
    law : bool
    fit : sequence of str
        Names from :data:`FIT_PARAMETERS`.

    Returns
    -------
    Calibration
    """
    import time

    started = time.perf_counter()
    counter = {"runs": 0}
    pairs = list(zip(params, traces))

    def run_all(ps):
        counter["runs"] += len(ps)
        return [align(_run(p, integrator), t, cfc) for p, t in zip(ps, traces)]

    before = [score(a) for a in run_all(params)]
    law_cal = None
    if law:
        law_cal = calibrate_law(pairs, cfc, degree, integrator)
        counter["runs"] += len(law_cal.iterations) * len(pairs)
        refined, evaluations = refine_law(pairs, law_cal.law, cfc, objective, integrator,
                                          degree)
        counter["runs"] += evaluations * len(pairs)
        params = [p.replace(crush_law=refined) for p in params]
        pairs = list(zip(params, traces))
    fitted, start = {}, {}
    if fit:
        result = fit_parameters(pairs, fit, cfc, objective, integrator)
        counter["runs"] += result.evaluations * len(pairs)
        params, fitted, start = result.params, result.values, result.start
    aligned = run_all(params)
    after = [score(a) for a in aligned]
    return Calibration(params, law_cal, fitted, start, before, after, aligned,
                       counter["runs"], time.perf_counter() - started)


def synthetic_measurement(p, dt=1e-5, noise=0.01, ringing_hz=8000.0, ringing=0.1, seed=0,
                          integrator="legacy", name="synthetic"):
    """A "measured" pulse made from known parameters ``p``: the run's test-item deceleration
    sampled every ``dt`` [s], plus white noise (``noise`` x the peak, standard deviation) and
    a decaying ringing at ``ringing_hz`` (``ringing`` x the peak, starting at the impact), as
    a recorder's mount adds. Starts 0.5 ms before the impact, so the pre-trigger is seen."""
    from ..workbook.trace import Trace

    r = _run(p, integrator)
    ok = np.isfinite(r.accel_kg)
    t_run, a_run = r.history.time[ok], r.accel_kg[ok]
    time = np.arange(-5e-4, t_run[-1], dt)
    accel = np.interp(time, t_run, a_run, left=0.0)
    peak = accel.max()
    rng = np.random.default_rng(seed)
    after = np.clip(time, 0, None)
    ring = ringing * peak * np.sin(2 * np.pi * ringing_hz * after) * np.exp(-after / 1e-3)
    accel = accel + np.where(time > 0, ring, 0.0) + noise * peak * rng.standard_normal(len(time))
    return Trace(time + 0.002, accel, dt, name, ("s", "kG"))  # a recorder's own clock
