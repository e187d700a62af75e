"""Design: solve for the shot a client asks for, in one of three modes, and fill the designed
shot's workbook.

- **a target** (``target_peak``, with ``target_duration`` two cells; or ``target_srs``): the
  value of the cell(s) that gives it;
- **the middle of a specification** (no target): the setting whose prediction's smallest
  margin is largest;
- **first-shot success** (``confidence`` with the scatter ``sd``): the setting most likely
  to pass, with its probability's 95 % interval; not reaching ``confidence`` is a FAIL
  (the CLI's exit 3).

:func:`run` takes a :class:`DesignRequest` and returns a :class:`DesignOutcome`; the CLI
(``airgun-xl design``) and the Python API (:func:`airgun_xl.design`) are both this."""
from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import limits
from ..cells import address
from ..errors import OptionError
from ..specification import parse_target
from .running import cluster_runner, shots_progress
from .specifying import SpecFields, resolve

if TYPE_CHECKING:
    from ..shot import Shot
    from ..specification import Specification
    from ..studies.design import Design

#: Messages' sink: a list of lines (warnings, notices) as they come.
Say = Callable[[list[str]], None]


@dataclass(frozen=True)
class DesignRequest:
    """The design asked for, the options as the CLI's, their values as typed (``"12kG"``,
    ``"A28=1.5%"``). ``output`` None fills no workbook (the CLI gives its default,
    ``SHOT.design.xlsx``); ``spec`` gives the specification's fields over the shot's sheet
    (and ``srs_q``, ``accel_unit`` a target SRS's Q and unit)."""

    shot: Path
    target_peak: str | None = None
    target_duration: str | None = None
    target_srs: str | None = None
    vary: tuple[str, ...] = ()
    range: str | None = None  # LO:HI of the (first) varied cell, in its unit
    filtered: bool = False  # match the filtered peak
    spec: SpecFields = field(default_factory=SpecFields)
    confidence: float | None = None
    sd: tuple[str, ...] = ()
    shots: int = 10_000  # Monte Carlo shots a setting
    seed: int = 1
    integrator: str = "legacy"
    model: str = "4-mass"
    output: Path | None = None
    force: bool = False
    crush_law: str = "workbook"
    archive: Path | None = None  # where a library law is read from
    scheduler: str | None = None
    workers: int | None = None
    chunk: int | None = None
    argv: tuple[str, ...] = ()  # the command, as the workbook's provenance records it
    pdf: Path | None = None  # the designed shot's report as a PDF too (needs an output)


@dataclass(frozen=True)
class DesignOutcome:
    """The design, the designed shot, what the command says of it, and the files written."""

    mode: str  # "target", "srs", "middle" or "confidence"
    design: Design  # the cells solved, their values, the designed parameters
    designed: Shot  # the shot with the solved values in its cells
    reached: bool  # False: no setting met the specification (middle) or reached P
    lines: tuple[str, ...]  # what the command prints of the solution, before the fill's
    filled: Any  # the designed shot's fill (app.fill.Filled), None without an output
    output: Path | None
    files: tuple[Path, ...]
    warnings: tuple[str, ...]  # the designed shot's and the study's
    confidence: Any = None  # first_shot.Confidence (probabilities, intervals), if asked

    def to_json(self) -> str:
        """The outcome as one JSON document (``design --json``): the mode, the values solved
        (in the cells' units), whether the specification or P was reached, first-shot
        success's probabilities with their 95 % intervals, and the designed shot's Summary
        figures where it was filled."""
        from .documents import dumps

        c = self.confidence

        def setting(s: Any) -> dict[str, Any]:
            return {"setting": s.setting, "probability": s.probability,
                    "interval": s.interval, "shots": s.shots, "passes": s.passes,
                    "failures": s.failures}

        summary = self.filled.summary if self.filled is not None else None
        return dumps({"mode": self.mode, "values": self.values, "reached": self.reached,
                      "confidence": None if c is None else {
                          "best": setting(c.best), "middle": setting(c.middle)},
                      "evaluations": self.design.evaluations,
                      "summary": None if summary is None else {
                          k: v for k, v in dataclasses.asdict(summary).items()
                          if k != "spectrum"},
                      "warnings": self.warnings, "files": self.files})

    @property
    def values(self) -> dict[str, float]:
        """{cell: value} solved (A28 stands for A28..A30), in the cells' units."""
        return {v.cell: float(x) for v, x in zip(self.design.variables, self.design.values,
                                                 strict=True)}


