"""A campaign: many shots filled by one command, and the table across them.

``airgun-xl fill a.xlsx b.xlsx day/`` fills each workbook (a folder means the ``.xlsx``
files in it) as its own transaction: its workbook, sidecar and archive entry are published
together or not at all. :func:`run_campaign` runs the shots in worker processes (``--jobs``);
a worker fills many shots, so its start-up is paid once. A bad shot gets its one line and the
others go on. Ctrl-C stops the batch: finished shots stay, the running ones clean up their
temp files, the rest are not started. A worker killed under a shot (SIGKILL, the
out-of-memory killer) loses that shot only: its row says "lost", and the shots the broken
pool took down with it are filled again by a new pool.

:class:`CampaignRequest` -> :func:`run` -> :class:`CampaignOutcome`; each shot is
:func:`airgun_xl.app.fill.fill_one` with the batch's
:class:`~airgun_xl.app.fill.FillSettings`. The campaign table (``fill --summary`` and
``history -o``) is :mod:`airgun_xl.reports.campaign`'s.
"""
from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import os
import signal
import time
import zipfile
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..crush_law import law_name
from ..errors import AirgunXlError, CampaignError, OptionError
from ..transaction import Interrupted, check_output, display
from ..transaction.locks import folder_lock
from ..transaction.publication import recover
from .settings import FillSettings, output_of

if TYPE_CHECKING:
    from .fill import Filled

#: A campaign table's row: one shot, its status and figures (the table's columns).
Row = dict[str, Any]

#: Most worker processes --jobs takes.
MAX_JOBS = 256

#: Outputs of the commands, left out when a folder is expanded (they are not shots to fill;
#: a calibrated workbook is, and is named on the command line when wanted).
DERIVED_SUFFIXES = (".out.xlsx", ".sweep.xlsx", ".srs.xlsx", ".design.xlsx", ".measured.xlsx",
                    ".calibrated.xlsx", ".convergence.xlsx")


def is_campaign_table(path: Path) -> bool:
    """Whether ``path`` is a campaign table airgun-xl wrote (its core properties' title); a
    file that is not a readable workbook is not (it fails as a shot, on its own line)."""
    from ..reports.campaign import TABLE_TITLE  # xlsxwriter: only when a folder is listed

    try:
        with zipfile.ZipFile(path) as z:
            info = z.getinfo("docProps/core.xml")
            if info.file_size > 65_536:
                return False
            return TABLE_TITLE in z.read(info).decode("utf-8", "replace")
    except (OSError, KeyError, zipfile.BadZipFile, RuntimeError, ValueError):
        return False


def shot_files(paths: Sequence[str | Path], exclude: Sequence[str | Path] = ()) -> list[Path]:
    """The workbooks ``paths`` name, in order: a file as given, a folder as its ``.xlsx``
    files (sorted; outputs of the commands, lock files and hidden files left out).

    Raises
    ------
    OptionError
        A path that does not exist, or a folder without a shot in it.
    """
    excluded = {Path(p).resolve() for p in exclude}
    out: list[Path] = []
    for given in paths:
        path = Path(given)
        if path.is_dir():
            found = sorted(p for p in path.iterdir()
                           if p.suffix.lower() == ".xlsx" and p.is_file()
                           and not p.name.startswith((".", "~$"))
                           and not p.name.lower().endswith(DERIVED_SUFFIXES)
                           and p.resolve() not in excluded and not is_campaign_table(p))
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


def row_of(path: Path, output: Path, filled: Filled, entry: str | None = None) -> Row:
    """A filled shot's row of the campaign table."""
    result, s = filled.result, filled.summary
    row: Row = {"file": display(path), "output": display(output), "status": "filled",
           "v0": result.params.v31, "peak_kg": result.peak_kg,
           "time_of_peak": result.time_of_peak, "warnings": list(filled.warnings),
           "warning_count": len(filled.warnings), "entry": entry,
           "crush_law": law_name(result.params.crush_law),
           "verdict": filled.verdict.word if filled.verdict is not None else ""}
    if s is not None:
        row.update(filtered_peak_kg=s.filtered_peak_kg, pulse_duration=s.pulse_duration,
                   max_crush=s.max_crush, final_length=s.final_length)
    return row


