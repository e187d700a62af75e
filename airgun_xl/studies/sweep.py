"""Grids and Monte Carlo over a shot's parameters, run with the batch kernel."""
import itertools
import math
import re
from dataclasses import dataclass

import numpy as np

from .. import limits
from ..cells import BY_ADDRESS, CELLS, address
from ..engine.batch import FIGURES, run_batch
from ..errors import AirgunXlError, OptionError
from ..models import apply_model
from .check import shot_findings

#: Cells whose value moves several fields: the bird's velocity goes to A28..A30 together.
GROUPED = {address("v31"): ("v31", "v32", "v33")}


def fields_of(cell, option):
    cell = cell.strip().upper()
    if cell in GROUPED:
        return cell, GROUPED[cell]
    if cell not in BY_ADDRESS:
        raise OptionError(f"{option}: found {cell!r}, expected a parameter cell such as A28, "
                          f"E40 ({', '.join(c.address for c in CELLS)})")
    return cell, (BY_ADDRESS[cell].name,)


def parse_vary(text, who="--vary"):
    """``A28=100:260:161`` -> (cell, fields, values); a refusal names ``who``."""
    match = re.fullmatch(r"\s*([A-Za-z]+[0-9]+)\s*=\s*([^:]+):([^:]+):(\d+)\s*", text)
    try:
        if match is None:
            raise ValueError(text)
        lo, hi, n = float(match.group(2)), float(match.group(3)), int(match.group(4))
    except ValueError:
        n = 0
    if n < 1 or n > limits.MAX_SHOTS or not (math.isfinite(lo) and math.isfinite(hi)):
        raise OptionError(f"{who}: found {text!r}, expected CELL=LO:HI:N with finite LO and "
                          f"HI and 1 <= N <= {limits.MAX_SHOTS:,}, such as A28=100:260:161")
    assert match is not None  # n = 0 above otherwise
    cell, fields = fields_of(match.group(1), who)
    return cell, fields, np.linspace(lo, hi, n)


def parse_sd(text, who="--sd"):
    """``E40=3%`` (relative) or ``E40=8e5`` (absolute) -> (cell, fields, sd, relative); a
    refusal names ``who``."""
    match = re.fullmatch(r"\s*([A-Za-z]+[0-9]+)\s*=\s*([0-9.eE+-]+)\s*(%?)\s*", text)
    try:
        if match is None:
            raise ValueError(text)
        sd = float(match.group(2))
    except ValueError:
        sd = -1.0
    if not (sd >= 0 and math.isfinite(sd)):
        raise OptionError(f"{who}: found {text!r}, expected CELL=SD or CELL=SD% such as E40=3%")
    assert match is not None  # sd = -1 above otherwise
    cell, fields = fields_of(match.group(1), who)
    return cell, fields, sd / 100 if match.group(3) else sd, bool(match.group(3))


def parse_sds(texts, who="--sd"):
    """Every ``--sd``, by :func:`parse_sd`; a cell scattered twice is refused (the last one
    would silently win)."""
    sds = []
    seen: dict[str, str] = {}
    for text in texts:
        sd = parse_sd(text, who)
        if sd[0] in seen:
            raise OptionError(f"{who}: found {sd[0]} twice ({seen[sd[0]]!r} and {text!r}), "
                              "expected one scatter per cell")
        seen[sd[0]] = text
        sds.append(sd)
    return sds


#: An absolute --sd below this fraction of its cell's value is refused: a percentage that lost
#: its "%" (E40=3 is 3 Pa on 2.7e7 Pa), whose spread would be zero to every digit shown.
SD_FLOOR = 1e-6


def check_spreads(p, sds):
    """Refuse an absolute deviation too small to move its cell (see :data:`SD_FLOOR`)."""
    for cell, fields, sd, relative in sds:
        mean = getattr(p, fields[0])
        if not relative and 0 < sd < SD_FLOOR * abs(mean):
            unit = BY_ADDRESS[cell].unit if cell in BY_ADDRESS else ""
            raise OptionError(f"--sd: found {cell}={sd:g}, a deviation of {sd:g} {unit} on "
                              f"{cell}'s {mean:.4g} {unit} ({sd / abs(mean):.2g} of it); "
                              f"expected a percentage such as {cell}={sd:g}% or a deviation "
                              f"in {unit or 'its unit'} of a size that moves it")


