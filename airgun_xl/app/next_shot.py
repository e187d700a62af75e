"""``next``: the closed loop (issue 45). A fired shot of a honeycomb lot is judged, the lot's
law is updated by every shot of the lot, and the next shot's setting is chosen for the
highest P(PASS) on what the lot is now known to be; the next shot's workbook is written, and
the verdict, the law's new version and the proposal are kept in the archive.

Everything that can be refused is refused before anything is written or recorded: the
options, the lot (unknown without ``new_lot``), the specification (it needs tolerances), the
gun's scatter, the lot's earlier shots (each file unchanged since it was recorded), the
recording and the output.

The law's update is :func:`~airgun_xl.studies.closed_loop.update_law`'s: its scale (what one
shot, or shots at one speed, pins), its tilt once the shots spread over speed, and the law
fitted whole where such shots show a shape the scale and tilt cannot follow. The gun's
scatter is the one given (``--sd A28=...``) until the lot has
:data:`~airgun_xl.studies.closed_loop.GUN_SHOTS` shots; from then on each shot's launch
velocity is fitted with the scale and the scatter is estimated from them (its source said
with every P(PASS)). With ``gun``, the launch velocities are fitted from the lot's first shot
and kept in its proposal, and the scatter is pooled over every lot of that gun in the
archive (:func:`~airgun_xl.studies.closed_loop.pooled_scatter`). ``vary`` names a second knob
set with the velocity (E13 or E16, for the duration; a lot stronger or weaker than the law
the shot was designed on cannot meet both a peak and a duration by the velocity alone).
"""
from __future__ import annotations

import dataclasses
import datetime
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import limits
from ..cells import address
from ..errors import ArchiveError, OptionError
from ..transaction.stages import stage
from .lot_chain import (
    FIGURE_UNITS,
    chain,
    expected_text,
    knobs_text,
    measured_text,
    model_error_of,
)
from .specifying import SpecFields, require, resolve

if TYPE_CHECKING:
    from ..shot import Shot
    from ..studies.acceptance import Verdict
    from ..studies.closed_loop import LawUpdate
    from ..studies.first_shot import PassProbability


@dataclass(frozen=True)
class NextRequest:
    """The fired shot and its recording, the lot and its archive, the specification's
    fields (over the shot's sheet and ``profile``), the gun's and zeta's scatter (``sd``:
    ``A28=1.5%``, ``E43=10%``), the confidence asked, the Monte Carlo's size and seed, how the
    recording is read, and where the next shot's workbook goes."""

    shot: Path
    recording: str
    archive: Path
    lot: str
    spec: SpecFields = field(default_factory=SpecFields)
    new_lot: bool = False
    sd: tuple[str, ...] = ()
    confidence: float = 0.9
    shots: int = 2000
    seed: int = 1
    channel: str | None = None
    sign: float = 1.0
    time_unit: str | None = None
    accel_unit: str | None = None
    integrator: str = "legacy"
    output: Path | None = None  # default SHOT.next.xlsx beside the shot
    force: bool = False
    argv: tuple[str, ...] = ()
    vary: str | None = None  # a second knob set with A28 (E13, E16 or A2)
    scheduler: str | None = None  # the draws on a Dask cluster (its scheduler's address)
    workers: int | None = None  # or on a local one of this many processes
    chunk: int | None = None  # shots a cluster task
    pdf: Path | None = None  # the next shot's report as a PDF too
    gun: str | None = None  # the gun's name: its scatter pooled over the lots it fired
    step: tuple[str, ...] = ()  # what the knobs can be set to: A28=0.5 (m/s), E13=...
    event: int | None = None  # of a recording of several shocks, the one judged (from 1)
    at: float | None = None  # [s] or the one at this instant of the recording


#: The second knobs ``next --vary`` takes: the mitigator's geometry and the exchange mass
#: (A28 is always set; E40 is the lot's strength, the law's, not a setting).
SECOND_KNOBS = (address("rcone"), address("hcone"), address("m1"))


@dataclass(frozen=True)
class NextOutcome:
    """The fired shot's verdict, the law's update and its new version, the setting chosen with
    its P(PASS), whether it reaches the confidence asked, and every file and warning."""

    verdict: Verdict
    update: LawUpdate
    law: str  # the law's new version, NAME@N
    setting: float  # [m/s] A28..A30 of the next shot
    best: PassProbability
    confidence: float
    reached: bool
    counted_once: bool  # this shot was recorded in the lot before
    output: Path
    proposal: str  # the proposal's version, LOT@N
    files: tuple[Path, ...]
    warnings: tuple[str, ...]
    second: tuple[str, str, float] | None = None  # (cell, unit, value) set with A28 (vary)
    gun: str = ""  # the gun's scatter drawn, and where it came from
    #: with ``step``: the best found between the steps (``best`` is the best on them)
    unrounded: PassProbability | None = None
    #: the model's own error drawn, and where it came from (issue 60)
    model_error: str = ""

    def to_json(self) -> str:
        """``next --json``: the verdict, the law's update, the setting and its P(PASS)."""
        from ..studies.first_shot import supported
        from .documents import dumps

        lo, hi = self.best.interval
        worst = self.best.most_failing()
        return dumps({
            "verdict": self.verdict.word,
            "criteria": [dataclasses.asdict(c) for c in self.verdict.criteria],
            "law": {"version": self.law, "scale": self.update.scale,
                    "scale_standard_error": self.update.error, "shots": self.update.shots,
                    **({"tilt": self.update.tilt,
                        "tilt_standard_error": self.update.tilt_error,
                        "tilt_about_m_s": self.update.v_ref} if self.update.tilted else {}),
                    **(_whole_record(self.update) if self.update.shape else {}),
                    "note": self.update.note},
            "next": {"A28_m_s": self.setting,
                     **({f"{self.second[0]}_{self.second[1]}": self.second[2]}
                        if self.second else {}),
                     "p_pass": self.best.probability,
                     "p_pass_supported": supported(self.best),
                     "interval": [lo, hi], "draws": self.best.shots,
                     "most_likely_to_fail": worst[0] if worst else None,
                     "expected": expected_record(self.best),
                     **({"unrounded": unrounded_record(self.unrounded, self.second)}
                        if self.unrounded is not None else {})},
            "gun": self.gun, "model_error": self.model_error,
            "confidence": self.confidence, "reached": self.reached,
            "proposal": self.proposal, "files": self.files, "warnings": self.warnings})


