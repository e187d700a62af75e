"""Designs that meet a specification, and the chance that they pass on the first shot
(issue 25).

- :func:`solve_middle`: the setting of one parameter whose predicted pulse sits in the middle
  of the tolerances: the largest smallest margin over the criteria (each margin a fraction of
  its nominal, as :mod:`airgun_xl.studies.acceptance` gives it).
- :func:`pass_probability`: a Monte Carlo of the shot with the scattered cells (``--sd``)
  drawn from normal distributions, every shot run on the batch lanes (or a Dask runner) and
  judged on the worker threads by :class:`~airgun_xl.studies.acceptance.BlockJudge`: the
  fraction that passes, with its Wilson 95 % interval, and how often each criterion fails.
- :func:`solve_confidence`: the setting with the highest probability: the middle design and
  :data:`CANDIDATES` settings across the span where the prediction passes are tried with a
  twentieth of the shots, then the best of them and the middle design with all of them, each
  round on one set of draws (common random numbers: settings compared on equal luck).

The SRS criterion is judged on single pulses only: a probability says when it leaves it out.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..engine.batch import run_batch
from ..errors import AirgunXlError, DesignError, OptionError
from ..models import apply_model
from ..specification import Specification
from .acceptance import BLOCK_VALUES, BlockJudge, flags_of, wilson_interval

#: Memory a Monte Carlo shot holds until its batch is judged [bytes]: its ShotParams (350
#: measured), its figures and judged values, with room.
SHOT_BYTES = 600

#: Points of the scan over the parameter's range.
SCAN_POINTS = 25

#: Settings of the first round that go on to the final with every shot (beside the middle
#: design, which always does): the one :func:`centred` chooses.
FINALISTS = 1

#: What the middle design's search counts a shot that cannot be judged as (minus its
#: smallest margin): worse than any judged shot's.
DIVERGED_MARGIN = 1e6

#: The first round of :func:`solve_confidence` runs this fraction of the shots a setting.
FIRST_ROUND = 0.05

#: Settings tried in the first round, across the span where the prediction passes (the scan's
#: passing points, one scan step wider each side).
CANDIDATES = 7



def margins(values: np.ndarray, spec: Specification) -> np.ndarray:
    """Each shot's smallest margin over the criteria (a fraction of the nominal; negative:
    outside), from a :class:`BlockJudge`'s columns; NaN (diverged) is -inf."""
    cols = []
    for k, name in enumerate(BLOCK_VALUES):
        v = values[:, k]
        if name == "corridor":
            if spec.corridor is not None and spec.shape != "none":
                cols.append(v)
            continue
        tol = {"peak": spec.peak, "duration": spec.duration,
               "velocity change": spec.velocity_change}[name]
        if tol is not None:
            lo, hi = tol.limits
            cols.append(np.minimum(v - lo, hi - v) / tol.nominal)
    if not cols:
        raise DesignError("the specification gives no criterion a design can aim at (peak, "
                          "duration, velocity change or corridor)")
    least = np.min(np.column_stack(cols), axis=1)
    return np.where(np.isfinite(least), least, -np.inf)


@dataclass
class MiddleDesign:
    """The setting whose prediction sits deepest inside the tolerances."""

    value: float
    margin: float  # smallest margin there, a fraction of the nominal
    passing: tuple[float, float] | None  # scan's span of settings whose prediction passes
    evaluations: int
    scan: tuple[np.ndarray, np.ndarray] = field(repr=False, default=(np.zeros(0),
                                                                     np.zeros(0)))


def as_measured(values, model_error):
    """``values`` (:class:`BlockJudge`'s columns) with each figure of
    :data:`~airgun_xl.studies.model_error.FIGURES` times the model error's typical ratio
    measured / expected (``exp`` of its mean: the median of the ratios drawn), so that a
    design aims what the lab will measure, not the model's own figure, at the middle (issue
    60: a lab whose shots measure 3 % under the model's peak had its proposals aimed 3 % low).
    ``model_error`` None, or centred: ``values`` as they are."""
    if model_error is None or not any(model_error.mean):
        return values
    from .model_error import FIGURES

    out = np.array(values, dtype=float, copy=True)
    for j, name in enumerate(FIGURES):
        out[:, BLOCK_VALUES.index(name)] *= math.exp(model_error.mean[j])
    return out


