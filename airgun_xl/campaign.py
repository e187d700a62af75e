"""A campaign: many shots filled by one command, and the table across them.

``airgun-xl fill a.xlsx b.xlsx day/`` fills each workbook (a folder means the ``.xlsx``
files in it) as its own transaction: its workbook, sidecar and archive entry are published
together or not at all. :func:`run_campaign` runs the shots in worker processes (``--jobs``);
a worker fills many shots, so its start-up is paid once. A bad shot gets its one line and the
others go on. Ctrl-C stops the batch: finished shots stay, the running ones clean up their
temp files, the rest are not started. A worker killed under a shot (SIGKILL, the
out-of-memory killer) loses that shot only: its row says "lost", and the shots the broken
pool took down with it are filled again by a new pool.

:class:`FillSettings` is what the command line asks of every shot (one declaration, pickled
to the workers); :func:`fill_one` fills one shot with it. The campaign table (``fill
--summary`` and ``history -o``) is :mod:`airgun_xl.reports.campaign`'s.
"""
from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

from .crush_law import law_name
from .errors import AirgunXlError, CampaignError, OptionError
from .specification import Specification
from .transaction import Interrupted, display

#: Outputs of the commands, left out when a folder is expanded (they are not shots to fill;
#: a calibrated workbook is, and is named on the command line when wanted).
DERIVED_SUFFIXES = (".out.xlsx", ".sweep.xlsx", ".srs.xlsx", ".design.xlsx", ".measured.xlsx",
                    ".calibrated.xlsx", ".convergence.xlsx")


def is_campaign_table(path):
    """Whether ``path`` is a campaign table airgun-xl wrote (its core properties' title); a
    file that is not a readable workbook is not (it fails as a shot, on its own line)."""
    import zipfile

    from .reports.campaign import TABLE_TITLE

    try:
        with zipfile.ZipFile(path) as z:
            info = z.getinfo("docProps/core.xml")
            if info.file_size > 65_536:
                return False
            return TABLE_TITLE in z.read(info).decode("utf-8", "replace")
    except (OSError, KeyError, zipfile.BadZipFile, RuntimeError, ValueError):
        return False


@dataclasses.dataclass(frozen=True)
class FillSettings:
    """What ``fill``'s options ask of each shot."""

    output: str | None = None  # one shot only; else SHOT.out.xlsx beside each
    force: bool = False
    host: str = "excel"
    only: str | None = None
    no_charts: bool = False
    every: str | None = None
    max_sheet_rows: str | None = None
    sidecar: str | None = None
    integrator: str = "legacy"
    allow_unstable: bool = False
    model: str = "4-mass"
    crush_law: str = "workbook"  # workbook, legacy, or a law of the archive's library
    unloading: str = "macro"
    compare_models: bool = False
    archive: str | None = None
    name: str | None = None
    reproducible: bool = False
    argv: tuple = ()
    # a tolerance profile (issue 25), under each shot's sheet: read once, before any shot
    profile: str | Specification | None = None
    spec: object = None  # the specification fields of the options, over each shot's sheet


def default_output(shot_path):
    shot_path = Path(shot_path)
    return shot_path.with_name(shot_path.stem + ".out.xlsx")


def shot_files(paths, exclude=()):
    """The workbooks ``paths`` name, in order: a file as given, a folder as its ``.xlsx``
    files (sorted; outputs of the commands, lock files and hidden files left out).

    Raises
    ------
    OptionError
        A path that does not exist, or a folder without a shot in it.
    """
    exclude = {Path(p).resolve() for p in exclude}
    out = []
    for given in paths:
        path = Path(given)
        if path.is_dir():
            found = sorted(p for p in path.iterdir()
                           if p.suffix.lower() == ".xlsx" and p.is_file()
                           and not p.name.startswith((".", "~$"))
                           and not p.name.lower().endswith(DERIVED_SUFFIXES)
                           and p.resolve() not in exclude and not is_campaign_table(p))
            if not found:
                raise OptionError(f"SHOT: {display(path)} holds no .xlsx shot, expected a "
                                  "folder of shot workbooks (outputs such as *.out.xlsx are "
                                  "left out)")
            out += found
        elif path.exists() or path.is_symlink():
            out.append(path)
        else:
            raise OptionError(f"SHOT: {display(path)} does not exist, expected a workbook or "
                              "a folder of them")
    return out


def _output(path, settings):
    """Where a shot of the batch is written: -o, or SHOT.out.xlsx beside it."""
    return Path(settings.output) if settings.output else default_output(Path(path))


