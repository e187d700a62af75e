"""``airgun-xl compare-measured SHOT.xlsx RECORDING``: the prediction against the test; its
options are its request's fields
(:class:`airgun_xl.app.compare_measured.CompareMeasuredRequest`)."""
from pathlib import Path

from .declared import add_declared, flags_named, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.compare_measured import CompareMeasuredRequest

    p = sub.add_parser("compare-measured",
                       help="compare the shot's predicted pulse with a measured one (a "
                            "CSV, a workbook range or a recorder's file)",
                       description="Run the shot, read the measured pulse (a CSV of time and "
                                   "acceleration, units in the header: s/ms/us and g/kG/m/s^2), "
                                   "filter both alike (SAE J211), align them at the impact, "
                                   "and score the peak, its time, the pulse, the velocity "
                                   "change and their correlation.")
    add_declared(p, CompareMeasuredRequest)
    add_json(p, "the scores")
    p.set_defaults(run=run)


def run(args):
    from ..app.compare_measured import CompareMeasuredRequest, lines
    from ..app.compare_measured import run as compare_measured
    from .messages import report

    shot_path = Path(args.shot)
    default = shot_path.with_name(shot_path.stem + ".measured.xlsx")
    request = request_of(CompareMeasuredRequest, args, output=args.output or default)
    with flags_named(CompareMeasuredRequest):
        outcome = compare_measured(request)
    return report(outcome, lines(request, outcome), args.json)