def _run(p, var, xs, spec, integrator, model, runner, model_error=None):
    params = [apply_model(var.apply(p, x), model) for x in xs]
    batch = (runner or run_batch)(params, integrator, extra=BlockJudge(spec))
    return as_measured(batch.extras, model_error)


def solve_middle(p, spec, var, bounds=None, integrator="legacy", model="4-mass", runner=None,
                 model_error=None):
    """The value of ``var`` with the largest smallest margin: a scan of :data:`SCAN_POINTS`,
    then a bounded search (scipy) between the best point's neighbours; with ``model_error``,
    the margins of the figures as the lab measures them (:func:`as_measured`).

    Raises
    ------
    DesignError
        When no setting in the range has a finite margin (every shot diverged).
    """
    from scipy.optimize import minimize_scalar

    lo, hi = bounds or var.bounds(p)
    xs = np.linspace(lo, hi, SCAN_POINTS)
    ys = margins(_run(p, var, xs, spec, integrator, model, runner, model_error), spec)
    if not np.isfinite(ys).any():
        raise DesignError(f"no {var.label} in {lo:.4g}-{hi:.4g} {var.unit} gives a pulse that "
                          "can be judged (every shot diverged)")
    best = int(np.argmax(ys))
    a, b = xs[max(best - 1, 0)], xs[min(best + 1, len(xs) - 1)]
    count = [len(xs)]

    def negative(x):
        count[0] += 1
        margin = float(margins(_run(p, var, [x], spec, integrator, model, runner,
                                    model_error), spec)[0])
        # a shot that cannot be judged (diverged) is the worst, but finite: the bounded
        # search's parabola steps would otherwise multiply infinities (NaN, and a warning)
        return -margin if math.isfinite(margin) else DIVERGED_MARGIN

    found = minimize_scalar(negative, bounds=(a, b), method="bounded",
                            options={"xatol": 1e-6 * max(abs(a), abs(b), 1e-12)})
    x, y = (float(found.x), -float(found.fun)) if -found.fun >= ys[best] else (
        float(xs[best]), float(ys[best]))
    passing = xs[ys >= 0]
    span = (float(passing.min()), float(passing.max())) if len(passing) else None
    return MiddleDesign(x, y, span, count[0], (xs, ys))


#: Levels of a :class:`Pair`'s second variable in its first scan (``next --vary``).
LEVELS = 9

#: Points a level's best first setting is searched on again, across two scan steps: its
#: resolution a tenth of a step (about 1 m/s of A28).
FINE_POINTS = 21

#: Most single runs of the pair's middle design's last search (Nelder-Mead).
PAIR_EVALUATIONS = 60


@dataclass(frozen=True)
class Pair:
    """Two variables set together (``next --vary``): ``first`` (the velocity) and ``second``
    (such as E13 or E16, for the duration); a setting is a tuple (first, second)."""

    first: Any
    second: Any

    @property
    def label(self) -> str:
        return f"{self.first.label} and {self.second.label}"

    def apply(self, p, x):
        return self.second.apply(self.first.apply(p, x[0]), x[1])


def _judged(p, var, xs, spec, integrator, model, runner):
    """:class:`BlockJudge`'s values at each setting of ``var``; a setting that makes no shot
    (parameters refused: a second variable can reach them) is NaN, the worst margin."""
    params, ok = [], np.zeros(len(xs), dtype=bool)
    for k, x in enumerate(xs):
        try:
            params.append(apply_model(var.apply(p, x), model))
            ok[k] = True
        except AirgunXlError:
            pass
    values = np.full((len(xs), len(BLOCK_VALUES)), np.nan)
    if params:
        values[ok] = (runner or run_batch)(params, integrator,
                                           extra=BlockJudge(spec)).extras
    return values


