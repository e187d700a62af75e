"""Many shots at once: the headline figures of each, for sweeps, Monte Carlo and design.

Shots with the same time grid run in the compiled batch kernel (the single-shot stepping code
in a loop, the GIL released) on two threads; the derived figures are computed for a whole
block of shots with the same numpy expressions as one shot's. Each figure therefore equals
the single-shot figure (:func:`airgun_xl.engine.summary.summarize`) to the last bit.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .derived import KG_DIVISOR
from .filtered import filter_stencils, filtered_values
from .integrators import displacement_bound, kernel_params, kernel_stats
from .interface import FINAL_COUNT, FINALS, final
from .kernel import batch_kernel
from .summary import KG, PULSE_FRACTION

if TYPE_CHECKING:
    from ..params import ShotParams
    from .filtered import Stencils

#: The figures of each shot, in column order of :attr:`Batch.figures`.
FIGURES = ("peak_kg", "time_of_peak", "filtered_peak_kg", "pulse_duration", "max_crush")

_INTEGRATOR_ID = {"legacy": 0, "newmark": 1}
N_FINALS = FINAL_COUNT  # the kernel's finals a shot (engine/interface.py)
BLOCK = 128  # shots a block: bounds memory at rows x 128 doubles (12 MB for shot A)


class Extra(Protocol):
    """What a batch computes more of a block's pulses while they are in memory
    (:class:`airgun_xl.studies.acceptance.BlockJudge`): ``width`` values a shot."""

    @property
    def width(self) -> int: ...

    def __call__(self, t: np.ndarray, kg: np.ndarray) -> np.ndarray: ...


@dataclass
class Batch:
    """Figures of many shots: ``figures[i, j]`` is shot i's ``FIGURES[j]`` (NaN when the shot
    diverged); ``diverged[i]`` says so."""

    figures: np.ndarray
    diverged: np.ndarray
    stats: list[Any] | None = None  # each shot's KernelStats (None where it diverged)
    extras: np.ndarray | None = None  # shots x extra.width: what ``extra`` computed

    def column(self, name: str) -> np.ndarray:
        return self.figures[:, FIGURES.index(name)]


def _grid_key(p: ShotParams) -> tuple[float, float, float, int]:
    return p.delta, p.max_time, p.filter_frequency, p.bird_masses


def run_batch(params: Sequence[ShotParams], integrator: str = "legacy", host: str = "excel",
              threads: int = 2, progress: Callable[[int], Any] | None = None,
              extra: Extra | None = None) -> Batch:
    """Headline figures of each of ``params`` (a list of :class:`ShotParams`).

    Parameters
    ----------
    progress : callable, optional
        Called with the number of shots finished after each block.
    extra : callable, optional
        ``extra(time, kg)`` of a block's pulses (the test item's acceleration [kG], a row a
        shot, at ``time`` [s]) gives ``extra.width`` more values a shot, computed on the
        worker threads while the block's pulses are in memory (the judge of a
        specification: :class:`airgun_xl.studies.acceptance.BlockJudge`).

    Returns
    -------
    Batch
    """
    n = len(params)
    figures = np.full((n, len(FIGURES)), np.nan)
    extras = None if extra is None else np.full((n, extra.width), np.nan)
    diverged = np.zeros(n, dtype=bool)
    stats: list[Any] = [None] * n
    groups: dict = {}
    for i, p in enumerate(params):
        groups.setdefault(_grid_key(p), []).append(i)
    pool = ThreadPoolExecutor(threads) if threads > 1 else None
    try:
        for indices in groups.values():
            first = params[indices[0]]
            stencils = filter_stencils(first.rows, first.samplerate, host)
            for start in range(0, len(indices), BLOCK):
                block = indices[start:start + BLOCK]
                figs, bad, finals, more = _run_block([params[i] for i in block], integrator,
                                                     stencils, pool, extra)
                figures[block] = figs
                if extras is not None:
                    extras[block] = more
                diverged[block] = bad
                for i, row, stopped in zip(block, finals, bad, strict=True):
                    stats[i] = None if stopped else kernel_stats(
                        dict(zip((name for name, _ in FINALS), row, strict=True)))
                if progress is not None:
                    progress(len(block))
    finally:
        if pool is not None:
            pool.shutdown()
    return Batch(figures, diverged, stats, extras)


def _run_block(block: Sequence[ShotParams], integrator: str, stencils: Stencils,
               pool: ThreadPoolExecutor | None, extra: Extra | None = None
               ) -> tuple[np.ndarray, ...]:
    p0 = block[0]
    rows, m = p0.rows, len(block)
    matrix = np.array([kernel_params(p) + [displacement_bound(p)] for p in block])
    halves = [(0, m // 2), (m // 2, m)] if pool is not None and m > 1 else [(0, m)]

    def work(half: tuple[int, int]) -> tuple[np.ndarray, ...]:  # half the block, one thread
        a, b = half
        y = np.empty((b - a, rows))
        finals = np.empty((b - a, N_FINALS))
        t = np.empty(rows)
        batch_kernel(matrix[a:b], rows, _INTEGRATOR_ID[integrator], p0.bird_masses, t, y,
                     finals)
        out, bad = _figures(y, t, finals, p0, stencils)
        more = np.full((b - a, extra.width if extra is not None else 0), np.nan)
        if extra is not None and rows >= 3:
            kg = ((1.0 / (p0.delta * p0.delta)) * (y[:, 2:] + y[:, :-2] - 2 * y[:, 1:-1])
                  / KG_DIVISOR)  # as _figures: the single shot's accel_kg, a row a shot
            more = np.asarray(extra(t[1:-1], kg), dtype=float)
            more[bad] = np.nan
        return out, bad, finals, more

    parts = (list(pool.map(work, halves)) if pool is not None and len(halves) > 1
             else [work(halves[0])])
    return tuple(np.concatenate([part[j] for part in parts]) for j in range(4))


def _figures(y: np.ndarray, t: np.ndarray, finals: np.ndarray, p0: ShotParams,
             stencils: Stencils) -> tuple[np.ndarray, np.ndarray]:
    """FIGURES of each row of ``y`` (the bird's last mass), as one shot's are computed."""
    m, rows = y.shape
    bad = finals[:, final("bad_row")] >= 0
    out = np.full((m, len(FIGURES)), np.nan)
    if rows >= 3:
        # as derived.test_item_derivatives, one shot a row
        accel = (1.0 / (p0.delta * p0.delta)) * (y[:, 2:] + y[:, :-2] - 2 * y[:, 1:-1])
        kg = accel / KG_DIVISOR
        i_peak = np.argmax(kg, axis=1)
        peak = kg[np.arange(m), i_peak]
        out[:, 0] = peak
        out[:, 1] = t[1 + i_peak]
        above = kg >= (PULSE_FRACTION * peak)[:, None]
        first = np.argmax(above, axis=1)
        last = kg.shape[1] - 1 - np.argmax(above[:, ::-1], axis=1)
        out[:, 3] = np.where(peak > 0, t[1 + last] - t[1 + first], 0.0)
    inside = stencils.write < rows
    if inside.any():
        values = filtered_values(y, p0.delta, p0.samplerate, stencils)[:, inside]
        out[:, 2] = np.max(values / KG, axis=1)
    out[:, 4] = finals[:, final("max_crush")]
    out[bad] = np.nan
    return out, bad
