"""Sheet XML for runs of numeric cells, the writer's fast path: the compiled
``_sheet_xml`` extension when it is built, else this module's Python twin (same text; a test
compares them). ``AIRGUN_XL_PURE=1`` forces the twin, as it does the kernel's."""
import math

from ..engine._reference import float64_count
from ..engine.kernel import PURE


def render_cells_python(column, first_row, values, style=-1):
    """'<c r="I5"><v>...</v></c>' per value (finite), rows from ``first_row`` (1-based),
    numbers with 17 significant digits, as the C extension writes them (with ``style`` >= 0,
    the cell's style index: ``<c r="I5" s="3">``); refusing what it refuses (a column name
    past 8 characters, a buffer that is not float64)."""
    if len(column) > 8:
        raise ValueError("column name too long")
    float64_count(values, writable=False, refusal="values must be a float64 buffer")
    out = []
    styled = f' s="{style}"' if style >= 0 else ""
    for i, x in enumerate(memoryview(values).tolist()):
        if not math.isfinite(x):
            raise ValueError(f"values must be finite (index {i})")
        out.append(f'<c r="{column}{first_row + i}"{styled}><v>{x:.17g}</v></c>')
    return out


try:
    if PURE:
        raise ImportError("AIRGUN_XL_PURE is set")
    from ._sheet_xml import render_cells
    COMPILED = True
except ImportError:
    render_cells = render_cells_python
    COMPILED = False
