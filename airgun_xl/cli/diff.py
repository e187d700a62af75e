"""``airgun-xl diff LEGACY NEW``: does the new engine give the legacy numbers?"""
import json

from .run_options import ATOL_HELP, RTOL_HELP, add_force, tolerance

DEFAULT_RTOL = 1e-12  # as airgun_xl.app.diff.DEFAULT_RTOL; the module loads only for a diff


def add_parser(sub):
    p = sub.add_parser("diff", help="compare a legacy workbook with a new one",
                       description="Compare the parameter cells, then every result column of "
                                   "two filled workbooks (.xlsx, .xlsm or .xls). Exit 0 within "
                                   "tolerance, 1 when they differ, 2 for bad input.")
    p.add_argument("legacy", metavar="LEGACY",
                   help="the workbook the macro filled (the reference)")
    p.add_argument("new", metavar="NEW", help="the workbook airgun-xl fill wrote")
    p.add_argument("--rtol", default=str(DEFAULT_RTOL), help=RTOL_HELP)
    p.add_argument("--atol", default="0", help=ATOL_HELP)
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--report", metavar="REPORT.xlsx",
                   help="also write a workbook: error table and the worst column's curves")
    add_force(p, "REPORT.xlsx")
    p.set_defaults(run=run)


def run(args):
    from ..app.diff import format_report
    from ..app.diff import run as diff

    rtol, atol = tolerance("--rtol", args.rtol), tolerance("--atol", args.atol)
    if args.report:  # refused before the comparison, not after its text is printed
        from ..app.diff import check_report

        check_report(args.report, args.force, [args.legacy, args.new])
    outcome = diff(args.legacy, args.new, rtol, atol)
    report = outcome.report
    print(json.dumps(report.as_dict(), indent=1) if args.json else format_report(report))
    if args.report:
        from ..app.diff import write_report

        write_report(report, args.report, args.force)
    return 0 if report.same else 1