def _whole_record(update: LawUpdate) -> dict[str, Any]:
    """The law fitted whole and the test of the scale and tilt against it (``--json`` and the
    proposal): whether it is the update's, the chi-square, its p, and its nodes' intervals."""
    assert update.shape is not None
    chi, dof, p = update.shape
    return {"whole": update.is_whole, "shape_chi2": chi if math.isfinite(chi) else None,
            "shape_dof": dof, "shape_p": p if math.isfinite(p) else None,
            "whole_nodes": [n.record() for n in update.nodes]}


def unrounded_record(unrounded: PassProbability,
                     second: tuple[str, str, float] | None) -> dict[str, Any]:
    """The best found between the knobs' steps (``--json`` and the proposal)."""
    return {"A28_m_s": unrounded.setting,
            **({f"{second[0]}_{second[1]}": unrounded.second} if second else {}),
            "p_pass": unrounded.probability}


#: The finest ``--step`` taken, in the knob's unit (SI: 1 nm of a radius, 1 nm/s of A28):
#: below it a step is no setting a knob has, and the grid's count would overflow.
STEP_FLOOR = 1e-9


def steps_of(request: NextRequest, p: Any = None) -> tuple[float | None, ...] | None:
    """``--step``: what A28 and the ``--vary`` knob can be set to, each a step in its unit
    (None: any value); None without ``--step``. One line for a step that is not a positive
    number, a cell that is neither, a cell given twice, or (with the shot's parameters
    ``p``) a step with no multiple in the range its knob is searched over."""
    import re

    from ..studies.design import variable

    if not request.step:
        return None
    knobs = [address("v31")] + ([second_knob(request.vary).cell] if request.vary else [])
    steps: list[float | None] = [None] * len(knobs)
    for text in request.step:
        match = re.fullmatch(r"\s*([A-Za-z]+[0-9]+)\s*=\s*([0-9.eE+-]+)\s*", str(text))
        value = math.nan
        if match is not None:
            try:
                value = float(match.group(2))
            except ValueError:
                pass
        cell = match.group(1).upper() if match is not None else ""
        if cell in (address("v32"), address("v33")):
            cell = address("v31")
        if not (math.isfinite(value) and value >= STEP_FLOOR) or cell not in knobs:
            raise OptionError(f"--step: found {text!r}, expected CELL=STEP with CELL one of "
                              f"{', '.join(knobs)} (A28, and the --vary knob) and STEP a "
                              f"number of at least {STEP_FLOOR:g} in its unit, such as "
                              "A28=0.5 (m/s)")
        k = knobs.index(cell)
        if steps[k] is not None:
            raise OptionError(f"--step: found {cell} twice, expected one step a knob")
        steps[k] = value
        if p is not None:
            lo, hi = variable(cell).bounds(p)
            if not math.ceil(lo / value) * value <= hi:
                raise OptionError(f"--step: found {text!r}, which has no multiple in the range "
                                  f"{cell} is searched over ({lo:.6g} to {hi:.6g} "
                                  f"{variable(cell).unit}); expected a step it can be set to "
                                  "within it")
    return tuple(steps)


def rounded_text(request: NextRequest, unrounded: PassProbability) -> str:
    """What ``--step`` did to the setting: the steps, and the best found between them."""
    return (f"set to the knobs' steps ({', '.join(request.step)}): the best between them, "
            f"{setting_text(request, unrounded)}, had P(PASS) = "
            f"{unrounded.probability:.4f} on the same draws")


def default_output(shot: Path) -> Path:
    return shot.with_name(shot.stem + ".next.xlsx")


