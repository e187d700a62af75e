"""``airgun-xl check SHOT.xlsx``: can this shot's run be trusted? (No run, no output.) Its
options are its request's fields (:class:`airgun_xl.app.check.CheckRequest`)."""
from .declared import add_declared, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.check import CheckRequest

    p = sub.add_parser("check", help="predict stability and list the model's limits for a shot",
                       description="Predict the critical time step of the chosen scheme and "
                                   "list what the shot stretches (crush-factor range, filter, "
                                   "row count, masses). Exit 0 when it can run, 2 when the "
                                   "time step is unstable.")
    add_declared(p, CheckRequest)
    add_json(p, "the critical steps and the findings")
    p.set_defaults(run=run)


def run(args):
    from ..app.check import CheckRequest
    from ..app.check import run as check

    outcome = check(request_of(CheckRequest, args))
    print(outcome.to_json() if args.json else "\n".join(outcome.lines(args.shot,
                                                                         args.integrator)))
    return 0 if outcome.stable else 2
