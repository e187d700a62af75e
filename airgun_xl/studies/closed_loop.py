"""The closed loop (issue 45): a lot's crush law updated by every shot fired from it, and the
next setting chosen on what the lot is now known to be.

- :func:`update_law`: the lot's prior law (its previous version, or the report's law for a
  new lot) scaled to every shot of the lot by least squares (:func:`~.calibrate.calibrate`
  with ``fit=("scale",)``), with the scale's standard error. A scale is what one shot, or
  shots at one speed, can pin. Once the shots' impact speeds spread over :data:`TILT_SPAN`,
  the law's tilt with speed is fitted with it (its first-order shape, about the shots' mean
  speed), with the two's covariance; the higher-order shape stays the prior's (said in
  :attr:`LawUpdate.note`). From :data:`WHOLE_SHOTS` such shots the whole law is fitted too
  (its 7 nodes and their covariance), on each shot's launch velocity fitted, and the scaled
  and tilted law tested against it (:func:`shape_test`): where the shots show a shape the
  scale and tilt cannot follow, the whole law is the update, drawn from its nodes'
  covariance. Not where the scale and tilt stop at a bound, nor where the whole law leaves a
  node above its lowest unpinned: the note says which.
- :func:`gun_scatter`: the gun's shot-to-shot scatter, from the lot's shots' launch
  velocities fitted with the scale (:func:`update_law` with ``velocities``) against their
  set values, once :data:`GUN_SHOTS` shots exist; :func:`pooled_scatter`, the same from the
  shots of every lot one gun fired (each lot's about its own mean).
- :func:`law_scatter`: the scale's standard error as a scatter of the law (relative, around
  1), the scale's and the tilt's covariance, or the whole law's nodes', drawn with the
  gun's and zeta's by :func:`~.first_shot.pass_probability` (the law known to its standard
  error: a posterior, not a shot-to-shot scatter).
- :func:`brier` and :func:`reliability`: how honest the predictions were, once shots were
  fired at the settings proposed: the Brier score, and the observed pass rate in each band of
  predicted P(PASS) with its Wilson 95 % interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..crush_law import CRUSH_FIT_RANGE, LEGACY_LAW, chebyshev_nodes, speeds_text
from .acceptance import wilson_interval
from .first_shot import JOINT, LAW_FIELDS, LAW_SCALE, NODES

#: The lot's shots' impact speeds must spread over this fraction of the fastest before the
#: law's tilt with speed is fitted: shots at one speed pin a tilt only through each pulse's
#: own sweep of speeds, which the scale mostly absorbs.
TILT_SPAN = 0.05

#: Shots (spread over :data:`TILT_SPAN`) from which the whole law is fitted too, at its 7
#: nodes, and the scaled and tilted law tested against it: two shots leave its top node
#: weakly pinned (over +/- 2 % at 95 %) on the recorder model; three pin every node but the
#: lowest, where the crush ends.
WHOLE_SHOTS = 3

#: The scaled and tilted law is rejected for the whole law when their values at the whole
#: law's nodes differ by a chi-square this improbable (5 degrees of freedom: 7 nodes less
#: the scale and tilt). Both are fitted on the shots' launch velocities fitted (on the set
#: values, the whole law bends to each shot's gun error: chi-squares of 20 to 110 on lots
#: whose law is a scaled and tilted prior). So fitted, on 49 such lots of 3 shots at 200 to
#: 256 m/s fired as the benchmark fires them (the gun's 1.5 %, zeta's 10 %, its recorder),
#: the chi-square's mean is 6.0 and its largest 15.0; a lot of the report's law times 1.05
#: with a 10 % bump about 150 m/s gives over 100. Hence 0.001 (a chi-square of 20.5).
SHAPE_P = 0.001


@dataclass(frozen=True)
class LawUpdate:
    """The lot's law after this shot: the prior scaled by ``scale`` (± ``error``, one
    standard error) on ``shots`` shots; the calibration behind it; what it pins."""

    law: Any  # CrushLaw
    prior: Any  # CrushLaw
    scale: float
    error: float
    shots: int
    speeds: tuple[float, float]  # [m/s] the lowest and highest impact speed of the shots
    calibration: Any  # studies.calibrate.Calibration
    note: str
    #: with ``velocities``: each shot's (impact speed set [m/s], fitted factor, its standard
    #: error)
    launch: tuple[tuple[float, float, float], ...] = ()
    #: with the tilt (shots spread over :data:`TILT_SPAN`): the law's tilt with speed about
    #: ``v_ref`` [-, m/s] and the scale's and tilt's covariance (2 x 2)
    tilt: float = 0.0
    tilt_error: float = math.nan
    v_ref: float = math.nan
    covariance: Any = None
    #: with :data:`WHOLE_SHOTS` shots spread over speed: the law fitted whole
    #: (:func:`~.calibrate.calibrate` with ``law``), and the chi-square test of the scaled and
    #: tilted law against it (:func:`shape_test`: chi-square, degrees of freedom, p)
    whole: Any = None  # studies.calibrate.Calibration
    shape: tuple[float, int, float] | None = None

    @property
    def tilted(self) -> bool:
        return math.isfinite(self.v_ref)

    @property
    def is_whole(self) -> bool:
        """The whole law is the update's (the scale and tilt were rejected)."""
        return self.shape is not None and self.shape[2] < SHAPE_P

    @property
    def nodes(self) -> Any:
        """The whole law's nodes [m/s] and the 95 % intervals there (NodeInterval)."""
        return self.whole.law_intervals if self.whole is not None else []

    @property
    def warnings(self) -> list[str]:
        said = list(self.calibration.warnings) if self.calibration is not None else []
        if self.is_whole:
            said += [w for w in self.whole.warnings if w not in said]
            weak = [n for n in self.nodes if n.weak]
            if weak:
                said.append("the lot's law, fitted whole, is weakly pinned at "
                            + ", ".join(f"{n.velocity:.1f} m/s (+/- {n.half_width:.1%})"
                                        for n in weak)
                            + ": P(PASS) draws it that widely there")
        if self.tilted and not np.all(np.isfinite(np.asarray(self.covariance, float))):
            said.append("the law's scale and tilt have no covariance (the fit could not "
                        "estimate one): P(PASS) draws the scale alone, and is optimistic")
        if not (math.isfinite(self.error) and self.error >= 0):
            said.append("the law's scale has no standard error (the fit could not estimate "
                        "one): P(PASS) draws the law as if it were known exactly, and is "
                        "optimistic")
        return said


