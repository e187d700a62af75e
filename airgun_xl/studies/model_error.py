"""The model's own error on a shot's judged figures (issue 60), as a probability of passing
must include it.

A prediction of a shot is the 4-mass model with the lot's law; the shot fired measures
something else, even at the law's best: the honeycomb's shape the law cannot take (compaction,
a tilt with speed), the mount, the recorder. The lab's own record holds that error shot by
shot: every proposal ``next`` keeps says what it expected of the shot (the median of its
draws' judged figures), and the verdict of the shot fired from it says what was measured.
Their log ratios, ``log(measured / expected)`` for the peak, the duration and the velocity
change, pooled across lots, are the model's error out of sample.

Each measured figure differs from the model's median for two reasons: the inputs the study
draws anyway (the gun's scatter, zeta's, the law's own uncertainty), and the model's error. A
pair carries the spread the drawn inputs explain (the standard deviation of the log, from the
90 % range of the model's own draws before its error was drawn); the model's error is the rest:
the pairs' variance less the mean explained variance, never below the sampling error of that
variance (``s^2 sqrt(2 / (n - 1))`` of ``n`` pairs: a rest the pairs cannot tell from zero is not
claimed as zero) nor :data:`MIN_SD` squared (the inputs drawn twice would make a probability
too low; the rest not taken out, too high).

- A figure with :data:`MIN_PAIRS` or more pairs is learnt: the figures so learnt take the
  pairs' sample mean and covariance (over the pairs complete in them; the variances net of
  what the inputs explain, the correlations the pairs' own), and a new shot's ratio is drawn
  from the predictive distribution of a normal model whose mean and covariance are unknown: a
  multivariate Student t of ``n - 1`` degrees of freedom, location the mean, scale the
  covariance times ``1 + 1/n`` (a few pairs give heavy tails, not false confidence). A figure
  the lab's specifications never judged (no pairs) keeps the prior, centred, uncorrelated.
  At each setting a study compares, a learnt figure's error is then what makes the pairs'
  whole spread there (:meth:`ModelError.at`): the drawn inputs' spread differs from setting
  to setting (the law's uncertainty, how much the gun's scatter moves the figure), but what a
  shot fired from a proposal measured against it did not follow it (issue 60's harder lab:
  the proposals whose inputs explained 1.9 % of the peak and 3.0 % measured 4.2 % and 2.8 %
  about their prediction), so a setting where the draws explain little is not given a
  narrower prediction for it.
- With fewer, each figure is the prior and its pairs weighed together, as a conjugate normal
  model weighs them (the prior counting as :data:`PRIOR_PAIRS` pairs): the variance
  ``(k s0^2 + (n - 1) s^2 + k n m^2 / (k + n)) / (k + n)`` of ``n`` pairs of mean ``m`` and
  net variance ``s^2`` (net of the inputs, from two pairs on) against the prior's ``s0^2``,
  and the bias shrunk toward none, ``n m / (k + n)``; uncorrelated, drawn as a normal. The
  prior's share is thus a half at 3 pairs and a quarter at 9: a lab whose model is better (or
  worse) than the prior, or whose gun runs slow, sees it in its probabilities from its first
  pairs, not only from its tenth (the prior alone held P(PASS) near 0.6 where 0.875 of 40
  shots passed, issue 60's simulated lab). The prior is the spread an independent simulated
  lab measured at the proposals (issue 60: 4.9 % on the peak, 2.6 % on the duration) rounded
  up; the velocity change, the pulse's integral, follows the gun's velocity, which the gun's
  own scatter already draws.

A drawn ratio multiplies each Monte Carlo shot's judged figure before it is judged
(:func:`~airgun_xl.studies.first_shot.pass_probability`), on a stream of its own seeded
from the study's seed: every setting compared sees the same ratios (common random numbers).

The spread itself is an estimate: :meth:`ModelError.widened` is the error at the upper end of
its one-sided 95 % confidence bound (chi-square on the pairs' degrees of freedom; the prior
counts as :data:`MIN_PAIRS` pairs), and a P(PASS)'s interval runs down to what the same
draws give under it, so that a probability near 1 is only printed with the evidence for it.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import OptionError

#: The judged figures the error is drawn for, in the order of its columns.
FIGURES = ("peak", "duration", "velocity change")

#: The prior's standard deviation of log(measured / expected) per figure [-], a *whole*
#: spread: what shots fired at proposals measure against their predictions, the inputs'
#: scatter and the model's own error together (issue 60's independent lab: 4.9 % peak, 2.6 %
#: duration). At a setting the model's error is what makes it with the spread the drawn
#: inputs give there (:meth:`ModelError.at`), never below :data:`MIN_SD`.
PRIOR_SD = {"peak": 0.05, "duration": 0.03, "velocity change": 0.01}

#: Pairs of a figure from which the archive's covariance (and mean) replaces the prior.
MIN_PAIRS = 10

#: What the prior weighs as, in pairs, while a figure has fewer than :data:`MIN_PAIRS`: its
#: share of the variance (and the bias's shrinkage) is ``PRIOR_PAIRS / (PRIOR_PAIRS + n)``.
PRIOR_PAIRS = 3

#: The smallest spread of the log ratio claimed for a figure [-]: the archive's figures are
#: measured to about this (a recording's noise and quantisation at the peak), so a spread the
#: inputs seem to explain whole is not read as a perfect model.
MIN_SD = 0.005

#: A measured / expected ratio outside this band is no pair of one shot: the archive's record
#: is refused (a unit lost, a workbook of another shot).
RATIO_BAND = (0.25, 4.0)

#: The draws' stream, beside the study's seed (the inputs' draws take the seed alone).
STREAM = 60

#: A normal's 5th to 95th percentile, in standard deviations (2 x scipy.stats.norm.ppf(0.95)):
#: a 90 % range of a log read as its standard deviation.
RANGE_SIGMAS = 3.2897072539029444


def explained_spread(low: float, high: float) -> float:
    """The standard deviation of the log [-] a 90 % range ``low`` to ``high`` (5th and 95th
    percentiles, positive) stands for, as a normal's; NaN where they are not such a range."""
    if not (0 < low <= high and math.isfinite(high)):
        return math.nan
    return math.log(high / low) / RANGE_SIGMAS