def fill_one(path, settings, warn, note=None, progress_for=None, started=None):
    """Fill the shot at ``path`` as ``settings`` ask; return (output path, Filled, archive
    root or None). ``progress_for(rows)`` makes the run's progress callback (told each stage;
    closed at the end if it has ``close``)."""
    from .archive import archive_dir
    from .archive.entry import now, shot_name
    from .archive.laws import shot_with_law
    from .outputs import from_sheet
    from .pipeline import ArchiveRequest, Options, fill_workbook

    started = time.perf_counter() if started is None else started
    output = _output(path, settings)
    root = archive_dir(settings.archive, required=False)
    # --crush-law legacy (or a library law) runs that law whatever the sheet says: not read
    shot = shot_with_law(path, settings.crush_law, root)
    if settings.unloading != "macro":
        shot = shot.with_params(unloading=settings.unloading)
    outputs = from_sheet(shot.source.outputs_block).with_flags(
        settings.only, settings.no_charts, settings.every, settings.max_sheet_rows,
        settings.sidecar)
    from .specification import combine

    options = Options(settings.integrator, settings.host, settings.model,
                      settings.compare_models, settings.force, settings.allow_unstable,
                      settings.reproducible, command=tuple(settings.argv),
                      spec=combine(settings.profile, shot.spec, settings.spec))
    if root is not None:
        outputs = dataclasses.replace(outputs, sidecar="never")  # the entry holds the history
        options.track_all = True
        options.archive = ArchiveRequest(root, shot_name(shot, settings.name), now())
    progress = progress_for(shot.params.rows) if progress_for is not None else None
    try:
        filled = fill_workbook(shot, output, outputs, options, warn, started, note, progress)
    finally:
        close = getattr(progress, "close", None)
        if close is not None:
            close()
    return output, filled, root


def row_of(path, output, filled, entry=None):
    """A filled shot's row of the campaign table."""
    result, s = filled.result, filled.summary
    row = {"file": display(path), "output": display(output), "status": "filled",
           "v0": result.params.v31, "peak_kg": result.peak_kg,
           "time_of_peak": result.time_of_peak, "warnings": list(filled.warnings),
           "warning_count": len(filled.warnings), "entry": entry,
           "crush_law": law_name(result.params.crush_law),
           "verdict": filled.verdict.word if filled.verdict is not None else ""}
    if s is not None:
        row.update(filtered_peak_kg=s.filtered_peak_kg, pulse_duration=s.pulse_duration,
                   max_crush=s.max_crush, final_length=s.final_length)
    return row


def _failed(path, output, status, message):
    """A row for a shot not filled: only a skipped one names its (existing) output."""
    return {"file": display(path), "output": display(output) if status == "skipped" else "",
            "status": status, "message": message, "warnings": [], "warning_count": 0}


# -- the worker side ---------------------------------------------------------------------

_STOP = None  # the batch's stop event, in a worker
_STARTED = None  # the batch's shared array: who started each shot, and how it ended

#: ``_STARTED[k]`` when shot k's worker returned after publishing it, or without publishing
#: it (0: not started; a positive value: the pid of the worker filling it now).
PUBLISHED, UNPUBLISHED = -1, -2


def _worker_init(stop, started=None):
    """A worker ignores Ctrl-C (the whole process group gets it) and stops at the next stage
    when the parent sets ``stop``: its fill's publication then cleans up."""
    import signal

    global _STOP, _STARTED
    _STOP, _STARTED = stop, started
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_IGN)


def _check_stop(stage):
    if _STOP is not None and _STOP.is_set():
        raise Interrupted(2)


def fill_task(path, settings, k=None):
    """Fill one shot of a batch (shot ``k`` of the shared array, when the batch has one);
    return its table row (never raises for the shot's own faults: they are its row's
    status)."""
    if _STARTED is not None and k is not None:
        _STARTED[k] = os.getpid()
    row = _fill_task(path, settings)
    if _STARTED is not None and k is not None:
        _STARTED[k] = PUBLISHED if row["status"] == "filled" else UNPUBLISHED
    return row


def _fill_task(path, settings):
    path = Path(path)
    output = _output(path, settings)
    warnings: list = []
    if _STOP is not None and _STOP.is_set():  # the batch was stopped before this shot began
        return _failed(path, output, "interrupted", "not started: the campaign was stopped")
    if not settings.force and os.path.lexists(output):  # filled before: not run again
        return _failed(path, output, "skipped", f"{display(output)} exists (--force "
                                                "overwrites it)")
    try:
        output, filled, _ = fill_one(path, settings, warnings.extend, None,
                                     lambda rows: _check_stop)
    except Interrupted:
        return _failed(path, output, "interrupted", "stopped before it was published")
    except AirgunXlError as exc:
        return _failed(path, output, "failed", str(exc))
    except MemoryError:
        return _failed(path, output, "failed", "out of memory during the run")
    except Exception as exc:  # noqa: BLE001 - a fault of ours in one shot: the batch goes on
        return _failed(path, output, "failed", f"internal error ({type(exc).__name__}: "
                                               f"{exc}); please report it")
    entry = filled.entry.ref if filled.entry is not None else None
    return row_of(path, output, filled, entry)