def _failed(path: Path, output: Path, status: str, message: str) -> Row:
    """A row for a shot not filled: only a skipped one names its (existing) output."""
    return {"file": display(path), "output": display(output) if status == "skipped" else "",
            "status": status, "message": message, "warnings": [], "warning_count": 0}


# -- the worker side ---------------------------------------------------------------------

_STOP: Any = None  # the batch's stop event, in a worker
_STARTED: Any = None  # the batch's shared array: who started each shot, and how it ended

#: ``_STARTED[k]`` when shot k's worker returned after publishing it, or without publishing
#: it (0: not started; a positive value: the pid of the worker filling it now).
PUBLISHED, UNPUBLISHED = -1, -2


def _worker_init(stop: Any, started: Any = None) -> None:
    """A worker ignores Ctrl-C (the whole process group gets it) and stops at the next stage
    when the parent sets ``stop``: its fill's publication then cleans up."""
    global _STOP, _STARTED
    _STOP, _STARTED = stop, started
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_IGN)


def _check_stop(stage: str) -> None:
    if _STOP is not None and _STOP.is_set():
        raise Interrupted(2)


def fill_task(path: str | Path, settings: FillSettings, k: int | None = None) -> Row:
    """Fill one shot of a batch (shot ``k`` of the shared array, when the batch has one);
    return its table row (never raises for the shot's own faults: they are its row's
    status)."""
    if _STARTED is not None and k is not None:
        _STARTED[k] = os.getpid()
    row = _fill_task(path, settings)
    if _STARTED is not None and k is not None:
        _STARTED[k] = PUBLISHED if row["status"] == "filled" else UNPUBLISHED
    return row


def _fill_task(given: str | Path, settings: FillSettings) -> Row:
    path = Path(given)
    output = output_of(path, settings)
    warnings: list[str] = []
    if _STOP is not None and _STOP.is_set():  # the batch was stopped before this shot began
        return _failed(path, output, "interrupted", "not started: the campaign was stopped")
    if not settings.force and os.path.lexists(output):  # filled before: not run again
        return _failed(path, output, "skipped", f"{display(output)} exists (--force "
                                                "overwrites it)")
    from .fill import fill_one  # the engine and the writers: in the worker, not the parent

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


def _lost(given: str | Path, settings: FillSettings, pid: int) -> Row:
    """The row of a shot whose worker process (``pid``) died under it (a signal such as
    SIGKILL, or the operating system's out-of-memory killer): nothing of it was published,
    and the temp files it left in its output's folder are removed."""
    path = Path(given)
    output = output_of(path, settings)
    if output.parent.is_dir():
        with contextlib.suppress(OSError), folder_lock(output.parent):
            recover(output.parent)  # the dead worker's temps and journal, if any
    return _failed(path, output, "lost", f"its worker process (pid {pid}) died before the shot "
                                         "was published (killed, or out of memory); nothing "
                                         "of it was kept (fill it again)")


def _unreported(given: str | Path, settings: FillSettings) -> Row:
    """The row of a shot published by a worker the broken pool took down before its row
    came back: the workbook is complete, its figures are not in this table."""
    path = Path(given)
    output = output_of(path, settings)
    return _failed(path, output, "skipped", f"{display(output)} was filled by this run, but "
                                            "its row was lost when another worker died (its "
                                            "figures are in the workbook)")


# -- the parent side ---------------------------------------------------------------------

