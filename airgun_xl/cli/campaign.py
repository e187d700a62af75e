"""``airgun-xl fill a.xlsx b.xlsx day/ --jobs N --summary DAY.xlsx``: a campaign of shots.

Each shot is its own fill (workbook, sidecar, archive entry: all or nothing); a bad one gets
its line and the others go on; exit 0 when all were filled, else 2 with the count. The
campaign is :mod:`airgun_xl.app.campaign`'s; this module shows one bar and says what
happened.
"""
from ..app.session import Interrupted
from ..errors import CampaignError
from ..untrusted_json import printable


def _said(row, bar):
    """A shot's outcome as it comes: its error, its skip or its warnings; the bar moves."""
    from .messages import _say, note, warn

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


def run_batch(args, settings):
    from ..app.campaign import CampaignRequest, checked_files, run
    from .messages import _say
    from .progress import CountBar

    request = CampaignRequest(tuple(args.shots), settings, args.jobs, args.summary)
    files, jobs = checked_files(request)
    bar = CountBar(len(files), enabled=False if args.json else None)
    try:
        outcome = run(request, lambda row: _said(row, bar), (files, jobs))
    except Interrupted as exc:
        bar.close()
        done = [r for r in getattr(exc, "rows", []) if r["status"] == "filled"]
        _say(f"airgun-xl: stopped by signal {exc.signum}: {len(done)} of {len(files)} shots "
             "were filled and stay; the running ones left nothing, the rest were not started"
             + (f"; no {args.summary}" if args.summary else ""))
        return 128 + exc.signum
    finally:
        bar.close()
    if args.json:
        print(outcome.to_json())
    else:
        print("\n".join(printable(line) for line in outcome.lines))
    if outcome.failure is not None:
        raise CampaignError(outcome.failure)
    return 0