def run(request: NextRequest) -> NextOutcome:
    """Judge, update, choose, write and record (see the module).

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written or recorded.
    """
    from ..readers.recording import input_file
    from ..shot import Shot
    from ..studies.closed_loop import GUN_SHOTS, law_scatter, update_law
    from ..studies.first_shot import p_pass_text, reaches

    output = _checked(request)
    shot = Shot.from_workbook(request.shot)
    spec = require(resolve(shot, request.spec), request.shot)
    _tolerances(spec)
    steps_of(request, shot.params)
    prior, earlier, proposal = _lot(request)
    this = {"shot": str(request.shot), "shot_sha256": _sha256(request.shot, "workbook"),
            "recording": str(request.recording),
            "recording_sha256": _sha256(input_file(request.recording), "recording"),
            **_reading(request)}
    counted_once = any(_same_shot(s, this) for s in earlier)
    lot_shots = earlier if counted_once else [*earlier, this]
    others, read_warnings = _gun_lots(request, lot_shots)
    freedom = sum(len(launch) - 1 for _lot, launch in others) + len(lot_shots) - 1
    estimated = freedom >= GUN_SHOTS - 1 if request.gun is not None else \
        len(lot_shots) >= GUN_SHOTS
    sds = _scatter(request, estimated)
    verdict = _judge(request, spec)
    params, traces = _read_lot(lot_shots)
    update = update_law(params, traces, prior, spec.judged.cfc, request.integrator,
                        velocities=estimated or request.gun is not None)
    _described(request, update, lot_shots)
    sds, gun, gun_warnings, offset = _gun(request, update, sds, len(lot_shots),
                                          shot.params.v31, others, freedom)
    gun_warnings = [*read_warnings, *gun_warnings]
    p_next = shot.params.replace(crush_law=update.law)
    model_error = model_error_of(request.archive)
    drawn = f"{model_error.words()}; {model_error.bound_words()}"
    best, unrounded, conf_warnings = _choose(request, spec, p_next,
                                             [*sds, law_scatter(update)], model_error)
    reached = reaches(best, request.confidence)
    if offset is not None:
        gun += "; " + gun_setting_text(best.setting, offset)
    warnings = list(dict.fromkeys([*map(str, shot.warnings), *verdict.warnings,
                                   *update.warnings, *gun_warnings, *conf_warnings]))
    if not reached:
        worst = best.most_failing()
        knob = "" if request.vary is not None else (
            f"; A28 alone moves the peak and the duration together: a second knob set with it "
            f"(--vary {' or '.join(SECOND_KNOBS)}, the mitigator's) can move "
            f"the {worst[0] if worst else 'duration'} apart from the peak")
        warnings.append(f"next: no A28{f' and {request.vary}' if request.vary else ''} in range"
                        f" reaches P(PASS) = {request.confidence:g}; the best found is "
                        f"{p_pass_text(best)} at {setting_text(request, best)}{knob}")
    return _publish(request, output, shot, spec, verdict, update, best, reached, lot_shots,
                    counted_once, warnings, gun, unrounded, proposal=proposal,
                    model_error=drawn)


def _described(request: NextRequest, update: LawUpdate,
               lot_shots: list[dict[str, Any]]) -> None:
    """Refuse, before anything is written, a lot's law fitted on a recording the model does
    not describe (the fit still misses it by over calibrate.POOR_FIT RMS of its peak: noise,
    a wrong unit, channel or sign) or one no honeycomb of the report's kind has
    (closed_loop.LOT_LAW_RATIO): the tool says so, so it does not store it."""
    from ..errors import WorkbookError
    from ..studies.calibrate import POOR_FIT
    from ..studies.closed_loop import implausible

    misses = [(after.rms, s["recording"]) for s, after in
              zip(lot_shots, update.calibration.after, strict=True)]
    rms, worst = max(misses)
    if rms > POOR_FIT:
        which = "it" if worst == str(request.recording) else f"the lot's {worst}"
        raise WorkbookError(f"{request.recording}: the lot's law fitted to the lot's "
                            f"recordings with it still misses {which} by {rms:.1%} RMS of its "
                            f"peak (over {POOR_FIT:.0%}), expected a recording of the shot "
                            "that the model describes (check its units, channel and sign): "
                            "the lot's law is not updated from it")
    why = implausible(update.law)
    if why:
        raise WorkbookError(f"{request.recording}: the lot's law fitted to the lot's "
                            f"recordings with it would be {why}, expected a recording of the "
                            "shot (check its units, channel and sign): the lot's law is not "
                            "updated from it")


def _checked(request: NextRequest) -> Path:
    """The options refused before any work; the output's path."""
    from ..archive import Archive
    from ..archive.store import safe_name
    from ..readers.recording import input_file
    from ..transaction import check_output

    if request.sign not in (1.0, -1.0):
        raise OptionError(f"--sign: found {request.sign!r}, expected 1 or -1")
    if not 0 < request.confidence < 1:
        raise OptionError(f"--confidence: found {request.confidence!r}, expected a probability "
                          "above 0 and below 1, such as 0.9")
    if not limits.MIN_DRAWS <= request.shots <= limits.MAX_DRAWS:
        raise OptionError(f"--shots: found {request.shots}, expected {limits.MIN_DRAWS} to "
                          f"{limits.MAX_DRAWS:,} Monte Carlo shots a setting")
    if not 0 <= request.seed <= limits.MAX_SEED:
        raise OptionError(f"--seed: found {request.seed}, expected a whole number from 0 to "
                          "2**128 - 1")
    if not request.lot or safe_name(request.lot) != request.lot:
        raise OptionError(f"--lot: found {request.lot!r}, expected a lot name of letters, "
                          "digits, '-', '_' and '.' (such as LOT-2026-07)")
    if request.gun is not None and (not request.gun or safe_name(request.gun) != request.gun):
        raise OptionError(f"--gun: found {request.gun!r}, expected a gun's name of letters, "
                          "digits, '-', '_' and '.' (such as GUN-4IN)")
    if request.vary is not None:
        second_knob(request.vary)
    steps_of(request)
    from .running import check_cluster

    check_cluster(request.scheduler, request.workers, request.chunk)  # before the law's fit
    output = request.output if request.output is not None else default_output(request.shot)
    check_output(output, request.force, inputs=[request.shot, input_file(request.recording)])
    if request.pdf is not None:
        from ..reports.pdf_report import check_pdf

        check_pdf(request.pdf, request.force, [request.shot, input_file(request.recording)],
                  beside=output)
    Archive(request.archive, create=True, dry_run=True)  # a folder that is not one: refused
    return output


def second_knob(name: str) -> Any:
    """The design variable ``--vary`` names (one of :data:`SECOND_KNOBS`), or one line."""
    from ..studies.design import variable

    var = variable(name)
    if var.cell not in SECOND_KNOBS:
        raise OptionError(f"--vary: found {name!r}, expected a second knob set with A28: "
                          f"{', '.join(SECOND_KNOBS)} (A28 is always set; E40 is the lot's "
                          "strength, which the law's update gives)")
    return var


def setting_text(request: NextRequest, best: PassProbability) -> str:
    """The setting chosen, as a person sets it: A28 (and the second knob)."""
    text = f"A28 = {best.setting:.6g} m/s"
    if request.vary is not None:
        var = second_knob(request.vary)
        text += f", {var.cell} = {best.second:.6g} {var.unit}"
    return text


