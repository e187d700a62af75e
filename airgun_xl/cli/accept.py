"""``airgun-xl accept SHOT.xlsx RECORDING``: did the fired shot meet its specification?

Exit 0 on PASS, 3 on FAIL (:data:`FAIL_EXIT`), 4 on NOT JUDGED (:data:`NOT_JUDGED_EXIT`: the
record cannot show a criterion and none failed), 2 for bad input."""
from pathlib import Path

from ..app.declared import ReportFields
from .declared import add_declared
from .recording_options import RECORDING_HELP, add_recording_options
from .run_options import SHOT_HELP, add_crush_law, add_force, add_json, add_output, add_pdf
from .spec_options import RECORD_HELP, add_spec_options
from .vocabulary import One

#: The exit status of a shot that fails its specification (2 stays for bad input).
FAIL_EXIT = 3

#: The exit status of a recording that cannot show a criterion, none failing (issue 63).
NOT_JUDGED_EXIT = 4


def add_parser(sub):
    p = sub.add_parser("accept", help="judge a recording against the shot's specification: "
                                      "PASS or FAIL, criterion by criterion",
                       description="Read the recording (as compare-measured does), judge it "
                                   "against the specification (the shot's Specification "
                                   "sheet, a --profile, the options): peak, duration, velocity"
                                   " change, the corridor round the ideal pulse and the SRS; "
                                   "write the verdict workbook. Exit 0 on PASS, 3 on FAIL, 4 "
                                   "on NOT JUDGED.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("recording", metavar="RECORDING", help="the recorded pulse: " + RECORDING_HELP)
    add_output(p, "verdict workbook", "SHOT.accept.xlsx")
    add_pdf(p, "the client's test report (the verdict, the criteria, the warnings, the "
               "sources, the charts and a signature block)")
    p.add_argument("--reproducible", action="store_true",
                   help="leave the date out of the PDF: the same run gives the same bytes")
    add_force(p)
    add_declared(p, ReportFields)
    add_recording_options(p, anti_alias=False, cfc_help=(
        RECORD_HELP + ", over the sheet's and the profile's (refused where the filter is "
        "unstable, below 4.155 x the class in samples a second; a warning below J211's 10 x)"))
    add_spec_options(p, cfc=False)
    p.add_argument("--archive", metavar="DIR", action=One,
                   help="record the verdict in the archive (the verdict file of the shot's "
                        "next entry), and the library --crush-law NAME is read from")
    add_crush_law(p, archive=False)
    add_json(p, "the verdict (criteria, tolerances, warnings, files written)")
    p.set_defaults(run=run)


def request_of(args):
    """The :class:`~airgun_xl.app.accept.AcceptRequest` the command line asks for (its
    default output beside the shot)."""
    from ..app.accept import AcceptRequest
    from ..app.specifying import SpecFields
    from .declared import request_of as declared_request

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".accept.xlsx")
    return AcceptRequest(shot_path, args.recording, SpecFields.of(args), output, args.force,
                         Path(args.archive) if args.archive else None, args.channel, args.sign,
                         args.time_unit, args.accel_unit, tuple(args.argv), args.crush_law,
                         Path(args.pdf) if args.pdf else None, args.reproducible,
                         event=args.event, at=args.at,
                         test=declared_request(ReportFields, args))


def run(args):
    from ..app.accept import lines
    from ..app.accept import run as accept
    from .messages import report

    request = request_of(args)
    outcome = accept(request)
    word = outcome.verdict.word
    return report(outcome, lines(request, outcome), args.json,
                  0 if word == "PASS" else FAIL_EXIT if word == "FAIL" else NOT_JUDGED_EXIT)
