"""Template: a fresh shot A workbook in the report's layout, with live formulas.

:func:`run` takes a :class:`TemplateRequest`; the CLI (``airgun-xl template``) and the Python
API (:func:`airgun_xl.template`) are both this."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from . import declared


@dataclass(frozen=True, kw_only=True)
class TemplateRequest(declared.Checked):
    """Where the template goes, and whether an old file there may be replaced. Declared once
    (:mod:`.declared`): the command's options and the API's keywords."""

    output: Path = declared.positional("output", help="where to write the template",
                                       metavar="OUT.xlsx", read=declared.a_path)
    force: bool = declared.force()


def run(request: TemplateRequest) -> Path:
    """Write the template at the request's output (``force`` over an old one); the path
    written.

    Raises
    ------
    airgun_xl.errors.OutputError
        The file exists (without ``force``) or cannot be written.
    """
    from ..reports.template import write_template

    write_template(request.output, force=request.force)
    return request.output