#: A lot's law against the report's, at every node of its range [-]: the bounds the
#: calibration holds a scale to (calibrate.FIT_PARAMETERS). A law past them is no honeycomb of
#: the report's kind: a record edited or damaged, or a recording misread.
LOT_LAW_RATIO = (0.25, 4.0)


def against_report(law):
    """The lowest and highest ratio [-] of ``law``'s polynomial to the report's, at the 7
    Chebyshev nodes of its range within the report's (-20 to 250 m/s); NaN when the ranges
    do not meet or a value is not finite."""
    lo = max(law.v_range[0], CRUSH_FIT_RANGE[0])
    hi = min(law.v_range[1], CRUSH_FIT_RANGE[1])
    if not lo < hi:
        return math.nan, math.nan
    nodes = chebyshev_nodes(lo, hi, 7)
    with np.errstate(all="ignore"):
        ratio = law.poly(nodes) / LEGACY_LAW.poly(nodes)
    if not np.all(np.isfinite(ratio)):
        return math.nan, math.nan
    return float(ratio.min()), float(ratio.max())


def implausible(law):
    """Why ``law`` cannot be a lot's law (its ratio to the report's past
    :data:`LOT_LAW_RATIO` somewhere, named), or '' when it can."""
    low, high = against_report(law)
    if low >= LOT_LAW_RATIO[0] and high <= LOT_LAW_RATIO[1]:
        return ""
    return (f"{low:.3g} to {high:.3g} times the report's law over its range, expected "
            f"{LOT_LAW_RATIO[0]:g} to {LOT_LAW_RATIO[1]:g} times")


