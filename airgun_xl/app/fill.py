"""``fill``: a shot run into a new workbook, from start to finish, shared by ``fill``,
``design`` and each shot of a campaign (:mod:`.campaign`).

Check, run, summarize, then publish the workbook, its sidecar and its archive entry as one
transaction (:class:`airgun_xl.transaction.Publication`): all of them, or none. What the run
says goes through ``warn`` and ``note`` callbacks and into the outcome.

- :class:`FillSettings`: what ``fill``'s options ask of every shot (pickled to a campaign's
  workers);
- :class:`FillRequest` -> :func:`run` -> :class:`FillOutcome`: one shot, as the command;
- :func:`fill_workbook`: the fill itself, on a loaded :class:`~airgun_xl.shot.Shot` with
  its :class:`Options` (``design`` fills its designed shot through it).
"""
from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..archive import Archive, archive_dir
from ..archive.entry import now, prepare_entry, shot_name
from ..archive.laws import shot_with_law
from ..engine.stability import CriticalStep
from ..engine.summary import PULSE_FRACTION, Summary, summarize
from ..errors import AirgunXlError, StabilityError
from ..limits import check_memory, fill_bytes
from ..models import apply_model
from ..outputs import Outputs, from_sheet
from ..provenance import Provenance
from ..reports.fill import render_workbook
from ..reports.sidecar import SIDECAR_SUFFIXES, render_history, sidecar_path
from ..specification import Specification, check, combine
from ..studies.check import after_run, before_run, quirk_fired, unloading_diverged
from ..transaction import (
    Publication,
    check_output,
    commit_after,
    display,
    for_file,
    signals_held,
)
from ..version import __version__
from ..xlsx.sheets import flagged_figures, variant_name
from .settings import FillSettings, output_of

if TYPE_CHECKING:
    from ..archive import Entry
    from ..result import Result
    from ..shot import Shot
    from ..studies.acceptance import Verdict

#: A callback told a list of messages (warnings, or notices such as a large run's memory).
Say = Callable[[list[str]], None]
#: A callback told each stage of the run as it starts ("running", "writing the workbook").
Stage = Callable[[str], None]


@dataclasses.dataclass(frozen=True)
class Options:
    """How :func:`fill_workbook` runs and writes a loaded shot."""

    integrator: str = "legacy"
    host: str = "excel"
    model: str = "4-mass"
    compare_models: bool = False
    force: bool = False
    allow_unstable: bool = False
    reproducible: bool = False
    track_all: bool = False  # record every step value (an archived run keeps them all)
    command: tuple[str, ...] = ()  # the command line, for provenance
    archive: ArchiveRequest | None = None  # also store the run as an archive entry
    force_word: str = "--force"  # how messages name `force`
    # (frequencies [Hz], levels [kG], Q): a design's SRS target, for the SRS sheets
    srs_requirement: tuple[Any, ...] | None = None
    spec: Specification | None = None  # judges the prediction (else the shot's sheet)
    study_notes: tuple[str, ...] = ()  # what the study behind the shot found (design)
    pdf: Path | None = None  # the shot's report as a PDF too (the Summary, the charts)


@dataclasses.dataclass(frozen=True)
class ArchiveRequest:
    root: Path
    name: str  # the shot's name in the archive (sanitized there)
    started_at: str  # ISO time the command started, for provenance


@dataclasses.dataclass(frozen=True)
class Filled:
    """A fill's figures and what it wrote."""

    result: Result
    summary: Summary | None
    stride: int
    sidecar: Path | None
    compared: Result | None = None  # the other model's (or unloading's) run, beside it
    entry: Entry | None = None  # the archive entry, when the run was archived
    verdict: Verdict | None = None  # the predicted verdict, when there is a specification
    warnings: tuple[str, ...] = ()  # all the run said, in order


#: What a refused or stopped unstable run can do instead.
WAY_OUT = "expected a smaller E2, --integrator newmark, or --allow-unstable"

#: The way out of an unloading spring that diverges (Newmark treats it explicitly too).
UNLOADING_WAY_OUT = "expected a smaller E2, or --allow-unstable"

#: Runs that need more memory than this, or write a larger sidecar, say so before they start.
NOTICE_MEMORY_BYTES = 1e9
NOTICE_SIDECAR_BYTES = 100e6


