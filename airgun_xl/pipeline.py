"""A fill from start to finish, shared by ``fill`` and ``design``: check, run, summarize,
then publish the workbook, its sidecar and its archive entry as one transaction
(:class:`airgun_xl.transaction.Publication`): all of them, or none. Reports go through a
``warn`` callback."""
import dataclasses
import time
from pathlib import Path

from .archive import Archive
from .archive.entry import prepare_entry
from .engine.summary import summarize
from .errors import AirgunXlError, StabilityError
from .limits import check_memory, fill_bytes
from .models import apply_model
from .reports.fill import render_workbook
from .reports.sidecar import SIDECAR_SUFFIXES, render_history, sidecar_path
from .studies.check import after_run, before_run, quirk_fired, unloading_diverged
from .transaction import Publication, check_output, display, signals_held
from .version import __version__


@dataclasses.dataclass
class Options:
    integrator: str = "legacy"
    host: str = "excel"
    model: str = "4-mass"
    compare_models: bool = False
    force: bool = False
    allow_unstable: bool = False
    reproducible: bool = False
    track_all: bool = False  # record every step value (an archived run keeps them all)
    command: tuple = ()  # the command line, for provenance
    archive: object = None  # an ArchiveRequest: also store the run as an archive entry
    force_word: str = "--force"  # how messages name `force`
    srs_requirement: tuple | None = None  # (frequencies [Hz], levels [kG], Q): SRS sheets
    spec: object = None  # a Specification to judge the prediction by (else the shot's sheet)
    study_notes: tuple = ()  # what the study behind the shot found (design --confidence)


@dataclasses.dataclass
class ArchiveRequest:
    root: Path
    name: str  # the shot's name in the archive (sanitized there)
    started_at: str  # ISO time the command started, for provenance


@dataclasses.dataclass
class Filled:
    result: object
    summary: object
    stride: int
    sidecar: object
    compared: object = None  # the other model's (or unloading's) Result, shown beside it
    entry: object = None  # the archive Entry, when the run was archived
    verdict: object = None  # the predicted Verdict, when the shot has a specification
    warnings: list = dataclasses.field(default_factory=list)  # all the run said, in order


#: What a refused or stopped unstable run can do instead (the pipeline serves the CLI).
WAY_OUT = "expected a smaller E2, --integrator newmark, or --allow-unstable"

#: The way out of an unloading spring that diverges (Newmark treats it explicitly too).
UNLOADING_WAY_OUT = "expected a smaller E2, or --allow-unstable"

#: Runs that need more memory than this, or write a larger sidecar, say so before they start.
NOTICE_MEMORY_BYTES = 1e9
NOTICE_SIDECAR_BYTES = 100e6


def _size(n):
    return f"{n / 1e9:.1f} GB" if n >= 1e9 else f"{n / 1e6:.0f} MB"


def notices(rows, track, sidecar):
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


def sidecar_bytes(rows, tracked):
    """Largest size of a Parquet sidecar [bytes]: time, four displacements, four derived columns
    and the tracked ones, 8 bytes a value (shot A at 5 ns: 163 MB estimated, 125 MB written,
    as the slowly changing columns compress)."""
    return rows * 8 * (9 + tracked)


def compare_continuous(shot, options):
    """(the shot run with a continuous unloading force, or None when that run fails too,
    and the error it failed with), to put beside a run the macro's quirk hit."""
    other = dataclasses.replace(shot, params=shot.params.replace(unloading="continuous"))
    try:
        run = other.run(integrator=options.integrator, host=options.host, track=())
    except AirgunXlError as error:  # the comparison is extra: the caller says why it is missing
        return None, error
    return dataclasses.replace(run, model="continuous unloading"), None


def fill_workbook(shot, output, outputs, options, warn, started=None, note=None,
                  progress=None):
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
    note, progress = note or (lambda messages: None), progress or (lambda stage: None)
    output = Path(output)
    model_shot = dataclasses.replace(shot, params=apply_model(shot.params, options.model))
    sidecar = _check_outputs(shot, output, outputs, options)
    record = [str(w) for w in shot.warnings]
    crit, track = _check_run(model_shot, outputs, options, sidecar, record, note)
    progress("running")
    result = _run_watched(shot, model_shot, crit, track, options, record)
    compared = _compared_run(shot, model_shot, result, options, record)
    result = dataclasses.replace(result, model=options.model)
    progress("summarizing")
    needs_summary = outputs.groups & {"summary", "spectrum", "charts"}
    summary = summarize(result) if needs_summary else None
    verdict = _predicted_verdict(shot, result, options, record)
    info = _provenance(shot, result, crit, compared, options, record, started)
    info["verdict"] = verdict
    filled = Filled(result, summary, outputs.stride(shot.params.rows), sidecar, compared,
                    warnings=record, verdict=verdict)
    filled.entry = _publish(shot, filled, output, outputs, info, options, record, progress,
                            started)
    warn(record)
    return filled