def _tolerances(spec: Any) -> None:
    """A specification the loop can aim at: a peak or a duration with a tolerance."""
    judged = [f for f in (spec.peak, spec.duration) if f is not None]
    if not judged:
        raise OptionError("next: found a specification without a peak or a duration, "
                          "expected --peak and/or --duration with their tolerances (the loop "
                          "aims A28 at them)")


def _scatter(request: NextRequest, estimated: bool) -> list[Any]:
    """The gun's scatter and zeta's, as given; the gun's is needed until the lot's shots
    estimate it (``estimated``)."""
    from ..studies.closed_loop import GUN_SHOTS
    from ..studies.sweep import parse_sds

    sds = parse_sds(request.sd)
    if not estimated and not any(cell == address("v31") for cell, *_ in sds):
        until = (f"lot has {GUN_SHOTS} shots to estimate it from" if request.gun is None else
                 f"lots of the gun {request.gun} hold {GUN_SHOTS - 1} shots beyond each "
                 "lot's first to estimate it from")
        raise OptionError("--sd: found no A28 scatter, expected the gun's shot-to-shot "
                          "scatter such as --sd A28=1.5% (and E43=10% for zeta's) until the "
                          + until)
    if any(cell == address("sigmay") for cell, *_ in sds):
        raise OptionError("--sd: found E40, expected the gun's (A28) and zeta's (E43) only: "
                          "the lot's crush strength is the law's, drawn from its update")
    return list(sds)


def gun_setting_text(setting: float, offset: float) -> str:
    """What to set the gun to so that it fires ``setting`` [m/s], its launch velocities
    ``offset`` [-] off the values set on average (the estimate's error is drawn)."""
    return (f"to fire {setting:.2f} m/s, set the gun to {setting / (1 + offset):.2f} m/s "
            f"(its mean offset {offset:+.2%} taken out)")


def _gun(request: NextRequest, update: LawUpdate, sds: list[Any], shots: int,
         velocity: float, others: list[tuple[str, tuple[tuple[float, float, float], ...]]],
         freedom: int) -> tuple[list[Any], str, list[str], float | None]:
    """The gun's scatter drawn: estimated from the lot's launch velocities once it has
    :data:`~airgun_xl.studies.closed_loop.GUN_SHOTS` shots (with ``--gun``, from the launch
    velocities of every lot of that gun, ``others`` and this one, once they hold one degree
    of freedom less), else the one given; with the words saying which, a warning when the
    given one lies outside the estimate's 95 % interval, and the gun's mean offset (None
    while the scatter is the one given).

    Once estimated, the launch velocities are fitted and the lot's law no longer absorbs the
    gun's mean offset from the values set: the setting proposed is the velocity to fire
    (the next workbook's A28, what ``fill`` predicts), the gun set to it divided by (1 +
    the offset), and the offset's own standard error drawn with the scatter (a shot fired
    ``(1 + e)(1 + s)`` off the velocity meant, to first order one normal of
    hypot(scatter, error))."""
    from ..studies.closed_loop import GUN_SHOTS, gun_scatter, pooled_scatter

    given = next((sd for sd in sds if sd[0] == address("v31")), None)
    shown = "" if given is None else (f"{given[0]}={given[2] * 100:g}%" if given[3]
                                      else f"{given[0]}={given[2]:g}")
    if request.gun is None:
        found = gun_scatter(update)
    else:
        found = pooled_scatter([*others, (request.lot, update.launch)], request.gun)
    if found is None and given is None:  # counted enough shots, but their fit gave fewer
        raise OptionError("--sd: found no A28 scatter, and the launch velocities fitted give "
                          "no estimate of the gun's (fewer than the shots counted), expected "
                          "--sd A28=... such as A28=1.5%")
    if found is None:
        assert given is not None  # for mypy: refused just above
        if request.gun is None:
            why = (f"the lot has {shots} shot{'s' * (shots > 1)}, and it is estimated from "
                   f"the shots' launch velocities from {GUN_SHOTS}")
        else:
            why = (f"the lots of the gun {request.gun} hold {max(freedom, 0)} shot"
                   f"{'s' * (freedom != 1)} beyond each lot's first, and it is estimated "
                   f"from their launch velocities from {GUN_SHOTS - 1}")
        return sds, f"the gun's scatter {shown} as given (--sd): {why}", [], None
    rest = [sd for sd in sds if sd[0] != address("v31")]
    cell, fields, _sd, _rel = given if given is not None else (
        address("v31"), ("v31", "v32", "v33"), 0.0, True)
    drawn = math.hypot(found.sd, found.bias_error)
    words = (f"{found.words()}; drawn {drawn:.2%} (the scatter with the error of the mean "
             "offset the setting is corrected by)")
    warnings = list(found.warnings)
    if given is not None:
        value = given[2] if given[3] else given[2] / abs(velocity)  # relative to the set A28
        words += f"; the {shown} given is not used"
        lo, hi = found.interval
        if not lo <= value <= hi:
            warnings.append(f"--sd {shown}: the gun's scatter given lies outside the "
                            f"95 % interval estimated from the {'gun' if request.gun else 'lot'}"
                            f"'s shots ({lo:.2%}-{hi:.2%}); the estimate, {found.sd:.2%}, is "
                            "drawn")
    return [*rest, (cell, fields, drawn, True)], words, warnings, found.bias


