"""``airgun-xl template OUT.xlsx [--force]``: write a fresh shot A template."""
import json

from .run_options import add_force, add_json


def add_parser(sub):
    p = sub.add_parser("template", help="write a fresh template in the report's layout (shot A)",
                       description="Write the report's parameter sheet, filled with shot A as "
                                   "the report's appendix ran it, with live formulas.")
    p.add_argument("output", metavar="OUT.xlsx", help="where to write the template")
    add_force(p)
    add_json(p, "the file written")
    p.set_defaults(run=run)


def run(args):
    from ..app.template import run as template

    written = template(args.output, args.force)
    print(json.dumps({"files": [str(written)]}) if args.json else f"wrote {args.output}")
    return 0