def _size(n: float) -> str:
    return f"{n / 1e9:.1f} GB" if n >= 1e9 else f"{n / 1e6:.0f} MB"


def notices(rows: int, track: tuple[str, ...], sidecar: Path | None) -> list[str]:
    """What a run should say before it starts: memory past 1 GB, a sidecar past 100 MB."""
    found = []
    memory = fill_bytes(rows, len(track))
    if memory > NOTICE_MEMORY_BYTES:
        found.append(f"{rows:,} rows: this run needs about {_size(memory)} of memory")
    if sidecar is not None:
        size = sidecar_bytes(rows, len(track))
        if size > NOTICE_SIDECAR_BYTES:
            found.append(f"the full history goes to {display(sidecar)}, up to {_size(size)}")
    return found


def sidecar_bytes(rows: int, tracked: int) -> int:
    """Largest size of a Parquet sidecar [bytes]: time, four displacements, four derived columns
    and the tracked ones, 8 bytes a value (shot A at 5 ns: 163 MB estimated, 125 MB written,
    as the slowly changing columns compress)."""
    return rows * 8 * (9 + tracked)


def compare_continuous(shot: Shot, options: Options) -> tuple[Result | None, Exception | None]:
    """(the shot run with a continuous unloading force, or None when that run fails too,
    and the error it failed with), to put beside a run the macro's quirk hit."""
    other = dataclasses.replace(shot, params=shot.params.replace(unloading="continuous"))
    try:
        run = other.run(integrator=options.integrator, host=options.host, track=())
    except AirgunXlError as error:  # the comparison is extra: the caller says why it is missing
        return None, error
    return dataclasses.replace(run, model="continuous unloading"), None


def fill_workbook(shot: Shot, output: str | Path, outputs: Outputs, options: Options, warn: Say,
                  started: float | None = None, note: Say | None = None,
                  progress: Stage | None = None) -> Filled:
    """Run ``shot`` and write ``output`` (and its sidecar) as ``outputs`` selects.

    The steps, each its own function: refuse what cannot be written (:func:`_check_outputs`)
    or run (:func:`_check_run`), run and watch (:func:`_run_watched`), run the comparison a
    reader needs beside it (:func:`_compared_run`), then write and publish everything as one
    transaction (:func:`_publish`).

    ``warn`` and ``note`` take lists of messages (warnings; notices such as a large run's
    memory); ``progress(stage)`` is told each stage as it starts (see
    :mod:`airgun_xl.cli.progress`). Every warning is kept in one record, written into the
    workbook and the archive entry and given to ``warn`` once the fill succeeds (a refusal
    stays one line, 23.24).

    Raises
    ------
    AirgunXlError
        Before anything is written: an existing output, an unstable time step, divergence.
    """
    started = time.perf_counter() if started is None else started
    say_note: Say = note or (lambda messages: None)
    stage: Stage = progress or (lambda name: None)
    output = Path(output)
    model_shot = dataclasses.replace(shot, params=apply_model(shot.params, options.model))
    sidecar = _check_outputs(shot, output, outputs, options)
    record = [str(w) for w in shot.warnings]
    crit, track = _check_run(model_shot, outputs, options, sidecar, record, say_note)
    stage("running")
    result = _run_watched(shot, model_shot, crit, track, options, record)
    compared = _compared_run(shot, model_shot, result, options, record)
    result = dataclasses.replace(result, model=options.model)
    stage("summarizing")
    needs_summary = outputs.groups & {"summary", "spectrum", "charts"}
    summary = summarize(result) if needs_summary else None
    verdict = _predicted_verdict(shot, result, options, record)
    info = _provenance(shot, result, crit, compared, options, record, started, verdict)
    filled = Filled(result, summary, outputs.stride(shot.params.rows), sidecar, compared,
                    verdict=verdict)
    filled = _publish(shot, filled, output, outputs, info, options, record, stage, started)
    warn(record)
    return filled


def _predicted_verdict(shot: Shot, result: Result, options: Options,
                       record: list[str]) -> Verdict | None:
    """The prediction judged by the specification (the options', else the shot's sheet's);
    None without one. Its warnings join the run's."""
    spec = options.spec if options.spec is not None else shot.spec
    if spec is None:
        return None
    from ..studies.acceptance import predicted_verdict

    verdict = predicted_verdict(result, check(spec, "the specification"))
    record.extend(w for w in verdict.warnings if w not in record)
    return verdict


