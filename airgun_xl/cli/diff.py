"""``airgun-xl diff LEGACY NEW``: does the new engine give the legacy numbers? Its options
are its request's fields (:class:`airgun_xl.app.diff.DiffRequest`)."""
import json

from .declared import add_declared, request_of


def add_parser(sub):
    from ..app.diff import DiffRequest

    p = sub.add_parser("diff", help="compare a legacy workbook with a new one",
                       description="Compare the parameter cells, then every result column of "
                                   "two filled workbooks (.xlsx, .xlsm or .xls). Exit 0 within "
                                   "tolerance, 1 when they differ, 2 for bad input.")
    add_declared(p, DiffRequest, skip=("report", "force"))
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    add_declared(p, DiffRequest, only=("report", "force"))
    p.set_defaults(run=run)


def run(args):
    from ..app.diff import DiffRequest, format_report
    from ..app.diff import run as diff

    outcome = diff(request_of(DiffRequest, args))
    report = outcome.report
    print(json.dumps(report.as_dict(), indent=1) if args.json else format_report(report))
    return 0 if report.same else 1
