"""Sweep: a grid of shots, a Monte Carlo or Sobol indices over uncertain inputs, with the
batch kernel, on this machine or a Dask cluster; the table, charts and spread written.

:func:`run` takes a :class:`SweepRequest` and returns a :class:`SweepOutcome`; the CLI
(``airgun-xl sweep``) and the Python API (:func:`airgun_xl.sweep`) are both this."""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import limits
from ..errors import OptionError
from .running import cluster_runner, shots_progress

if TYPE_CHECKING:
    import pandas as pd

    from ..studies.sweep import SweepResult


@dataclass(frozen=True)
class SweepRequest:
    """The study: a grid (``vary``: ``CELL=LO:HI:N`` each, several make a grid), or ``mc``
    (a Monte Carlo of that many shots) or ``sobol`` (N x (inputs + 2) shots) with the
    spreads ``sd`` (``CELL=SD[%]`` each), drawn from ``seed``; the options as the CLI's,
    their values as typed. ``output`` None writes no workbook (the CLI gives its default,
    ``SHOT.sweep.xlsx``)."""

    shot: Path
    vary: tuple[str, ...] = ()
    mc: str | None = None
    sd: tuple[str, ...] = ()
    sobol: str | None = None
    seed: int = 1
    integrator: str = "legacy"
    model: str = "4-mass"
    output: Path | None = None
    force: bool = False
    crush_law: str = "workbook"  # workbook, legacy or NAME[@N] of the archive's library
    archive: Path | None = None  # where a library law is read from
    scheduler: str | None = None  # a Dask scheduler's address
    workers: int | None = None  # a local Dask cluster of this many processes
    chunk: int | None = None  # shots a cluster task


@dataclass(frozen=True)
class SweepOutcome:
    """The shots' figures, the spread or the indices, what the command warns, and the files
    written."""

    result: SweepResult
    stats: dict[str, float]  # the spread of the peak [kG] (a Monte Carlo's, Sobol's draws)
    sensitivity: Any  # Sobol's indices (studies.sensitivity), or None
    seed: int | None  # the draws' seed (None for a grid)
    shots: int
    seconds: float  # [s], the runs' time
    steps_per_second: float  # [1/s], shot-steps
    output: Path | None
    files: tuple[Path, ...]
    warnings: tuple[str, ...]

    @property
    def kind(self) -> str:
        """``grid``, ``montecarlo`` or ``sobol``."""
        return str(self.result.kind)

    def to_json(self) -> str:
        """The outcome as one JSON document (``sweep --json``): the study, the spread of the
        peak [kG], the Sobol indices, and a row a shot as :meth:`to_frame` gives it."""
        from .documents import dumps

        sensitivity = None
        if self.sensitivity is not None:
            sensitivity = {"cells": list(self.sensitivity.cells),
                           "indices": self.sensitivity.indices}
        return dumps({"kind": self.kind, "shots": self.shots, "seed": self.seed,
                      "seconds": self.seconds, "peak_kG": self.stats,
                      "sensitivity": sensitivity,
                      "rows": self.to_frame().to_dict(orient="records"),
                      "warnings": self.warnings, "files": self.files})

    def to_frame(self) -> pd.DataFrame:
        """One row a shot: the varied or drawn cells (in their units), the figures
        (``peak_kg`` [kG], ``time_of_peak`` [s], ``filtered_peak_kg`` [kG],
        ``pulse_duration`` [s], ``max_crush`` [m]), ``diverged``, ``invalid``, and each
        shot's ``warnings`` (a tuple of text). A figure the run could not give is NaN."""
        import pandas as pd

        from ..engine.batch import FIGURES

        result = self.result
        data: dict[str, Any] = {cell: result.values[:, i] for i, cell in enumerate(result.cells)}
        data.update({name: result.figures[:, j] for j, name in enumerate(FIGURES)})
        data["diverged"] = np.asarray(result.diverged, dtype=bool)
        data["invalid"] = np.asarray(result.invalid, dtype=bool)
        flags = result.flags or [[] for _ in result.values]
        data["warnings"] = [tuple(found) for found in flags]
        return pd.DataFrame(data)


def _count(option: str, text: str | None, sds: list[Any]) -> int:
    """A Monte Carlo's or Sobol's number of shots, checked."""
    try:
        n = int(str(text))
    except ValueError:
        n = 0
    if n < 2 or n > limits.MAX_SHOTS or not sds:
        raise OptionError(f"{option}: found {text!r}{'' if sds else ' without --sd'}, "
                          f"expected a number of shots from 2 to {limits.MAX_SHOTS:,}, "
                          "with --sd")
    return n