def _check_outputs(shot: Shot, output: Path, outputs: Outputs, options: Options) -> Path | None:
    """Refuse, before the run, outputs that cannot be written (and a foreign archive folder);
    return the sidecar's path, or None."""
    inputs = [shot.source.path] if shot.source is not None else []
    sidecar = sidecar_path(output) if outputs.writes_sidecar(shot.params.rows) else None
    check_output(output, options.force, inputs=inputs, force_word=options.force_word)
    if sidecar is not None:
        check_output(sidecar, options.force, inputs=inputs, suffixes=(".parquet", ".csv"),
                     force_word=options.force_word)
    if options.archive is not None:
        Archive(options.archive.root, create=True, dry_run=True)  # a foreign folder: now
    if options.pdf is not None:
        from ..reports.pdf_report import check_pdf

        check_pdf(options.pdf, options.force, inputs, beside=output,
                  force_word=options.force_word)
    return sidecar


def _check_run(model_shot: Shot, outputs: Outputs, options: Options, sidecar: Path | None,
               record: list[str], note: Say) -> tuple[CriticalStep, tuple[str, ...]]:
    """Refuse an unstable step and a run past the memory budget; return the critical steps
    and the step values to track. Findings go to ``record``; notices (a large run) to
    ``note``, after the refusals."""
    crit, findings = before_run(model_shot.params, options.integrator)
    if crit.ratio > 1 and not options.allow_unstable:
        error = next(f for f in findings if f.level == "error")
        raise StabilityError(f"{error}; {WAY_OUT}")
    record.extend(str(f) for f in findings if f.level != "note")
    rows = model_shot.params.rows
    track = tuple(outputs.tracked_series(sidecar is not None or options.track_all))
    check_memory(fill_bytes(rows, len(track)),  # Shot.run checks too, in the API's words
                 f"a run of {rows:,} rows ({len(track)} step values tracked)",
                 "fewer rows (a larger E2 or a shorter E6) or fewer outputs (--only summary; "
                 "an archived run tracks every step value)")
    note(notices(rows, track, sidecar))
    return crit, track


def _run_watched(shot: Shot, model_shot: Shot, crit: CriticalStep, track: tuple[str, ...],
                 options: Options, record: list[str]) -> Result:
    """The run, and what watching it found: a divergence after an unloading is refused
    (unless allowed), the rest recorded."""
    result = model_shot.run(integrator=options.integrator, host=options.host, track=track)
    diverged = unloading_diverged(result, crit, options.integrator)
    if diverged is not None and not options.allow_unstable:
        raise StabilityError(f"{diverged}; {UNLOADING_WAY_OUT}")
    if diverged is not None:
        record.append(str(diverged))
    # the run's own warnings, but for one the checks before it said in the same words
    record.extend(w for w in map(str, result.warnings[len(shot.warnings):]) if w not in record)
    record.extend(str(f) for f in after_run(result))
    return result


def _compared_run(shot: Shot, model_shot: Shot, result: Result, options: Options,
                  record: list[str]) -> Result | None:
    """The run shown beside this one: the other model (``compare_models``), or, when the
    macro's unloading quirk fired, the same shot without it; None otherwise."""
    if options.compare_models:
        other = "rigid" if options.model == "4-mass" else "4-mass"
        compared = dataclasses.replace(shot, params=apply_model(shot.params, other)).run(
            integrator=options.integrator, host=options.host, track=())
        return dataclasses.replace(compared, model=other)
    if not quirk_fired(result):
        return None
    without, error = compare_continuous(model_shot, options)
    record.append(f"the run without the quirk (--unloading continuous) fails too, so the quirk "
                  f"is not the only cause: {error}" if without is None else
                  f"without the quirk (--unloading continuous) the peak is "
                  f"{without.peak_kg:.5g} kG, against {result.peak_kg:.5g} kG with it; both "
                  "are in the workbook")
    return without


