"""Sheet XML for runs of numeric cells, the writer's fast path: the compiled
``_sheet_xml`` extension when it is built, else this module's Python twin (same text; a test
compares them). ``AIRGUN_XL_PURE=1`` forces the twin, as it does the kernel's."""
import math

from ..engine.kernel import PURE


def render_cells_python(column, first_row, values):
    """'<c r="I5"><v>...</v></c>' per value (finite), rows from ``first_row`` (1-based),
    numbers with 17 significant digits, as the C extension writes them."""
    out = []
    for i, x in enumerate(values.tolist() if hasattr(values, "tolist") else values):
        if not math.isfinite(x):
            raise ValueError(f"values must be finite (index {i})")
        out.append(f'<c r="{column}{first_row + i}"><v>{x:.17g}</v></c>')
    return out


try:
    if PURE:
        raise ImportError("AIRGUN_XL_PURE is set")
    from ._sheet_xml import render_cells
    COMPILED = True
except ImportError:
    render_cells = render_cells_python
    COMPILED = False