@dataclass
class PairMiddle:
    """The pair's setting whose prediction sits deepest inside the tolerances, and the
    candidates of :func:`solve_confidence`: at each level of the second variable, the first
    variable's best setting (the ridge), deepest first."""

    value: tuple[float, float]
    margin: float
    candidates: list[tuple[float, float]]
    evaluations: int


def solve_middle_pair(p, spec, pair, integrator="legacy", model="4-mass", runner=None,
                      bounds=None, model_error=None):
    """The :class:`Pair` setting with the largest smallest margin: a scan of
    :data:`SCAN_POINTS` first settings at :data:`LEVELS` second ones, each level's best
    searched again on :data:`FINE_POINTS` points, then Nelder-Mead (scipy, bounded, at most
    :data:`PAIR_EVALUATIONS` runs) from the deepest; with ``model_error``, the margins of the
    figures as the lab measures them (:func:`as_measured`).

    Raises
    ------
    DesignError
        When no setting gives a pulse that can be judged.
    """
    from scipy.optimize import minimize

    (lo1, hi1), (lo2, hi2) = bounds or pair.first.bounds(p), pair.second.bounds(p)
    xs, ys = np.linspace(lo1, hi1, SCAN_POINTS), np.linspace(lo2, hi2, LEVELS)

    def judged(points):
        return margins(as_measured(_judged(p, pair, points, spec, integrator, model, runner),
                                   model_error), spec)

    coarse = judged([(x, y) for y in ys for x in xs]).reshape(LEVELS, SCAN_POINTS)
    if not np.isfinite(coarse).any():
        raise DesignError(f"no {pair.label} in {lo1:.4g}-{hi1:.4g} {pair.first.unit} and "
                          f"{lo2:.4g}-{hi2:.4g} {pair.second.unit} gives a pulse that can be "
                          "judged (every shot diverged)")
    step = xs[1] - xs[0]
    rows = [np.linspace(max(xs[j] - step, lo1), min(xs[j] + step, hi1), FINE_POINTS)
            for j in np.argmax(coarse, axis=1)]
    fine = judged([(x, y) for y, row in zip(ys, rows, strict=True)
                   for x in row]).reshape(LEVELS, FINE_POINTS)
    ridge = sorted(((float(row[int(np.argmax(m))]), float(y), float(np.max(m)))
                    for y, row, m in zip(ys, rows, fine, strict=True) if np.isfinite(m).any()),
                   key=lambda r: -r[2])
    count = [coarse.size + fine.size]
    spans = np.array([hi1 - lo1, hi2 - lo2])
    origin = np.array([lo1, lo2])

    def negative(u):
        count[0] += 1
        margin = float(judged([tuple(origin + np.clip(u, 0, 1) * spans)])[0])
        return -margin if math.isfinite(margin) else DIVERGED_MARGIN

    start = (np.array(ridge[0][:2]) - origin) / spans
    simplex = [start, start + [0.1 * step / spans[0], 0.0],
               start + [0.0, 0.5 * (ys[1] - ys[0]) / spans[1]]]
    found = minimize(negative, start, method="Nelder-Mead", bounds=[(0, 1), (0, 1)],
                     options={"initial_simplex": np.clip(simplex, 0, 1),
                              "maxfev": PAIR_EVALUATIONS, "xatol": 1e-4, "fatol": 1e-5})
    if -found.fun > ridge[0][2]:
        x, y = origin + np.clip(found.x, 0, 1) * spans
        value, margin = (float(x), float(y)), -float(found.fun)
    else:
        value, margin = ridge[0][:2], ridge[0][2]
    # the levels whose best passes nominally (or, when none does, the three deepest)
    candidates = [r[:2] for r in ridge if r[2] >= 0][:CANDIDATES + 1] or [
        r[:2] for r in ridge[:3]]
    return PairMiddle(value, margin, candidates, count[0])


