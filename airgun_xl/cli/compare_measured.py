"""``airgun-xl compare-measured SHOT.xlsx RECORDING``: the prediction against the test."""
from pathlib import Path

from .recording_options import RECORDING_HELP, add_recording_options
from .run_options import SHOT_HELP, add_crush_law, add_force, add_json, add_output, add_run_options


def add_parser(sub):
    p = sub.add_parser("compare-measured",
                       help="compare the shot's predicted pulse with a measured one (a "
                            "CSV, a workbook range or a recorder's file)",
                       description="Run the shot, read the measured pulse (a CSV of time and "
                                   "acceleration, units in the header: s/ms/us and g/kG/m/s^2), "
                                   "filter both alike (SAE J211), align them at the impact, "
                                   "and score the peak, its time, the pulse, the velocity "
                                   "change and their correlation.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("measured", metavar="RECORDING", help="the measured pulse: " + RECORDING_HELP)
    add_output(p, "scores and traces", "SHOT.measured.xlsx")
    add_force(p)
    add_recording_options(p)
    p.add_argument("--align", default="threshold", choices=("threshold", "xcorr"),
                   help="impact instant: where the zeroed pulse first holds 5%% of its peak "
                        "(or 5 sigma of its pre-trigger noise, if more) for 0.05 ms (default),"
                        " or the cross-correlation's best lag; each checks the other")
    add_run_options(p)
    add_crush_law(p)
    add_json(p, "the scores")
    p.set_defaults(run=run)


def run(args):
    from ..app.compare_measured import CompareMeasuredRequest, lines
    from ..app.compare_measured import run as compare_measured
    from .messages import report

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".measured.xlsx")
    request = CompareMeasuredRequest(
        shot_path, args.measured, args.cfc, args.align, args.anti_alias, args.sign,
        args.time_unit, args.accel_unit, args.channel, args.integrator, args.model, output,
        args.force, args.crush_law, Path(args.archive) if args.archive else None)
    outcome = compare_measured(request)
    return report(outcome, lines(request, outcome), args.json)
