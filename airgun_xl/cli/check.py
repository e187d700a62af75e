"""``airgun-xl check SHOT.xlsx``: can this shot's run be trusted? (No run, no output.)"""
from .run_options import add_integrator, add_json


def add_parser(sub):
    p = sub.add_parser("check", help="predict stability and list the model's limits for a shot",
                       description="Predict the critical time step of the chosen scheme and "
                                   "list what the shot stretches (crush-factor range, filter, "
                                   "row count, masses). Exit 0 when it can run, 2 when the "
                                   "time step is unstable.")
    p.add_argument("shot", metavar="SHOT.xlsx", help="workbook in the report's layout")
    add_integrator(p)
    add_json(p, "the critical steps and the findings")
    p.set_defaults(run=run)


def run(args):
    from pathlib import Path

    from ..app.check import CheckRequest
    from ..app.check import run as check

    outcome = check(CheckRequest(Path(args.shot), args.integrator))
    print(outcome.to_json() if args.json else "\n".join(outcome.lines(args.shot,
                                                                         args.integrator)))
    return 0 if outcome.stable else 2
