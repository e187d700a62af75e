"""``airgun-xl convergence SHOT.xlsx``: error against time step and run time; its options are
its request's fields (:class:`airgun_xl.app.convergence.ConvergenceRequest`)."""
from pathlib import Path

from .declared import add_declared, flags_named, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.convergence import ConvergenceRequest

    p = sub.add_parser("convergence", help="run a shot over a ladder of time steps",
                       description="Run the shot at each time step of a ladder, report each "
                                   "figure's error against the finest level (with Richardson "
                                   "extrapolation and the observed order), recommend the "
                                   "coarsest time step that meets --rtol on the peak, and "
                                   "write a workbook and a PNG of error against run time.")
    add_declared(p, ConvergenceRequest)
    add_json(p, "the ladders")
    p.set_defaults(run=run)


def run(args):
    from ..app.convergence import ConvergenceRequest, lines
    from ..app.convergence import run as convergence
    from .messages import report

    shot_path = Path(args.shot)
    default = shot_path.with_name(shot_path.stem + ".convergence.xlsx")
    request = request_of(ConvergenceRequest, args, output=args.output or default)
    with flags_named(ConvergenceRequest):
        outcome = convergence(request)
    return report(outcome, lines(request, outcome), args.json)
