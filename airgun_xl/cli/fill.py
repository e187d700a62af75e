"""``airgun-xl fill SHOT.xlsx [-o OUT.xlsx] [--force] [...]``: run a shot into a new workbook."""
from pathlib import Path

from ..app.archive import archive_root, prestart
from ..choices import ARCHIVE_ENV, HOSTS, SIDECAR_MODES, UNLOADINGS
from ..outputs import GROUPS
from ..untrusted_json import printable
from .run_options import add_crush_law, add_force, add_integrator, add_json, add_model, add_pdf
from .spec_options import add_spec_options
from .vocabulary import One


def add_parser(sub):
    p = sub.add_parser("fill", help="run the shot in a workbook and write a new filled workbook",
                       description="Read the report's parameter cells from SHOT, run ArtSim, and "
                                   "write the macro's result columns, a summary and charts into "
                                   "a new workbook. SHOT itself is never modified. The "
                                   "workbook's Outputs sheet, if any, picks the outputs; the "
                                   "flags below override it.")
    p.add_argument("shots", nargs="+", metavar="SHOT.xlsx",
                   help="workbook in the report's layout; several, or a folder (its .xlsx "
                        "shots), fill a campaign")
    p.add_argument("-o", "--output", metavar="OUT.xlsx", action=One,
                   help="output workbook (default: SHOT.out.xlsx beside SHOT; one shot only)")
    add_force(p)
    p.add_argument("--jobs", metavar="N",
                   help="worker processes for a campaign (default: the cores this process "
                        "may use)")
    p.add_argument("--summary", metavar="DAY.xlsx",
                   help="also write the campaign's table: one row a shot, the peak against "
                        "v0, every warning")
    _add_outputs(p)
    _add_run(p)
    add_spec_options(p)
    add_json(p, "the filled shot (a campaign's rows)")
    p.set_defaults(run=run)


def _add_outputs(p):
    """What the workbook holds: the options over its Outputs sheet."""
    p.add_argument("--host", choices=HOSTS, default="excel",
                   help="whose Offset rounding the filtered column reproduces when 1/(E2*E34) "
                        "is fractional (default: excel)")
    p.add_argument("--only", metavar="GROUPS",
                   help=f"write only these comma-separated outputs: {', '.join(GROUPS)}")
    p.add_argument("--no-charts", action="store_true", help="leave out the Charts sheet")
    p.add_argument("--every", metavar="N", help="write every N-th time row to the sheets")
    p.add_argument("--max-sheet-rows", metavar="N",
                   help="most time rows on a sheet before every N-th row is written")
    p.add_argument("--sidecar", choices=SIDECAR_MODES,
                   help="full time history beside the output: auto (when rows are left out), "
                        "always or never")


def _add_run(p):
    """How the shot runs, and where it is archived."""
    add_integrator(p)
    p.add_argument("--allow-unstable", action="store_true",
                   help="run even when the time step is above the critical step (a diverging "
                        "run still stops)")
    add_model(p)
    add_crush_law(p, archive=False)  # fill's --archive is its own (below)
    p.add_argument("--unloading", choices=UNLOADINGS, default="macro",
                   help="macro: the macro's unloading force, quirk included (default); "
                        "continuous: each unloading starts from the force before it (no jump "
                        "at a second unloading)")
    p.add_argument("--compare-models", action="store_true",
                   help="also run the other model; both curves in the acceleration chart and "
                        "both peaks in the Summary")
    p.add_argument("--archive", metavar="DIR", action=One,
                   help=f"also store the run as a new entry of this archive (default: "
                        f"${ARCHIVE_ENV} when set)")
    p.add_argument("--name", help="shot name in the archive (default: the cell beside a 'Shot' "
                                  "label in the sheet, else SHOT's file name)")
    p.add_argument("--reproducible", action="store_true",
                   help="leave run times out of the Summary (and the date out of --pdf), so "
                        "equal inputs give equal bytes")
    add_pdf(p, "one shot's report (the Summary, the predicted verdict, the warnings and the "
               "charts)")


def print_summary(output, filled):
    """A filled shot's figures, as ``fill`` and ``design`` print them."""
    from ..app.fill import summary_lines

    print("\n".join(printable(line) for line in summary_lines(output, filled)))  # never codes


def settings_of(args):
    """The :class:`~airgun_xl.app.settings.FillSettings` the command line asks for."""
    from ..app.settings import FillSettings
    from ..app.specifying import SpecFields, options_spec
    from ..specification import load_profile

    return FillSettings(
        args.output, args.force, args.host, args.only, args.no_charts, args.every,
        args.max_sheet_rows, args.sidecar, args.integrator, args.allow_unstable, args.model,
        args.crush_law, args.unloading, args.compare_models, archive_root(args.archive),
        args.name, args.reproducible, tuple(args.argv),
        load_profile(args.profile) if args.profile else None,  # once, before any shot
        options_spec(SpecFields.of(args)), args.pdf)


def run(args):
    prestart(archive_root(args.archive))  # a server index's psycopg loads meanwhile
    settings = settings_of(args)
    if len(args.shots) == 1 and not Path(args.shots[0]).is_dir() and not args.summary:
        return run_one(args.shots[0], settings, args.json)
    from .campaign import run_batch

    return run_batch(args, settings)


def run_one(path, settings, as_json=False):
    """One shot, as fill always did: its warnings and notes on the terminal, a progress bar,
    its figures printed (or, with ``--json``, the outcome as a document)."""
    from ..app.fill import FillRequest
    from ..app.fill import run as fill
    from .messages import note, warn
    from .progress import Progress

    outcome = fill(FillRequest(path, settings), warn, note, None if as_json else
                   Progress.for_rows)
    if as_json:
        print(outcome.to_json())
        return 0
    print("\n".join(printable(line) for line in outcome.lines))
    return 0
