"""The ISO/TS 18571 objective rating of a simulated signal against a test's, with the
standard's published formulas and parameters.

Both signals are resampled at the standard's 10 kHz over the evaluation interval. Four scores
in 0..1 are weighted into the overall rating R:

- corridor Z (weight 0.4): inner and outer corridors of half-width a0 = 0.05 and b0 = 0.5
  times the test's largest magnitude; a point inside the inner one scores 1, outside the outer
  one 0, and between ((delta_o - |C - T|) / (delta_o - delta_i))^kz with kz = 2; Z is the mean;
- phase E_P (0.2): the shift n_eps (in samples, either way, up to eps_P = 20 % of the
  interval) that maximises the Pearson correlation of the overlapping parts;
  E_P = ((eps_P N - |n_eps|) / (eps_P N))^kP with kP = 1, 0 beyond;
- magnitude E_M (0.2): on the shifted signals, warped by dynamic time warping (Sakoe-Chiba
  band of 10 % of the samples, squared-difference cost; dtaidistance),
  eps_mag = ||C_w - T_w||_1 / ||T_w||_1 and E_M = ((eps_M - eps_mag) / eps_M)^kM, eps_M = 0.5,
  kM = 1;
- slope E_S (0.2): the shifted signals' central-difference derivatives smoothed by a 9-point
  moving average (1, 3, 5 and 7 points at the ends), eps_slope as eps_mag, and
  E_S = (eps_S - eps_slope) / eps_S, eps_S = 2.

R = 0.4 Z + 0.2 E_P + 0.2 E_M + 0.2 E_S; the standard grades it excellent above 0.94, good
above 0.8, fair above 0.58, else poor.
"""
from dataclasses import dataclass

import numpy as np

#: The standard's sampling rate [Hz].
SAMPLE_RATE = 10_000.0

A0, B0, KZ = 0.05, 0.5, 2
EPS_P, KP = 0.2, 1
EPS_M, KM = 0.5, 1
EPS_S = 2.0
DTW_BAND = 0.1
WEIGHTS = {"corridor": 0.4, "phase": 0.2, "magnitude": 0.2, "slope": 0.2}
GRADES = ((0.94, "excellent"), (0.8, "good"), (0.58, "fair"), (-np.inf, "poor"))


@dataclass
class Rating:
    """The four scores and their weighted sum, each in 0..1."""

    corridor: float
    phase: float
    magnitude: float
    slope: float
    overall: float
    shift: int  # n_eps [samples at 10 kHz]; positive: the simulation lags the test
    correlation: float  # the Pearson correlation at that shift

    @property
    def grade(self):
        """excellent, good, fair or poor; "n/a" for a rating that is not a number."""
        return next((name for limit, name in GRADES if self.overall > limit), "n/a")


def resample(time, values, start, end):
    """``values`` at 10 kHz from ``start`` to ``end`` [s] (linear interpolation)."""
    grid = start + np.arange(int(np.floor((end - start) * SAMPLE_RATE + 1e-9)) + 1) / SAMPLE_RATE
    return np.interp(grid, time, values)


def corridor_score(test, sim):
    t_norm = np.max(np.abs(test))
    inner, outer = A0 * t_norm, B0 * t_norm
    diff = np.abs(sim - test)
    score = np.clip((outer - diff) / (outer - inner), 0.0, 1.0) ** KZ
    score[diff < inner] = 1.0
    return float(np.mean(score))


def _correlation(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.corrcoef(a, b)[0, 1]
    return float(r) if np.isfinite(r) else (1.0 if np.array_equal(a, b) else 0.0)


def best_shift(test, sim):
    """(n_eps, rho): the shift of ``sim`` against ``test`` within eps_P N that maximises the
    overlaps' correlation; ``sim[n:]`` pairs ``test[:-n]`` for n > 0 (the simulation lags)."""
    n = len(test)
    limit = int(np.floor(EPS_P * n))
    best = (0, _correlation(test, sim))
    for k in range(1, limit + 1):
        for shift, a, b in ((k, test[:-k], sim[k:]), (-k, test[k:], sim[:-k])):
            r = _correlation(a, b)
            if r > best[1]:
                best = (shift, r)
    return best


def _shifted(test, sim, shift):
    if shift > 0:
        return test[:-shift], sim[shift:]
    if shift < 0:
        return test[-shift:], sim[:shift]
    return test, sim


def warped(test, sim):
    """Both signals along their dynamic-time-warping path (Sakoe-Chiba band of 10 %)."""
    from dtaidistance import dtw

    window = int(np.ceil(DTW_BAND * len(test)))  # |i - j| < window, the diagonal included
    path = np.array(dtw.warping_path(np.ascontiguousarray(sim, dtype=np.double),
                                     np.ascontiguousarray(test, dtype=np.double),
                                     window=window))
    return test[path[:, 1]], sim[path[:, 0]]


def smoothed_slope(values):
    """Central-difference derivative [per sample at 10 kHz, scaled to per s] smoothed by a
    9-point moving average, with 1-, 3-, 5- and 7-point averages at the ends."""
    d = np.gradient(values, 1 / SAMPLE_RATE)
    out = np.empty_like(d)
    if len(d) < 9:
        return d
    out[4:-4] = np.convolve(d, np.ones(9) / 9, mode="valid")
    for i, width in enumerate((1, 3, 5, 7)):
        out[i] = d[:width].mean()
        out[-1 - i] = d[-width:].mean()
    return out


def _relative_error_score(test, sim, limit, k):
    norm = np.sum(np.abs(test))
    err = np.sum(np.abs(sim - test)) / norm if norm else (0.0 if np.array_equal(test, sim)
                                                         else np.inf)
    return float(max(0.0, (limit - err) / limit) ** k)


def rating(time, test, sim, start=None, end=None):
    """The ISO/TS 18571 rating of ``sim`` against ``test``, both sampled at ``time`` [s].

    Parameters
    ----------
    time : numpy.ndarray
        Common sample instants [s], increasing.
    test, sim : numpy.ndarray
        The reference (test) and the comparison (simulation) signals.
    start, end : float, optional
        The evaluation interval [s]; the whole ``time`` span by default.

    Returns
    -------
    Rating
    """
    start = time[0] if start is None else start
    end = time[-1] if end is None else end
    t = resample(time, test, start, end)
    c = resample(time, sim, start, end)
    if len(t) < 10:
        raise ValueError(f"the evaluation interval holds {len(t)} samples at 10 kHz, "
                         "expected at least 10 (a pulse of 1 ms or more)")
    z = corridor_score(t, c)
    shift, rho = best_shift(t, c)
    limit = EPS_P * len(t)
    phase = 1.0 if shift == 0 else max(0.0, (limit - abs(shift)) / limit) ** KP
    ts, cs = _shifted(t, c, shift)
    tw, cw = warped(ts, cs)
    magnitude = _relative_error_score(tw, cw, EPS_M, KM)
    slope = _relative_error_score(smoothed_slope(ts), smoothed_slope(cs), EPS_S, 1)
    overall = (WEIGHTS["corridor"] * z + WEIGHTS["phase"] * phase
               + WEIGHTS["magnitude"] * magnitude + WEIGHTS["slope"] * slope)
    return Rating(z, phase, magnitude, slope, overall, shift, rho)