def update_law(params, traces, prior, cfc=None, integrator="legacy", velocities=False,
               whole=True):
    """The prior law scaled to the shots (``params`` each with its set values, ``traces``
    each its recording), by least squares on the filtered pulses; with ``velocities``, each
    shot's launch velocity fitted with it (:attr:`LawUpdate.launch`). Spread over speed, its
    tilt is fitted too; from :data:`WHOLE_SHOTS` such shots (and ``whole``), the whole law
    is fitted as well and replaces the scale and tilt where :func:`shape_test` rejects them.

    Returns
    -------
    LawUpdate
    """
    from .calibrate import WEAK_PIN, at_bound, calibrate

    start = [p.replace(crush_law=prior) for p in params]
    speeds = [p.v31 - p.v1 for p in params]
    lo, hi = min(speeds), max(speeds)
    v_ref = float(np.mean(speeds)) if hi - lo >= TILT_SPAN * hi else math.nan
    n = len(params)
    # the law fitted whole is judged on the shots' launch velocities fitted (on the set
    # values it bends to each shot's gun error), and so are the scale and tilt it is tested
    # against: they then carry the velocities' uncertainty too, as with ``velocities``
    wholly = whole and math.isfinite(v_ref) and n >= WHOLE_SHOTS
    velocities = velocities or wholly
    cal = calibrate(start, traces, law=False, fit=("scale",), cfc=cfc, integrator=integrator,
                    velocities=velocities, tilt_about=v_ref if math.isfinite(v_ref) else None)
    scale, error = float(cal.fitted["scale"]), float(cal.errors.get("scale", math.nan))
    note = f"{n} shot{'s' * (n > 1)} at {lo:.4g}" + (f" to {hi:.4g}" if hi > lo else "")
    if math.isfinite(v_ref):
        tilt, tilt_error = float(cal.fitted["tilt"]), float(cal.errors.get("tilt", math.nan))
        note += (f" m/s pin the law's scale and its tilt with speed ({tilt:+.4f} +/- "
                 f"{tilt_error:.4f} per {v_ref:.4g} m/s about {v_ref:.4g} m/s); its "
                 "higher-order shape stays the prior's")
        law = prior.tilted(scale, tilt, v_ref)
    else:
        tilt, tilt_error = 0.0, math.nan
        note += (f" m/s pin{'s' * (n == 1)} the law's scale only; its shape over speed stays "
                 "the prior's "
                 f"(its tilt is fitted once the shots' speeds spread over {TILT_SPAN:.0%})")
        law = prior.scaled(scale)
    if velocities:
        note += "; each shot's launch velocity fitted with it"
    fitted, shape = None, None
    if wholly:
        bounded = at_bound(cal)
        if bounded:
            note += ("; the law is not fitted whole: the scale and tilt's fit is at its bound ("
                     + ", ".join(bounded) + "), so the shots do not pin even them")
        else:
            fitted = calibrate([q.replace(crush_law=law) for q in cal.params], traces,
                               law=True, cfc=cfc, integrator=integrator)
            loose = [node for node in fitted.law_intervals[1:] if node.weak]
            if loose:
                note += ("; the law fitted whole is not tested against them: it is weakly "
                         f"pinned (over +/- {WEAK_PIN:.1%} at 95 %) at " + ", ".join(
                             f"{node.velocity:.1f} m/s (+/- {node.half_width:.0%})"
                             for node in loose))
            else:
                note, shape = _judged(note, law, fitted, n, lo, hi)
                if shape[2] < SHAPE_P:
                    law = fitted.params[0].crush_law
    return LawUpdate(law, prior, scale, error, n, (lo, hi), cal, note,
                     tuple(tuple(v) for v in cal.velocities), tilt, tilt_error, v_ref,
                     cal.covariance[:2, :2] if math.isfinite(v_ref) else None, fitted, shape)