def run(request: SweepRequest,
        progress_for: Callable[[int], Any] | None = None) -> SweepOutcome:
    """Run the study ``request`` asks for. ``progress_for(shots)``, once the shots are
    counted, makes the progress callback: told ``advance(k)`` as shots end (or called with
    k, if a plain function), and ``close()``d at the end if it has one.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input (a cell, an option, a file), named; nothing is written.
    """
    from ..archive.laws import shot_with_law
    from ..studies.sensitivity import sobol
    from ..studies.sweep import grid, monte_carlo, parse_sds, parse_vary, spread
    from ..transaction import check_output

    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    varies = [parse_vary(v) for v in request.vary]
    sds = parse_sds(list(request.sd))
    if request.mc is not None and request.sobol is not None:
        raise OptionError("--sobol: found it with --mc, expected one or the other")
    n = 1
    if request.mc is not None or request.sobol is not None:
        random = "--mc" if request.mc is not None else "--sobol"
        n = _count(random, request.mc if request.mc is not None else request.sobol, sds)
        if not 0 <= request.seed < 2**128:
            raise OptionError(f"--seed: found {request.seed}, expected a whole number from 0 "
                              "to 2**128 - 1")
        if varies:
            raise OptionError(f"--vary: found a grid with {random}, expected one or the other")
    elif not varies:
        raise OptionError("--vary: found none, expected CELL=LO:HI:N (or --mc N with --sd)")
    if request.output is not None:
        check_output(request.output, request.force, inputs=[request.shot])
    total = n if request.mc is not None else n * (len(sds) + 2) \
        if request.sobol is not None else 1
    for _, _, values in varies:
        total *= len(values)
    if total > limits.MAX_SHOTS:
        raise OptionError(f"--vary: found a grid of {total:,} shots, expected at most "
                          f"{limits.MAX_SHOTS:,} (fewer points per cell)")
    limits.check_memory(limits.sweep_bytes(total, shot.params.rows),
                        f"a sweep of {total:,} shots of {shot.params.rows:,} rows",
                        "fewer shots (--mc, or fewer points per --vary) or fewer rows")
    started = time.perf_counter()
    with cluster_runner(request.scheduler, request.workers, request.chunk) as runner, \
            shots_progress(progress_for, total) as progress:
        sensitivity = None
        if request.mc is not None:
            result = monte_carlo(shot.params, sds, n, request.seed, request.integrator,
                                 request.model, progress, runner)
        elif request.sobol is not None:
            sensitivity = sobol(shot.params, sds, n, request.seed, request.integrator,
                                request.model, progress, runner)
            result = sensitivity.shots
        else:
            result = grid(shot.params, varies, request.integrator, request.model, progress,
                          runner)
    seconds = time.perf_counter() - started
    stats = spread(result.figures[:, 0])
    seed = None if result.kind == "grid" else request.seed
    if request.output is not None:
        from ..reports.sweep import write_sweep

        write_sweep(result, request.output, request.force,
                    stats if request.mc is not None else None, sensitivity,
                    shot=Path(request.shot).name, seed=seed)
    flagged, cells = result.flagged()
    where = (f"the Warnings column and sheet of {request.output}" if request.output is not None
             else "the warnings column of to_frame()")
    warnings = ([f"{flagged:,} of {total:,} shots have warnings, naming "
                 + ", ".join(f"{cell} ({k:,} shots)" for cell, k in sorted(cells.items()))
                 + f": see {where}"] if flagged else [])
    steps = total * (shot.params.rows - 2)
    files = (request.output,) if request.output is not None else ()
    return SweepOutcome(result, stats, sensitivity, seed, total, seconds,
                        steps / seconds if seconds > 0 else float("inf"), request.output,
                        files, tuple(warnings))


def lines(request: SweepRequest, outcome: SweepOutcome) -> list[str]:
    """What ``sweep`` prints: the shots run, how fast, how many diverged; the peak's range
    over a grid or its spread over the draws; Sobol's indices."""
    result, stats = outcome.result, outcome.stats
    said = [f"wrote {outcome.output}: {outcome.shots:,} shots in {outcome.seconds:.2f} s "
            f"({outcome.steps_per_second:.3g} shot-steps/s); {int(result.diverged.sum())} "
            f"diverged, {int(result.invalid.sum())} invalid"]
    if result.kind == "grid":  # every combination, not a distribution: its extremes
        peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
        if len(peaks):
            said.append(f"  peak from {peaks.min():.4f} to {peaks.max():.4f} kG over the grid")
    else:
        said.append(f"  peak {stats['mean']:.4f} kG mean, sd {stats['sd']:.4f}, 5-95% "
                    f"{stats['p5']:.4f}-{stats['p95']:.4f} kG (seed {request.seed})")
    if outcome.sensitivity is not None:
        found = outcome.sensitivity.indices["peak_kg"]
        said.append("  Sobol indices of the peak: " + ", ".join(
            f"{cell} S1 {s1:.3f} ST {st:.3f}" for cell, s1, st in
            zip(outcome.sensitivity.cells, found["S1"], found["ST"], strict=True)))
    return said