def _gun_lots(request: NextRequest, lot_shots: list[dict[str, Any]]
              ) -> tuple[list[tuple[str, tuple[tuple[float, float, float], ...]]], list[str]]:
    """With ``--gun``: every other lot's launch velocities fitted for that gun (its latest
    proposal naming it), read back from the archive (untrusted: each entry checked, a shot of
    this lot left out, a lot whose records cannot be read left out with a warning)."""
    if request.gun is None:
        return [], []
    from ..archive.lots import gun_launches, lot_names
    from ..errors import ArchiveError
    from ..studies.calibrate import VELOCITY_REACH

    mine = {(s["shot_sha256"], s["recording_sha256"]) for s in lot_shots}
    seen = set(mine)
    found, warnings = [], []
    for lot in lot_names(request.archive):
        if lot == request.lot:
            continue
        try:
            launch = gun_launches(request.archive, lot, request.gun)
        except ArchiveError as error:
            warnings.append(f"the gun's scatter: the lot {lot} is left out: {error}")
            continue
        wild = [e["factor"] for e in launch if not abs(e["factor"] - 1) <= VELOCITY_REACH]
        if wild:
            warnings.append(f"the gun's scatter: the lot {lot} is left out: its record holds "
                            f"a launch velocity factor of {wild[0]:.6g}, expected within 1 "
                            f"+/- {VELOCITY_REACH:g} (the fit's bound)")
            continue
        kept = []
        for entry in launch:
            key = (entry["shot_sha256"], entry["recording_sha256"])
            if key not in seen:  # a shot recorded in two lots counts once
                seen.add(key)
                kept.append((entry["speed_m_s"], entry["factor"], entry["error"]))
        if len(kept) >= 2:
            found.append((lot, tuple(kept)))
    return found, warnings


def _lot(request: NextRequest) -> tuple[Any, list[dict[str, Any]], int]:
    """The lot's prior law (its latest version the archive holds, or the report's law for a
    new lot), its shots so far (each file checked unchanged) and the version its next
    proposal must take (the one after the chain read: the call's commit point, refused if
    another call takes it first)."""
    from ..archive.laws import load_law
    from ..archive.lots import proposals, shot_keys
    from ..crush_law import LEGACY_LAW
    from ..errors import AirgunXlError
    from ..studies.closed_loop import implausible

    chain = proposals(request.archive, request.lot)
    proposal = (chain[-1][0] if chain else 0) + 1
    try:
        prior, _record = load_law(request.archive, request.lot)
    except OptionError:  # no law of that name (a law of a next that did not finish is none)
        prior = None
    if prior is None and not chain:
        if not request.new_lot:
            raise OptionError(f"--lot: found {request.lot!r}, which the archive "
                              f"{request.archive} does not know, expected a lot it holds or "
                              "--new-lot to start one from the report's law")
        return LEGACY_LAW, [], proposal
    if request.new_lot:
        raise OptionError(f"--new-lot: found the lot {request.lot!r} in the archive already, "
                          "expected a new lot's name (or no --new-lot to go on with it)")
    if prior is None:
        raise ArchiveError(f"--lot: the lot {request.lot!r} has proposals but the archive "
                           "holds no law of it, expected its law versions (see airgun-xl "
                           "archive verify)")
    why = implausible(prior)
    if why:
        raise ArchiveError(f"{prior.source}: the lot's law is {why} (a record edited or "
                           "damaged; see airgun-xl archive verify)")
    earlier = list(chain[-1][1]["shots"]) if chain else []
    if chain:
        shot_keys(chain[-1][1], request.archive, request.lot, chain[-1][0])
    for s in earlier:
        for key, what in (("shot", "workbook"), ("recording", "recording")):
            try:
                path = s[key] if key == "shot" else _recording_file(s[key])
                same = _sha256(path, what) == s[f"{key}_sha256"]
            except (AirgunXlError, KeyError, TypeError):  # gone, not a file, too large
                same = False
            if not same:
                raise ArchiveError(f"{s.get(key, '?')}: the lot {request.lot}'s {what} "
                                   "differs from the one recorded (or is gone), expected it "
                                   "unchanged: the lot's law is fitted on the shots as fired")
    return prior, earlier, proposal


def _sha256(path: str | Path, what: str) -> str:
    """The SHA-256 of a file the loop names (given, or read back from the archive's records:
    untrusted): a regular file, read without blocking and capped as every input is
    (:func:`airgun_xl.readers.guard.read_bytes`), or one line naming it."""
    import hashlib

    from ..readers.guard import read_bytes

    return hashlib.sha256(read_bytes(path, f"expected the {what} a lot's shot was fired with",
                                     what)).hexdigest()


def _recording_file(text: str) -> str:
    from ..readers.recording import input_file

    return str(input_file(text))


def _same_shot(one: dict[str, Any], other: dict[str, Any]) -> bool:
    """The same workbook and recording, and the same event of it (a session's recording
    holds several shots)."""
    return all(one.get(k) == other.get(k)
               for k in ("shot_sha256", "recording_sha256", "event", "at"))


def _reading(request: NextRequest) -> dict[str, Any]:
    return {"sign": request.sign, "time_unit": request.time_unit,
            "accel_unit": request.accel_unit, "channel": request.channel,
            "event": request.event, "at": request.at}


def _judge(request: NextRequest, spec: Any) -> Verdict:
    """The fired shot judged as ``accept`` judges it (nothing written)."""
    from .accept import AcceptRequest
    from .accept import run as accept

    outcome = accept(AcceptRequest(request.shot, request.recording, request.spec,
                                   channel=request.channel, sign=request.sign,
                                   time_unit=request.time_unit,
                                   accel_unit=request.accel_unit, argv=request.argv,
                                   event=request.event, at=request.at))
    return outcome.verdict


