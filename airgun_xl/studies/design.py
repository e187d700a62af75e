"""Test design: find the parameter value that gives a client's requested pulse.

The peak of the test item's acceleration is a piecewise-smooth function of a parameter (the
OBR's ringing shifts which oscillation is highest), so the solver first scans the parameter's
range in one batch run, then refines the first bracket where the peak crosses the target
with scipy's brentq, which needs only a sign change, not smoothness.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from ..cells import BY_NAME, address
from ..engine.batch import run_batch
from ..errors import DesignError, OptionError
from ..models import apply_model


@dataclass(frozen=True)
class Variable:
    """A parameter the design may vary: its cells, the fields they fill, and a search range
    (absolute, or relative to the sheet's value when ``relative``)."""

    cell: str
    label: str
    unit: str
    fields: tuple
    cells: tuple
    range: tuple
    relative: bool = False

    def value(self, p):
        return getattr(p, self.fields[0])

    def bounds(self, p):
        lo, hi = self.range
        if self.relative and self.value(p) == 0:
            raise OptionError(f"--range: {self.cell} is 0 on the sheet, so the default range "
                              f"(x{lo:g} to x{hi:g} of it) is empty; expected --range LO:HI")
        return (lo * self.value(p), hi * self.value(p)) if self.relative else (lo, hi)

    def apply(self, p, x):
        return p.replace(**{f: float(x) for f in self.fields})


def _variable(fields, search, relative=False, label=None):
    """A variable over the cells of ``fields`` (the first names it, and gives its unit)."""
    first = BY_NAME[fields[0]]
    return Variable(first.address, label or first.address, first.unit, fields,
                    tuple(address(f) for f in fields), search, relative)


VARIABLES = {v.cell: v for v in (
    _variable(("v31", "v32", "v33"), (10.0, 260.0), label="v0"),  # the bird, all three
    _variable(("rcone",), (0.5, 2.0), True),
    _variable(("hcone",), (0.2, 3.0), True),
    _variable(("sigmay",), (0.5, 2.0), True),
    _variable(("m1",), (0.25, 4.0), True),
)}

#: Points of the first scan over a parameter's range.
SCAN_POINTS = 25


def variable(name):
    key = name.strip().upper()
    if key in (address("v32"), address("v33"), "V0"):
        key = address("v31")
    if key not in VARIABLES:
        raise OptionError(f"--vary: found {name!r}, expected one of {', '.join(VARIABLES)}")
    return VARIABLES[key]


@dataclass
class Design:
    """A solved design."""

    variables: list
    values: list
    params: object
    peak_kg: float
    duration: float
    evaluations: int
    warnings: list = field(default_factory=list)
    margin: float = math.nan  # SRS designs: least SRS / required - 1 over the frequencies
    governing_hz: float = math.nan  # where that least margin is


class _Objective:
    """Figures of the shot at parameter values, counting simulations."""

    def __init__(self, p, integrator, model, filtered, runner=None):
        self.p, self.integrator, self.model = p, integrator, model
        self.runner = runner or run_batch
        self.column = 2 if filtered else 0
        self.evaluations = 0

    def figures(self, params_list):
        self.evaluations += len(params_list)
        batch = self.runner([apply_model(q, self.model) for q in params_list], self.integrator)
        return batch.figures

    def peak(self, params):
        return float(self.figures([params])[0, self.column])


def _bracket(xs, ys, target):
    """First consecutive pair of scan points whose values straddle the target."""
    for i in range(len(xs) - 1):
        a, b = ys[i] - target, ys[i + 1] - target
        if np.isfinite(a) and np.isfinite(b) and (a == 0 or a * b < 0):
            return xs[i], xs[i + 1]
    return None


def _span_message(var, p, xs, ys, what):
    finite = ys[np.isfinite(ys)]
    lo, hi = var.bounds(p)
    held = "" if var.cell == address("rcone") else f"with E13 = {p.rcone:.3g} m "
    if not len(finite):
        return f"{held}every shot diverged for {var.label} in {lo:.4g}-{hi:.4g} {var.unit}"
    return (f"{held}the {what} spans {finite.min():.3g}-{finite.max():.3g} kG for {var.label} "
            f"in {lo:.4g}-{hi:.4g} {var.unit}")


def solve_peak(p, target_kg, var, filtered=False, integrator="legacy", model="4-mass",
               bounds=None, objective=None, runner=None):
    """The value of ``var`` that gives a peak of ``target_kg``.

    Parameters
    ----------
    p : airgun_xl.params.ShotParams
    target_kg : float
        Requested peak [kG].
    var : Variable
    filtered : bool
        Match the filtered peak instead of the raw one.
    bounds : (float, float), optional
        Search range; :attr:`Variable.range` by default.
    runner : callable, optional
        Runs batches of shots: ``run_batch`` here, or a ``ClusterRunner``.

    Returns
    -------
    Design

    Raises
    ------
    DesignError
        When the peak never reaches the target over the range; the message gives the span.
    """
    from scipy.optimize import brentq

    obj = objective or _Objective(p, integrator, model, filtered, runner)
    lo, hi = bounds or var.bounds(p)
    xs = np.linspace(lo, hi, SCAN_POINTS)
    ys = obj.figures([var.apply(p, x) for x in xs])[:, obj.column]
    bracket = _bracket(xs, ys, target_kg)
    if bracket is None:
        what = "filtered peak" if filtered else "peak"
        raise DesignError(f"a {'filtered ' if filtered else ''}peak of {target_kg:.5g} kG is "
                          f"out of reach: {_span_message(var, p, xs, ys, what)}")
    x = brentq(lambda v: obj.peak(var.apply(p, v)) - target_kg, *bracket, xtol=1e-12,
               rtol=1e-12, maxiter=200)
    solved = var.apply(p, x)
    figs = obj.figures([solved])[0]
    design = Design([var], [x], solved, float(figs[obj.column]), float(figs[3]),
                    obj.evaluations)
    design.warnings = design_warnings(solved, target_kg, design.peak_kg)
    return design


def solve_peak_and_duration(p, target_kg, target_s, var1, var2, filtered=False,
                            integrator="legacy", model="4-mass", runner=None):
    """Two parameters for a peak and a pulse duration: ``var1`` meets the peak for each
    value of ``var2``, and brentq on ``var2`` meets the duration."""
    from scipy.optimize import brentq

    obj = _Objective(p, integrator, model, filtered, runner)

    def duration_at(v2):
        design = solve_peak(var2.apply(p, v2), target_kg, var1, filtered, integrator, model,
                            objective=obj)
        return design.duration, design

    lo, hi = var2.bounds(p)
    xs = np.linspace(lo, hi, 9)
    durations = []
    for x in xs:
        try:
            durations.append(duration_at(x)[0])
        except DesignError:
            durations.append(math.nan)
    ds = np.array(durations)
    bracket = _bracket(xs, ds, target_s)
    if bracket is None:
        finite = ds[np.isfinite(ds)]
        span = (f"{finite.min() * 1e3:.3g}-{finite.max() * 1e3:.3g} ms" if len(finite)
                else "nothing")
        raise DesignError(f"a pulse of {target_s * 1e3:.4g} ms at {target_kg:.5g} kG is out "
                          f"of reach: varying {var2.label} over {lo:.4g}-{hi:.4g} {var2.unit}"
                          f" gives {span}")
    x2 = brentq(lambda v: duration_at(v)[0] - target_s, *bracket, xtol=1e-12, rtol=1e-9,
                maxiter=100)
    _, inner = duration_at(x2)
    inner.variables, inner.values = [var1, var2], [inner.values[0], x2]
    inner.evaluations = obj.evaluations
    return inner


def design_warnings(p, target_kg, achieved):
    """Where the solution stretches the model."""
    out = []
    if abs(achieved - target_kg) > 1e-3 * abs(target_kg):
        out.append(f"the peak jumps across the target here: {achieved:.5g} kG is the closest "
                   "this parameter reaches")
    from .check import impact_speed_finding

    speed = impact_speed_finding(p)
    if speed is not None:  # the words the fill of the designed shot uses too
        out.append(str(speed))
    return out


def srs_margin(p, frequencies, required, q, integrator="legacy", model="4-mass"):
    """(margin, index): the least ratio of the shot's SRS to the required one, less 1, over
    ``frequencies`` [Hz], and the index of the frequency where it is (the governing one)."""
    from ..shot import Shot
    from .shock import srs

    r = Shot(apply_model(p, model)).run(integrator=integrator, track=())
    a = r.accel_kg[np.isfinite(r.accel_kg)]
    if not len(a) or not np.isfinite(r.history.y33).all():
        return math.nan, 0
    ratio = srs(a, p.delta, frequencies, q) / required
    k = int(np.argmin(ratio))
    return float(ratio[k] - 1), k


def _enveloping_side(x, bracket, margin):
    """``x`` moved, by steps doubling from 1e-12 of it, to where the margin is >= 0: brentq's
    root may sit a rounding below it, and a design said to envelop must (no "-0.00 %")."""
    a, b = bracket
    toward = b if margin(b)[0] >= 0 else a
    step = 1e-12 * max(abs(x), abs(toward - x))
    while margin(x)[0] < 0 and step < abs(toward - x):
        x = x + math.copysign(step, toward - x)
        step *= 2
    return x if margin(x)[0] >= 0 else toward


def solve_srs(p, frequencies, required, var, q=10.0, integrator="legacy", model="4-mass",
              bounds=None):
    """The least value of ``var`` whose shock response spectrum envelops ``required``.

    Shock test specifications give a spectrum the test must reach at every frequency; the
    cheapest test meets it with the least margin. The margin (the least of SRS / required,
    less 1) is scanned over the range, then brentq finds where it first reaches 0.

    Parameters
    ----------
    frequencies, required : numpy.ndarray
        The specification: natural frequencies [Hz] and SRS levels [kG].
    q : float
        The SRS's quality factor.

    Raises
    ------
    DesignError
        When no value in the range envelops the requirement: the message names the governing
        frequency and how far the best value falls short.
    """
    from scipy.optimize import brentq

    evaluations = [0]

    def margin(x):
        evaluations[0] += 1
        return srs_margin(var.apply(p, x), frequencies, required, q, integrator, model)

    lo, hi = bounds or var.bounds(p)
    xs = np.linspace(lo, hi, SCAN_POINTS)
    scanned = [margin(x) for x in xs]
    ms = np.array([m for m, _ in scanned])
    if np.isfinite(ms[0]) and ms[0] >= 0:
        x = lo  # the least value of the range already envelops it
    else:
        bracket = _bracket(xs, ms, 0.0)
        if bracket is None:
            finite = np.isfinite(ms)
            if not finite.any():
                raise DesignError(f"the required SRS is out of reach: every shot diverged for "
                                  f"{var.label} in {lo:.4g}-{hi:.4g} {var.unit}")
            best = int(np.nanargmax(ms))
            k = scanned[best][1]
            raise DesignError(
                f"the required SRS is out of reach for {var.label} in {lo:.4g}-{hi:.4g} "
                f"{var.unit}: the best, {var.label} = {xs[best]:.4g} {var.unit}, reaches "
                f"{1 + ms[best]:.1%} of it at {frequencies[k]:,.0f} Hz (the governing "
                f"frequency; {required[k]:.4g} kG required)")
        x = brentq(lambda v: margin(v)[0], *bracket, xtol=1e-10, rtol=1e-10, maxiter=100)
        x = _enveloping_side(x, bracket, margin)
    solved = var.apply(p, x)
    m, k = margin(x)
    from ..engine.batch import run_batch

    figs = run_batch([apply_model(solved, model)], integrator).figures[0]
    design = Design([var], [x], solved, float(figs[0]), float(figs[3]), evaluations[0] + 1,
                    margin=m, governing_hz=float(frequencies[k]))
    design.warnings = design_warnings(solved, design.peak_kg, design.peak_kg)
    return design