@dataclass(frozen=True)
class ModelError:
    """The model's error on :data:`FIGURES`, as log ratios measured / expected.

    Attributes
    ----------
    mean : tuple of float
        Location of the log ratio per figure [-].
    covariance : tuple of tuple of float
        Its scale matrix [-] (the covariance of a normal; of a t, the scale).
    pairs : int
        The archive's pairs it was learnt from (0: the prior).
    dof : float
        Degrees of freedom of the t it is drawn from (inf: normal).
    explained : tuple of float
        Per figure, the root mean square spread of the log the drawn inputs explained at
        the pairs, taken out of their spread [-] (0: none known).
    learnt : tuple of str
        The figures whose error is the pairs' (with :data:`MIN_PAIRS` or more); the others'
        the prior weighed with their pairs (:data:`PRIOR_PAIRS`).
    total : tuple of float
        Per figure, the whole variance of the log ratio a new shot's measured / expected
        spreads by, inputs and error together [-]: a learnt figure's pairs', times
        ``1 + 1/n``; the others' the prior's (:data:`PRIOR_SD`, a whole spread) weighed with
        their pairs. 0 (an error made by hand): the covariance is the error at every
        setting.
    floor : tuple of float
        Per figure, the least variance its error is given at any setting [-]: a learnt
        figure's the sampling error of the pairs' variance (or :data:`MIN_SD` squared),
        times ``1 + 1/n``; the others' :data:`MIN_SD` squared.
    """

    mean: tuple[float, ...]
    covariance: tuple[tuple[float, ...], ...]
    pairs: int
    dof: float = math.inf
    explained: tuple[float, ...] = (0.0, 0.0, 0.0)
    learnt: tuple[str, ...] = ()
    total: tuple[float, ...] = (0.0, 0.0, 0.0)
    floor: tuple[float, ...] = (0.0, 0.0, 0.0)

    @classmethod
    def prior(cls) -> ModelError:
        """:data:`PRIOR_SD`, centred, uncorrelated; a whole spread."""
        return cls._diagonal([PRIOR_SD[f] for f in FIGURES], 0)

    @classmethod
    def _diagonal(cls, sds: list[float], pairs: int,
                  explained: tuple[float, ...] = (0.0, 0.0, 0.0),
                  mean: tuple[float, ...] = (0.0, 0.0, 0.0),
                  whole: Sequence[float] | None = None) -> ModelError:
        """Uncorrelated errors of spreads ``sds``, each the model's share of the whole
        variance ``whole`` at a setting (``sds`` squared, whole spreads, when not given)."""
        n = len(FIGURES)
        cov = tuple(tuple(sds[i] ** 2 if i == j else 0.0 for j in range(n)) for i in range(n))
        total = tuple(float(v) for v in (whole if whole is not None else
                                         [s ** 2 for s in sds]))
        return cls(mean, cov, pairs, explained=explained, total=total,
                   floor=(MIN_SD ** 2,) * n)

    @classmethod
    def from_pairs(cls, pairs: Iterable[Mapping[str, tuple[float, ...]]],
                   where: str = "the archive") -> ModelError:
        """From pairs ``{figure: (expected, measured[, explained])}`` (each in one unit;
        ``explained`` the standard deviation of the log the drawn inputs give there, 0 when
        not given); a pair that lacks a figure leaves it out of that figure's spread.

        Raises
        ------
        OptionError
            A ratio that is not finite and positive, or outside :data:`RATIO_BAND`; an
            explained spread that is not a finite number from 0 to 1.
        """
        rows, drawn = [], []
        for k, pair in enumerate(pairs):
            row, spread = [], []
            for f in FIGURES:
                got = pair.get(f)
                if got is None:
                    row.append(math.nan)
                    spread.append(math.nan)
                    continue
                expected, measured = got[0], got[1]
                ratio = measured / expected if expected else math.nan
                if not (math.isfinite(ratio) and RATIO_BAND[0] <= ratio <= RATIO_BAND[1]):
                    raise OptionError(
                        f"{where}: pair {k + 1}'s {f} measured {measured:.6g} against "
                        f"{expected:.6g} expected, expected a ratio within {RATIO_BAND[0]:g} "
                        f"to {RATIO_BAND[1]:g} (a unit lost, or the record of another shot)")
                explained = got[2] if len(got) > 2 else 0.0
                if not (math.isfinite(explained) and 0.0 <= explained <= 1.0):
                    raise OptionError(
                        f"{where}: pair {k + 1}'s {f} spread explained by the inputs "
                        f"{explained:.6g}, expected a standard deviation of the log from 0 "
                        "to 1 (a 90 % range out of order, or the record of another shot)")
                row.append(math.log(ratio))
                spread.append(explained ** 2)
            rows.append(row)
            drawn.append(spread)
        logs = np.array(rows, dtype=float).reshape(-1, len(FIGURES))
        variances = np.array(drawn, dtype=float).reshape(-1, len(FIGURES))
        counts = np.isfinite(logs).sum(axis=0)
        learnt = [j for j in range(len(FIGURES)) if counts[j] >= MIN_PAIRS]
        complete = np.all(np.isfinite(logs[:, learnt]), axis=1) if learnt else \
            np.zeros(len(logs), dtype=bool)
        n = int(complete.sum())
        if learnt and n >= MIN_PAIRS:
            return cls._learnt(logs[complete][:, learnt], variances[complete][:, learnt],
                               learnt, n)
        sds: list[float] = []
        spreads: list[float] = []
        means: list[float] = []
        wholes: list[float] = []
        w = float(PRIOR_PAIRS)
        for j, f in enumerate(FIGURES):
            has = np.isfinite(logs[:, j])
            column = logs[has, j]
            m = len(column)
            inputs = float(variances[has, j].mean()) if has.any() else 0.0
            mean = float(column.mean()) if m else 0.0
            seen = float(np.var(column, ddof=1)) if m >= 2 else 0.0
            # net of the inputs, never below the sampling error of the pairs' variance
            # (as learnt; with 3 pairs or fewer that error is the variance itself)
            net = max(seen - inputs, seen * min(1.0, math.sqrt(2 / (m - 1))) if m >= 2
                      else 0.0, MIN_SD ** 2)
            # the conjugate normal model's weighing: the prior as w pairs of its variance
            # and no bias, the pairs' own variance on m - 1 degrees, and their mean's
            # distance from the prior's none
            pooled = (w * PRIOR_SD[f] ** 2 + (m - 1) * net * (m >= 2)
                      + w * m * mean ** 2 / (w + m)) / (w + m)
            # the whole spread a shot measures, weighed alike: the prior's (a whole one)
            # with the pairs' own, not net of their inputs
            wholes.append((w * PRIOR_SD[f] ** 2 + (m - 1) * max(seen, MIN_SD ** 2) * (m >= 2)
                           + w * m * mean ** 2 / (w + m)) / (w + m) if m else
                          PRIOR_SD[f] ** 2)
            # no pair of the figure: the prior itself, to the last bit
            sds.append(math.sqrt(pooled) if m else PRIOR_SD[f])
            means.append(m * mean / (w + m))
            spreads.append(math.sqrt(inputs))
        return cls._diagonal(sds, len(logs), tuple(spreads), tuple(means), wholes)

    @classmethod
    def _learnt(cls, logs: np.ndarray, variances: np.ndarray, learnt: list[int],
                n: int) -> ModelError:
        """The figures ``learnt`` (columns of ``logs``, ``n`` complete pairs) from the pairs,
        net of the variances the inputs explain; the others the prior's."""
        sample = np.atleast_2d(np.cov(logs, rowvar=False, ddof=1))
        inputs = variances.mean(axis=0)
        # what is left once the inputs are taken out, never below the sampling error of the
        # pairs' own variance (a normal's: s^2 sqrt(2 / (n - 1))): a rest the pairs cannot
        # tell from zero is not claimed as zero
        resolution = np.diag(sample) * math.sqrt(2 / (n - 1))
        net = np.sqrt(np.maximum.reduce([np.diag(sample) - inputs, resolution,
                                         np.full(len(inputs), MIN_SD ** 2)]))
        raw = np.sqrt(np.diag(sample))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = sample / np.outer(raw, raw)
        corr = np.where(np.isfinite(corr), corr, 0.0)
        np.fill_diagonal(corr, 1.0)
        block = corr * np.outer(net, net) * (1 + 1 / n)
        size = len(FIGURES)
        cov = np.diag([PRIOR_SD[f] ** 2 for f in FIGURES])
        mean = np.zeros(size)
        explained = np.zeros(size)
        cov[np.ix_(learnt, learnt)] = block
        mean[learnt] = logs.mean(axis=0)
        explained[learnt] = np.sqrt(inputs)
        total = np.array([PRIOR_SD[f] ** 2 for f in FIGURES])  # the prior's, a whole one
        floor = np.full(size, MIN_SD ** 2)
        total[learnt] = np.diag(sample) * (1 + 1 / n)
        floor[learnt] = np.maximum(resolution, MIN_SD ** 2) * (1 + 1 / n)
        return cls(tuple(float(v) for v in mean),
                   tuple(tuple(float(v) for v in r) for r in cov), n, float(n - 1),
                   tuple(float(v) for v in explained), tuple(FIGURES[j] for j in learnt),
                   tuple(float(v) for v in total), tuple(float(v) for v in floor))

    @property
    def sd(self) -> tuple[float, ...]:
        """Each figure's spread of the log ratio (the t's, where it has one) [-]."""
        scale = math.sqrt(self.dof / (self.dof - 2)) if 2 < self.dof < math.inf else 1.0
        return tuple(math.sqrt(self.covariance[i][i]) * scale for i in range(len(FIGURES)))

    @property
    def freedom(self) -> int:
        """Degrees of freedom of the spread's estimate: the pairs' less one, or
        ``MIN_PAIRS - 1`` for the prior (it stands for an archive of that size)."""
        return max(self.pairs, MIN_PAIRS) - 1

    def widened(self) -> ModelError:
        """The error with its covariance at the upper end of its one-sided 95 % confidence
        bound, ``k / chi2.ppf(0.05, k)`` times it (``k`` :attr:`freedom`), and the whole
        spread and the floor it is made up to at a setting alike: drawn on the same stream,
        each ratio is the nominal one's log stretched by the bound's square root."""
        from scipy.stats import chi2

        k = self.freedom
        stretch = k / float(chi2.ppf(0.05, k))
        cov = tuple(tuple(v * stretch for v in row) for row in self.covariance)
        return dataclasses.replace(self, covariance=cov,
                                   total=tuple(v * stretch for v in self.total),
                                   floor=tuple(v * stretch for v in self.floor))

    def at(self, explained: Sequence[float]) -> ModelError:
        """The error at one setting, whose drawn inputs spread each figure's log by
        ``explained`` (a standard deviation [-] a figure, NaN: unknown): a learnt figure's
        error is what makes the pairs' whole spread there, ``sqrt(total - explained^2)``,
        never below its floor; its correlations kept. The pairs' whole spread is what a
        shot fired from a proposal measured against it, whatever the spread the inputs
        drawn there (a setting where the draws explain little is not thereby a setting the
        model knows better: issue 60's harder lab, where the proposals whose inputs
        explained 1.9 % were predicted 0.83 and passed 0.65). A figure of the prior alike:
        the prior is a whole spread (:data:`PRIOR_SD`; drawn on top of the inputs', the
        prior's era was under-confident in the harder lab: 0.653 predicted, 0.841 passed)."""
        if not any(t > 0 for t in self.total):
            return self
        sd = np.sqrt(np.diag(np.array(self.covariance, dtype=float)))
        new = sd.copy()
        for j in range(len(FIGURES)):
            e = float(explained[j])
            if self.total[j] > 0 and math.isfinite(e):
                new[j] = math.sqrt(max(self.total[j] - e * e, self.floor[j]))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = np.array(self.covariance, dtype=float) / np.outer(sd, sd)
        corr = np.where(np.isfinite(corr), corr, 0.0)
        np.fill_diagonal(corr, 1.0)
        cov = corr * np.outer(new, new)
        return dataclasses.replace(self, covariance=tuple(tuple(float(v) for v in r)
                                                          for r in cov))

    def factors(self, n: int, seed: int) -> np.ndarray:
        """``n`` draws of measured / expected, a column per figure of :data:`FIGURES`."""
        rng = np.random.default_rng([seed, STREAM])
        cov = np.array(self.covariance, dtype=float)
        # eigh, not cholesky: a covariance of perfectly correlated pairs is only semidefinite
        w, v = np.linalg.eigh(cov)
        root = v * np.sqrt(np.clip(w, 0.0, None))
        z = rng.standard_normal((n, len(FIGURES))) @ root.T
        if math.isfinite(self.dof):
            z *= np.sqrt(self.dof / rng.chisquare(self.dof, n))[:, None]
        return np.exp(np.asarray(self.mean) + z)

    def words(self) -> str:
        """The error in words, as a study states it."""
        spread = ", ".join(f"{f} {100 * s:.1f} %" for f, s in zip(FIGURES, self.sd,
                                                                   strict=True))
        taken = [(f, e) for f, e in zip(FIGURES, self.explained, strict=True) if e > 0]
        net = (f" (net of the spread the drawn inputs explain there: "
               f"{', '.join(f'{f} {100 * e:.1f} %' for f, e in taken)})" if taken else "")
        if self.learnt:
            bias = ", ".join(f"{f} {100 * (math.exp(m) - 1):+.1f} %"
                             for f, m in zip(FIGURES, self.mean, strict=True)
                             if f in self.learnt)
            prior = [f for f in FIGURES if f not in self.learnt]
            whole = ", ".join(f"{f} {100 * math.sqrt(t):.1f} %"
                              for f, t in zip(FIGURES, self.total, strict=True) if t > 0)
            return (f"the model's own error from the archive's {self.pairs} pairs of expected "
                    f"and measured shots: spread (1 sigma) {spread}{net}; bias {bias}"
                    + (f"; {', '.join(prior)}: the prior (no pairs enough)" if prior else "")
                    + (f"; at each setting, with the spread its drawn inputs give, as much as "
                       f"makes the pairs' whole spread ({whole})" if whole else ""))
        whole = ", ".join(f"{f} {100 * math.sqrt(t):.1f} %"
                          for f, t in zip(FIGURES, self.total, strict=True) if t > 0)
        share = (f"; a whole spread ({whole}): at each setting the model's error is as much "
                 "as makes it with the spread its drawn inputs give" if whole else "")
        if not self.pairs:
            return ("the model's own error, the prior (the archive holds no pair of expected "
                    f"and measured shots): spread (1 sigma) {spread}, centred{share}")
        bias = ", ".join(f"{f} {100 * (math.exp(m) - 1):+.1f} %"
                         for f, m in zip(FIGURES, self.mean, strict=True))
        return (f"the model's own error, the prior weighed as {PRIOR_PAIRS} pairs with the "
                f"archive's {self.pairs} pair{'s' * (self.pairs != 1)} (fewer than "
                f"{MIN_PAIRS}): spread (1 sigma) {spread}{net}; bias {bias}{share}")

    def bound_words(self) -> str:
        """What the low end of a P(PASS)'s interval assumes of this error."""
        wide = ", ".join(f"{f} {100 * s:.1f} %" for f, s in zip(FIGURES, self.widened().sd,
                                                                 strict=True))
        return (f"the interval's low end draws the model's error at the upper 95 % bound of "
                f"its spread ({wide}; {self.freedom} degrees of freedom)")