def _predicted_verdict(shot, result, options, record):
    """The prediction judged by the specification (the options', else the shot's sheet's);
    None without one. Its warnings join the run's."""
    spec = options.spec if options.spec is not None else shot.spec
    if spec is None:
        return None
    from .specification import check
    from .studies.acceptance import predicted_verdict

    verdict = predicted_verdict(result, check(spec, "the specification"))
    record.extend(w for w in verdict.warnings if w not in record)
    return verdict


def _check_outputs(shot, output, outputs, options):
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
    return sidecar


def _check_run(model_shot, outputs, options, sidecar, record, note):
    """Refuse an unstable step and a run past the memory budget; return the critical steps
    and the step values to track. Findings go to ``record``; notices (a large run) to
    ``note``, after the refusals."""
    crit, findings = before_run(model_shot.params, options.integrator)
    if crit.ratio > 1 and not options.allow_unstable:
        error = next(f for f in findings if f.level == "error")
        raise StabilityError(f"{error}; {WAY_OUT}")
    record.extend(str(f) for f in findings if f.level != "note")
    rows = model_shot.params.rows
    track = outputs.tracked_series(sidecar is not None or options.track_all)
    check_memory(fill_bytes(rows, len(track)),  # Shot.run checks too, in the API's words
                 f"a run of {rows:,} rows ({len(track)} step values tracked)",
                 "fewer rows (a larger E2 or a shorter E6) or fewer outputs (--only summary; "
                 "an archived run tracks every step value)")
    note(notices(rows, track, sidecar))
    return crit, track


def _run_watched(shot, model_shot, crit, track, options, record):
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


def _compared_run(shot, model_shot, result, options, record):
    """The run shown beside this one: the other model (``compare_models``), or, when the
    macro's unloading quirk fired, the same shot without it; None otherwise."""
    if options.compare_models:
        other = "rigid" if options.model == "4-mass" else "4-mass"
        compared = dataclasses.replace(shot, params=apply_model(shot.params, other)).run(
            integrator=options.integrator, host=options.host, track=())
        return dataclasses.replace(compared, model=other)
    if not quirk_fired(result):
        return None
    compared, error = compare_continuous(model_shot, options)
    record.append(f"the run without the quirk (--unloading continuous) fails too, so the quirk "
                  f"is not the only cause: {error}" if compared is None else
                  f"without the quirk (--unloading continuous) the peak is "
                  f"{compared.peak_kg:.5g} kG, against {result.peak_kg:.5g} kG with it; both "
                  "are in the workbook")
    return compared


def _provenance(shot, result, crit, compared, options, record, started):
    """What the Summary says of the run beside its figures."""
    info = {"version": __version__, "command": " ".join(options.command), "warnings": record,
            "dt_crit": crit.dt_crit, "dt_compacted": crit.dt_compacted,
            "dt_unloading": crit.dt_unloading, "dt_ratio": crit.ratio, "compared": compared,
            "srs_requirement": options.srs_requirement,
            "study_notes": options.study_notes}
    if shot.source is not None:
        info.update(input=str(shot.source.path), sha256=shot.source.sha256)
    if not options.reproducible:
        info.update(kernel_seconds=result.history.kernel_seconds,
                    run_seconds=time.perf_counter() - started)
    return info


def _publish(shot, filled, output, outputs, info, options, record, progress, started):
    """Write the workbook, the sidecar and the archive entry, and publish them together (a
    failure or a signal leaves none of them, nor an archive folder this fill created);
    return the archive entry, or None."""
    result, sidecar = filled.result, filled.sidecar
    with Publication(options.force, options.force_word) as pub:
        progress("writing the workbook")
        # what writing found (a parameter cell's text cut, say) reaches the archive entry too;
        # the Summary was written before it was known
        record.extend(render_workbook(result, pub.stage(output), outputs, filled.summary,
                                      info, shown=output))
        workbook = pub.files[0][0]
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
            if archive is not None:
                archive.remove_if_unused()
            raise
    return pending.entry if pending is not None else None
