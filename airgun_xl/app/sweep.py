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

from .. import limits
from ..errors import OptionError
from . import declared
from .running import cluster_runner, shots_progress

if TYPE_CHECKING:
    import pandas as pd

    from ..studies.sweep import SweepResult


def some_varied(value: Any, who: str) -> tuple[str, ...]:
    """Grids of cells: ``CELL=LO:HI:N`` each (a text, or a list of them), each checked
    (:func:`~airgun_xl.studies.sweep.parse_vary`); several make a grid."""
    from ..studies.sweep import parse_vary

    found = declared.texts(value, who)
    for text in found:
        parse_vary(text, who)
    return found


def some_spreads(value: Any, who: str) -> tuple[str, ...]:
    """Spreads of uncertain inputs: ``CELL=SD[%]`` each (a text, or a list of them), each
    cell once (:func:`~airgun_xl.studies.sweep.parse_sds`)."""
    from ..studies.sweep import parse_sds

    found = declared.texts(value, who)
    parse_sds(list(found), who)
    return found


def some_shots_or_none(value: Any, who: str) -> int | None:
    """A Monte Carlo's or Sobol's number: a whole number from 2 to
    :data:`~airgun_xl.limits.MAX_SHOTS`, or None."""
    if value is None:
        return None
    try:
        return declared.a_whole(value, who, 2, limits.MAX_SHOTS)
    except OptionError:
        raise OptionError(f"{who}: found {value!r}, expected a number of shots from 2 to "
                          f"{limits.MAX_SHOTS:,}") from None


@dataclass(frozen=True, kw_only=True)
class SweepRequest(declared.Checked):
    """The study: a grid (``vary``: ``CELL=LO:HI:N`` each, several make a grid), or ``mc``
    (a Monte Carlo of that many shots) or ``sobol`` (N x (inputs + 2) shots) with the
    spreads ``sd`` (``CELL=SD[%]`` each), drawn from ``seed``. ``output`` None writes no
    workbook (the CLI gives its default, ``SHOT.sweep.xlsx``). Declared once
    (:mod:`.declared`): the command's options and the API's keywords."""

    shot: Path = declared.shot()
    vary: tuple[str, ...] = declared.option(
        (), "--vary", kind="repeated", metavar="CELL=LO:HI:N", read=some_varied,
        help="a parameter cell and its values, e.g. A28=100:260:161")
    mc: int | None = declared.option(None, "--mc", metavar="N", read=some_shots_or_none,
                                     help="Monte Carlo: this many shots")
    sd: tuple[str, ...] = declared.option(
        (), "--sd", kind="repeated", metavar="CELL=SD[%]", read=some_spreads,
        help="spread of an uncertain input, e.g. E40=3%% (Monte Carlo)")
    sobol: int | None = declared.option(
        None, "--sobol", metavar="N", read=some_shots_or_none,
        help="Sobol indices of the peak, pulse and crush to the --sd inputs (SALib): N (a "
             "power of 2) x (inputs + 2) shots")
    seed: int = declared.seed("seed of the Monte Carlo's and Sobol's draws (default 1, so "
                              "that a run repeats; printed with the results)")
    integrator: str = declared.integrator()
    model: str = declared.model()
    output: Path | None = declared.output("table and charts", "SHOT.sweep.xlsx")
    force: bool = declared.force()
    scheduler: str | None = declared.scheduler()
    workers: int | None = declared.workers()
    chunk: int | None = declared.chunk()
    crush_law: str = declared.crush_law()
    archive: Path | None = declared.archive()  # where a library law is read from


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
        import numpy as np
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
    varies = [parse_vary(v, "vary") for v in request.vary]
    sds = parse_sds(list(request.sd), "sd")
    if request.mc is not None and request.sobol is not None:
        raise declared.refusal("{0}: found it with {1}, expected one or the other", "sobol",
                               "mc")
    n = 1
    if request.mc is not None or request.sobol is not None:
        random = "mc" if request.mc is not None else "sobol"
        n = request.mc if request.mc is not None else request.sobol or 0
        if not sds:
            raise declared.refusal("{0}: found {n} without {1}, expected the spreads of the "
                                   "inputs to draw ({1} CELL=SD[%])", random, "sd", n=n)
        if varies:
            raise declared.refusal("{0}: found a grid with {1}, expected one or the other",
                                   "vary", random)
    elif not varies:
        raise declared.refusal("{0}: found none, expected CELL=LO:HI:N (or {1} N with {2})",
                               "vary", "mc", "sd")
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
    import numpy as np

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
