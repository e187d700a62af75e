"""Convergence: the shot run at each time step of a ladder, each figure's error against the
finest level (with Richardson extrapolation and the observed order), the coarsest time step
that meets the tolerance on the peak; a workbook and a PNG of error against run time.

:func:`run` takes a :class:`ConvergenceRequest` and returns a :class:`ConvergenceOutcome`;
the CLI (``airgun-xl convergence``) and the Python API (:func:`airgun_xl.convergence`) are
both this."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import OptionError
from . import declared

#: The warning where the PNG could not be drawn.
NO_PNG = "matplotlib is not installed: no PNG (pip install 'airgun-xl[plots]')"


def a_ladder(value: Any, who: str) -> tuple[float, ...] | None:
    """A ladder of time steps [s]: text (``"5us,2us,1us"``), a sequence of durations as text
    or numbers [s], or None (the sheet's E2, then 1-2-5 steps down to 5 ns); at least two."""
    from ..units import parse_duration

    if value is None:
        return None
    texts = ([t for t in value.split(",") if t.strip()] if isinstance(value, str) else
             list(value) if isinstance(value, (list, tuple)) else [value])
    steps = tuple(declared.a_number(t, who) if isinstance(t, (int, float))
                  and not isinstance(t, bool) else parse_duration(t, who) for t in texts)
    if not all(0 < d < math.inf for d in steps):
        raise OptionError(f"{who}: found {value!r}, expected positive time steps")
    if len(steps) < 2:
        raise OptionError(f"{who}: found {value!r}, expected at least two time steps")
    return steps


def a_peak_tolerance(value: Any, who: str) -> float:
    """The tolerance on the peak [-]: a number between 0 and 1."""
    try:
        found = declared.a_number(value, who)
    except OptionError:
        found = math.nan
    if not 0 < found < 1:
        raise OptionError(f"{who}: found {value!r}, expected a number between 0 and 1")
    return found


@dataclass(frozen=True, kw_only=True)
class ConvergenceRequest(declared.Checked):
    """The ladder: ``levels`` the time steps [s] (None: the sheet's E2, then 1-2-5 steps down
    to 5 ns), run with each of ``integrators``; ``rtol`` the tolerance on the peak [-].
    ``output`` None writes no workbook (the CLI gives its default,
    ``SHOT.convergence.xlsx``, and the PNG beside it). Declared once (:mod:`.declared`): the
    command's options and the API's keywords."""

    shot: Path = declared.shot()
    levels: tuple[float, ...] | None = declared.option(
        None, "--levels", read=a_ladder,
        help="comma-separated time steps, e.g. 5us,2us,1us,500ns (default: the sheet's E2, "
             "then 1-2-5 steps down to 5ns)")
    integrators: tuple[str, ...] = declared.integrators()
    rtol: float = declared.option(1e-3, "--rtol", read=a_peak_tolerance,
                                  help="tolerance on the peak (default 0.1%%)")
    output: Path | None = declared.output("workbook; the PNG goes beside it",
                                          "SHOT.convergence.xlsx")
    force: bool = declared.force()
    crush_law: str = declared.crush_law()
    archive: Path | None = declared.archive()  # where a library law is read from


@dataclass(frozen=True)
class ConvergenceOutcome:
    """Each integrator's ladder (studies.convergence.Ladder: its levels' figures, errors,
    orders and run times, the Richardson extrapolation, the step recommended), the
    warnings, and the files written."""

    ladders: tuple[Any, ...]
    output: Path | None
    png: Path | None  # the figure, if drawn
    files: tuple[Path, ...]
    warnings: tuple[str, ...]

    @property
    def recommended(self) -> dict[str, float]:
        """{integrator: the coarsest time step [s] whose peak is within the tolerance of the
        finest level's} (NaN: none of the coarser levels)."""
        return {lad.integrator: float(lad.recommended) for lad in self.ladders}

    def to_json(self) -> str:
        """The outcome as one JSON document (``convergence --json``); run times in s."""
        from .documents import dumps

        return dumps({"ladders": self.ladders, "recommended_s": self.recommended,
                      "warnings": self.warnings, "files": self.files})


def run(request: ConvergenceRequest) -> ConvergenceOutcome:
    """Run the ladder ``request`` asks for.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written.
    """
    from ..archive.laws import shot_with_law
    from ..studies.convergence import default_ladder, ladder
    from ..transaction import check_output

    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    deltas = (list(request.levels) if request.levels is not None
              else default_ladder(shot.params.delta))
    if len(deltas) < 2:
        raise OptionError(f"levels: the sheet's time step E2 = {shot.params.delta:g} s is "
                          "already at the finest default level (5 ns), expected two or more "
                          "time steps, e.g. 10ns,5ns,2ns")
    for d in deltas:
        shot.params.replace(delta=d)  # each level is a valid shot (raises on the cell)
    png = request.output.with_suffix(".png") if request.output is not None else None
    if request.output is not None and png is not None:
        check_output(request.output, request.force, inputs=[request.shot])
        check_output(png, request.force, inputs=[request.shot], suffixes=(".png",))
    warnings = [str(w) for w in shot.warnings]
    ladders = tuple(ladder(shot, deltas, name, request.rtol)
                    for name in request.integrators)
    files: tuple[Path, ...] = ()
    if request.output is not None:
        from ..reports.convergence import write_convergence

        drew = write_convergence(list(ladders), request.output, request.force, shot, png)
        if not drew:
            warnings.append(NO_PNG)
            png = None
        files = tuple(p for p in (request.output, png) if p is not None)
    return ConvergenceOutcome(ladders, request.output, png, files, tuple(warnings))


def lines(request: ConvergenceRequest, outcome: ConvergenceOutcome) -> list[str]:
    """What ``convergence`` prints: a table an integrator (each level's step, rows, times,
    peak and crush with their errors and orders), Richardson's peak, the coarsest step
    within the tolerance; the files."""
    said = []
    for lad in outcome.ladders:
        said += [f"{lad.integrator} integrator:",
                 f"  {'dt':>9} {'rows':>10} {'kernel s':>9} {'total s':>8} {'peak kG':>10} "
                 f"{'rel.err':>9} {'order':>6} {'crush m':>8} {'rel.err':>9}"]
        for lv in lad.levels:
            order = lv.order.get("peak_kg")
            said.append(f"  {lv.delta:9.3g} {lv.rows:10,} {lv.kernel_seconds:9.4f} "
                        f"{lv.total_seconds:8.3f} {lv.figures['peak_kg']:10.5f} "
                        f"{lv.errors['peak_kg']:9.2e} "
                        f"{'' if order is None else f'{order:6.2f}':>6} "
                        f"{lv.figures['max_crush']:8.5f} {lv.errors['max_crush']:9.2e}")
        extrapolated = lad.richardson["peak_kg"]
        finest = lad.levels[-1].figures["peak_kg"]
        rec = lad.recommended
        said += [f"  Richardson: peak {extrapolated:.5f} kG (finest level off by "
                 f"{abs(finest - extrapolated) / abs(extrapolated):.1e})",
                 f"  coarsest dt with peak within {lad.rtol:.1%} of the finest: "
                 + (f"{rec:.3g} s" if not math.isnan(rec) else "none of the coarser levels")]
    said.append(f"wrote {outcome.output} and {outcome.png}" if outcome.png else
                f"wrote {outcome.output}")
    return said
