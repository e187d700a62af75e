"""``airgun-xl fill a.xlsx b.xlsx day/ --jobs N --summary DAY.xlsx``: a campaign of shots.

Each shot is its own fill (workbook, sidecar, archive entry: all or nothing); a bad one gets
its line and the others go on; exit 0 when all were filled, else 2 with the count. The
machinery is :mod:`airgun_xl.campaign`; this module checks the options, shows one bar and
says what happened.
"""
import time
from pathlib import Path

from ..errors import CampaignError, OptionError
from ..transaction import Interrupted, check_output, display

#: Most worker processes --jobs takes.
MAX_JOBS = 256


def parse_jobs(text):
    from ..campaign import default_jobs

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


def _check_summary(summary, given, files):
    """Refuse a summary path that is one of the campaign's shots (a folder lists it as one,
    and --force would replace it) or one of its outputs (SHOT.out.xlsx), before any work."""
    from ..campaign import shot_files

    real = summary.resolve()
    shots = {p.resolve() for p in shot_files(given)}
    if real in shots:
        raise OptionError(f"--summary: found {display(summary)}, one of the campaign's shots, "
                          "expected a new file name for the campaign table")
    outputs = {f.with_name(f.stem + ".out.xlsx").resolve() for f in files}
    if real in outputs:
        raise OptionError(f"--summary: found {display(summary)}, the output of one of the "
                          "campaign's shots, expected a file name of its own")


def run_batch(args, settings):
    from ..campaign import run_campaign, shot_files
    from .messages import _say, note, warn
    from .progress import CountBar

    jobs = parse_jobs(args.jobs)
    summary = Path(args.summary) if args.summary else None
    files = shot_files(args.shots, exclude=[summary] if summary else ())
    if settings.output and len(files) > 1:
        raise OptionError(f"-o: found with {len(files)} shots, expected one shot (a campaign "
                          "writes SHOT.out.xlsx beside each)")
    if summary is not None:
        check_output(summary, args.force, inputs=files)  # before any shot runs
        _check_summary(summary, args.shots, files)
    from ..archive.laws import check_law_source

    check_law_source(settings.crush_law, settings.archive)  # refused before any run
    started = time.perf_counter()
    bar = CountBar(len(files))

    def said(row):  # each shot's outcome as it comes
        name = row["file"]
        if row["status"] in ("failed", "lost"):  # named once, though the message may name it
            message = str(row["message"])
            if row["status"] == "lost":
                message = f"lost: {message}"
            _say(f"airgun-xl: error: {message}" if message.startswith(f"{name}: ") else
                 f"airgun-xl: error: {name}: {message}")
        elif row["status"] == "skipped":
            note([f"{name}: skipped, {row['message']}"])  # exists, or its row was lost
        else:
            warn([f"{name}: {w}" for w in row["warnings"]])
        bar.update(row["status"] in ("failed", "lost"))

    try:
        rows = run_campaign(files, settings, min(jobs, len(files)), said)
    except Interrupted as exc:
        bar.close()
        done = [r for r in getattr(exc, "rows", []) if r["status"] == "filled"]
        _say(f"airgun-xl: stopped by signal {exc.signum}: {len(done)} of {len(files)} shots "
             "were filled and stay; the running ones left nothing, the rest were not started"
             + (f"; no {display(summary)}" if summary else ""))
        return 128 + exc.signum
    finally:
        bar.close()
    seconds = time.perf_counter() - started
    counts = {s: sum(r["status"] == s for r in rows)
              for s in ("filled", "failed", "lost", "skipped")}
    lost_part = f"{counts['lost']} lost, " if counts["lost"] else ""
    for row in rows:
        if row["status"] == "filled":
            print(f"{row['file']} -> {row['output']}: peak {row['peak_kg']:.5f} kG at "
                  f"{row['time_of_peak'] * 1e3:.4f} ms"
                  + (f", {row['warning_count']} warnings" if row["warning_count"] else "")
                  + (f", archived as {row['entry']}" if row.get("entry") else ""))
    print(f"{len(files)} shots: {counts['filled']} filled, {counts['failed']} failed, {lost_part}"
          f"{counts['skipped']} skipped, in {seconds:.2f} s with {min(jobs, len(files))} "
          f"job{'s' * (min(jobs, len(files)) > 1)} ({seconds / len(files):.2f} s a shot)")
    if summary is not None:
        from ..reports.campaign import write_campaign

        write_campaign(summary, rows, f"Campaign: {len(files)} shots filled by airgun-xl "
                                      f"({counts['filled']} filled, {counts['failed']} "
                                      f"failed, {lost_part}{counts['skipped']} skipped)",
                       args.force, label=summary.name)
        print(f"wrote {summary}: one row a shot, the peak against v0")
    if counts["failed"] or counts["lost"]:
        failed, lost = counts["failed"], counts["lost"]
        what = (f"{failed} of {len(files)} shots failed"
                + (f" and {lost} lost with their worker" if lost else "")) if failed else \
            f"{lost} of {len(files)} shots lost with their worker"
        raise CampaignError(f"{what} (each said above); the others were filled")
    return 0
