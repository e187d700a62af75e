"""``airgun-xl template OUT.xlsx [--force]``: write a fresh shot A template; its options are
its request's fields (:class:`airgun_xl.app.template.TemplateRequest`)."""
import json

from .declared import add_declared, request_of
from .run_options import add_json


def add_parser(sub):
    from ..app.template import TemplateRequest

    p = sub.add_parser("template", help="write a fresh template in the report's layout (shot A)",
                       description="Write the report's parameter sheet, filled with shot A as "
                                   "the report's appendix ran it, with live formulas.")
    add_declared(p, TemplateRequest)
    add_json(p, "the file written")
    p.set_defaults(run=run)


def run(args):
    from ..app.template import TemplateRequest
    from ..app.template import run as template

    written = template(request_of(TemplateRequest, args))
    print(json.dumps({"files": [str(written)]}) if args.json else f"wrote {args.output}")
    return 0