def _judged(note, based, fitted, n, lo, hi):
    """The note of a law fitted whole and pinned, and :func:`shape_test`'s figures."""
    from .calibrate import WEAK_PIN

    shape = shape_test(based, fitted)
    chi, dof, p_value = shape
    if p_value < SHAPE_P:
        law = fitted.params[0].crush_law
        return (f"{n} shots at {lo:.4g} to {hi:.4g} m/s pin the law whole (every node but "
                f"the lowest within +/- {WEAK_PIN:.1%} at 95 %, over "
                f"{speeds_text(law.v_range)}): a scale and a tilt of the prior cannot follow "
                f"its shape (chi-square {chi:.3g} on {dof} degrees of freedom, p = "
                f"{p_value:.2g}); the law fitted whole is drawn from its nodes' covariance",
                shape)
    if math.isfinite(p_value):
        return (note + f"; the law fitted whole agrees with them (chi-square {chi:.3g} on "
                f"{dof} degrees of freedom, p = {p_value:.2g})", shape)
    return note + "; the law fitted whole has no covariance to test them against", shape


def shape_test(law, whole):
    """The scaled and tilted ``law`` against the law fitted ``whole`` (a Calibration with
    its law's nodes and their covariance): (chi-square, degrees of freedom, p) of their
    values' differences at the nodes, d^T C^+ d with C the whole law's covariance (its
    pseudo-inverse: a node the shots leave unpinned weighs nothing), on the nodes less 2
    degrees of freedom (scipy.stats.chi2); p NaN without a finite covariance."""
    from scipy.stats import chi2

    nodes = np.asarray(whole.law_nodes, dtype=float)
    covariance = np.asarray(whole.law_covariance, dtype=float)
    dof = len(nodes) - 2
    if not np.all(np.isfinite(covariance)):
        return math.nan, dof, math.nan
    d = law.poly(nodes) - whole.params[0].crush_law.poly(nodes)
    value = float(d @ np.linalg.pinv((covariance + covariance.T) / 2, hermitian=True) @ d)
    return value, dof, float(chi2.sf(value, dof))


#: Shots of a lot from which the gun's scatter is estimated (:func:`gun_scatter`; pooled
#: over lots, :func:`pooled_scatter`, one less degrees of freedom): with 7 degrees of
#: freedom the 95 % interval of a standard deviation is 0.66 to 2.0 times the estimate
#: (chi-square); with fewer, one lucky shot can halve the estimate and the P(PASS) drawn
#: from it would be over-confident.
GUN_SHOTS = 8


#: Standard errors the gun's mean offset must pass before it is warned of (two: 5 % of
#: unbiased guns are warned of falsely).
BIAS_SIGMAS = 2.0