@dataclass
class PassProbability:
    """A Monte Carlo's pass rate at one setting."""

    setting: float
    passes: int
    shots: int
    failures: dict[str, int]  # criterion -> shots failing it (a shot may fail several)
    diverged: int
    invalid: int  # draws that are not a shot (a negative mass): counted as failures
    second: float = math.nan  # a :class:`Pair`'s second setting (NaN: one variable)
    #: Each judged figure the specification limits (peak [kG], duration [s], velocity
    #: change [m/s]) over the draws that ran: its 5th, 50th and 95th percentiles, the
    #: middle and 90 % range of what the shot is expected to measure.
    figures: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    #: With a model error drawn: the shots that pass on the same draws with the error at the
    #: upper 95 % bound of its spread (:meth:`~.model_error.ModelError.widened`).
    cautious: int | None = None
    #: With a model error drawn: :attr:`figures` before it was drawn, the model's own
    #: prediction over the drawn inputs; an archive's pair of this shot is its median against
    #: what was measured, less the spread its 90 % range says the inputs explain
    #: (:func:`~airgun_xl.app.lot_chain.archive_pairs`). Without one: empty (:attr:`figures`
    #: is the model's own).
    model_figures: dict[str, tuple[float, float, float]] = field(default_factory=dict)

    @property
    def probability(self) -> float:
        return self.passes / self.shots if self.shots else math.nan

    @property
    def interval(self) -> tuple[float, float]:
        """The 95 % interval of P(PASS): the Monte Carlo's Wilson interval, its low end taken
        down to the cautious count's (the model's error as large as its evidence allows)."""
        lo, hi = wilson_interval(self.passes, self.shots)
        if self.cautious is not None:
            lo = min(lo, wilson_interval(self.cautious, self.shots)[0])
        return lo, hi

    def most_failing(self) -> tuple[str, int] | None:
        if not self.failures or max(self.failures.values()) == 0:
            return None
        name = max(self.failures, key=lambda k: self.failures[k])
        return name, self.failures[name]


#: A P(PASS) above this is more than a Monte Carlo with an estimated model error can show
#: alone: it is printed as a value only when its interval's low end (the model's error at the
#: upper bound of its spread) is above it too, and read as reaching a confidence above it
#: only then (issue 60: proposals printed 1.0000 passed 95.8 % of the time).
SUPPORTED_TOP = 0.99


def supported(result: PassProbability) -> bool:
    """Whether ``result``'s P(PASS) may be printed as it is: at most :data:`SUPPORTED_TOP`, or
    its interval's low end above it too."""
    return not result.probability > SUPPORTED_TOP or result.interval[0] > SUPPORTED_TOP


def reaches(result: PassProbability, confidence: float) -> bool:
    """Whether ``result`` reaches a P(PASS) of ``confidence``: its probability (its interval's
    low end where that is all :func:`supported` lets it claim) and its interval's high end
    at least that."""
    lo, hi = result.interval
    claimed = result.probability if supported(result) else lo
    return claimed >= confidence and hi >= confidence


def p_pass_text(result: PassProbability) -> str:
    """``P(PASS) = 0.9523 (95 % interval 0.9480-0.9563)``; a P(PASS) above
    :data:`SUPPORTED_TOP` that its interval does not support, as its low end: ``P(PASS) at
    least 0.9712 (95 % interval 0.9712-0.9991; 0.9975 with the model's error as estimated,
    which does not support more than 0.99)``."""
    lo, hi = result.interval
    span = f"95 % interval {lo:.4f}-{hi:.4f}"
    if supported(result):
        return f"P(PASS) = {result.probability:.4f} ({span})"
    return (f"P(PASS) at least {lo:.4f} ({span}; {result.probability:.4f} with the model's "
            f"error as estimated, which does not support more than {SUPPORTED_TOP:g})")


#: The crush law's scale as a scattered quantity (issue 45): an ``sds`` entry
#: ``(LAW_SCALE, LAW_FIELDS, sd, True)`` draws a factor around 1 that multiplies the whole law
#: of each shot (a lot's law known to a standard error; see
#: :mod:`airgun_xl.studies.closed_loop`).
LAW_SCALE, LAW_FIELDS = "scale", ("crush_law",)

