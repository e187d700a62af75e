"""``airgun-xl design SHOT.xlsx --target-peak 12kG``: solve for the pulse a client asks for."""
from pathlib import Path

from ..choices import DESIGN_VARIABLES
from .cluster_options import add_cluster_options
from .fill import print_summary
from .run_options import (
    SHOT_HELP,
    add_crush_law,
    add_force,
    add_json,
    add_output,
    add_pdf,
    add_run_options,
)
from .spec_options import add_spec_options
from .vocabulary import Alias


def add_parser(sub):
    p = sub.add_parser("design", help="design a shot: to a target, to the middle of a "
                                      "specification, or most likely to pass it",
                       description="Design the shot and write it as a filled workbook, in one "
                                   "of three modes. With --target-peak (and --target-duration) "
                                   "or --target-srs: solve for the value of one parameter (two "
                                   "with a duration) that gives the target. Without a target, "
                                   "from a specification (the Specification sheet, a --profile "
                                   "or the options): the setting at the middle of the "
                                   "tolerances, whose smallest margin is largest. With "
                                   "--confidence P and the shot-to-shot scatter (--sd): the "
                                   "setting most likely to pass, its probability with a 95 % "
                                   "interval, and exit 3 when no setting reaches P.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    _add_targets(p)
    add_run_options(p)
    add_output(p, "designed shot, filled", "SHOT.design.xlsx")
    add_pdf(p, "the designed shot's report (the design, the Summary, the predicted verdict, "
               "the warnings and the charts)")
    add_force(p)
    add_cluster_options(p)
    add_spec_options(p)
    _add_first_shot(p)
    add_crush_law(p)
    add_json(p, "the design")
    p.set_defaults(run=run)


def _add_targets(p):
    """What is solved for, and to which target."""
    target = p.add_mutually_exclusive_group()
    target.add_argument("--target-peak", metavar="PEAK",
                        help="requested peak: 12kG, 11750g or 1.2e5m/s2")
    target.add_argument("--target-srs", metavar="REQ.csv",
                        help="required shock response spectrum (CSV: 'frequency [Hz],srs [g]'):"
                             " the least value whose SRS envelops it")
    p.add_argument("--q", dest="srs_q", metavar="Q", action=Alias, idea="SRS quality factor")
    p.add_argument("--accel-unit", help="the required SRS's unit, g, kG or m/s^2 (default: "
                                        "from its header)")
    p.add_argument("--target-duration", metavar="DURATION",
                   help="requested pulse duration (>= 10%% of peak): 5ms, 4500us; needs two "
                        "--vary")
    p.add_argument("--vary", action="append", metavar="CELL",
                   help=f"parameter to solve for: {', '.join(DESIGN_VARIABLES)} (A28: A28..A30 "
                        "together, the default)")
    p.add_argument("--range", metavar="LO:HI",
                   help="search range of the (first) varied parameter, in its unit")
    p.add_argument("--filtered", action="store_true", help="match the filtered peak")


def _add_first_shot(p):
    """First-shot success: the confidence asked, the scatter, the Monte Carlo's size."""
    first = p.add_argument_group("first-shot success (with a specification, no --target-*)")
    first.add_argument("--confidence", type=float, metavar="P",
                       help="find the setting most likely to pass with the scatter of --sd, "
                            "and say whether it reaches P (0.95): exit 3 if none does")
    first.add_argument("--sd", action="append", metavar="CELL=SD",
                       help="a cell's shot-to-shot scatter: A28=1.5%% (the gun), E40=5%% (the "
                            "lot), E43=10%% (zeta); repeatable")
    first.add_argument("--shots", type=int, default=10_000, metavar="N",
                       help="Monte Carlo shots a setting (default 10,000)")
    first.add_argument("--seed", type=int, default=1, help="of the draws (default 1)")


def request_of(args):
    """The :class:`~airgun_xl.app.design.DesignRequest` the command line asks for (its
    default output beside the shot)."""
    from ..app.design import DesignRequest
    from ..app.specifying import SpecFields

    return DesignRequest(
        Path(args.shot), args.target_peak, args.target_duration, args.target_srs,
        tuple(args.vary or ()), args.range, args.filtered, SpecFields.of(args),
        args.confidence, tuple(args.sd or ()), args.shots, args.seed, args.integrator,
        args.model, design_output(args), args.force, args.crush_law,
        Path(args.archive) if args.archive else None, args.scheduler, args.workers,
        args.chunk, tuple(args.argv), Path(args.pdf) if args.pdf else None)


def run(args):
    from ..app.design import run as design
    from .messages import note, warn
    from .progress import Progress, count_bar

    quiet = args.json  # a document on stdout: no bar on stderr either
    outcome = design(request_of(args), warn, note, None if quiet else Progress.for_rows,
                     None if quiet else count_bar)
    if args.json:
        print(outcome.to_json())
        return 0 if outcome.reached else 3
    for line in outcome.lines:
        print(line)
    print_summary(outcome.output, outcome.filled)
    return 0 if outcome.reached else 3


def design_output(args):
    """The designed shot's workbook: -o, or SHOT.design.xlsx beside the shot."""
    shot_path = Path(args.shot)
    return Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".design.xlsx")
