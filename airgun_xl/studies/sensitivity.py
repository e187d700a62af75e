"""What the spread of the figures comes from: Sobol indices (SALib), and how the Monte Carlo's
5-95 % band settles with the number of shots.

Sobol: the uncertain inputs are the ``--sd`` cells, normal around the sheet's values as in the
Monte Carlo. SALib draws Saltelli's sample (N (D + 2) shots for D inputs, first- and total-order
indices only), the shots run on the batch kernel (or a cluster), and SALib estimates each
input's first-order index S1 (its share of the variance alone) and total index ST (with all its
interactions), with 95 % confidence half-widths, for the peak, the pulse duration and the
crush. SALib loads only here (1.8 s, scipy.stats).
"""
from dataclasses import dataclass

import numpy as np

from ..engine.batch import FIGURES
from ..errors import OptionError
from .sweep import SweepResult, _evaluate, check_spreads

#: The figures whose sensitivity is estimated (names of ``FIGURES``).
SENSITIVITY_FIGURES = ("peak_kg", "pulse_duration", "max_crush")


@dataclass
class Sensitivity:
    """Sobol indices of each figure to each input.

    Attributes
    ----------
    cells : list of str
        The uncertain inputs.
    indices : dict
        figure -> {"S1", "S1_conf", "ST", "ST_conf"} -> array over ``cells``.
    shots : SweepResult
        Every shot of the Saltelli sample, as a sweep's table.
    """

    cells: list
    indices: dict
    shots: SweepResult


def _problem(p, sds):
    names, bounds = [], []
    for cell, fields, sd, relative in sds:
        mean = getattr(p, fields[0])
        names.append(cell)
        bounds.append([mean, sd * abs(mean) if relative else sd])
    return {"num_vars": len(names), "names": names, "bounds": bounds,
            "dists": ["norm"] * len(names)}


def sobol(p, sds, n, seed=None, integrator="legacy", model="4-mass", progress=None,
          runner=None):
    """Sobol indices of the peak, pulse and crush to the ``sds`` inputs.

    Parameters
    ----------
    p : airgun_xl.params.ShotParams
    sds : list
        From :func:`airgun_xl.studies.sweep.parse_sd`, at least two.
    n : int
        Base sample size, a power of 2 (SALib's Sobol sequence); the run takes n (D + 2) shots.

    Raises
    ------
    OptionError
        For fewer than two inputs, n not a power of 2, or sampled shots that are invalid or
        diverge (the indices need every shot).
    """
    try:
        from SALib.analyze import sobol as analyze
        from SALib.sample import sobol as sample
    except ImportError:
        raise OptionError("--sobol: needs SALib, expected it installed: pip install "
                          "'airgun-xl[sobol]'") from None

    if len(sds) < 2:
        raise OptionError(f"--sd: found {len(sds)}, expected two or more uncertain inputs for "
                          "Sobol indices")
    if n < 2 or n & (n - 1):
        raise OptionError(f"--sobol: found {n}, expected a power of 2 (Sobol sequence), "
                          "such as 256")
    check_spreads(p, sds)
    cells = [cell for cell, _, _, _ in sds]
    twice = sorted({c for c in cells if cells.count(c) > 1})
    if twice:  # SALib would stop with its own error (issue 23.13)
        raise OptionError(f"--sd: found {twice[0]} twice, expected each uncertain input once")
    flat = [cell for cell, _, sd, _ in sds if not sd > 0]
    if flat:
        raise OptionError(f"--sd: found {flat[0]} with a deviation of 0, expected a spread above "
                          "0 for each input of the Sobol indices")
    problem = _problem(p, sds)
    samples = sample.sample(problem, n, calc_second_order=False, seed=seed)
    varied = [(cell, fields) for cell, fields, _, _ in sds]
    figures, diverged, invalid, flags = _evaluate(p, varied, samples, integrator, model,
                                                  progress, runner)
    bad = int(diverged.sum() + invalid.sum())
    if bad:
        raise OptionError(f"--sobol: {bad:,} of the {len(samples):,} sampled shots were not "
                          "valid or diverged; expected smaller --sd spreads (the indices need "
                          "every shot)")
    indices = {}
    for name in SENSITIVITY_FIGURES:
        y = figures[:, FIGURES.index(name)]
        found = analyze.analyze(problem, y, calc_second_order=False, seed=seed,
                                print_to_console=False)
        indices[name] = {k: np.asarray(found[k], dtype=float)
                         for k in ("S1", "S1_conf", "ST", "ST_conf")}
    shots = SweepResult(problem["names"], samples, figures, diverged, invalid, flags, "sobol")
    return Sensitivity(problem["names"], indices, shots)


def band_convergence(values, points=20):
    """The 5th and 95th percentiles and the mean of the first n values, for n from 10 to all
    of them on a geometric grid: how a Monte Carlo's band settles with its number of shots.

    Returns
    -------
    numpy.ndarray
        Rows (n, mean, p5, p95), NaN values left out.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if len(v) < 10:
        return np.zeros((0, 4))
    ns = np.unique(np.geomspace(10, len(v), points).round().astype(int))
    return np.array([(k, v[:k].mean(), np.percentile(v[:k], 5), np.percentile(v[:k], 95))
                     for k in ns])