@dataclass(frozen=True)
class GunScatter:
    """The gun's shot-to-shot scatter: a relative standard deviation of the launch velocity
    [-], its 95 % interval, from ``shots`` shots (of ``lots`` lots: each lot's shots about
    their own mean, so ``shots - lots`` degrees of freedom); the mean launch velocity's
    offset from the set value (the gun's bias) [-]; ``gun`` names the gun when the lots of
    one gun were pooled (``next --gun``)."""

    sd: float
    interval: tuple[float, float]
    shots: int
    bias: float
    bias_error: float
    at_bound: tuple[int | str, ...] = ()  # shots (from 1; "lot L's shot k" pooled) at the bound
    lots: int = 1
    gun: str = ""

    def _whose(self) -> str:
        return (f"the gun {self.gun}'s {self.shots} shots of {self.lots} lots" if self.gun
                else f"the lot's {self.shots} shots")

    @property
    def warnings(self) -> list[str]:
        from .calibrate import VELOCITY_REACH

        found = []
        if self.at_bound:
            which = ", ".join(map(str, self.at_bound))
            if not self.gun:
                which = f"shot{'s' * (len(self.at_bound) > 1)} {which} of the lot"
            found.append(f"the gun's scatter: {which} fitted a launch "
                         f"velocity {VELOCITY_REACH:.0%} from the one set (the fit's bound): "
                         "not a gun's scatter (a wrong setting or recording?); the scatter "
                         "estimated from them is not to be trusted")
        if abs(self.bias) > BIAS_SIGMAS * self.bias_error:
            found.append(f"the gun fires {self.bias:+.2%} (+/- {self.bias_error:.2%}) off its "
                         f"set velocity on average over {self._whose()}: the "
                         "setting proposed is the velocity to fire; set the gun to the value "
                         "next states beside it (the offset taken out, its error drawn)")
        return found

    def words(self) -> str:
        lo, hi = self.interval
        source = (f"{self.shots} shots' launch velocities" if not self.gun else
                  f"the launch velocities of {self.shots} shots of {self.lots} lots fired "
                  f"by the gun {self.gun} (each lot's about its own mean)")
        return (f"the gun's scatter {self.sd:.2%} (95 % interval {lo:.2%}-{hi:.2%}), estimated "
                f"from {source} fitted against their set values "
                f"(their mean {self.bias:+.2%} +/- {self.bias_error:.2%} off them)")


def gun_scatter(update):
    """The gun's scatter from the lot's fitted launch velocities (:attr:`LawUpdate.launch`),
    or None under :data:`GUN_SHOTS` shots (:func:`pooled_scatter` of the one lot)."""
    return pooled_scatter([("", update.launch)])


def pooled_scatter(lots, gun=""):
    """The gun's scatter from the launch velocities fitted in each of ``lots`` (``[(name,
    launch)]``, ``launch`` as :attr:`LawUpdate.launch`), or None under ``GUN_SHOTS - 1``
    degrees of freedom.

    Each lot's factors are taken about their own mean: a lot's law absorbs part of a
    launch velocity's offset (a lot of one shot tells nothing of the scatter), and what is
    left is the shot-to-shot scatter. The pooled sample variance less what the fits' own
    errors add, s^2 = sum (f - mean_lot f)^2 / sum (n_lot - 1) - sum se^2 (1 - 1/n_lot) /
    sum (n_lot - 1), at least 0 (one lot: var(f) - mean(se^2)); its 95 % interval from the
    chi-square distribution with sum (n_lot - 1) degrees of freedom. The bias is the mean
    of the factors less 1, its error from their spread about that mean."""
    from scipy.stats import chi2

    from .calibrate import VELOCITY_REACH

    kept = [(name, launch) for name, launch in lots if len(launch) >= 2]
    dof = sum(len(launch) - 1 for _name, launch in kept)
    if dof < GUN_SHOTS - 1:
        return None
    squares = noise = 0.0
    factors, at_bound = [], []
    for name, launch in kept:
        f = np.array([x for _v, x, _e in launch], dtype=float)
        e = np.array([x for _v, _f, x in launch], dtype=float)
        e = np.where(np.isfinite(e), e, 0.0)
        squares += float(np.sum((f - f.mean()) ** 2))
        noise += float(np.sum(e ** 2)) * (1 - 1 / len(f))
        factors.append(f)
        at_bound += [f"lot {name}'s shot {k + 1}" if name else k + 1 for k, x in enumerate(f)
                     if abs(x - 1.0) >= VELOCITY_REACH * (1 - 1e-3)]
    spread, noise = squares / dof, noise / dof
    sd = math.sqrt(max(spread - noise, 0.0))
    lo = math.sqrt(max(dof * spread / chi2.ppf(0.975, dof) - noise, 0.0))
    hi = math.sqrt(max(dof * spread / chi2.ppf(0.025, dof) - noise, 0.0))
    every = np.concatenate(factors)
    n = len(every)
    bias = float(np.mean(every) - 1.0)
    return GunScatter(sd, (lo, hi), n, bias, math.sqrt(float(np.var(every, ddof=1)) / n),
                      tuple(at_bound), len(kept), gun)


