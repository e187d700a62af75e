"""``airgun-xl sweep SHOT.xlsx --vary A28=100:260:161``: many shots at once; its options are
its request's fields (:class:`airgun_xl.app.sweep.SweepRequest`)."""
from pathlib import Path

from .declared import add_declared, flags_named, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.sweep import SweepRequest

    p = sub.add_parser("sweep", help="run a grid of shots, a Monte Carlo or Sobol indices over "
                                     "uncertain inputs",
                       description="Evaluate a grid of shots (--vary; several make a grid), a "
                                   "Monte Carlo (--mc N with --sd) or Sobol sensitivity indices "
                                   "(--sobol N with --sd) with the batch kernel, on this "
                                   "machine's cores or on a Dask cluster (--scheduler, "
                                   "--workers); write the headline figures per shot, the "
                                   "charts, and the spread or the indices.")
    add_declared(p, SweepRequest)
    add_json(p, "the shots' figures and the spread")
    p.set_defaults(run=run)


def run(args):
    from ..app.sweep import SweepRequest, lines
    from ..app.sweep import run as sweep
    from .messages import report
    from .progress import count_bar

    shot_path = Path(args.shot)
    default = shot_path.with_name(shot_path.stem + ".sweep.xlsx")
    request = request_of(SweepRequest, args, output=args.output or default)
    with flags_named(SweepRequest):
        outcome = sweep(request, None if args.json else count_bar)
    return report(outcome, lines(request, outcome), args.json)
