"""``airgun-xl convergence SHOT.xlsx``: error against time step and run time."""
from pathlib import Path

from .run_options import (
    SHOT_HELP,
    add_crush_law,
    add_force,
    add_integrator,
    add_json,
    add_output,
)


def add_parser(sub):
    p = sub.add_parser("convergence", help="run a shot over a ladder of time steps",
                       description="Run the shot at each time step of a ladder, report each "
                                   "figure's error against the finest level (with Richardson "
                                   "extrapolation and the observed order), recommend the "
                                   "coarsest time step that meets --rtol on the peak, and "
                                   "write a workbook and a PNG of error against run time.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("--levels", help="comma-separated time steps, e.g. 5us,2us,1us,500ns "
                                    "(default: the sheet's E2, then 1-2-5 steps down to 5ns)")
    add_integrator(p, repeated=True)
    p.add_argument("--rtol", default="1e-3", help="tolerance on the peak (default 0.1%%)")
    add_output(p, "workbook; the PNG goes beside it", "SHOT.convergence.xlsx")
    add_force(p)
    add_crush_law(p)
    add_json(p, "the ladders")
    p.set_defaults(run=run)


def run(args):
    from ..app.convergence import ConvergenceRequest, lines
    from ..app.convergence import run as convergence
    from .messages import report

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".convergence.xlsx")
    request = ConvergenceRequest(shot_path, args.levels, tuple(args.integrator), args.rtol,
                                 output, args.force, args.crush_law,
                                 Path(args.archive) if args.archive else None)
    outcome = convergence(request)
    return report(outcome, lines(request, outcome), args.json)
