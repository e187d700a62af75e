"""``airgun-xl diff LEGACY NEW``: does the new engine give the legacy numbers?"""
import json

from .run_options import ATOL_HELP, RTOL_HELP, add_force, tolerance

DEFAULT_RTOL = 1e-12  # as airgun_xl.diff.DEFAULT_RTOL; the module loads only for a diff


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
    from ..diff import diff_workbooks, format_report
    from ..reports.diff_report import write_diff_report

    rtol, atol = tolerance("--rtol", args.rtol), tolerance("--atol", args.atol)
    if args.report:
        from ..transaction import check_output

        check_output(args.report, args.force, inputs=[args.legacy, args.new])
    report = diff_workbooks(args.legacy, args.new, rtol, atol)
    print(json.dumps(report.as_dict(), indent=1) if args.json else format_report(report))
    if args.report:
        write_diff_report(report, args.report, args.force)
    return 0 if report.same else 1
