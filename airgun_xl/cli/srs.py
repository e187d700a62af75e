"""``airgun-xl srs SHOT.xlsx``: the shock response spectrum of the predicted pulse; its
options are its request's fields (:class:`airgun_xl.app.srs.SrsRequest`)."""
from pathlib import Path

from .declared import add_declared, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.srs import SrsRequest

    p = sub.add_parser("srs", help="shock response spectrum of the shot's predicted pulse",
                       description="Run the shot and write the maximax shock response "
                                   "spectrum of the test item's acceleration (Smallwood's "
                                   "ramp-invariant filter), as a table and a log-log chart.")
    add_declared(p, SrsRequest)
    add_json(p, "the spectrum")
    p.set_defaults(run=run)


def run(args):
    from ..app.srs import SrsRequest, lines
    from ..app.srs import run as spectrum
    from .messages import report

    shot_path = Path(args.shot)
    default = shot_path.with_name(shot_path.stem + ".srs.xlsx")
    request = request_of(SrsRequest, args, output=args.output or default)
    outcome = spectrum(request)
    return report(outcome, lines(request, outcome), args.json)