#: An ``sds`` entry ``(LAW_SCALE, LAW_FIELDS, (covariance, v_ref), JOINT)`` draws the law's
#: scale (around 1) and its tilt with speed (around 0, about ``v_ref`` [m/s]) together from
#: their 2 x 2 covariance (:meth:`~airgun_xl.crush_law.CrushLaw.tilted`): two columns of the
#: draws, the second named :data:`LAW_TILT`.
JOINT, LAW_TILT = "joint", ("crush_law_tilt",)

#: An ``sds`` entry ``(LAW_SCALE, LAW_FIELDS, (covariance, nodes), NODES)`` draws the whole
#: law: a factor (around 1) on its value at each of its ``nodes`` [m/s], together from their
#: covariance (relative), and the law through the products (:func:`~.calibrate.law_through`):
#: a column of the draws a node, each named :data:`LAW_NODE`.
NODES, LAW_NODE = "nodes", ("crush_law_node",)


def _mean(p, fields):
    return 1.0 if fields == LAW_FIELDS else getattr(p, fields[0])


def draws(p, sds, n, seed):
    """``n`` draws of the scattered cells: a (n, cells) array of values, and the cells'
    fields (as :func:`airgun_xl.studies.sweep.monte_carlo` draws them; the law's scale, see
    :data:`LAW_SCALE`, around 1)."""
    from .sweep import check_spreads

    check_spreads(p, [sd for sd in sds if sd[1] != LAW_FIELDS])
    rng = np.random.default_rng(seed)
    columns, names = [], []
    for _cell, fields, sd, relative in sds:
        if relative == JOINT:  # the law's scale and tilt, together
            pair = rng.multivariate_normal([1.0, 0.0], np.asarray(sd[0], dtype=float), n,
                                           method="eigh")
            columns += [pair[:, 0], pair[:, 1]]
            names += [LAW_FIELDS, LAW_TILT]
        elif relative == NODES:  # the whole law: a factor on each node's value, together
            covariance = np.asarray(sd[0], dtype=float)
            factors = rng.multivariate_normal(np.ones(len(covariance)), covariance, n,
                                              method="eigh")
            columns += list(factors.T)
            names += [LAW_NODE] * len(covariance)
        else:
            columns.append(rng.normal(_mean(p, fields), sd * abs(_mean(p, fields)) if relative
                                      else sd, n))
            names.append(fields)
    return np.column_stack(columns) if columns else np.zeros((n, 0)), names