def _range(text: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except (ValueError, AttributeError):
        lo = hi = float("nan")
    if not lo < hi:
        raise OptionError(f"--range: found {text!r}, expected LO:HI with LO < HI")
    return lo, hi


def _label(var: Any) -> str:
    return var.cell if len(var.cells) == 1 else f"{var.cells[0]}..{var.cells[-1]}"


def run(request: DesignRequest, warn: Say | None = None, note: Say | None = None,
        progress_for: Callable[[int], Any] | None = None,
        shots_progress_for: Callable[[int], Any] | None = None) -> DesignOutcome:
    """Design the shot ``request`` asks for, and fill it (``request.output``).

    ``warn`` and ``note`` are told the fill's warnings and notices as they come (they are in
    the outcome too); ``progress_for(rows)`` makes the fill's progress callback (told each
    stage, closed at the end if it has ``close``); ``shots_progress_for(shots)`` the first-shot
    study's (told ``advance(k)`` as its Monte Carlo shots end, closed at the end), given the
    most shots the study can run.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written.
    """
    _check_pdf(request)
    if request.target_srs is not None:
        mode, study = "srs", _solve_srs
    elif request.target_peak is None:
        mode, study = ("middle" if request.confidence is None else "confidence"), _solve_spec
    else:
        mode, study = "target", _solve_target
    if study is _solve_spec:
        shot, design, lines, extra = _solve_spec(request, shots_progress_for)
    else:
        shot, design, lines, extra = study(request)
    return _fill(request, mode, shot, design, lines, extra, warn, note, progress_for)


def _check_pdf(request: DesignRequest) -> None:
    """``--pdf``: a file it may write, beside a workbook, before any study."""
    if request.pdf is None:
        return
    from ..reports.pdf_report import check_pdf

    if request.output is None:
        raise OptionError("--pdf: found without a workbook to fill, expected an output too "
                          "(the PDF is the designed shot's report)")
    check_pdf(request.pdf, request.force, [request.shot], beside=request.output)


def _solve_target(request: DesignRequest) -> tuple[Shot, Design, list[str], dict[str, Any]]:
    from ..archive.laws import shot_with_law
    from ..studies.design import solve_peak, solve_peak_and_duration, variable

    if request.confidence is not None:
        raise OptionError("--confidence: found with --target-peak, expected a design by the "
                          "specification (its fields, with no --target-*)")
    assert request.target_peak is not None
    # the grammar of every quantity: the same reading, or refusal, as --peak and --duration
    target = parse_target("peak", request.target_peak, "--target-peak")
    duration = parse_target("duration", request.target_duration, "--target-duration") \
        if request.target_duration else None
    variables = [variable(n) for n in request.vary or (address("v31"),)]
    if duration is not None and len(variables) != 2:
        raise OptionError("--target-duration: found one --vary, expected two (the first meets "
                          "the peak, the second the duration)")
    if duration is None and len(variables) != 1:
        raise OptionError("--vary: found two parameters, expected one (or add "
                          "--target-duration)")
    bounds = _range(request.range) if request.range else None
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    started = time.perf_counter()
    with cluster_runner(request.scheduler, request.workers, request.chunk) as runner:
        if duration is None:
            design = solve_peak(shot.params, target, variables[0], request.filtered,
                                request.integrator, request.model, bounds, runner=runner)
        else:
            design = solve_peak_and_duration(shot.params, target, duration, variables[0],
                                             variables[1], request.filtered,
                                             request.integrator, request.model, runner=runner)
    seconds = time.perf_counter() - started
    lines = [f"{_label(var)} = {value:.6g} {var.unit}"
             for var, value in zip(design.variables, design.values, strict=True)]
    lines += [f"  achieved peak {design.peak_kg:.5f} kG (target {target:.5f} kG), pulse "
              f"{design.duration * 1e3:.4f} ms"
              + (f" (target {duration * 1e3:.4f} ms)" if duration is not None else ""),
              f"  {design.evaluations} simulations in {seconds:.2f} s"]
    return shot, design, lines, {}


def _solve_srs(request: DesignRequest) -> tuple[Shot, Design, list[str], dict[str, Any]]:
    from ..archive.laws import shot_with_law
    from ..readers.recording import read_spectrum
    from ..specification import parse_q
    from ..studies.design import solve_srs, variable

    for flag, value in (("--scheduler", request.scheduler), ("--workers", request.workers),
                        ("--chunk", request.chunk)):
        if value is not None:
            raise OptionError(f"{flag}: found with --target-srs, expected it only with "
                              "--target-peak (an SRS design runs on this machine)")
    if request.target_duration:
        raise OptionError("--target-duration: found with --target-srs, expected one target: "
                          "the spectrum, or a peak and a duration")
    if len(request.vary) > 1:
        raise OptionError("--vary: found two parameters, expected one with --target-srs")
    var = variable((request.vary or (address("v31"),))[0])
    # the SRS's quality factor (default 10) [-], by the grammar every command reads it with
    q = 10.0 if request.spec.srs_q is None else parse_q(request.spec.srs_q, "--srs-q")
    bounds = _range(request.range) if request.range else None
    assert request.target_srs is not None
    frequencies, required = read_spectrum(request.target_srs, request.spec.accel_unit)
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    started = time.perf_counter()
    design = solve_srs(shot.params, frequencies, required, var, q, request.integrator,
                       request.model, bounds)
    lines = [f"{_label(var)} = {design.values[0]:.6g} {var.unit}",
             f"  its SRS (Q = {q:g}) envelops the {len(frequencies)} required levels with a "
             f"least margin of {design.margin:+.2%}, at {design.governing_hz:,.0f} Hz",
             f"  peak {design.peak_kg:.5f} kG, pulse {design.duration * 1e3:.4f} ms; "
             f"{design.evaluations} simulations in {time.perf_counter() - started:.2f} s"]
    return shot, design, lines, {"requirement": (frequencies, required, q)}


def _check_spec_options(request: DesignRequest) -> list[Any]:
    """The first-shot options, checked; the scatter's spreads."""
    from ..studies.sweep import parse_sds

    if request.confidence is not None and not 0 < request.confidence < 1:
        raise OptionError(f"--confidence: found {request.confidence!r}, expected a probability "
                          "between 0 and 1, such as 0.95")
    if request.confidence is not None and \
            not limits.MIN_DRAWS <= request.shots <= limits.MAX_DRAWS:
        raise OptionError(f"--shots: found {request.shots!r}, expected {limits.MIN_DRAWS} to "
                          f"{limits.MAX_DRAWS:,}")
    sds: list[Any] = parse_sds(list(request.sd))
    if request.confidence is not None and not sds:
        raise OptionError("--confidence: found no --sd, expected the scatter to design "
                          "against (--sd A28=1.5% --sd E40=5%)")
    if request.confidence is None and sds:
        raise OptionError("--sd: found without --confidence, expected both")
    if not 0 <= request.seed <= limits.MAX_SEED:
        raise OptionError(f"--seed: found {request.seed}, expected a whole number from 0 to "
                          "2**128 - 1")
    return sds


def _solve_spec(request: DesignRequest, shots_progress_for: Callable[[int], Any] | None = None
                ) -> tuple[Shot, Design, list[str], dict[str, Any]]:
    """By the specification: the middle of its tolerances, or with ``confidence`` the
    setting most likely to pass on the first shot."""
    from ..archive.laws import shot_with_law
    from ..studies.design import Design, variable
    from ..studies.first_shot import p_pass_text, reaches, solve_confidence, solve_middle
    from ..transaction import check_output

    if len(request.vary) > 1:
        raise OptionError("--vary: found two parameters, expected one for a design by the "
                          "specification")
    var = variable((request.vary or (address("v31"),))[0])
    bounds = _range(request.range) if request.range else None
    sds = _check_spec_options(request)
    if request.output is not None:  # before the study
        check_output(request.output, request.force, inputs=[request.shot])
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    spec = resolve(shot, request.spec)
    if spec is None:
        raise OptionError("design: found no target and an empty specification, expected "
                          "--target-peak, --target-srs, or the specification's fields (the "
                          "Specification sheet, --profile, --peak 12kG:10%...)")
    started = time.perf_counter()
    label = _label(var)
    extra: list[str] = []  # warnings
    notes: list[str] = []  # the study's figures, for the Summary
    lines: list[str] = []
    reached, confidence = True, None
    with cluster_runner(request.scheduler, request.workers, request.chunk) as runner:
        if request.confidence is None:
            middle = solve_middle(shot.params, spec, var, bounds, request.integrator,
                                  request.model, runner)
            value, evaluations = middle.value, middle.evaluations
            lines.append(f"{label} = {value:.6g} {var.unit}: the prediction's smallest margin "
                         f"is {middle.margin:+.2%} of its nominal (the middle of the "
                         "tolerances)")
            if middle.margin < 0:
                extra.append(f"design: no {var.label} in range makes the prediction pass; the "
                             f"best misses by {-middle.margin:.2%} of a nominal")
                reached = False
            notes_after = [f"design by the specification: {label} = {value:.6g} {var.unit}, "
                           f"the largest smallest margin ({middle.margin:+.2%} of a nominal)"]
        else:
            from .lot_chain import model_error_of

            model_error = model_error_of(request.archive)
            with shots_progress(shots_progress_for, _most_shots(request.shots)) as progress:
                c = confidence = solve_confidence(shot.params, spec, var, sds,
                                                  request.shots, request.seed, bounds,
                                                  request.integrator, request.model, runner,
                                                  progress, model_error=model_error)
            value, evaluations = c.best.setting, sum(r.shots for r in c.tried)
            worst = c.best.most_failing()
            lines.append(f"{label} = {value:.6g} {var.unit}: {p_pass_text(c.best)}, "
                         f"{c.shots:,} shots")
            lines.append(f"  the middle design, {label} = {c.middle.setting:.6g} {var.unit}: "
                         f"{p_pass_text(c.middle)}")
            if worst is not None:
                lines.append(f"  most likely to fail: {worst[0]} ({worst[1]:,} of "
                             f"{c.shots:,} shots)")
            lines.append(f"  P(PASS) includes {model_error.words()}")
            lines.append(f"  {model_error.bound_words()}")
            scatter = ", ".join(request.sd)
            notes += [f"design --confidence {request.confidence:g}: {p_pass_text(c.best)} at "
                      f"{label} = {value:.6g} {var.unit}, over {c.shots:,} shots with "
                      f"{scatter}, seed {request.seed}; most likely to fail: "
                      f"{worst[0] if worst else 'none'}",
                      f"the middle design, {label} = {c.middle.setting:.6g} {var.unit}: "
                      f"{p_pass_text(c.middle)}",
                      f"P(PASS) includes {model_error.words()}; {model_error.bound_words()}"]
            extra += c.warnings
            if not reaches(c.best, request.confidence):
                extra.append(f"design --confidence: no {var.label} in range reaches "
                             f"P(PASS) = {request.confidence:g}; the best found is "
                             f"{p_pass_text(c.best)} at {value:.6g} {var.unit}")
                reached = False
            notes_after = []
    solved = var.apply(shot.params, value)
    design = Design([var], [value], solved, math.nan, math.nan, evaluations, extra)
    lines.append(f"  {evaluations:,} simulations in {time.perf_counter() - started:.2f} s")
    return shot, design, lines, {"spec": spec, "notes": tuple(notes + notes_after),
                                 "reached": reached, "confidence": confidence}


def _most_shots(n: int) -> int:
    """The most shots the first-shot study runs for ``n`` a setting: every candidate's first
    round and the finalists' full one."""
    from ..studies.first_shot import CANDIDATES, FINALISTS, FIRST_ROUND

    return (CANDIDATES + 1) * max(200, int(round(n * FIRST_ROUND))) + (FINALISTS + 1) * n


def _fill(request: DesignRequest, mode: str, shot: Shot, design: Design, lines: list[str],
          extra: dict[str, Any], warn: Say | None, note: Say | None,
          progress_for: Callable[[int], Any] | None) -> DesignOutcome:
    """The designed shot, filled into ``request.output`` (if given)."""
    from ..outputs import from_sheet
    from .fill import Options, fill_workbook

    designed = with_cells(shot, design)  # its warnings go with the designed shot's figures
    designed = dataclasses.replace(designed, warnings=list(designed.warnings)
                                   + [w for w in design.warnings if w not in designed.warnings])
    filled, said = None, []
    if request.output is not None:
        spec: Specification | None = extra.get("spec")
        options = Options(request.integrator, "excel", request.model, False, request.force,
                          command=request.argv, srs_requirement=extra.get("requirement"),
                          spec=spec, study_notes=extra.get("notes", ()), pdf=request.pdf)

        def warned(messages: list[str]) -> None:
            said.extend(messages)
            if warn is not None:
                warn(messages)

        progress = progress_for(designed.params.rows) if progress_for is not None else None
        try:
            filled = fill_workbook(designed, request.output, from_sheet(
                shot.source.outputs_block), options, warned, None, note, progress)
        finally:
            close = getattr(progress, "close", None)
            if close is not None:
                close()
    warnings = tuple(dict.fromkeys([*said, *map(str, designed.warnings)]))
    files = tuple(p for p in (request.output, request.pdf if filled is not None else None)
                  if p is not None)
    return DesignOutcome(mode, design, designed, bool(extra.get("reached", True)),
                         tuple(lines), filled, request.output, files, warnings,
                         extra.get("confidence"))


def with_cells(shot: Shot, design: Design) -> Shot:
    """The shot with the solved values in their cells (as constants) and in its parameters."""
    from openpyxl.utils.cell import coordinate_to_tuple

    from ..params import ShotParams

    assert isinstance(design.params, ShotParams)
    block = dict(shot.source.block)
    for var, value in zip(design.variables, design.values, strict=True):
        for cell in var.cells:
            block[coordinate_to_tuple(cell)] = (float(value), None)
    source = dataclasses.replace(shot.source, block=block)
    return dataclasses.replace(shot, params=design.params, source=source)