def _provenance(shot: Shot, result: Result, crit: CriticalStep, compared: Result | None,
                options: Options, record: list[str], started: float,
                verdict: Verdict | None) -> Provenance:
    """What the Summary says of the run beside its figures."""
    timed = not options.reproducible
    source = shot.source
    return Provenance(
        version=__version__, command=" ".join(options.command), warnings=tuple(record),
        dt_crit=crit.dt_crit, dt_compacted=crit.dt_compacted, dt_unloading=crit.dt_unloading,
        dt_ratio=crit.ratio, compared=compared, srs_requirement=options.srs_requirement,
        study_notes=options.study_notes, verdict=verdict,
        input=str(source.path) if source is not None else None,
        sha256=source.sha256 if source is not None else None,
        kernel_seconds=result.history.kernel_seconds if timed else None,
        run_seconds=time.perf_counter() - started if timed else None)


def _publish(shot: Shot, filled: Filled, output: Path, outputs: Outputs, info: Provenance,
             options: Options, record: list[str], progress: Stage, started: float) -> Filled:
    """Write the workbook, the sidecar and the archive entry, and publish them together (a
    failure or a signal leaves none of them, nor an archive folder this fill created);
    return ``filled`` with every warning and its archive entry (or None)."""
    result, sidecar = filled.result, filled.sidecar
    with Publication(options.force, options.force_word) as pub:
        progress("writing the workbook")
        # what writing found (a parameter cell's text cut, say) reaches the archive entry too;
        # the Summary was written before it was known
        record.extend(render_workbook(result, pub.stage(output), outputs, filled.summary,
                                      info, shown=output))
        filled = dataclasses.replace(filled, warnings=tuple(record))
        workbook = pub.files[0][0]
        later = pub  # a PDF in another folder: published after the workbook (for_file)
        if options.pdf is not None:
            progress("writing the PDF")
            later = for_file(pub, options.pdf, options.force, options.force_word)
            _write_pdf(shot, filled, later.stage(options.pdf), info, options, record)
        if sidecar is not None:
            progress("writing the sidecar")
            render_history(result, pub.stage(sidecar), shown=sidecar)
        if options.force:  # a sidecar left by an earlier run must not pair with this workbook
            for stale in (output.with_name(output.stem + s) for s in SIDECAR_SUFFIXES):
                if stale != sidecar:
                    pub.remove(stale)
        pending, archive = None, None
        try:
            if options.archive is not None:
                progress("archiving")
                with signals_held():  # its folder and marker made together, or neither
                    archive = Archive(options.archive.root, create=True)  # after the run
                pending = prepare_entry(archive, options.archive, shot, workbook, filled,
                                        options, time.perf_counter() - started)
                pub.join(pending)
            progress("publishing")
            pub.commit()
        except BaseException:
            pub.abort()  # the entry's scratch first, then the archive this fill created
            if later is not pub:
                later.abort()
            if archive is not None:
                archive.remove_if_unused()
            raise
    commit_after(pub, later)
    return dataclasses.replace(filled, entry=pending.entry if pending is not None else None)


def _write_pdf(shot: Shot, filled: Filled, path: Path, info: Provenance, options: Options,
               record: list[str]) -> None:
    """The shot's report as a PDF: its Summary's figures as the sheet shows them, the
    predicted verdict, every warning, and the Charts page's charts."""
    from ..identification import Identification
    from ..reports.pdf_report import summary_text, write_fill_pdf
    from ..untrusted_json import printable
    from ..xlsx.charts import CHARTS, series_data, spectrum_range
    from ..xlsx.sheets import flagged_figures, parameter_rows

    result = filled.result
    summary = filled.summary if filled.summary is not None else summarize(result)
    name = shot.source.path.name if shot.source is not None else "shot"
    written = dataclasses.replace(info, warnings=tuple(record)).written(
        filled.stride, len(range(0, result.rows, filled.stride)), name)
    rows = [(printable(a), printable(b), printable(c), printable(d))
            for a, b, c, d in summary_text(result, summary, written)]
    data = series_data(result, summary.spectrum, filled.compared, summary.natural_initial)
    end = float(result.history.time[-1]) * 1e3
    charts = [(spec, data, spectrum_range(summary.spectrum) if spec.key == "spectrum"
               else (0.0, end))
              for spec in CHARTS if any(s.key in data for s in spec.series)]
    source = filled.verdict.spec.source if filled.verdict is not None else ""
    inputs = [(cell, printable(label), "blank" if value is None else f"{value:.7g}", unit)
              for cell, label, value, unit, _meaning in parameter_rows(result.params)]
    write_fill_pdf(path, rows, filled.verdict, [printable(w) for w in record], charts,
                   (f"Shot: {printable(name)}", f"{result.model} model, {result.integrator} "
                    "integrator", f"Specification: {printable(source or 'none given')}"),
                   options.reproducible, tuple(printable(n) for n in options.study_notes),
                   tuple(flagged_figures(record).get("Peak acceleration (raw)", [])),
                   inputs, [(label, printable(text))
                            for label, text in Identification(shot.test).rows()])