def law_scatter(update):
    """The ``sds`` entry that draws the law from its posterior: its scale around 1, with the
    standard error relative to the scale fitted; with a tilt, the scale (around 1) and the
    tilt (around 0, about ``v_ref``) drawn together from their covariance, to first order
    relative to the law updated (an entry :data:`~.first_shot.JOINT`); the law fitted whole,
    a factor on each node's value from their covariance relative to the values (an entry
    :data:`~.first_shot.NODES`)."""
    if update.is_whole:
        nodes = np.asarray(update.whole.law_nodes, dtype=float)
        values = update.law.poly(nodes)
        factors = np.asarray(update.whole.law_covariance, float) / np.outer(values, values)
        if np.all(np.isfinite(factors)):
            return (LAW_SCALE, LAW_FIELDS, (_drawable(factors), nodes), NODES)
    if update.tilted:
        cov = np.asarray(update.covariance, dtype=float)
        scaled = cov * np.array([[1 / update.scale ** 2, 1 / update.scale],
                                 [1 / update.scale, 1.0]])
        if update.scale > 0 and np.all(np.isfinite(scaled)):
            return (LAW_SCALE, LAW_FIELDS, (_drawable(scaled), update.v_ref), JOINT)
    relative = update.error / update.scale if update.scale > 0 else math.nan
    if not (math.isfinite(relative) and relative >= 0):
        relative = 0.0
    return (LAW_SCALE, LAW_FIELDS, relative, True)


def _drawable(covariance):
    """A covariance symmetric and positive semi-definite to the last bit (the sandwich's
    rounding would make numpy's multivariate normal warn, or draw NaN)."""
    values, vectors = np.linalg.eigh((covariance + covariance.T) / 2)
    return (vectors * np.clip(values, 0.0, None)) @ vectors.T


def outcomes(shots):
    """(predicted P(PASS), passed) of the ``shots`` ({"predicted", "verdict"} each) that have
    an outcome: a shot NOT JUDGED (its record could not show a criterion; issue 63) has
    none, and is left out of the bands and the score."""
    judged = [s for s in shots if s["verdict"] in ("PASS", "FAIL")]
    return [s["predicted"] for s in judged], [s["verdict"] == "PASS" for s in judged]


def brier(predicted, passed):
    """The Brier score of probabilities ``predicted`` against outcomes ``passed`` (0 best)."""
    p, o = np.asarray(predicted, float), np.asarray(passed, float)
    return float(np.mean((p - o) ** 2)) if len(p) else math.nan


@dataclass(frozen=True)
class Band:
    """Shots whose predicted P(PASS) fell in [low, high): how many passed."""

    low: float
    high: float
    shots: int
    passed: int
    mean_predicted: float

    @property
    def rate(self) -> float:
        return self.passed / self.shots if self.shots else math.nan

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.passed, self.shots)

    @property
    def honest(self) -> bool:
        """The mean prediction lies inside the observed rate's 95 % interval."""
        lo, hi = self.interval
        return self.shots > 0 and lo <= self.mean_predicted <= hi


def reliability(predicted, passed, edges=(0.0, 0.5, 0.7, 0.8, 0.9, 0.95, 1.0)):
    """The observed pass rate in each band of predicted P(PASS) (the last band includes 1)."""
    p, o = np.asarray(predicted, float), np.asarray(passed, bool)
    bands = []
    for k, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        inside = (p >= lo) & ((p <= hi) if k == len(edges) - 2 else (p < hi))
        bands.append(Band(lo, hi, int(inside.sum()), int(o[inside].sum()),
                          float(p[inside].mean()) if inside.any() else math.nan))
    return bands