def default_jobs() -> int:
    """The cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def run_campaign(files: Sequence[Path], settings: FillSettings, jobs: int,
                 on_row: Callable[[Row], None] | None = None) -> list[Row]:
    """Fill ``files`` with ``jobs`` worker processes (1: in this process); return their rows
    in the order of ``files``. ``on_row(row)`` is told each as it finishes.

    Raises
    ------
    Interrupted
        After Ctrl-C (or SIGTERM): the finished shots stay, the running ones stopped at their
        next stage and cleaned up; its ``rows`` attribute holds the rows so far.
    """
    told: Callable[[Row], None] = on_row or (lambda row: None)
    rows: list[Row | None] = [None] * len(files)
    if jobs <= 1 or len(files) == 1:
        try:
            for k, path in enumerate(files):
                row = rows[k] = fill_task(path, settings)
                told(row)
        except Interrupted as exc:
            exc.rows = [r for r in rows if r is not None]
            raise
        return [r for r in rows if r is not None]
    context = multiprocessing.get_context("spawn")  # as on Windows and macOS
    todo = list(range(len(files)))
    while todo:  # a round a pool; a new round only after a worker died under a shot
        lost = _pool_round(context, files, settings, jobs, todo, rows, told)
        todo = [k for k in todo if rows[k] is None]
        if todo and not lost:  # no shot lost, none finished: the workers die as they start
            raise CampaignError(f"{len(todo)} of {len(files)} shots were not filled: the "
                                "worker processes died before they started a shot")
    return [r for r in rows if r is not None]


def _pool_round(context: Any, files: Sequence[Path], settings: FillSettings, jobs: int,
                todo: list[int], rows: list[Row | None], on_row: Callable[[Row], None]) -> int:
    """Fill the shots ``todo`` in one pool; return how many were lost with their worker.

    When a worker dies, concurrent.futures fails every shot left in its pool. The shared
    array tells them apart: the dead worker's shot still holds its pid (lost, its temps
    removed); the others' workers were told to stop, and their shots are filled by the next
    round (or kept, when one was published before its row could come back).
    """
    stop = context.Event()
    started = context.Array("q", len(files), lock=False)
    pool = ProcessPoolExecutor(min(jobs, len(todo)), context, _worker_init, (stop, started))
    futures: dict[Future[Row], int] = {}
    broken = False
    try:
        futures = {pool.submit(fill_task, str(files[k]), settings, k): k for k in todo}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                k = futures[future]
                try:
                    row = future.result()
                except BrokenProcessPool:
                    if not broken:  # the others stop at their next stage and clean up
                        broken = True
                        stop.set()
                    continue
                if broken and row["status"] == "interrupted":  # stopped by us: the next
                    continue  # round fills it
                rows[k] = row
                on_row(row)
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
            row = _lost(files[k], settings, started[k])
            lost += 1
        elif started[k] == PUBLISHED:
            row = _unreported(files[k], settings)
        else:
            continue  # not started, or stopped unpublished: the next round fills it
        rows[k] = row
        on_row(row)
    return lost


# -- the command -------------------------------------------------------------------------


def parse_jobs(text: str | int | None) -> int:
    """``--jobs``: a whole number of worker processes, 1 to :data:`MAX_JOBS`; None: the cores
    this process may use."""
    if text is None:
        return default_jobs()
    try:
        jobs = int(str(text).strip())
    except ValueError:
        jobs = 0
    if not 1 <= jobs <= MAX_JOBS:
        raise OptionError(f"--jobs: found {text!r}, expected a whole number of worker "
                          f"processes, 1 to {MAX_JOBS}")
    return jobs


@dataclasses.dataclass(frozen=True)
class CampaignRequest:
    """Shots (workbooks, or folders of them) filled with one set of options; ``summary``
    also writes the campaign table."""

    shots: tuple[str, ...]
    settings: FillSettings = FillSettings()
    jobs: int | str | None = None  # worker processes (default: the cores this process may use)
    summary: str | None = None  # DAY.xlsx: one row a shot


@dataclasses.dataclass(frozen=True)
class CampaignOutcome:
    """Every shot's row (in the order given), the counts, and what ``fill`` prints."""

    rows: tuple[Row, ...]
    counts: dict[str, int]  # filled, failed, lost, skipped
    jobs: int
    seconds: float
    files: tuple[Path, ...]  # every workbook written, the table last
    summary: Path | None
    lines: tuple[str, ...]

    def to_json(self) -> str:
        """The outcome as one JSON document (``fill SHOTS... --json``): a row a shot (its
        status, figures in SI and warnings, or why it was not filled), the counts, the
        files written."""
        from .documents import dumps

        return dumps({"rows": self.rows, "counts": self.counts, "jobs": self.jobs,
                      "files": self.files, "summary": self.summary,
                      "failure": self.failure})

    @property
    def failure(self) -> str | None:
        """Why the campaign is not a success (shots failed or lost), or None."""
        failed, lost, total = self.counts["failed"], self.counts["lost"], len(self.rows)
        if not failed and not lost:
            return None
        what = (f"{failed} of {total} shots failed"
                + (f" and {lost} lost with their worker" if lost else "")) if failed else \
            f"{lost} of {total} shots lost with their worker"
        return f"{what} (each said above); the others were filled"