def pass_probability(p, spec, sds, n, seed=1, var=None, setting=None, integrator="legacy",
                     model="4-mass", runner=None, progress=None, drawn=None,
                     model_error=None):
    """The fraction of ``n`` shots that pass ``spec``, with ``var`` at ``setting`` (None: the
    sheet's) and the ``sds`` cells scattered (:func:`airgun_xl.studies.sweep.parse_sd`);
    with ``model_error`` (a :class:`~airgun_xl.studies.model_error.ModelError`), each shot's
    judged peak, duration and velocity change multiplied by a drawn measured / expected
    ratio before it is judged (the corridor, a shape, is judged as predicted).

    A setting moves a scattered cell's mean: a drawn value is its draw's offset from the
    sheet's value, added to the setting (so the gun's scatter follows the velocity set).
    """
    from ..engine.batch import BLOCK
    from ..limits import check_memory

    # a checked ShotParams a shot (350 bytes measured) and its figures and values, then a
    # block's pulses and the judge's arrays (about 8 rows-long doubles a shot of the block)
    check_memory(n * SHOT_BYTES + BLOCK * p.rows * 8 * 8,
                 f"a Monte Carlo of {n:,} shots of {p.rows:,} rows", "fewer --shots")
    values, fields_list = drawn if drawn is not None else draws(p, sds, n, seed)
    base = var.apply(p, setting) if var is not None and setting is not None else p
    first, second = setting if isinstance(setting, tuple) else (setting, math.nan)
    params, invalid = [], np.zeros(n, dtype=bool)
    law = (LAW_FIELDS, LAW_TILT, LAW_NODE)
    offsets = [(fields, 0.0 if fields in law else
                getattr(base, fields[0]) - getattr(p, fields[0])) for fields in fields_list]
    v_ref = next((sd[2][1] for sd in sds if sd[3] == JOINT), math.nan)
    nodes = next((np.asarray(sd[2][1], float) for sd in sds if sd[3] == NODES), None)
    at_nodes = base.crush_law.poly(nodes) if nodes is not None else None
    is_node = np.array([fields == LAW_NODE for fields in fields_list], dtype=bool)
    for i in range(n):
        try:
            changes = {f: float(value + shift) for (fields, shift), value
                       in zip(offsets, values[i], strict=True) for f in fields
                       if fields not in law}
            drawn_law = {fields: float(value) for (fields, _), value
                         in zip(offsets, values[i], strict=True) if fields in law}
            if nodes is not None:  # the whole law through its drawn node values
                from .calibrate import law_through

                factors = values[i][is_node]
                if not np.all(factors > 0):  # a law at or below 0 somewhere: not a shot
                    raise DesignError(f"a drawn law factor of {float(np.min(factors)):.3g}")
                changes["crush_law"] = law_through(nodes, at_nodes * factors,
                                                   base.crush_law.v_range)
            elif LAW_FIELDS in drawn_law:  # a scale at or below 0 is no law: not a shot
                value = drawn_law[LAW_FIELDS]
                if not value > 0:
                    raise DesignError(f"a drawn law scale of {value:.3g}")
                changes["crush_law"] = (base.crush_law.tilted(value, drawn_law[LAW_TILT], v_ref)
                                        if LAW_TILT in drawn_law
                                        else base.crush_law.scaled(value))
            params.append(apply_model(base.replace(**changes), model))
        except AirgunXlError:
            invalid[i] = True
    batch = (runner or run_batch)(params, integrator, progress=progress,
                                  extra=BlockJudge(spec))
    values = batch.extras
    cautious, model_figures = None, {}
    if model_error is not None:
        model_figures = expected_figures(values, spec)
        model_error = model_error.at(_explained(values))
        wide = _with_model_error(values, model_error.widened(), n, seed, invalid)
        wide_ok = np.ones(len(params), dtype=bool)
        for f in flags_of(wide, spec).values():
            wide_ok &= f
        cautious = int(wide_ok.sum())
        values = _with_model_error(values, model_error, n, seed, invalid)
    flags = flags_of(values, spec)
    ok = np.ones(len(params), dtype=bool)
    for f in flags.values():
        ok &= f
    failures = {name: int((~f).sum()) + int(invalid.sum()) for name, f in flags.items()}
    return PassProbability(float(first) if first is not None else math.nan,
                           int(ok.sum()), n, failures, int(batch.diverged.sum()),
                           int(invalid.sum()), float(second),
                           expected_figures(values, spec), cautious, model_figures)


def _explained(values):
    """Per figure of :data:`~airgun_xl.studies.model_error.FIGURES`, the spread of its log
    over the drawn inputs at this setting (from its 5th to 95th percentile, as a normal's,
    :func:`~airgun_xl.studies.model_error.explained_spread`): what the draws explain
    there, the rest of the pairs' spread being the model's (NaN where a figure has no two
    finite positive values)."""
    from .model_error import FIGURES, explained_spread

    out = []
    for name in FIGURES:
        column = np.asarray(values, dtype=float)[:, BLOCK_VALUES.index(name)]
        column = column[np.isfinite(column) & (column > 0)]
        lo, hi = (np.percentile(column, (5.0, 95.0)) if column.size >= 2
                  else (math.nan, math.nan))
        out.append(explained_spread(float(lo), float(hi)))
    return out


def _with_model_error(values, model_error, n, seed, invalid):
    """``values`` (:class:`BlockJudge`'s columns of the shots that ran) with each shot's
    figures of :data:`~airgun_xl.studies.model_error.FIGURES` times its drawn ratio: draw
    ``i`` of ``n`` belongs to draw ``i`` of the inputs, whichever settings are compared."""
    from .model_error import FIGURES

    factors = model_error.factors(n, seed)[~invalid]
    out = np.array(values, dtype=float, copy=True)
    for j, name in enumerate(FIGURES):
        out[:, BLOCK_VALUES.index(name)] *= factors[:, j]
    return out


