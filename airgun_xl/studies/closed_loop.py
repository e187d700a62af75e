"""The closed loop (issue 45): a lot's crush law updated by every shot fired from it, and the
next setting chosen on what the lot is now known to be.

- :func:`update_scale`: the lot's prior law (its previous version, or the report's law for a
  new lot) scaled to every shot of the lot by least squares (:func:`~.calibrate.calibrate`
  with ``fit=("scale",)``), with the scale's standard error. A scale is what one shot, or
  shots at one speed, can pin. Once the shots' impact speeds spread over :data:`TILT_SPAN`,
  the law's tilt with speed is fitted with it (its first-order shape, about the shots' mean
  speed), with the two's covariance; the higher-order shape stays the prior's (said in
  :attr:`LawUpdate.note`).
- :func:`gun_scatter`: the gun's shot-to-shot scatter, from the lot's shots' launch
  velocities fitted with the scale (:func:`update_scale` with ``velocities``) against their
  set values, once :data:`GUN_SHOTS` shots exist; :func:`pooled_scatter`, the same from the
  shots of every lot one gun fired (each lot's about its own mean).
- :func:`law_scatter`: the scale's standard error as a scatter of the law (relative, around
  1), or the scale's and the tilt's covariance, drawn with the gun's and zeta's by
  :func:`~.first_shot.pass_probability` (the law known to its standard error: a posterior,
  not a shot-to-shot scatter).
- :func:`brier` and :func:`reliability`: how honest the predictions were, once shots were
  fired at the settings proposed: the Brier score, and the observed pass rate in each band of
  predicted P(PASS) with its Wilson 95 % interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .acceptance import wilson_interval
from .first_shot import JOINT, LAW_FIELDS, LAW_SCALE

#: The lot's shots' impact speeds must spread over this fraction of the fastest before the
#: law's tilt with speed is fitted: shots at one speed pin a tilt only through each pulse's
#: own sweep of speeds, which the scale mostly absorbs.
TILT_SPAN = 0.05


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

    @property
    def tilted(self) -> bool:
        return math.isfinite(self.v_ref)

    @property
    def warnings(self) -> list[str]:
        said = list(self.calibration.warnings) if self.calibration is not None else []
        if self.tilted and not np.all(np.isfinite(np.asarray(self.covariance, float))):
            said.append("the law's scale and tilt have no covariance (the fit could not "
                        "estimate one): P(PASS) draws the scale alone, and is optimistic")
        if not (math.isfinite(self.error) and self.error >= 0):
            said.append("the law's scale has no standard error (the fit could not estimate "
                        "one): P(PASS) draws the law as if it were known exactly, and is "
                        "optimistic")
        return said


def update_scale(params, traces, prior, cfc=None, integrator="legacy", velocities=False):
    """The prior law scaled to the shots (``params`` each with its set values, ``traces``
    each its recording), by least squares on the filtered pulses; with ``velocities``, each
    shot's launch velocity fitted with it (:attr:`LawUpdate.launch`).

    Returns
    -------
    LawUpdate
    """
    from .calibrate import calibrate

    start = [p.replace(crush_law=prior) for p in params]
    speeds = [p.v31 - p.v1 for p in params]
    lo, hi = min(speeds), max(speeds)
    v_ref = float(np.mean(speeds)) if hi - lo >= TILT_SPAN * hi else math.nan
    cal = calibrate(start, traces, law=False, fit=("scale",), cfc=cfc, integrator=integrator,
                    velocities=velocities, tilt_about=v_ref if math.isfinite(v_ref) else None)
    scale, error = float(cal.fitted["scale"]), float(cal.errors.get("scale", math.nan))
    n = len(params)
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
    return LawUpdate(law, prior, scale, error, n, (lo, hi), cal, note,
                     tuple(tuple(v) for v in cal.velocities), tilt, tilt_error, v_ref,
                     cal.covariance[:2, :2] if math.isfinite(v_ref) else None)


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
                         "setting proposed is the velocity to fire, which this gun reaches "
                         "set that much the other way; the draws assume no such offset")
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
    relative to the law updated (an entry :data:`~.first_shot.JOINT`)."""
    if update.tilted:
        cov = np.asarray(update.covariance, dtype=float)
        scaled = cov * np.array([[1 / update.scale ** 2, 1 / update.scale],
                                 [1 / update.scale, 1.0]])
        if update.scale > 0 and np.all(np.isfinite(scaled)):
            # symmetric and positive semi-definite to the last bit (the sandwich's rounding
            # would make numpy's multivariate normal warn, or draw NaN)
            values, vectors = np.linalg.eigh((scaled + scaled.T) / 2)
            scaled = (vectors * np.clip(values, 0.0, None)) @ vectors.T
            return (LAW_SCALE, LAW_FIELDS, (scaled, update.v_ref), JOINT)
    relative = update.error / update.scale if update.scale > 0 else math.nan
    if not (math.isfinite(relative) and relative >= 0):
        relative = 0.0
    return (LAW_SCALE, LAW_FIELDS, relative, True)


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