@dataclass
class SweepResult:
    cells: list  # the varied cells
    values: np.ndarray  # shots x cells
    figures: np.ndarray  # shots x FIGURES
    diverged: np.ndarray
    invalid: np.ndarray  # shots whose sampled values were not a valid shot
    flags: list | None = None  # each shot's warnings (str), as a fill of it would say them
    kind: str = "grid"  # "grid" (every combination), "montecarlo" or "sobol" (samples)

    def flagged(self):
        """How many shots have a warning, and how often each cell is named: (n, {cell: n})."""
        cells: dict = {}
        for found in self.flags or []:
            for cell in sorted({text.split(" ", 1)[0] for text in found}):
                cells[cell] = cells.get(cell, 0) + 1
        return sum(1 for found in self.flags or [] if found), cells


def _set(p, fields, value):
    return p.replace(**{f: float(value) for f in fields})


def _evaluate(p, varied, rows_values, integrator, model, progress, runner=None):
    params, invalid = [], np.zeros(len(rows_values), dtype=bool)
    for i, row in enumerate(rows_values):
        q = p
        try:
            for (_cell, fields), value in zip(varied, row, strict=True):
                q = _set(q, fields, value)
            params.append(apply_model(q, model))
        except AirgunXlError:
            invalid[i] = True
    batch = (runner or run_batch)(params, integrator, progress=progress)
    figures = np.full((len(rows_values), len(FIGURES)), np.nan)
    diverged = np.zeros(len(rows_values), dtype=bool)
    figures[~invalid] = batch.figures
    diverged[~invalid] = batch.diverged
    flags: list = [[] for _ in rows_values]
    for k, q, stats in zip(np.flatnonzero(~invalid), params, batch.stats or [],
                           strict=True):
        flags[k] = ([] if stats is None else [str(f) for f in shot_findings(q, stats)])
    return figures, diverged, invalid, flags


def grid(p, varies, integrator="legacy", model="4-mass", progress=None, runner=None):
    """Every combination of the ``varies`` values (from :func:`parse_vary`).

    ``runner`` runs the shots: :func:`~airgun_xl.engine.batch.run_batch` on this machine by
    default, or a :class:`~airgun_xl.studies.cluster.ClusterRunner`."""
    varied = [(cell, fields) for cell, fields, _ in varies]
    combos = np.array(list(itertools.product(*(v for _, _, v in varies))))
    figures, diverged, invalid, flags = _evaluate(p, varied, combos, integrator, model,
                                                  progress, runner)
    return SweepResult([c for c, _ in varied], combos, figures, diverged, invalid, flags)


def monte_carlo(p, sds, n, seed=None, integrator="legacy", model="4-mass", progress=None,
                runner=None):
    """``n`` shots with the ``sds`` cells drawn from normal distributions around the sheet's
    values (a draw that is not a valid shot, e.g. a negative mass, is counted as invalid)."""
    check_spreads(p, sds)
    rng = np.random.default_rng(seed)
    columns = []
    for _cell, fields, sd, relative in sds:
        mean = getattr(p, fields[0])
        columns.append(rng.normal(mean, sd * abs(mean) if relative else sd, n))
    samples = np.column_stack(columns) if columns else np.zeros((n, 0))
    varied = [(cell, fields) for cell, fields, _, _ in sds]
    figures, diverged, invalid, flags = _evaluate(p, varied, samples, integrator, model,
                                                  progress, runner)
    return SweepResult([c for c, _ in varied], samples, figures, diverged, invalid, flags,
                       "montecarlo")


def spread(values):
    """Mean, standard deviation, 5th and 95th percentiles of the finite values."""
    v = values[np.isfinite(values)]
    if not len(v):
        return dict(mean=np.nan, sd=np.nan, p5=np.nan, p95=np.nan, n=0)
    return dict(mean=float(v.mean()), sd=float(v.std(ddof=1)) if len(v) > 1 else 0.0,
                p5=float(np.percentile(v, 5)), p95=float(np.percentile(v, 95)), n=len(v))