#: The percentiles of a judged figure a proposal states: its middle and 90 % range.
RANGE_PERCENTILES = (5.0, 50.0, 95.0)


def expected_figures(values, spec):
    """``{criterion: (5th, 50th, 95th percentile)}`` of each judged figure ``spec`` limits,
    from a :class:`~.acceptance.BlockJudge`'s columns (a diverged draw's NaN left out; none
    that ran: NaN)."""
    from .acceptance import BLOCK_VALUES

    spec = spec.resolved()
    out = {}
    for name, tolerance in (("peak", spec.peak), ("duration", spec.duration),
                            ("velocity change", spec.velocity_change)):
        if tolerance is None:
            continue
        column = np.asarray(values, dtype=float)[:, BLOCK_VALUES.index(name)]
        column = column[np.isfinite(column)]
        out[name] = (tuple(float(v) for v in np.percentile(column, RANGE_PERCENTILES))
                     if column.size else (math.nan,) * 3)
    return out


def centrality(result, spec):
    """How near the middle of every tolerance a setting's expected figures (the medians of
    its draws) sit: the smallest over the criteria of the distance to the nearer limit as a
    fraction of half the tolerance (1 in the middle, 0 on a limit, negative outside; -inf
    when a figure is unknown)."""
    spec = spec.resolved()
    least = math.inf
    for name, tolerance in (("peak", spec.peak), ("duration", spec.duration),
                            ("velocity change", spec.velocity_change)):
        if tolerance is None:
            continue
        lo, hi = tolerance.limits
        mid = result.figures.get(name, (math.nan,) * 3)[1]
        if not math.isfinite(mid) or not hi > lo:
            return -math.inf
        least = min(least, min(mid - lo, hi - mid) / (0.5 * (hi - lo)))
    return least


def centred(results, spec):
    """The setting to propose among ``results`` (:class:`PassProbability`): of those whose
    P(PASS) is within the best's error of it (at least the lower end of the best's Wilson
    interval), the one whose expected figures sit nearest the middle of every tolerance
    (:func:`centrality`, largest); a tie to the higher P(PASS), then the first. A plateau of
    P(PASS) near 1 then still chooses: the middle, not a setting half the tolerance off."""
    def p(r):  # a setting of no shot (NaN) ranks last
        return r.probability if math.isfinite(r.probability) else -1.0

    top = max(results, key=p)
    floor = top.interval[0]
    plateau = [r for r in results if p(r) >= floor] or [top]
    return max(plateau, key=lambda r: (centrality(r, spec), p(r)))


@dataclass
class ConfidenceDesign:
    """The setting with the highest pass probability, and the middle design's (None when it
    was not run with every shot: ``keep_middle`` False)."""

    best: PassProbability
    middle: PassProbability | None
    middle_design: Any  # MiddleDesign, or PairMiddle for a Pair
    tried: list[PassProbability]
    shots: int
    warnings: list[str] = field(default_factory=list)
    #: with ``steps``: the best found between them (``best`` is then the best on them)
    unrounded: PassProbability | None = None


def _span(middle):
    """One variable's candidates: across the span where the prediction passes."""
    xs, _ys = middle.scan
    step = xs[1] - xs[0] if len(xs) > 1 else 0.0
    if middle.passing is not None:
        lo, hi = middle.passing
        span = np.linspace(max(lo - step, xs[0]), min(hi + step, xs[-1]), CANDIDATES)
    else:  # nothing passes nominally: round the middle design
        span = np.clip(middle.value + step * np.linspace(-1, 1, CANDIDATES), xs[0], xs[-1])
    return sorted({float(x) for x in span} | {middle.value})