def _read_lot(lot_shots: list[dict[str, Any]]) -> tuple[list[Any], list[Any]]:
    """Each shot's parameters as set, and its recording as read."""
    from ..readers.recording import read_trace
    from ..shot import Shot

    params = [Shot.from_workbook(s["shot"]).params for s in lot_shots]
    traces = [read_trace(s["recording"], s.get("time_unit"), s.get("accel_unit"),
                         float(s.get("sign", 1.0)), s.get("channel"), s.get("event"),
                         s.get("at")) for s in lot_shots]
    return params, traces


def _choose(request: NextRequest, spec: Any, p: Any, sds: list[Any], model_error: Any
            ) -> tuple[PassProbability, PassProbability | None, list[str]]:
    """The A28 most likely to pass, drawing the gun, zeta, the law and the model's own error,
    each prediction judged on the specification's record, as the fired shot's recording was
    (on the batch lanes, or a Dask cluster: the same draws, the same shots, the same
    P(PASS)); with ``step``, the best the knobs can be set to, and the best found between
    their steps."""
    from ..studies.design import variable
    from ..studies.first_shot import solve_confidence
    from .running import cluster_runner

    second = second_knob(request.vary) if request.vary is not None else None
    with cluster_runner(request.scheduler, request.workers, request.chunk) as runner:
        found = solve_confidence(p, spec, variable(address("v31")), sds, request.shots,
                                 request.seed, integrator=request.integrator,
                                 runner=runner, second=second, keep_middle=False,
                                 steps=steps_of(request), model_error=model_error)
    return found.best, found.unrounded, list(found.warnings)


def _publish(request: NextRequest, output: Path, shot: Shot, spec: Any, verdict: Verdict,
             update: LawUpdate, best: PassProbability, reached: bool,
             lot_shots: list[dict[str, Any]], counted_once: bool,
             warnings: list[str], gun: str,
             unrounded: PassProbability | None = None, *, proposal: int,
             model_error: str = "") -> NextOutcome:
    """Store the law's new version, write the next shot's workbook, keep the verdict and the
    proposal (exactly version ``proposal``, the commit point: another call on the lot that
    stored it first refuses this one); a failure takes back what was done."""
    from ..archive import Archive
    from ..archive import sha256 as file_sha256  # the workbook just written: ours
    from ..archive.laws import LAWS, store_law
    from ..archive.lots import store_proposal
    from ..archive.records import VersionTaken
    from ..archive.verdicts import StoredVerdict, store_verdict
    from ..crush_law import CrushLaw
    from ..studies.closed_loop import against_report
    from ..transaction import signals_held

    done: list[Any] = []
    try:
        with signals_held():
            ref = store_law(request.archive, request.lot, update.law, lot_shots,
                            [{"shot": s["shot"]} for s in lot_shots], request.argv,
                            [n.record() for n in update.nodes] if update.is_whole else None,
                            proposal=proposal)
            version = int(ref.rpartition("@")[2])
            done.append(StoredVerdict(Path(request.archive) / LAWS / request.lot /
                                      f"v{version:04d}.json", Archive(request.archive)))
        stage("next-law-stored")
        law = CrushLaw(update.law.coefficients, update.law.v_range, "fitted", source=ref)
        _write(request, output, shot, spec, verdict, update, best, law, ref, warnings, gun,
               unrounded, model_error)
        done += [output] + ([request.pdf] if request.pdf is not None else [])
        with signals_held():
            done.append(store_verdict(request.archive, shot, verdict, request.recording,
                                      output, request.argv, lot=request.lot))
        stage("next-verdict-stored")
        lo, hi = best.interval
        worst = best.most_failing()
        record = {"lot": request.lot, "shot": str(request.shot),
                  "recording": str(request.recording), "verdict": verdict.word,
                  "law": ref, "scale": update.scale, "scale_error": update.error,
                  **({"tilt": update.tilt, "tilt_error": update.tilt_error,
                      "tilt_about": update.v_ref} if update.tilted else {}),
                  **(_whole_record(update) if update.shape else {}),
                  "setting_A28": best.setting,
                  **({"second_cell": request.vary and second_knob(request.vary).cell,
                      "second_value": best.second} if request.vary else {}),
                  "p_pass": best.probability,
                  "interval": [lo, hi], "draws": best.shots,
                  "expected": expected_record(best), "measured": measured_record(verdict),
                  "expected_model": expected_record(best, model=True),
                  "against_report": [v if math.isfinite(v) else None
                                     for v in against_report(update.law)],
                  "most_likely_to_fail": worst[0] if worst else None,
                  **({"step": list(request.step),
                      "unrounded": unrounded_record(unrounded, knob_value(request, unrounded))}
                     if unrounded is not None else {}),
                  "confidence": request.confidence, "reached": reached,
                  "sd": list(request.sd), "gun": gun, "model_error": model_error,
                  "seed": request.seed,
                  **({"gun_name": request.gun,
                      "launch": [{"shot_sha256": s["shot_sha256"],
                                  "recording_sha256": s["recording_sha256"],
                                  "speed_m_s": v, "factor": f,
                                  "error": e if math.isfinite(e) else None}
                                 for s, (v, f, e) in zip(lot_shots, update.launch,
                                                         strict=True)]}
                     if request.gun is not None else {}),
                  "next_workbook": str(output), "next_sha256": file_sha256(output),
                  "shots": lot_shots, "warnings": warnings,
                  "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
                  "command": list(request.argv)}
        try:
            stored = store_proposal(request.archive, request.lot, record, proposal)
        except VersionTaken:
            raise ArchiveError(f"--lot: another next stored the lot {request.lot}'s proposal "
                               f"{request.lot}@{proposal} while this one ran, expected one next "
                               "at a time on a lot: nothing of this call is kept, run it "
                               "again") from None
        done.append(stored)
        stage("next-proposal-stored")
    except BaseException:
        for thing in reversed(done):
            if isinstance(thing, Path):
                thing.unlink(missing_ok=True)
            else:
                thing.take_back()
        raise
    files = (output,) + ((request.pdf,) if request.pdf is not None else ())
    return NextOutcome(verdict, update, ref, best.setting, best, request.confidence, reached,
                       counted_once, output, f"{request.lot}@{proposal}", files,
                       tuple(warnings),
                       knob_value(request, best), gun, unrounded, model_error)