# -- the command -------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class FillRequest:
    """One shot to fill: its workbook and what the options ask."""

    shot: str | Path
    settings: FillSettings = FillSettings()


@dataclasses.dataclass(frozen=True)
class FillOutcome:
    """A filled shot: where it went, its figures, every warning, the lines ``fill`` prints."""

    output: Path
    filled: Filled
    archive: Path | None  # the archive's folder, when the run was archived
    files: tuple[Path, ...]
    warnings: tuple[str, ...]
    lines: tuple[str, ...]

    @property
    def result(self) -> Result:
        return self.filled.result

    @property
    def summary(self) -> Summary | None:
        return self.filled.summary

    @property
    def verdict(self) -> Verdict | None:
        return self.filled.verdict

    def to_json(self) -> str:
        """The outcome as one JSON document (``fill --json``): the run (rows, model,
        integrator, crush law), the Summary's figures in SI, the compared run's peak, the
        predicted verdict's criteria, the archive entry, every warning and file."""
        from .documents import dumps

        return dumps(document(self.filled) | {
            "output": self.output, "files": self.files, "warnings": self.warnings,
            "archived": None if self.filled.entry is None else {
                "entry": self.filled.entry.ref, "archive": self.archive}})


def fill_one(path: str | Path, settings: FillSettings, warn: Say, note: Say | None = None,
             progress_for: Callable[[int], Any] | None = None,
             started: float | None = None) -> tuple[Path, Filled, Path | None]:
    """Fill the shot at ``path`` as ``settings`` ask; return (output path, Filled, archive
    root or None). ``progress_for(rows)`` makes the run's progress callback (told each stage;
    closed at the end if it has ``close``)."""
    started = time.perf_counter() if started is None else started
    output = output_of(path, settings)
    root = archive_dir(settings.archive, required=False)
    # --crush-law legacy (or a library law) runs that law whatever the sheet says: not read
    shot = shot_with_law(path, settings.crush_law, root)
    if settings.unloading != "macro":
        shot = shot.with_params(unloading=settings.unloading)
    assert shot.source is not None  # read from a workbook
    outputs = from_sheet(shot.source.outputs_block).with_flags(
        settings.only, settings.no_charts, settings.every, settings.max_sheet_rows,
        settings.sidecar)
    options = Options(settings.integrator, settings.host, settings.model,
                      settings.compare_models, settings.force, settings.allow_unstable,
                      settings.reproducible, command=tuple(settings.argv),
                      spec=combine(settings.profile, shot.spec, settings.spec),
                      pdf=Path(settings.pdf) if settings.pdf else None)
    if root is not None:
        outputs = dataclasses.replace(outputs, sidecar="never")  # the entry holds the history
        options = dataclasses.replace(options, track_all=True, archive=ArchiveRequest(
            root, shot_name(shot, settings.name), now()))
    progress = progress_for(shot.params.rows) if progress_for is not None else None
    try:
        filled = fill_workbook(shot, output, outputs, options, warn, started, note, progress)
    finally:
        close = getattr(progress, "close", None)
        if close is not None:
            close()
    return output, filled, root


def run(request: FillRequest, warn: Say | None = None, note: Say | None = None,
        progress_for: Callable[[int], Any] | None = None) -> FillOutcome:
    """Fill one shot (``airgun-xl fill SHOT.xlsx``); ``warn`` is told the run's warnings
    once it succeeds, ``note`` its notices (a large run), ``progress_for(rows)`` makes its
    progress callback."""
    output, filled, root = fill_one(request.shot, request.settings, warn or (lambda w: None),
                                    note, progress_for)
    files = (output,) + ((filled.sidecar,) if filled.sidecar is not None else ()) + (
        (Path(request.settings.pdf),) if request.settings.pdf else ())
    lines = summary_lines(output, filled)
    if filled.entry is not None and root is not None:
        lines.append(f"  archived as {filled.entry.ref} in {display(root)}")
    return FillOutcome(output, filled, root, files, filled.warnings, tuple(lines))