def _check_summary(summary: Path, given: Sequence[str], files: Sequence[Path]) -> None:
    """Refuse a summary path that is one of the campaign's shots (a folder lists it as one,
    and --force would replace it) or one of its outputs (SHOT.out.xlsx), before any work."""
    real = summary.resolve()
    shots = {p.resolve() for p in shot_files(given)}
    if real in shots:
        raise OptionError(f"--summary: found {display(summary)}, one of the campaign's shots, "
                          "expected a new file name for the campaign table")
    outputs = {f.with_name(f.stem + ".out.xlsx").resolve() for f in files}
    if real in outputs:
        raise OptionError(f"--summary: found {display(summary)}, the output of one of the "
                          "campaign's shots, expected a file name of its own")


def checked_files(request: CampaignRequest) -> tuple[list[Path], int]:
    """The shots to fill and the worker processes, every option refused before any run."""
    jobs = parse_jobs(request.jobs)
    summary = Path(request.summary) if request.summary else None
    files = shot_files(request.shots, exclude=[summary] if summary else ())
    if request.settings.pdf and (len(files) > 1 or summary is not None):
        raise OptionError(f"--pdf: found with {len(files)} shots, expected one shot's "
                          "workbook (a campaign's shots are each their own report)")
    if request.settings.output and len(files) > 1:
        raise OptionError(f"-o: found with {len(files)} shots, expected one shot (a campaign "
                          "writes SHOT.out.xlsx beside each)")
    if summary is not None:
        check_output(summary, request.settings.force, inputs=files)  # before any shot runs
        _check_summary(summary, request.shots, files)
    from ..archive.laws import check_law_source

    check_law_source(request.settings.crush_law, request.settings.archive)  # before any run
    return files, min(jobs, len(files))


def run(request: CampaignRequest, on_row: Callable[[Row], None] | None = None,
        files: tuple[list[Path], int] | None = None) -> CampaignOutcome:
    """Fill the campaign's shots; ``on_row(row)`` is told each as it finishes (``files``:
    :func:`checked_files`'s answer, when the caller checked first).

    Raises
    ------
    OptionError
        Before any shot runs.
    Interrupted
        Ctrl-C or SIGTERM: the finished shots stay (``rows`` on the exception), no table.
    """
    shots, jobs = files if files is not None else checked_files(request)
    started = time.perf_counter()
    rows = run_campaign(shots, request.settings, jobs, on_row)
    seconds = time.perf_counter() - started
    counts = {s: sum(r["status"] == s for r in rows)
              for s in ("filled", "failed", "lost", "skipped")}
    lost_part = f"{counts['lost']} lost, " if counts["lost"] else ""
    lines = [f"{row['file']} -> {row['output']}: peak {row['peak_kg']:.5f} kG at "
             f"{row['time_of_peak'] * 1e3:.4f} ms"
             + (f", {row['warning_count']} warnings" if row["warning_count"] else "")
             + (f", archived as {row['entry']}" if row.get("entry") else "")
             for row in rows if row["status"] == "filled"]
    lines.append(f"{len(shots)} shots: {counts['filled']} filled, {counts['failed']} failed, "
                 f"{lost_part}{counts['skipped']} skipped, in {seconds:.2f} s with {jobs} "
                 f"job{'s' * (jobs > 1)} ({seconds / len(shots):.2f} s a shot)")
    written = [output_of(shot, request.settings)
               for shot, row in zip(shots, rows, strict=True) if row["status"] == "filled"]
    summary = Path(request.summary) if request.summary else None
    if summary is not None:
        from ..reports.campaign import write_campaign

        write_campaign(summary, rows, f"Campaign of {len(shots)} shots by airgun-xl: "
                                      f"{counts['filled']} filled, {counts['failed']} "
                                      f"failed, {lost_part}{counts['skipped']} skipped",
                       request.settings.force, label=summary.name)
        lines.append(f"wrote {summary}: one row a shot, the peak against v0")
        written.append(summary)
    return CampaignOutcome(tuple(rows), counts, jobs, seconds, tuple(written), summary,
                           tuple(lines))