def _lost(path, settings, pid):
    """The row of a shot whose worker process (``pid``) died under it (a signal such as
    SIGKILL, or the operating system's out-of-memory killer): nothing of it was published,
    and the temp files it left in its output's folder are removed."""
    import contextlib

    from .transaction.locks import folder_lock
    from .transaction.publication import recover

    path = Path(path)
    output = _output(path, settings)
    if output.parent.is_dir():
        with contextlib.suppress(OSError), folder_lock(output.parent):
            recover(output.parent)  # the dead worker's temps and journal, if any
    return _failed(path, output, "lost", f"its worker process (pid {pid}) died before the shot "
                                         "was published (killed, or out of memory); nothing "
                                         "of it was kept (fill it again)")


def _unreported(path, settings):
    """The row of a shot published by a worker the broken pool took down before its row
    came back: the workbook is complete, its figures are not in this table."""
    path = Path(path)
    output = _output(path, settings)
    return _failed(path, output, "skipped", f"{display(output)} was filled by this run, but "
                                            "its row was lost when another worker died (its "
                                            "figures are in the workbook)")


# -- the parent side ---------------------------------------------------------------------

def default_jobs():
    """The cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def run_campaign(files, settings, jobs, on_row=None):
    """Fill ``files`` with ``jobs`` worker processes (1: in this process); return their rows
    in the order of ``files``. ``on_row(row)`` is told each as it finishes.

    Raises
    ------
    Interrupted
        After Ctrl-C (or SIGTERM): the finished shots stay, the running ones stopped at their
        next stage and cleaned up; its ``rows`` attribute holds the rows so far.
    """
    on_row = on_row or (lambda row: None)
    rows = [None] * len(files)
    if jobs <= 1 or len(files) == 1:
        try:
            for k, path in enumerate(files):
                rows[k] = fill_task(path, settings)
                on_row(rows[k])
        except Interrupted as exc:
            exc.rows = [r for r in rows if r is not None]
            raise
        return rows
    import multiprocessing

    context = multiprocessing.get_context("spawn")  # as on Windows and macOS
    todo = list(range(len(files)))
    while todo:  # a round a pool; a new round only after a worker died under a shot
        lost = _pool_round(context, files, settings, jobs, todo, rows, on_row)
        todo = [k for k in todo if rows[k] is None]
        if todo and not lost:  # no shot lost, none finished: the workers die as they start
            raise CampaignError(f"{len(todo)} of {len(files)} shots were not filled: the "
                                "worker processes died before they started a shot")
    return rows


def _pool_round(context, files, settings, jobs, todo, rows, on_row):
    """Fill the shots ``todo`` in one pool; return how many were lost with their worker.

    When a worker dies, concurrent.futures fails every shot left in its pool. The shared
    array tells them apart: the dead worker's shot still holds its pid (lost, its temps
    removed); the others' workers were told to stop, and their shots are filled by the next
    round (or kept, when one was published before its row could come back).
    """
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    stop = context.Event()
    started = context.Array("q", len(files), lock=False)
    pool = ProcessPoolExecutor(min(jobs, len(todo)), context, _worker_init, (stop, started))
    futures: dict = {}
    broken = False
    try:
        futures = {pool.submit(fill_task, str(files[k]), settings, k): k for k in todo}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                k = futures[future]
                try:
                    rows[k] = future.result()
                except BrokenProcessPool:
                    if not broken:  # the others stop at their next stage and clean up
                        broken = True
                        stop.set()
                    continue
                if broken and rows[k]["status"] == "interrupted":  # stopped by us: the
                    rows[k] = None  # next round fills it
                    continue
                on_row(rows[k])
    except Interrupted as exc:
        stop.set()  # the running shots stop at their next stage and clean up
        for future in futures:
            future.cancel()
        pool.shutdown(wait=True, cancel_futures=True)
        for future, k in futures.items():
            if rows[k] is None and future.done() and not future.cancelled() \
                    and future.exception() is None:
                rows[k] = future.result()
        exc.rows = [r for r in rows if r is not None]
        raise
    pool.shutdown(wait=True)
    lost = 0
    for k in todo:
        if rows[k] is not None:
            continue
        if started[k] > 0:  # started, and its worker never came back
            rows[k] = _lost(files[k], settings, started[k])
            lost += 1
        elif started[k] == PUBLISHED:
            rows[k] = _unreported(files[k], settings)
        else:
            continue  # not started, or stopped unpublished: the next round fills it
        on_row(rows[k])
    return lost