def document(filled: Filled) -> dict[str, Any]:
    """A filled shot's figures for JSON: SI units unless a key names its own."""
    result, s, v = filled.result, filled.summary, filled.verdict
    law = result.params.crush_law
    summary = None if s is None else {k: x for k, x in dataclasses.asdict(s).items()
                                      if k != "spectrum"} | {
        "dominant_frequencies_hz": list(s.spectrum.peaks)}
    compared = filled.compared
    return {
        "rows": result.rows, "stride": filled.stride, "model": result.model,
        "integrator": result.integrator,
        "crush_law": "legacy" if law.is_legacy else (law.source or "the workbook's"),
        "peak_kg": result.peak_kg, "time_of_peak_s": result.time_of_peak, "summary": summary,
        "compared": None if compared is None else {
            "run": variant_name(compared), "peak_kg": compared.peak_kg,
            "time_of_peak_s": compared.time_of_peak},
        "predicted_verdict": None if v is None else {
            "verdict": v.word, "specification": v.spec.source or "options",
            "criteria": [dataclasses.asdict(c) for c in v.criteria]},
        "sidecar": filled.sidecar}


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.4f} ms"


def summary_lines(output: str | Path, filled: Filled) -> list[str]:
    """What ``fill`` (and ``design``) print of a filled shot: the rows, the model and the
    law, the figures, the compared run, the sidecar, the predicted verdict."""
    result, s, stride, sidecar = filled.result, filled.summary, filled.stride, filled.sidecar
    law = result.params.crush_law
    lines = [f"wrote {output}: {result.rows:,} rows"
             + (f", 1 in {stride} on the sheets" if stride > 1 else "")
             + f"; {result.params.model.split(' (')[0]} model"
             + (" (rigid)" if result.model == "rigid" else "")
             + f", {result.integrator} integrator"
             + ("" if law.is_legacy else f", the archive's crush law {law.source}"
                if law.source else ", the workbook's fitted crush law (Crush law sheet)")]
    if s is not None:
        filtered = ("no filtered samples" if math.isnan(s.filtered_peak_kg) else
                    f"filtered {s.filtered_peak_kg:.5f} kG at "
                    f"{_ms(s.time_of_filtered_peak)}")
        lines.append(f"  peak {s.peak_kg:.5f} kG at {_ms(s.time_of_peak)}; {filtered}")
        lines.append(f"  pulse {_ms(s.pulse_duration)} (>= {PULSE_FRACTION:.0%} of peak), "
                     f"max crush {s.max_crush:.4f} m, final length {s.final_length:.4f} m")
        if s.spectrum.peaks and result.model != "rigid":  # one body: no modes to name
            lines.append("  dominant frequencies "
                         + ", ".join(f"{f / 1e3:.2f}" for f in s.spectrum.peaks) + " kHz")
    else:
        lines.append(f"  peak {result.peak_kg:.5f} kG at {_ms(result.time_of_peak)}")
    if filled.compared is not None:
        c = filled.compared
        lines.append(f"  {variant_name(c)}: peak {c.peak_kg:.5f} kG at {_ms(c.time_of_peak)}")
    if sidecar is not None:
        lines.append(f"  full history in {sidecar}")
    if filled.verdict is not None:
        lines += _verdict_lines(filled.verdict, list(filled.warnings))
    return lines


def _verdict_lines(v: Verdict, warnings: list[str]) -> list[str]:
    """The predicted verdict, each criterion with its margin, its sources and notes."""
    doubted = flagged_figures(warnings).get("Peak acceleration (raw)")
    lines = [f"  specification ({v.spec.source or 'options'}), predicted: {v.word}"
             + (f" (DOUBTED: see the warnings on {', '.join(doubted)})" if doubted else "")
             + ": " + "; ".join(f"{c.name} {c.value:.5g} {c.unit} {c.margin:+.2f} "
                                f"{c.margin_unit} {c.word}"
                                for c in v.criteria)]
    lines += [f"    {line}" for line in v.sources()]
    lines += [f"    note: {line}" for line in v.spec.notes]  # a profile's caveats
    return lines