def knob_value(request: NextRequest, best: PassProbability) -> tuple[str, str, float] | None:
    """The ``--vary`` knob's (cell, unit, value) at ``best``; None without ``--vary``."""
    if request.vary is None:
        return None
    knob = second_knob(request.vary)
    return knob.cell, knob.unit, best.second


def _write(request: NextRequest, output: Path, shot: Shot, spec: Any, verdict: Verdict,
           update: LawUpdate, best: PassProbability, law: Any, ref: str,
           warnings: list[str], gun: str, unrounded: PassProbability | None = None,
           model_error: str = "") -> None:
    """The next shot's workbook: the chosen A28..A30, the lot's law (its Crush law sheet),
    and on its Summary the prediction of P(PASS) and where it came from."""
    from ..outputs import from_sheet
    from ..studies.design import Design, variable
    from .design import with_cells
    from .fill import Options, fill_workbook

    knobs, values = [variable(address("v31"))], [best.setting]
    if request.vary is not None:
        knobs.append(second_knob(request.vary))
        values.append(best.second)
    params = shot.params.replace(crush_law=law)
    for var, value in zip(knobs, values, strict=True):
        params = var.apply(params, value)
    designed = with_cells(shot, Design(knobs, values, params, math.nan, math.nan, best.shots))
    # what the loop said travels with the figures it qualifies (the Summary's P(PASS))
    designed = dataclasses.replace(designed, warnings=list(warnings))
    from ..studies.first_shot import p_pass_text

    worst = best.most_failing()
    notes = (f"next shot of lot {request.lot}: {setting_text(request, best)}, "
             f"{p_pass_text(best)}, {best.shots:,} draws of the gun "
             f"({', '.join(request.sd)}) and the law, seed {request.seed}",
             *([rounded_text(request, unrounded)] if unrounded is not None else []),
             *([f"expected there (median, 90 % of the draws): "
                f"{expected_text(expected_record(best))}"] if best.figures else []),
             gun, *([f"P(PASS) includes {model_error}"] if model_error else []),
             f"most likely to fail: {worst[0] if worst else 'none'}",
             f"the lot's law {ref}: {update_text(update)}; {against_report_text(update)}; "
             f"{update.note}",
             f"from {request.shot} ({verdict.word}), recording {request.recording}")
    assert designed.source is not None
    options = Options(request.integrator, force=request.force, command=request.argv,
                      spec=spec, study_notes=notes, pdf=request.pdf)
    said: list[str] = []
    fill_workbook(designed, output, from_sheet(designed.source.outputs_block), options,
                  said.extend)
    warnings.extend(w for w in said if w not in warnings)


def tilt_text(update: LawUpdate) -> str:
    """The law's tilt with speed, when the shots' speeds pinned one (else nothing)."""
    if not update.tilted:
        return ""
    return (f" and tilted by {update.tilt:+.4f} +/- {update.tilt_error:.4f} per "
            f"{update.v_ref:.4g} m/s")


def update_text(update: LawUpdate, errors: str = "") -> str:
    """What the law's update is: the prior scaled (and tilted), or the law fitted whole."""
    n = update.shots
    shots = f"on {n} shot{'s' * (n > 1)}"
    if update.is_whole:
        return f"the law fitted whole at its {len(update.nodes)} nodes {shots}"
    return (f"the prior scaled by {update.scale:.4f} +/- {update.error:.4f}{errors}"
            f"{tilt_text(update)} {shots}")


def expected_record(best: PassProbability, model: bool = False
                    ) -> dict[str, list[float | None]]:
    """The judged figures expected at the proposal, for its record and ``--json``:
    ``{criterion: [5th, 50th, 95th percentile]}`` in the judge's units (kG, s, m/s; a NaN
    null); with ``model``, the model's own before its error was drawn (what the archive's
    pair of the shot is taken against)."""
    figures = best.model_figures if model else best.figures
    return {name: [v if math.isfinite(v) else None for v in values]
            for name, values in figures.items()}


def measured_record(verdict: Verdict) -> dict[str, dict[str, Any]]:
    """The fired shot's judged figures beside what was expected of it: ``{criterion:
    {"value", "unit"}}`` (a value that could not be measured: null)."""
    return {c.name: {"value": c.value if math.isfinite(c.value) else None, "unit": c.unit}
            for c in verdict.criteria if c.name in FIGURE_UNITS}


def against_report_text(update: LawUpdate) -> str:
    """The lot's law against the report's, all its updates together (each update's scale is
    against the version before)."""
    from ..studies.closed_loop import against_report

    low, high = against_report(update.law)
    if not (math.isfinite(low) and math.isfinite(high)):
        return "the lot's law against the report's: not comparable (no common speed)"
    if abs(high - low) <= 5e-4 * abs(high):
        return f"the lot's law is x{0.5 * (low + high):.4f} the report's"
    return f"the lot's law is x{low:.4f} to x{high:.4f} the report's over its range"