def settable(best, steps, ranges):
    """The settings a knob can be set to nearest ``best`` (one value, or a pair's two): on
    each variable's grid of ``steps`` (multiples of the step, in its unit; None: any value),
    the step below and the one above, within ``ranges`` (lo, hi); a grid with no value in
    its range near ``best`` is refused in one line.

    Returns
    -------
    list
        The settings (floats, or tuples for a pair), the grid's values rounded to 12
        significant digits (a multiple of 0.1 reads as written).
    """
    values = best if isinstance(best, tuple) else (best,)
    axes = []
    for value, step, (lo, hi) in zip(values, steps, ranges, strict=True):
        if step is None:
            axes.append([value])
            continue
        k = math.floor(value / step)
        near = sorted({float(f"{j * step:.12g}") for j in (k, k + 1)})
        inside = [v for v in near if lo <= v <= hi]
        if not inside:
            raise OptionError(f"--step: found a step of {step:g}, whose settings nearest the "
                              f"best {value:.6g} ({', '.join(f'{v:g}' for v in near)}) are "
                              f"outside the range searched, {lo:g} to {hi:g}; expected a "
                              "step the knob can be set to within it")
        axes.append(inside)
    grid = [tuple(x) for x in itertools.product(*axes)]
    return grid if isinstance(best, tuple) else [x[0] for x in grid]


def solve_confidence(p, spec, var, sds, n, seed=1, bounds=None, integrator="legacy",
                     model="4-mass", runner=None, progress=None, second=None,
                     keep_middle=True, steps=None, model_error=None):
    """The setting of ``var`` most likely to pass (see the module's notes), each shot judged
    on the specification's record (:func:`~airgun_xl.studies.acceptance.judged_record`), as
    a recording of it would be.

    ``second``: a second variable set with ``var`` (a :class:`Pair`, candidates from
    :func:`solve_middle_pair`); the results' ``second`` holds its setting. ``keep_middle``
    False runs only the first round's best with every shot (the middle design's probability
    is then not known). ``steps``: what each knob can be set to (the step of ``var``'s and
    of ``second``'s grids, None for any value): the best is then the highest P(PASS) among
    the settable neighbours of the best found between them (:func:`settable`), on the final
    round's draws, a tie to the nearest; the result's ``unrounded`` keeps the best found."""
    if second is None:
        middle = solve_middle(p, spec, var, bounds, integrator, model, runner, model_error)
        knobs, candidates = var, _span(middle)
    else:
        knobs = Pair(var, second)
        middle = solve_middle_pair(p, spec, knobs, integrator, model, runner, bounds,
                                   model_error)
        candidates = sorted(set(middle.candidates) | {middle.value})
    first_n = max(200, int(round(n * FIRST_ROUND)))
    drawn_first = draws(p, sds, first_n, seed)
    first = [pass_probability(p, spec, sds, first_n, seed, knobs, x, integrator, model, runner,
                              progress, drawn_first, model_error) for x in candidates]
    # among the settings within the best's error of it, the one aimed at the middle
    chosen = centred(first, spec)
    finalists = [candidates[first.index(chosen)]][:FINALISTS]
    if keep_middle and middle.value not in finalists:
        finalists.append(middle.value)
    drawn = draws(p, sds, n, seed + 1)  # fresh draws: the first round's luck does not carry
    final = [pass_probability(p, spec, sds, n, seed + 1, knobs, x, integrator, model, runner,
                              progress, drawn, model_error) for x in sorted(finalists)]
    best = centred(final, spec)
    mid = (final[sorted(finalists).index(middle.value)] if middle.value in finalists
           else None)
    unrounded = None
    if steps is not None and any(step is not None for step in steps):
        at = (best.setting, best.second) if second is not None else best.setting
        ranges = [bounds or var.bounds(p)] + ([second.bounds(p)] if second is not None else [])
        near = settable(at, steps, ranges)
        if at not in near:  # the best found is between the grids' values
            on_grid = [pass_probability(p, spec, sds, n, seed + 1, knobs, x, integrator,
                                        model, runner, progress, drawn, model_error) for x in near]
            unrounded, best = best, centred(on_grid, spec)
            final += on_grid
    warnings = []
    if spec.srs is not None:
        warnings.append("the SRS criterion is not in the probability: it is judged on the "
                        "designed shot's prediction only")
    return ConfidenceDesign(best, mid, middle, first + final, n, warnings, unrounded)
