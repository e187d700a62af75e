"""``airgun-xl next SHOT.xlsx RECORDING --archive DIR --lot NAME --sd A28=1.5%``: the closed
loop. Exit 0 when the setting proposed reaches ``--confidence``, 3 when none does (the best
is still written), 2 for bad input (nothing written or recorded)."""
from pathlib import Path

from .cluster_options import add_cluster_options
from .recording_options import RECORDING_HELP, add_recording_options
from .run_options import SHOT_HELP, add_force, add_integrator, add_json, add_output, add_pdf
from .spec_options import RECORD_HELP, add_spec_options
from .vocabulary import One

#: The exit status when no setting reaches the confidence asked.
NOT_REACHED = 3


#: What ``next --help`` says the command does.
DESCRIPTION = ("Judge the fired shot as accept does; update the lot's crush law on every shot "
               "of the lot in the archive and this one (its scale; its tilt with speed once "
               "the shots spread over speed; the law whole where 3 such shots show a shape "
               "the scale and tilt cannot follow; each with its covariance); choose the A28 "
               "most likely to pass with the gun's scatter (--sd, or estimated from the shots "
               "of the lot or, with --gun, of every lot of that gun) and the law "
               "drawn from its update; write NEXT.xlsx (fill runs it as it is) and keep the "
               "verdict, the law's new version and the proposal in the archive. Exit 0 when "
               "P(PASS) reaches --confidence, 3 when not (the best is written).")


def add_parser(sub):
    p = sub.add_parser("next", help="the closed loop: judge the fired shot, update the lot's "
                                    "law, and write the next shot most likely to pass",
                       description=DESCRIPTION)
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP + " (the shot fired)")
    p.add_argument("recording", metavar="RECORDING", help="its recorded pulse: "
                   + RECORDING_HELP)
    p.add_argument("--archive", metavar="DIR", action=One, required=True,
                   help="the lab's archive: the lot's law and shots, and where this is kept")
    p.add_argument("--lot", metavar="NAME", action=One, required=True,
                   help="the honeycomb lot, e.g. LOT-2026-07 (its law in the archive)")
    p.add_argument("--new-lot", action="store_true",
                   help="start the lot: its prior is the report's law")
    p.add_argument("--sd", action="append", metavar="CELL=SD",
                   help="the gun's scatter, A28=1.5%% (needed), and zeta's, E43=10%%")
    _add_knobs(p)
    p.add_argument("--confidence", type=float, default=0.9, metavar="P",
                   help="the P(PASS) asked of the next shot (default 0.9): exit 3 below it")
    p.add_argument("--shots", type=int, default=2000, metavar="N",
                   help="Monte Carlo draws a setting (default 2,000)")
    p.add_argument("--seed", type=int, default=1, help="of the draws (default 1)")
    add_output(p, "next shot's workbook", "SHOT.next.xlsx")
    add_pdf(p, "the next shot's report (the proposal and its P(PASS), the Summary, the "
               "warnings and the charts)")
    add_force(p)
    add_recording_options(p, anti_alias=False, cfc_help=RECORD_HELP)
    add_spec_options(p, cfc=False)
    add_integrator(p)
    add_cluster_options(p)
    add_json(p, "the verdict, the law's update and the next setting")
    p.set_defaults(run=run)


def _add_knobs(p):
    """The gun, the second knob and what each can be set to."""
    p.add_argument("--gun", metavar="NAME", action=One,
                   help="the gun that fires the lot: its scatter is estimated from the launch "
                        "velocities of every lot fired with the same --gun (each lot's shots "
                        "about their own mean) once they hold 7 shots beyond each lot's first")
    p.add_argument("--vary", metavar="CELL", action=One,
                   help="a second knob set with A28 for the duration: E13, E16 or A2 "
                        "(a lot whose strength differs from the law's cannot meet a peak "
                        "and a duration by A28 alone)")
    p.add_argument("--step", action="append", metavar="CELL=STEP",
                   help="what a knob can be set to: A28=0.5 (m/s) sets A28 to a multiple of "
                        "0.5 (and the --vary knob, in its unit); the best of the settable "
                        "neighbours of the best found, on the same draws")


def request_of(args):
    from ..app.next_shot import NextRequest
    from ..app.specifying import SpecFields

    return NextRequest(Path(args.shot), args.recording, Path(args.archive), args.lot,
                       SpecFields.of(args), args.new_lot, tuple(args.sd or ()),
                       args.confidence, args.shots, args.seed, args.channel, args.sign,
                       args.time_unit, args.accel_unit, args.integrator,
                       Path(args.output) if args.output else None, args.force,
                       tuple(args.argv), args.vary, args.scheduler, args.workers,
                       args.chunk, Path(args.pdf) if args.pdf else None, args.gun,
                       tuple(args.step or ()), event=args.event, at=args.at)


def run(args):
    from ..app.next_shot import lines
    from ..app.next_shot import run as next_shot
    from .messages import report

    request = request_of(args)
    outcome = next_shot(request)
    return report(outcome, lines(request, outcome), args.json,
                  0 if outcome.reached else NOT_REACHED)
