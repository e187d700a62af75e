"""Error against run time: a shot over a ladder of time steps.

Each level runs the shot at one time step and records the headline figures and the run
times. Errors are taken against the finest level, and the finest level's own error is
estimated by Richardson extrapolation with the observed order.
"""
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..engine.summary import summarize
from ..units import parse_duration as _parse

#: Figures compared across levels: (attribute of the level, label, unit).
QUANTITIES = (
    ("peak_kg", "Peak acceleration (raw)", "kG"),
    ("filtered_peak_kg", "Peak acceleration (filtered)", "kG"),
    ("time_of_peak", "Time of peak", "s"),
    ("max_crush", "Maximum crush", "m"),
    ("pulse_duration", "Pulse duration", "s"),
    ("final_m1", "Final M1", "kg"),
    ("final_m31", "Final m31", "kg"),
)

#: Default finest time step [s].
FINEST = 5e-9

def parse_duration(text, option="--levels"):
    """A time step such as ``500ns`` [s] (see :func:`airgun_xl.units.parse_duration`)."""
    return _parse(text, option)


def default_ladder(dt, finest=FINEST):
    """The sheet's dt, then the 1-2-5 steps below it, down to ``finest``."""
    levels = [dt]
    for exponent in range(0, -13, -1):
        for mantissa in (5, 2, 1):
            step = mantissa * 10.0 ** exponent
            if finest * (1 - 1e-9) <= step < dt * (1 - 1e-9):
                levels.append(float(f"{step:.3g}"))
    return sorted(set(levels), reverse=True)


@dataclass
class Level:
    """One rung of the ladder."""

    integrator: str
    delta: float
    rows: int
    kernel_seconds: float
    total_seconds: float
    figures: dict
    errors: dict = field(default_factory=dict)  # quantity -> relative error vs the reference
    order: dict = field(default_factory=dict)  # quantity -> observed order to the next level


@dataclass
class Ladder:
    integrator: str
    levels: list
    richardson: dict  # quantity -> extrapolated value
    recommended: float  # coarsest dt whose peak error <= rtol (nan if none)
    rtol: float


#: A level shorter than this is repeated (up to 5 times) and its fastest run kept, so that
#: the run times of small levels are not timer noise.
MIN_TIMED = 0.05


def run_level(shot, delta, integrator):
    """Run one level; its times are the fastest of enough repeats to measure."""
    leveled = shot.with_params(delta=delta)
    totals: list = []
    kernels: list = []
    spent = 0.0
    while not totals or (spent < MIN_TIMED and len(totals) < 5):
        started = time.perf_counter()
        result = leveled.run(integrator=integrator, track=("deflection", "v31", "v1"))
        s = summarize(result)
        totals.append(time.perf_counter() - started)
        kernels.append(result.history.kernel_seconds)
        spent += totals[-1]
    return Level(integrator, delta, result.rows, min(kernels), min(totals),
                 {q: float(getattr(s, q)) for q, _, _ in QUANTITIES})


def _relative(value, reference):
    if not (math.isfinite(value) and math.isfinite(reference)):
        return math.nan
    return abs(value - reference) / abs(reference) if reference else abs(value - reference)


def ladder(shot, deltas, integrator="legacy", rtol=1e-3):
    """Run ``shot`` at each time step of ``deltas`` (coarse to fine) with one integrator.

    Returns
    -------
    Ladder
    """
    levels = [run_level(shot, d, integrator) for d in sorted(deltas, reverse=True)]
    ref = levels[-1].figures
    richardson = {}
    for q, _, _ in QUANTITIES:
        for lv in levels:
            lv.errors[q] = _relative(lv.figures[q], ref[q])
        for a, b in zip(levels, levels[1:-1], strict=False):  # orders need a non-zero error at b
            ea, eb = a.errors[q], b.errors[q]
            if ea > 0 and eb > 0:
                a.order[q] = math.log(ea / eb) / math.log(a.delta / b.delta)
        richardson[q] = _extrapolate(levels, q)
    recommended = math.nan  # the coarsest level that, with every finer one, meets rtol
    for lv in reversed(levels[:-1]):
        if not lv.errors["peak_kg"] <= rtol:
            break
        recommended = lv.delta
    return Ladder(integrator, levels, richardson, recommended, rtol)


def _extrapolate(levels, q):
    """Richardson estimate from the three finest levels, with their observed order."""
    if len(levels) < 3:
        return math.nan
    f1, f2, f3 = (lv.figures[q] for lv in levels[-3:])
    r1 = levels[-3].delta / levels[-2].delta
    r2 = levels[-2].delta / levels[-1].delta
    d12, d23 = f1 - f2, f2 - f3
    if d23 == 0 or d12 == 0 or np.sign(d12) != np.sign(d23):
        return f3
    p = math.log(abs(d12 / d23)) / math.log(math.sqrt(r1 * r2))
    if not 0.2 < p < 6:
        return f3
    return f3 + d23 / (r2 ** p - 1)