def lines(request: NextRequest, outcome: NextOutcome) -> list[str]:
    """What ``next`` prints: the fired shot's verdict, the law's update, the next setting
    with its P(PASS), the files and the archive's records."""
    from .accept import verdict_lines

    u, b = outcome.update, outcome.best
    from ..studies.first_shot import p_pass_text
    worst = b.most_failing()
    said = verdict_lines(outcome.verdict, f"{request.recording} against {request.shot}")
    if outcome.counted_once:
        said.append("  this shot was recorded in the lot before: counted once")
    said += [f"lot {request.lot}: the law {outcome.law}, "
             f"{update_text(u, ' (1 standard error)')}", f"  {u.note}",
             f"  {against_report_text(u)}",
             f"next: {setting_text(request, b)}, {p_pass_text(b)}, over {b.shots:,} draws"
             + (f"; most likely to fail: {worst[0]}" if worst else ""),
             *([f"  {rounded_text(request, outcome.unrounded)}"]
               if outcome.unrounded is not None else []),
             *([f"  expected there (median, 90 % of the draws): "
                f"{expected_text(expected_record(b))}"] if b.figures else []),
             f"  {outcome.gun}",
             *([f"  P(PASS) includes {outcome.model_error}"] if outcome.model_error else []),
             f"  {'reaches' if outcome.reached else 'does NOT reach'} --confidence "
             f"{outcome.confidence:g}",
             f"wrote {outcome.output}; kept the verdict, the law {outcome.law} and the "
             f"proposal {outcome.proposal} in {request.archive}"]
    return said


def chain_lines(lot: str, rows: list[dict[str, Any]]) -> list[str]:
    """``history --lot``: a line a shot of the chain."""
    def p(value: Any) -> str:
        return f"{value:.3f}" if isinstance(value, (int, float)) else "n/a"

    lines = [f"lot {lot}: {'proposal':<16} {'verdict':<7} {'P before':>8}  {'law':<16} "
             f"{'next A28 m/s':>12} {'P(PASS)':>8}  shot"]
    for r in rows:
        nxt = r["next_A28"]
        lines.append(f"       {r['proposal']:<16} {r['verdict']!s:<7} "
                     f"{p(r['predicted_before']):>8}  {r['law']!s:<16} "
                     f"{nxt if not isinstance(nxt, (int, float)) else f'{nxt:.3f}':>12} "
                     f"{p(r['next_p_pass']):>8}  {r['shot']}")
        expected, measured = expected_text(r.get("expected_before")), \
            measured_text(r.get("measured"))
        if expected:
            lines.append(f"         expected of this shot: {expected}")
        if measured:
            lines.append(f"         measured: {measured}")
        ratio = r.get("against_report")
        if isinstance(ratio, list) and len(ratio) == 2 and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in ratio):
            lines.append(f"         the lot's law: x{ratio[0]:.4f} to x{ratio[1]:.4f} the "
                         "report's")
        if knobs_text(r):
            lines.append(f"         next: {knobs_text(r)}")
    return lines


@dataclass(frozen=True)
class PredictionRecord:
    """``history --calibration``: every shot fired from a proposal with its verdict, the
    P(PASS) predicted for it, the bands and the Brier score."""

    shots: tuple[dict[str, Any], ...]
    bands: tuple[Any, ...]  # studies.closed_loop.Band
    brier: float
    files: tuple[Path, ...]

    @property
    def not_judged(self) -> int:
        """Shots whose record could not show a criterion (NOT JUDGED): no outcome, left out
        of the bands and the score."""
        return sum(s["verdict"] not in ("PASS", "FAIL") for s in self.shots)

    def lines(self) -> list[str]:
        apart = (f" ({self.not_judged} NOT JUDGED, left out of the bands and the score)"
                 if self.not_judged else "")
        said = [f"{len(self.shots)} shots fired from next's proposals{apart}; Brier score "
                + (f"{self.brier:.4f}" if len(self.shots) > self.not_judged else "none yet")]
        for band in self.bands:
            if band.shots:
                lo, hi = band.interval
                said.append(f"  P(PASS) {band.low:.2f}-{band.high:.2f}: {band.shots} shots, "
                            f"mean predicted {band.mean_predicted:.3f}, passed "
                            f"{band.rate:.3f} [{lo:.3f}, {hi:.3f}]: "
                            + ("honest" if band.honest else "NOT honest" if band.shots >= 30
                               else "under 30 shots"))
        said += [f"wrote {f}" for f in self.files]
        return said

    def to_json(self) -> str:
        from .documents import dumps

        return dumps({"shots": self.shots, "brier": self.brier,
                      "not_judged": self.not_judged, "bands": [
            {"low": b.low, "high": b.high, "shots": b.shots, "passed": b.passed,
             "mean_predicted": b.mean_predicted, "interval": list(b.interval),
             "honest": b.honest} for b in self.bands], "files": self.files})


def prediction_record(root: str | Path | None, output: str | None = None,
                      force: bool = False) -> PredictionRecord:
    """Across the archive's lots, each P(PASS) predicted before a shot was fired against the
    shot's verdict; ``output`` also writes the record's workbook (a reliability chart)."""
    from ..archive import Archive, archive_dir
    from ..archive.lots import lot_names
    from ..studies.closed_loop import brier, outcomes, reliability
    from ..transaction import check_output, display

    if output is not None:
        check_output(output, force)
    found = Archive(archive_dir(root))
    shots = [{"lot": lot, "proposal": row["proposal"], "shot": row["shot"],
              "predicted": float(row["predicted_before"]), "verdict": row["verdict"]}
             for lot in lot_names(found.root) for row in chain(found.root, lot)
             if isinstance(row["predicted_before"], (int, float))]
    predicted, passed = outcomes(shots)  # a shot NOT JUDGED counted apart
    bands = reliability(predicted, passed)
    score = brier(predicted, passed)
    files: tuple[Path, ...] = ()
    if output is not None:
        from ..reports.reliability import write_reliability

        write_reliability(output, bands, score, shots, f"Predictions of {display(found.root)}: "
                          "P(PASS) before each shot against its verdict", force,
                          label=display(found.root.name))
        files = (Path(output),)
    return PredictionRecord(tuple(shots), tuple(bands), score, files)
