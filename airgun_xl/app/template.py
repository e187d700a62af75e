"""Template: a fresh shot A workbook in the report's layout, with live formulas."""
from __future__ import annotations

from pathlib import Path


def run(output: str | Path, force: bool = False) -> Path:
    """Write the template at ``output`` (``force`` over an old one); the path written.

    Raises
    ------
    airgun_xl.errors.OutputError
        The file exists (without ``force``) or cannot be written.
    """
    from ..reports.template import write_template

    write_template(output, force=force)
    return Path(output)
