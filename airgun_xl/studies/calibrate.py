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

import math
from dataclasses import dataclass, field

import numpy as np

from ..cells import address
from ..crush_law import DEGREE, CrushLaw, chebyshev_nodes
from ..errors import OptionError
from .measured import KG_MS2, on_measured_grid, threshold_shift

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
FIT_PARAMETERS = {address("sigmay"): ("sigmay", 0.25, 4.0), address("zeta"): ("zeta", None, None),
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
    velocity: np.ndarray | None = None  # the last iteration's samples: V [m/s]
    factor: np.ndarray | None = None  # and X [-], the measured crush factor


@dataclass
class FitResult:
    """Fitted values, by name of :data:`FIT_PARAMETERS`, with the fit's figures."""

    values: dict
    start: dict
    cost: float
    evaluations: int
    params: list = field(default_factory=list)  # each shot's ShotParams, fitted
    errors: dict = field(default_factory=dict)  # standard error of each value (Jacobian)
    bounds: dict = field(default_factory=dict)  # (low, high) each value was held to
    #: with ``velocities``: (impact speed set [m/s], fitted factor on it, its standard error)
    #: of each shot
    velocities: list = field(default_factory=list)
    covariance: np.ndarray | None = None  # of the values, in the order of ``values``


def _run(p, integrator):
    from ..shot import Shot

    return Shot(p).run(integrator=integrator, track=TRACK)


def _run_law(p, law, integrator):
    """A run of ``p`` with a law the calibration fitted: when that law makes the run diverge,
    the refusal names the law and the recordings, not the shot's time step."""
    from ..errors import DivergenceError, StabilityError

    try:
        return _run(p.replace(crush_law=law), integrator)
    except (DivergenceError, StabilityError) as exc:
        raise OptionError(f"RECORDING: the crush law fitted to the recordings makes the run "
                          f"diverge ({str(exc).split(';')[0]}), expected measured pulses that "
                          "cover the crush of their shots (a longer record, the right --sign "
                          "and units)") from None


def align(result, rec, nudge=0.0):
    """The run's pulse on the measured :class:`~airgun_xl.studies.measured.Recording`'s grid,
    both filtered alike (its CFC class, and its anti-alias model on the run) and aligned at
    the impact instant (where each first holds the recording's level, a fraction of its peak
    above the noise).

    ``nudge`` [s] is added to the threshold's shift: the law's least squares fits it, as a
    threshold crossing on a noisy rise can miss by a fraction of a sample, which the steep
    rise turns into a large residual.

    Every measured sample is kept (the run is at rest before it starts and holds its last
    value after), so the residuals of two runs have the same length."""
    h = result.history
    ok = np.isfinite(result.accel_kg)
    t_run, a_run = h.time[ok], result.accel_kg[ok]
    trace = rec.trace
    shift = threshold_shift(t_run, a_run, rec)[0] + nudge
    t = trace.time + shift
    if ((t >= t_run[0]) & (t <= t_run[-1])).sum() < 16:
        raise OptionError("the aligned traces overlap in fewer than 16 samples, expected the "
                          "measured pulse to cover the simulated one")
    sim = on_measured_grid(t, t_run, a_run, trace.dt, rec.cfc, rec.anti_alias)
    rows = h.time[2:]
    cf = np.interp(t, rows, h.crush_factor[2:])
    prev = np.interp(t - result.params.delta, rows, h.deflection[2:])
    now = np.interp(t, rows, h.deflection[2:])
    force = np.interp(t, rows, h.force[2:], left=0.0, right=0.0)
    loading = (now > prev) & (force > 0) & (t >= rows[0]) & (t <= rows[-1])
    p = result.params
    mass = np.interp(t, rows, h.m31[2:]) + p.m32 + p.m33
    v = np.interp(t, h.time[1:-1], (h.v31 - h.v1)[1:-1])
    return Aligned(t, sim, rec.filtered, shift, cf, v, loading, mass)


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


#: The law is valid over the velocities its samples cover, between these percentiles: the
#: first and last 1 % (the rise's first samples, smeared by any filter) pin nothing.
SPAN_PERCENTILES = (1, 99)


def shots_range(v):
    """The velocities the shots' samples cover [m/s] (:data:`SPAN_PERCENTILES`): the fitted
    law claims no more; a shot faster than its top meets the extrapolation warning of any
    run of it (:func:`airgun_xl.studies.check.impact_speed_finding`)."""
    lo, hi = np.percentile(v, SPAN_PERCENTILES)
    return (float(lo), float(hi))


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
            a = align(_run_law(p, law, integrator) if number > 1 else  # a fitted law
                      _run(p.replace(crush_law=law), integrator), trace)
            v, x = law_samples(a)
            vs.append(v)
            xs.append(x)
            errors.append(rms_error(a))
        v, x = np.concatenate(vs), np.concatenate(xs)
        if len(v) <= degree:  # before the range: no samples has no percentiles
            raise OptionError(f"RECORDING: {len(v)} samples of the crush law where the run "
                              "loads the mitigator and both pulses are above the noise, "
                              f"expected more than the law's degree ({degree}): measured "
                              "pulses that cover the crush of their shots")
        new = fit_law(v, x, degree, shots_range(v))
        change = law_change(new, law, np.linspace(v.min(), v.max(), 101))
        out.iterations.append(Iteration(number, change, float(np.max(errors)), len(v)))
        out.law, out.velocity, out.factor = new, v, x
        law = new
        if change < tolerance:
            out.converged = True
            break
    return out


_chebyshev_nodes = chebyshev_nodes


def law_through(v_nodes, x_nodes, v_range):
    """The polynomial law through (V, X) nodes (degree len - 1)."""
    from numpy.polynomial import Polynomial

    poly = Polynomial.fit(v_nodes, x_nodes, len(v_nodes) - 1).convert()
    return CrushLaw(tuple(poly.coef), v_range, "fitted")


def by_shot(fun, sizes, dense, shot_columns, rel_step, bounds):
    """``fun`` and a ``jac`` for scipy.optimize.least_squares: the 2-point finite differences
    least_squares takes itself (scipy's approx_derivative, at ``rel_step``, within
    ``bounds``), with the columns that move one shot's pulse alone perturbed together.

    The residuals are the shots' blocks of ``sizes`` rows in turn; the first ``dense``
    columns move every shot, and each list of ``shot_columns`` holds one column a shot (its
    alignment, its launch velocity) that moves that shot's block only. A column perturbed
    with others of its group changes its own shot's rows exactly as alone (each shot is run
    on its own), so the Jacobian is approx_derivative's column by column (a fit through it
    and one through least_squares's own '2-point' differ by 6e-7 of a scale whose standard
    error is 3e-3, measured on 5 shots; by nothing on 1); it
    takes a run of every shot per group instead of per column: 3 or 4 groups instead of
    2 + 2 a shot. Should the residuals' length ever differ from the blocks', the columns
    are taken one by one.

    Returns
    -------
    (callable, callable)
        The residuals (keeping the last for the Jacobian's base point), and the Jacobian.
    """
    from scipy.optimize._numdiff import approx_derivative

    starts = np.cumsum([0, *sizes])
    n = dense + sum(len(columns) for columns in shot_columns)
    structure = np.zeros((int(starts[-1]), n), dtype=bool)
    structure[:, :dense] = True
    groups = np.arange(n)
    for g, columns in enumerate(shot_columns):
        for k, column in enumerate(columns):
            structure[starts[k]:starts[k + 1], column] = True
            groups[column] = dense + g
    last: dict = {}

    def residuals(x):
        f = fun(x)
        last["x"], last["f"] = np.array(x, copy=True), f
        return f

    def jac(x):
        f0 = last["f"] if "x" in last and np.array_equal(last["x"], x) else residuals(x)
        if len(f0) != structure.shape[0]:
            return approx_derivative(fun, x, "2-point", rel_step, f0=f0, bounds=bounds)
        return approx_derivative(fun, x, "2-point", rel_step, f0=f0, bounds=bounds,
                                 sparsity=(structure, groups)).toarray()

    return residuals, jac


def window_sizes(recs):
    """The rows of each shot's L2 residuals (:func:`_objective_residuals`): its measured
    samples at 10 % of its peak or more."""
    return [int(np.count_nonzero(rec.filtered >= 0.1 * np.max(rec.filtered)))
            for rec in recs]


def refine_law(pairs, law, integrator="legacy", degree=DEGREE):
    """Least squares on the law itself: its values at ``degree + 1`` Chebyshev velocities of
    its range, moved until the filtered pulses agree (scipy.optimize.least_squares, on their
    L2 difference: the ISO/TS 18571 rating is jagged in the law, so it only rates).

    The iteration's fixed point is where the samples' ratio is orthogonal to the polynomials;
    with a filter that smears the pulse's rise, that is not always where the pulses agree.
    This step finishes the job from the iteration's law.

    Returns
    -------
    (CrushLaw, int, numpy.ndarray, numpy.ndarray, numpy.ndarray, numpy.ndarray)
        The law, the runs it took, the nodes [m/s], the standard errors of the law's values
        there [-], each shot's share in them (nodes x shots; :func:`error_budget`) and their
        covariance (nodes x nodes).
    """
    from scipy.optimize import least_squares

    lo, hi = law.v_range
    nodes = _chebyshev_nodes(lo, hi, degree + 1)
    x0 = np.concatenate([law.poly(nodes), np.zeros(len(pairs))])
    steps = np.array([rec.trace.dt for _, rec in pairs])
    evaluations = [0]

    def residuals(x):
        evaluations[0] += 1
        trial = law_through(nodes, x[:len(nodes)], law.v_range)
        aligned = [align(_run_law(p, trial, integrator), rec, nudge * dt)
                   for (p, rec), nudge, dt in zip(pairs, x[len(nodes):], steps, strict=True)]
        return _objective_residuals(aligned, "l2")

    # the law's values, and each shot's alignment nudged within 2 samples of the threshold's
    lo = np.concatenate([np.full(len(nodes), -np.inf), np.full(len(pairs), -2.0)])
    hi = np.concatenate([np.full(len(nodes), np.inf), np.full(len(pairs), 2.0)])
    scale = np.concatenate([np.abs(x0[:len(nodes)]), np.full(len(pairs), 0.1)])
    k = len(nodes)
    fun, jac = by_shot(residuals, window_sizes([rec for _, rec in pairs]), k,
                       [list(range(k, k + len(pairs)))], 1e-4, (lo, hi))
    fit = least_squares(fun, x0, jac=jac, bounds=(lo, hi), x_scale=scale, max_nfev=150)
    errors, shares, covariance = error_budget(fit, residual_blocks([rec for _, rec in pairs]),
                                              residuals, scale, covariance=True)
    return (law_through(nodes, fit.x[:k], law.v_range), evaluations[0], nodes, errors[:k],
            shares[:k], covariance[:k, :k])


#: The standard error of a median of n samples of Gaussian noise sigma is this times
#: sigma / sqrt(n) (sqrt(pi / 2)): the baseline removed from a recording is such a median.
MEDIAN_SE = float(np.sqrt(np.pi / 2))


@dataclass(frozen=True)
class Block:
    """One shot's rows of the L2 residuals (:func:`_objective_residuals`), for the error
    budget (:func:`error_budget`).

    Attributes
    ----------
    rows : int
        Residuals of this shot (its measured pulse above 10 % of its peak).
    acf : numpy.ndarray
        Autocorrelation of white noise through the recording's CFC filter at lags 0, 1, ...
        [-] (just [1.0] unfiltered): the correlation its noise has whatever a short record's
        estimate says.
    offset : float
        Standard error of the baseline removed from the recording, in residual units
        (divided by its peak and by sqrt(rows), as the residuals are) [-].
    rest : numpy.ndarray
        The recording's samples at rest, zeroed and unfiltered [kG], for its noise's own
        correlation (:func:`noise_acf`).
    filtered : bool
        The residuals are of pulses through a CFC filter (``acf``): the noise's correlation
        is then read from the rest alone and passed through the filter's.
    """

    rows: int
    acf: np.ndarray
    offset: float
    rest: np.ndarray = field(default_factory=lambda: np.zeros(0))
    filtered: bool = False

    @property
    def tau(self):
        """The filter's integrated autocorrelation time [samples]: 1 + 2 sum of acf[1:]."""
        return float(1 + 2 * np.sum(self.acf[1:]))


def filter_acf(cfc, dt):
    """The autocorrelation [-] at lags 0, 1, ... of white noise through the phaseless CFC
    filter at step ``dt`` [s] (the impulse response's own, normalised; lags past 1e-6 of
    the peak dropped); [1.0] without a filter."""
    if not cfc:
        return np.ones(1)
    from .shock import cfc_filter

    n = 2 * int(max(2000, 40 / (cfc * dt))) + 1
    impulse = np.zeros(n)
    impulse[n // 2] = 1.0
    h = cfc_filter(impulse, dt, cfc)
    acf = np.correlate(h, h, "full")[n - 1:]
    acf /= acf[0]
    keep = np.flatnonzero(np.abs(acf) > 1e-6)
    return acf[:keep[-1] + 1]


def residual_blocks(recs):
    """Each recording's :class:`Block`: the rows :func:`_objective_residuals` gives it, its
    filter's noise correlation and its baseline's standard error (MEDIAN_SE sigma / sqrt(n) of
    the samples at rest; none when the recording has none, which it warns of)."""
    out = []
    for rec in recs:
        measured = np.asarray(rec.filtered, dtype=float)
        peak = float(np.max(measured))
        rows = int(np.sum(measured >= 0.1 * peak))
        base = rec.base
        known = base.samples > 0 and np.isfinite(base.noise)
        offset = MEDIAN_SE * base.noise / np.sqrt(base.samples) if known else 0.0
        rest = np.asarray(rec.corrected, dtype=float)[base.start:base.start + base.samples] \
            if known else np.zeros(0)
        out.append(Block(rows, filter_acf(rec.cfc, rec.trace.dt),
                         float(offset / (peak * np.sqrt(max(rows, 1)))), rest,
                         bool(rec.cfc)))
    return out


#: The largest lag-1 and lag-2-to-lag-1 ratio a shot's noise is taken to have (noise_acf):
#: nearer 1 its correlation time would grow without bound on a short record's estimate.
MAX_CORRELATION = 0.98


#: Lags of a shot's noise's autocorrelation the ARMA(1,1) form is fitted to (noise_acf).
NOISE_LAGS = 6

#: The largest share of a stretch's variance its fit is taken to have absorbed (noise_acf).
MAX_BIAS = 0.25

#: The values of phi the fit tries, 0 to MAX_CORRELATION.
_PHIS = np.linspace(0.0, MAX_CORRELATION, 99)


def noise_acf(segments, length, absorbed=None):
    """The autocorrelation [-] at lags 0 .. ``length`` - 1 of the noise in ``segments``
    (stretches of one shot's noise, each with a fit removed from it: its mean, or the
    calibration's ``absorbed`` parameters' worth): ``rho_k = c phi^(k-1)``, an ARMA(1,1)'s,
    fitted by least squares to the stretches' autocorrelations at lags 1 to
    :data:`NOISE_LAGS`. It holds white noise (c = 0), an AR(1) (c = phi) and a mix of the
    two, and keeps the correlation's tail, which summing a short record's own
    autocorrelation until it first turns negative cut off (issue 42).

    A fit of ``a`` smooth directions to ``n`` correlated samples takes ``a tau / n`` of their
    variance from every lag alike (tau the correlation time, ``1 + 2 sum rho_k``), so a
    stretch's own autocorrelation reads ``r_k = (rho_k - a tau / n) / (1 - a tau / n)``: the
    estimate is that equation solved for rho, by iterating on tau, for every stretch at
    once (each pooled by its length). A lag-1 correlation within two standard errors of
    none (2 / sqrt(n), n all the stretches' samples) is taken as none: the ratio of two
    noises would otherwise make up a correlation time.

    Parameters
    ----------
    segments : sequence of numpy.ndarray
    length : int
    absorbed : sequence of float, optional
        Each stretch's fitted directions (1, its mean, by default).
    """
    absorbed = list(absorbed) if absorbed is not None else [1.0] * len(segments)
    stretches = []
    for seg, a in zip(segments, absorbed, strict=True):
        p = np.asarray(seg, dtype=float)
        if len(p) <= NOISE_LAGS + 2:
            continue
        p = p - np.mean(p)
        power = float(p @ p)
        if power > 0:
            stretches.append((len(p), max(float(a), 1.0), np.array(
                [float(p[k:] @ p[:len(p) - k]) / power for k in range(1, NOISE_LAGS + 1)])))
    out = np.zeros(max(int(length), 1))
    out[0] = 1.0
    if not stretches or len(out) < 2:
        return out
    total = sum(n for n, _, _ in stretches)
    # the longest correlation time the stretches can tell: the correction is taken no
    # further than a quarter of the longest one's variance (past it, an offset common to
    # every lag, which is what the correction adds, reads as a correlation that never ends)
    most = max(1.0, max(MAX_BIAS * n / a for n, a, _ in stretches))
    powers = _PHIS[:, None] ** np.arange(NOISE_LAGS)[None, :]  # phi^(k-1), a row a phi
    tau, c, phi = 1.0, 0.0, 0.0
    for _ in range(50):
        lags = np.zeros(NOISE_LAGS)
        for n, a, r in stretches:
            bias = min(a * tau / n, MAX_BIAS)
            lags += n / total * (r * (1 - bias) + bias)
        if lags[0] < 2 / math.sqrt(total):
            return out
        scale = powers @ lags / np.sum(powers ** 2, axis=1)  # c for each phi
        misfit = np.sum((lags[None, :] - scale[:, None] * powers) ** 2, axis=1)
        best = int(np.argmin(misfit))
        c, phi = min(float(scale[best]), MAX_CORRELATION), float(_PHIS[best])
        if 1 + 2 * c / (1 - phi) > most:  # as much correlation as the stretches tell
            phi = max(0.0, 1 - 2 * c / (most - 1)) if most > 1 else 0.0
            c = min(c, (most - 1) * (1 - phi) / 2)
        new = 1 + 2 * c / (1 - phi)
        if abs(new - tau) <= 1e-6 * tau:
            break
        tau = new
    out[1:] = c * phi ** np.arange(len(out) - 1)
    return out


def through_filter(noise, response):
    """The autocorrelation [-] of noise of autocorrelation ``noise`` through a filter whose
    own (white noise's) autocorrelation is ``response`` (both from lag 0): their two-sided
    convolution, normalised, as long as ``noise``."""
    if len(response) <= 1:
        return noise
    two = np.concatenate([noise[:0:-1], noise])
    h = np.concatenate([response[:0:-1], response])
    full = np.convolve(two, h)
    middle = len(full) // 2
    out = full[middle:middle + len(noise)]
    return out / out[0]


def _correlated(Js, acf):
    """J^T R J for noise of autocorrelation ``acf`` (R its Toeplitz matrix)."""
    out = Js.T @ Js
    for lag in range(1, min(len(acf), len(Js))):
        cross = Js[lag:].T @ Js[:-lag]
        out += acf[lag] * (cross + cross.T)
    return out


#: The step of the Jacobian the errors are computed from, relative to each parameter (or its
#: scale): the residuals are piecewise linear on the model's 1 us grid, so the fit's own
#: forward differences at 1e-4 can land on a kink (a node's error came out 0.46 % where
#: steps of 3e-4 to 1e-2, forward or central, all give 1.2-1.3 %).
JACOBIAN_STEP = 3e-3


def error_budget(fit, blocks, residuals=None, scale=None, covariance=False):
    """Standard errors of a least-squares fit's parameters, and each shot's share of each
    parameter's variance.

    The Jacobian is taken afresh at the solution (``residuals``, forward differences of
    :data:`JACOBIAN_STEP` times each parameter or its ``scale``, scipy.optimize.approx_fprime)
    when ``residuals`` is given; else the fit's own.

    The covariance is the sandwich H M H, H = (J^T J)^-1, over the shots' blocks of rows
    (:class:`Block`), which are independent of one another:

    - each shot's noise, s_i^2 J_i^T R_i J_i: R_i the correlation of its noise (issue 42):
      the noise's own, an ARMA(1,1) read from its residuals and its rest (:func:`noise_acf`;
      from the rest alone when the residuals are filtered), through its filter's where one
      was applied (:func:`through_filter`); a Toeplitz matrix, not a scalar, which would
      misstate it where the Jacobian lives in fewer samples than the correlation's length,
      as on a fast shot's rise. s_i^2 its residuals' own variance (the shots' residuals are
      scaled by their peaks and lengths, so one pooled s^2 understates the shot with the
      fewest samples), over the degrees of freedom the fit leaves it: its rows less
      tr(H J_i^T N_i J_i), what the fit absorbs of noise correlated as N_i, the noise's own
      correlation without its filter's (n rows / m of white noise's, more of a correlated
      one's);
    - its baseline's error, a constant under all its rows: (J_i^T 1) (J_i^T 1)^T o_i^2, o_i
      the standard error of a median of its rest, whose correlated samples count as fewer
      (the correlation of their signs, (2/pi) arcsin(rho), a Gaussian's).

    Measured on the recorder model over 200 seeds (tests/test_calibration_intervals.py),
    white noise and AR(1) noise of 0.6 (half its variance) and 0.8: every node's 95 %
    interval holds the truth inside the exact binomial band taken family-wise over the 37
    intervals checked (pooled, AR(1) 0.8's cover 92.7 %: slightly narrow).

    A singular J^T J (a parameter the residuals do not see) gives infinite errors.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The standard errors (one a parameter), and the shares [-] (parameters x shots, each
        row summing to 1) of each shot in each parameter's variance: the shots that pin it;
        with ``covariance``, a third: the parameters' covariance matrix (the same sandwich,
        whole; its diagonal the errors squared).
    """
    r = np.asarray(fit.fun, dtype=float)
    if residuals is not None:
        from scipy.optimize import approx_fprime

        x = np.asarray(fit.x, dtype=float)
        size = np.maximum(np.abs(x), np.abs(scale) if scale is not None else 0.0)
        step = JACOBIAN_STEP * np.where(size > 0, size, 1.0)
        J = np.asarray(approx_fprime(x, residuals, step), dtype=float).reshape(len(r), len(x))
    else:
        J = np.asarray(fit.jac, dtype=float)
    m, n = J.shape
    try:
        H = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        singular = np.full(n, np.inf), np.full((n, len(blocks)), np.nan)
        return (*singular, np.full((n, n), np.inf)) if covariance else singular
    parts = np.zeros((len(blocks), n))
    whole = np.zeros((n, n))
    start = 0
    for k, block in enumerate(blocks):
        rows = slice(start, start + block.rows)
        start += block.rows
        Js, rs = J[rows], r[rows]
        # the noise's own correlation: from its rest and (unfiltered) its residuals, and
        # through the filter's where one was applied
        absorbed = float(np.trace(H @ (Js.T @ Js)))  # the parameters' share in its rows
        noise_rho = noise_acf([block.rest] if block.filtered else [rs, block.rest],
                              block.rows, None if block.filtered else [absorbed, 1.0])
        acf = through_filter(noise_rho, block.acf)
        correlated = _correlated(Js, acf)
        # the residuals' degrees of freedom: what the fit absorbs of the noise is its hat
        # matrix's share of it, tr(H J^T R J) (n rows / m of white noise's, more of a
        # correlated one's), R the noise's own correlation: counting the filter's too
        # overstated the errors under CFC 600 by 10 to 20 % on the recorder model (the fit
        # absorbs less of a filtered noise than its linearisation says)
        dof = max(block.rows - float(np.trace(H @ _correlated(Js, noise_rho))), 1.0)
        s2 = float(rs @ rs) / dof
        G = H @ Js.T
        noise = H @ correlated @ H
        # the baseline's error: a median of correlated samples varies as that of fewer, the
        # correlation of their signs (2/pi) arcsin(rho) counting (a Gaussian's)
        offset = block.offset * math.sqrt(float(
            1 + 2 * np.sum(2 / np.pi * np.arcsin(noise_rho[1:block.rest.size]))))
        parts[k] = s2 * np.diag(noise) + (offset * G.sum(axis=1)) ** 2
        whole += s2 * noise + np.outer(offset * G.sum(axis=1), offset * G.sum(axis=1))
    if start != m:  # the blocks describe other residuals: a fault of ours, not the data's
        raise ValueError(f"error budget: {start} rows in the blocks, {m} residuals")
    variance = parts.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        shares = (parts / variance).T
    errors = np.sqrt(np.clip(variance, 0, None))
    errors = np.where(np.isfinite(errors), errors, np.inf)
    return (errors, shares, whole) if covariance else (errors, shares)


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
    if address("sigmay") in names and "scale" in names:
        raise OptionError("--fit: found both E40 and scale, expected one of them: the yield "
                          "stress and the law's scale multiply the same crush force, so no "
                          "pulse can tell them apart")
    if objective not in OBJECTIVES:
        raise OptionError(f"--objective: found {objective!r}, expected one of "
                          f"{', '.join(OBJECTIVES)}")
    return names


#: A fitted value within this fraction of a bound is tried at the bound (fit_parameters).
BOUND_REACH = 0.05

#: The law's tilt with speed is fitted within +/- this (a law 50 % stronger at twice the
#: reference speed than at it).
TILT_REACH = 0.5

#: A shot's launch velocity is fitted within this fraction of its set value (a gun 15 % off
#: its setting is not scatter).
VELOCITY_REACH = 0.15


def fit_parameters(pairs, names, cfc=None, objective="l2", integrator="legacy",
                   velocities=False, tilt_about=None):
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
    velocities : bool
        Also fit each shot's launch velocity (A28..A30, a factor on the set value within
        +/- :data:`VELOCITY_REACH`): the shots' own speeds, with the pooled values
        (:attr:`FitResult.velocities`). L2 only.
    tilt_about : float or None
        With the scale, also fit the law's tilt with speed about this speed [m/s]
        (:meth:`~airgun_xl.crush_law.CrushLaw.tilted`, within +/- :data:`TILT_REACH`),
        named ``"tilt"``. L2 only.

    Returns
    -------
    FitResult
    """
    from scipy.optimize import least_squares, minimize

    names = check_fit(names, objective)
    if (velocities or tilt_about is not None) and objective != "l2":
        raise OptionError("the launch velocities and the law's tilt are fitted on the L2 "
                          "objective only")
    if tilt_about is not None and "scale" not in names:
        raise OptionError("--fit: the law's tilt is fitted with its scale only")
    p0 = pairs[0][0]
    start = {address("sigmay"): p0.sigmay, address("zeta"): p0.zeta, "scale": 1.0,
             "tilt": 0.0}
    x0, lo, hi = [], [], []
    for n in names:
        _, low, high = FIT_PARAMETERS[n]
        x0.append(start[n])
        lo.append(start[n] * low if low else 0.0)
        hi.append(start[n] * high if high else 0.5)
    if tilt_about is not None:
        names = [*names, "tilt"]
        x0.append(0.0)
        lo.append(-TILT_REACH)
        hi.append(TILT_REACH)
    evaluations = [0]

    k = len(pairs)

    def shots(x):
        values = dict(zip(names, x[:len(names)], strict=True))
        factors = x[len(names) + k:] if velocities else np.ones(k)
        out = []
        for (p, _), factor in zip(pairs, factors, strict=True):
            changes = {}
            if velocities:
                changes.update({f: getattr(p, f) * float(factor) for f in ("v31", "v32", "v33")})
            if address("sigmay") in values:
                changes["sigmay"] = values[address("sigmay")]
            if address("zeta") in values:
                changes["zeta"] = values[address("zeta")]
            if "tilt" in values:
                changes["crush_law"] = p.crush_law.tilted(values["scale"], values["tilt"],
                                                          tilt_about)
            elif "scale" in values:
                changes["crush_law"] = p.crush_law.scaled(values["scale"])
            out.append(p.replace(**changes))
        return out

    steps = np.array([rec.trace.dt for _, rec in pairs])

    def residuals(x, objective="l2", nudges=None):
        evaluations[0] += 1
        nudges = x[len(names):len(names) + k] if nudges is None else nudges
        aligned = [align(_run(p, integrator), rec, nudge * dt)
                   for p, (_, rec), nudge, dt in zip(shots(x), pairs, nudges, steps,
                                                     strict=True)]
        return _objective_residuals(aligned, objective)

    # the values, and each shot's alignment nudged within 2 samples of the threshold's (a
    # crossing on a noisy rise is early on average: left fixed, it biased E40 by 0.6 of its
    # standard error)
    m = k if velocities else 0
    start_x = np.concatenate([np.clip(x0, lo, hi), np.zeros(k), np.ones(m)])
    scale = np.concatenate([np.where(start_x[:len(names)] > 0, np.abs(start_x[:len(names)]),
                                     0.01), np.full(k, 0.1), np.full(m, 0.01)])
    upper = np.concatenate([hi, np.full(k, 2.0), np.full(m, 1 + VELOCITY_REACH)])
    lower = np.concatenate([lo, np.full(k, -2.0), np.full(m, 1 - VELOCITY_REACH)])
    d = len(names)
    # (the least squares are on L2 for either objective; a shot's alignment and launch
    # velocity move its own pulse alone)
    fun, jac = by_shot(residuals, window_sizes([rec for _, rec in pairs]), d,
                       [list(range(d, d + k))] + ([list(range(d + k, d + k + m))] if m else []),
                       1e-4, (lower, upper))
    fit = least_squares(fun, start_x, jac=jac, bounds=(lower, upper), x_scale=scale,
                        xtol=1e-10, ftol=1e-10, gtol=1e-10, max_nfev=200)
    # a fit that stops short of a bound its cost still falls towards (the residuals are
    # piecewise on the model's grid, so the trust region can stall within a few % of it) is
    # taken to the bound and polished from there when that costs less
    for i in range(len(names)):
        for bound in (lower[i], upper[i]):
            if abs(fit.x[i] - bound) <= BOUND_REACH * abs(bound) and fit.x[i] != bound:
                trial = fit.x.copy()
                trial[i] = bound
                r = residuals(trial)
                if 0.5 * float(r @ r) < fit.cost:
                    fit = least_squares(fun, trial, jac=jac, bounds=(lower, upper),
                                        x_scale=scale, xtol=1e-10, ftol=1e-10, gtol=1e-10,
                                        max_nfev=100)
    x, cost, nudges = fit.x[:len(names)], float(fit.cost), fit.x[len(names):len(names) + k]
    budget, _shares, whole = error_budget(fit, residual_blocks([rec for _, rec in pairs]),
                                          residuals, scale, covariance=True)
    errors = budget[:len(names)]
    speeds = [(float(p.v31 - p.v1), float(f), float(e)) for (p, _), f, e in zip(
        pairs, fit.x[len(names) + k:], budget[len(names) + k:], strict=True)] if velocities else []
    if objective == "iso18571":
        # the rating is jagged in the parameters (its DTW and phase search move in steps), so
        # a finite-difference slope can point the wrong way: a derivative-free search (Powell,
        # bounded) from the L2 fit, its alignment kept; the L2 fit's standard errors stand
        def worse(y):
            return float(np.sum(residuals(y, "iso18571", nudges)))

        found = minimize(worse, x, method="Powell", bounds=list(zip(lo, hi, strict=True)),
                         options={"xtol": 1e-4, "ftol": 1e-6, "maxfev": 200})
        if found.fun < worse(x):
            x, cost = found.x, float(found.fun)
    return FitResult(dict(zip(names, map(float, x), strict=True)),
                     {n: start[n] for n in names}, cost, evaluations[0],
                     shots(np.concatenate([x, fit.x[len(names):]])),
                     dict(zip(names, map(float, errors), strict=True)),
                     {n: (float(a), float(b)) for n, a, b in zip(names, lo, hi, strict=True)},
                     speeds, whole[:len(names), :len(names)])


@dataclass
class Score:
    rms: float  # RMS error over the measured pulse, relative to its peak
    iso: float  # ISO/TS 18571 overall rating


@dataclass
class Calibration:
    """What :func:`calibrate` found: each shot's fitted parameters, the way there, and the
    verdict: ``warnings`` name what cannot be vouched for, and ``trusted`` is False then."""

    params: list
    law_calibration: LawCalibration | None
    fitted: dict
    start: dict
    before: list
    after: list
    aligned: list  # each shot's pulses after calibration
    runs: int = 0
    seconds: float = 0.0
    errors: dict = field(default_factory=dict)  # standard error of each fitted value
    bounds: dict = field(default_factory=dict)  # (low, high) of each fitted value
    law_nodes: np.ndarray | None = None  # [m/s] where the law's standard errors are
    law_errors: np.ndarray | None = None  # [-] standard errors of the law's values there
    law_shares: np.ndarray | None = None  # [-] each shot's share in them (nodes x shots)
    law_covariance: np.ndarray | None = None  # [-] of the law's values there (nodes x nodes)
    recordings: list = field(default_factory=list)  # each shot's measured Recording
    law_intervals: list = field(default_factory=list)  # NodeInterval of each law node
    warnings: list = field(default_factory=list)
    notes: list = field(default_factory=list)  # said with the figures; no verdict on them
    #: with ``velocities``: each shot's (impact speed set [m/s], fitted factor, its standard
    #: error)
    velocities: list = field(default_factory=list)
    covariance: np.ndarray | None = None  # of the fitted values, in the order of ``fitted``

    @property
    def trusted(self):
        return not self.warnings


def score(a):
    """RMS error and ISO/TS 18571 rating of an aligned pair, over the measured pulse widened by
    a tenth of its duration each side, from the impact on (as compare-measured rates it); the
    rating is NaN where it cannot be computed (too short a pulse)."""
    from ..engine.summary import pulse
    from .iso18571 import rating

    start, end, duration = pulse(a.time, a.measured_kg)
    lo, hi = max(0.0, start - 0.1 * duration), min(a.time[-1], end + 0.1 * duration)
    try:
        iso = rating(a.time, a.measured_kg, a.simulated_kg, lo, hi).overall
    except ValueError:
        iso = float("nan")
    return Score(rms_error(a), iso)


#: A fitted value whose standard error passes this fraction of it is not identified.
UNIDENTIFIED = 0.5

#: A calibrated shot whose RMS error stays above this fraction of its peak is not described
#: by the model (the recorder model's 3 % noise leaves about 3 %).
POOR_FIT = 0.10

#: How much worse a shot's RMS error must be after the calibration to be said [-, of it]: a
#: fit of the whole lot trades a shot's residual for the others' by a fraction of a percent
#: on every update ("2.13% -> 2.13%" piled up on each of a lot's shots); 1 % of it is past
#: that and shows in the two decimals printed.
WORSE_RMS = 0.01

#: A value within this fraction of its range from a bound is at the bound.
AT_BOUND = 0.01


def at_bound(cal):
    """The names of ``cal``'s fitted values within :data:`AT_BOUND` of their range from a
    bound (a Calibration's ``fitted`` and ``bounds``)."""
    return [name for name, value in cal.fitted.items()
            if min(value - cal.bounds[name][0], cal.bounds[name][1] - value)
            <= AT_BOUND * (cal.bounds[name][1] - cal.bounds[name][0])]


def verdict(cal, cfc, objective, p0):
    """(warnings, notes) of a calibration.

    Warnings: a value at a bound, or with a standard error past :data:`UNIDENTIFIED` of it;
    zeta fitted through a filter that removes the modes it damps; a law that did not converge
    or whose values the pulses do not pin down; a shot whose residual (or, for the ISO
    objective, rating) got worse, or stays past :data:`POOR_FIT`. Notes: a law measured below
    the shots' impact speed (the law claims only its samples' span)."""
    from ..engine.summary import natural_frequencies

    found, notes = [], []
    bounded = at_bound(cal)
    for name, value in cal.fitted.items():
        lo, hi = cal.bounds[name]
        error = cal.errors.get(name, np.inf)
        # the tilt is no --fit name: next fits it with the scale (docs/studies.md)
        shown = "the law's tilt with speed" if name == "tilt" else f"--fit {name}"
        if name in bounded:
            found.append(f"{shown}: {value:.6g} is at its bound ({lo:.4g}..{hi:.4g}): "
                         "not identified by these pulses")
        elif not error <= UNIDENTIFIED * (TILT_REACH if name == "tilt" else abs(value)):
            found.append(f"{shown}: {value:.6g} +/- {error:.3g} (1 standard error): the "
                         "pulses do not pin it down (not identified)")
    if address("zeta") in cal.fitted and cfc:
        chain = (p0.m31, p0.m32, p0.m33)[:p0.bird_masses]
        springs = (-p0.k2, -p0.k3)[:p0.bird_masses - 1]
        lowest = min(natural_frequencies(chain, springs), default=np.inf)
        corner = 1.65 * cfc  # the J211 class's -3 dB frequency
        if lowest > corner:
            found.append(f"--fit E43: zeta damps the OBR modes (from {lowest:,.0f} Hz), which "
                         f"the CFC {cfc} filter (-3 dB at {corner:,.0f} Hz) takes out of both "
                         "pulses: not identified through it (fit unfiltered, or with a higher "
                         "class)")
    lc = cal.law_calibration
    if lc is not None:
        if not lc.converged:
            found.append(f"crush law: not converged in {len(lc.iterations)} iterations (last "
                         f"change {lc.iterations[-1].change:.2%})")
        lo, hi = cal.params[0].crush_law.v_range
        fastest = max(p.v31 - p.v1 for p in cal.params)
        if fastest > hi:
            notes.append(f"crush law: measured from {lo:.1f} to {hi:.1f} m/s (its samples' "
                         f"{SPAN_PERCENTILES[0]}st to {SPAN_PERCENTILES[1]}th percentile), "
                         f"below the shots' impact speed of {fastest:.1f} m/s: a run of them "
                         "extrapolates it at first (fill warns); the law itself is not "
                         "claimed there")
        if cal.law_errors is not None and np.any(
                cal.law_errors > UNIDENTIFIED * np.abs(cal.params[0].crush_law.poly(
                    cal.law_nodes))):
            found.append("crush law: a value of the law has a standard error over "
                         f"{UNIDENTIFIED:.0%} of it: the pulses do not pin the law down there")
    for i, (before, after) in enumerate(zip(cal.before, cal.after, strict=True), start=1):
        if after.rms > POOR_FIT:
            found.append(f"shot {i}: after calibration the model still misses the measured "
                         f"pulse by {after.rms:.1%} RMS of its peak (over {POOR_FIT:.0%}): the "
                         "model does not describe this recording, whatever the fitted values")
        if after.rms > before.rms * (1 + WORSE_RMS):
            found.append(f"shot {i}: the calibration made its RMS error worse ({before.rms:.2%} "
                         f"-> {after.rms:.2%})")
        if objective == "iso18571" and after.iso < before.iso - 1e-9:
            found.append(f"shot {i}: the calibration made its ISO/TS 18571 rating worse "
                         f"({before.iso:.3f} -> {after.iso:.3f})")
    return found, notes


def calibrate(params, traces, law=True, fit=(), cfc=None, degree=DEGREE, objective="l2",
              integrator="legacy", anti_alias="auto", velocities=False, tilt_about=None):
    """Calibrate the model on measured shots: the crush-factor law (the report's iteration,
    then least squares on the law's values, :func:`refine_law`), then the named parameters
    (:func:`fit_parameters`), and its :func:`verdict`.

    Parameters
    ----------
    params : list of ShotParams
    traces : list of Trace
        The measured pulse of each shot (zeroed, filtered and its impact level set by
        :func:`~airgun_xl.studies.measured.prepare`).
    law : bool
    fit : sequence of str
        Names from :data:`FIT_PARAMETERS`.
    anti_alias : float, "auto" or "none"
        The recorders' anti-alias filter, modelled on the runs.
    velocities : bool
        With ``fit``, also each shot's launch velocity (:func:`fit_parameters`):
        :attr:`Calibration.velocities`.
    tilt_about : float or None
        With ``fit=("scale",)``, also the law's tilt with speed about this speed [m/s]
        (:func:`fit_parameters`), fitted as ``"tilt"``.

    Returns
    -------
    Calibration
    """
    import time

    from .measured import alignment_shift, prepare
    from .recording_quality import Expected

    started = time.perf_counter()
    counter = {"runs": 0}
    first = [_run(p, integrator) for p in params]  # also what each recording should show
    recs = [prepare(t, cfc, anti_alias, p.delta, expected=Expected.of_pulse(
        run.history.time, run.accel_kg)) for p, t, run in zip(params, traces, first,
                                                               strict=True)]
    pairs = list(zip(params, recs, strict=True))

    before = [score(align(run, r)) for run, r in zip(first, recs, strict=True)]
    counter["runs"] += len(params)
    law_cal, nodes, law_errors, law_shares, law_covariance = None, None, None, None, None
    if law:
        law_cal = calibrate_law(pairs, cfc, degree, integrator)
        counter["runs"] += len(law_cal.iterations) * len(pairs)
        refined, evaluations, nodes, law_errors, law_shares, law_covariance = refine_law(
            pairs, law_cal.law, integrator, degree)
        counter["runs"] += evaluations * len(pairs)
        params = [p.replace(crush_law=refined) for p in params]
        pairs = list(zip(params, recs, strict=True))
    fitted, start, errors, bounds, velocity_fit, covariance = {}, {}, {}, {}, [], None
    if fit:
        result = fit_parameters(pairs, fit, cfc, objective, integrator, velocities,
                                tilt_about)
        counter["runs"] += result.evaluations * len(pairs)
        params, fitted, start = result.params, result.values, result.start
        errors, bounds = result.errors, result.bounds
        velocity_fit, covariance = result.velocities, result.covariance
    runs = [_run(p, integrator) for p in params]
    counter["runs"] += len(runs)
    aligned = [align(run, rec) for run, rec in zip(runs, recs, strict=True)]
    after = [score(a) for a in aligned]
    cal = Calibration(params, law_cal, fitted, start, before, after, aligned,
                      counter["runs"], time.perf_counter() - started, errors, bounds, nodes,
                      law_errors, law_shares, law_covariance, recs,
                      velocities=velocity_fit, covariance=covariance)
    for rec, run in zip(recs, runs, strict=True):  # the same runs, cross-checked
        cal.warnings += [f"{rec.trace.name}: {w}" for w in rec.warnings]
        ok = np.isfinite(run.accel_kg)
        said = alignment_shift(run.history.time[ok], run.accel_kg[ok], rec, "threshold")[3]
        cal.warnings += [f"{rec.trace.name}: {w}" for w in said]
    found, cal.notes = verdict(cal, cfc, objective, params[0])
    cal.warnings += found
    if law_errors is not None:
        cal.law_intervals = node_intervals(cal, integrator)
    return cal


#: Two-sided 95 % quantile of the normal distribution (scipy.stats.norm.ppf(0.975)).
Z95 = 1.959963984540054

#: A law node whose 95 % interval is wider than this (relative, each side) is weakly pinned.
WEAK_PIN = 0.02

#: A shot whose share of a node's variance reaches this is named as pinning it.
PINNING_SHARE = 0.2


@dataclass
class NodeInterval:
    """The law's value at one of its nodes, with its 95 % interval and who pins it.

    Attributes
    ----------
    velocity : float
        The node [m/s].
    value, error : float
        The fitted law there, and its standard error [-] (:func:`error_budget`).
    shares : list of (int, float, float)
        (shot number, impact speed [m/s], share of the node's variance [-]) of the shots
        that pin it (share at least :data:`PINNING_SHARE`), largest first.
    suggested : float or None
        For a weakly pinned node: the impact speed [m/s] of the shot that would pin it best
        (:func:`pinning_speed`).
    """

    velocity: float
    value: float
    error: float
    shares: list
    suggested: float | None = None

    @property
    def half_width(self):
        """The 95 % interval's half width, relative to the value [-]."""
        return Z95 * self.error / abs(self.value) if self.value else float("inf")

    @property
    def weak(self):
        return not self.half_width <= WEAK_PIN

    @property
    def low(self):
        return self.value - Z95 * self.error

    @property
    def high(self):
        return self.value + Z95 * self.error

    def record(self):
        """The node as the archive keeps it (a law's ``intervals``; a value that is not
        finite, as an unpinned node's error, kept as null: JSON has no infinity)."""
        def number(x):
            return float(x) if np.isfinite(x) else None

        return {"velocity": number(self.velocity), "value": number(self.value),
                "error": number(self.error), "low": number(self.low),
                "high": number(self.high), "weak": bool(self.weak)}

    def pinned_by(self):
        return ", ".join(f"shot {k} ({v:.1f} m/s, {share:.0%})" for k, v, share in self.shares)

    def words(self):
        text = (f"crush law at {self.velocity:.1f} m/s: {self.value:.4f} +/- "
                f"{self.half_width:.1%} (95 %), weakly pinned (over +/- {WEAK_PIN:.0%}); "
                f"pinned by {self.pinned_by() or 'no shot in particular'}")
        if self.suggested is not None:
            text += f"; a shot at about {self.suggested:.0f} m/s would pin it best"
        return text


def pinning_speed(p, law, velocity, width, integrator="legacy"):
    """The impact speed [m/s] of the shot that would pin the law best at ``velocity`` [m/s]:
    of speeds from ``velocity`` to 1.6 times it, the slowest whose pulse dwells within
    ``width`` / 2 of it, loading with at least half its peak force (past the rise, before the
    end), for at least 95 % of the longest such dwell. Runs ``p`` with ``law`` at each."""
    from ..errors import AirgunXlError

    candidates = velocity + width / 2 + np.linspace(0.0, 0.6 * velocity, 25)
    dwell = np.zeros(len(candidates))
    for k, v0 in enumerate(candidates):
        try:
            run = _run(p.replace(v31=v0 + p.v1, v32=v0 + p.v1, v33=v0 + p.v1, crush_law=law),
                       integrator)
        except AirgunXlError:  # a speed the law cannot run at is no suggestion
            continue
        h = run.history
        t, force = h.time[2:], h.force[2:]
        v = np.interp(t, h.time[1:-1], (h.v31 - h.v1)[1:-1])
        near = (np.abs(v - velocity) <= width / 2) & (force >= 0.5 * np.max(force))
        dwell[k] = float(np.sum(np.gradient(t)[near]))
    if not np.any(dwell > 0):
        return None
    return float(candidates[np.flatnonzero(dwell >= 0.95 * dwell.max())[0]])


def node_intervals(cal, integrator="legacy"):
    """Each law node's :class:`NodeInterval`, with the shots that pin it and, for a weakly
    pinned one, the impact speed that would pin it best."""
    law = cal.params[0].crush_law
    nodes = np.asarray(cal.law_nodes, dtype=float)
    speeds = [p.v31 - p.v1 for p in cal.params]
    spacing = np.diff(nodes)
    out = []
    for k, v in enumerate(nodes):
        row = cal.law_shares[k] if cal.law_shares is not None else ()
        shares = sorted(((i + 1, speeds[i], float(x)) for i, x in enumerate(row)
                         if np.isfinite(x) and x >= PINNING_SHARE), key=lambda s: -s[2])
        node = NodeInterval(float(v), float(law(v)), float(cal.law_errors[k]), shares)
        if node.weak:
            width = float(min(spacing[max(k - 1, 0)], spacing[min(k, len(spacing) - 1)]))
            node.suggested = pinning_speed(cal.params[0], law, float(v), width, integrator)
        out.append(node)
    return out


def synthetic_measurement(p, dt=1e-5, noise=0.01, ringing_hz=8000.0, ringing=0.1, seed=0,
                          integrator="legacy", name="synthetic"):
    """A "measured" pulse made from known parameters ``p`` by the recorder model
    (:class:`~airgun_xl.studies.recorder.Recorder`): sampled every ``dt`` [s] through a
    4-pole anti-alias filter at a fifth of the rate, with white noise (``noise`` x the peak)
    and a decaying mount ringing at ``ringing_hz`` (``ringing`` x the peak); 0.5 ms of
    pre-trigger, no offset, the macro's sign, on a clock 2 ms ahead."""
    from .recorder import Recorder

    rec = Recorder(rate=1 / dt, noise=noise, offset_g=0.0, pre_trigger=5e-4, sign=1.0,
                   ringing=ringing, ringing_hz=ringing_hz)
    return rec.record(_run(p, integrator), seed=seed, name=name)
