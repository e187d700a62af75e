"""``airgun-xl srs SHOT.xlsx``: the shock response spectrum of the predicted pulse."""
from pathlib import Path

from .recording_options import CfcOption, cfc_value
from .run_options import SHOT_HELP, add_crush_law, add_force, add_json, add_output, add_run_options
from .vocabulary import Alias, One


def _q(text):
    """--srs-q: the one grammar of the SRS's quality factor (finite, above 0.5, at most
    1,000), as every command reads it."""
    from ..specification import parse_q

    return parse_q(text, "--srs-q")


def add_parser(sub):
    p = sub.add_parser("srs", help="shock response spectrum of the shot's predicted pulse",
                       description="Run the shot and write the maximax shock response "
                                   "spectrum of the test item's acceleration (Smallwood's "
                                   "ramp-invariant filter), as a table and a log-log chart.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    add_output(p, "the SRS workbook", "SHOT.srs.xlsx")
    add_force(p)
    p.add_argument("--srs-q", type=_q, default=10.0, metavar="Q", action=One,
                   help="quality factor (default 10: 5 %% damping)")
    p.add_argument("--q", type=_q, dest="srs_q", metavar="Q", action=Alias,
                   idea="SRS quality factor")
    p.add_argument("--cfc", type=cfc_value, action=CfcOption, metavar="N|none",
                   help="filter the pulse first: SAE J211 class 60, 180, 600 or 1000, or "
                        "none (the default)")
    p.add_argument("--from", dest="lo", type=float, default=100.0, metavar="HZ",
                   help="lowest natural frequency (default 100)")
    p.add_argument("--to", dest="hi", type=float, default=10_000.0, metavar="HZ",
                   help="highest natural frequency (default 10000)")
    add_run_options(p)
    add_crush_law(p)
    add_json(p, "the spectrum")
    p.set_defaults(run=run)


def run(args):
    from ..app.srs import SrsRequest, lines
    from ..app.srs import run as spectrum
    from .messages import report

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".srs.xlsx")
    request = SrsRequest(shot_path, args.srs_q, args.cfc, args.lo, args.hi, args.integrator,
                         args.model, output, args.force, args.crush_law,
                         Path(args.archive) if args.archive else None)
    outcome = spectrum(request)
    return report(outcome, lines(request, outcome), args.json)
