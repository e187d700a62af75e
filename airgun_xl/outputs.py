"""Which outputs a fill writes: the `Outputs` block of a workbook, overridden by CLI flags.

The block is a small table on a sheet named ``Outputs``: column A names an output, column B
says whether to write it (TRUE/FALSE) or gives a number. The template carries it with the
defaults. Groups of sheet 1 columns and whole sheets can be left out; nothing left out is
computed beyond what the selected outputs need.
"""
from dataclasses import dataclass, field, replace

from . import choices
from .choices import TRACKED
from .errors import OptionError
from .limits import MAX_EVERY

#: Output groups: name -> what it writes.
GROUPS = {
    "positions": "Sheet 1, H..L: time and the four displacements; final masses below I",
    "crush": "Sheet 1, M..P: crush factor, M31, mitigator deflection, plastic front",
    "accel": "Sheet 1, R..U: test-item acceleration, velocity, acceleration in kG",
    "filtered": "Sheet 1, AA..AB: the macro's filtered acceleration",
    "tracked": "Tracked sheet: force, plastic front, deflection, masses, velocities",
    "spectrum": "Spectrum sheet: amplitude spectrum of the acceleration, 0-15 kHz",
    "summary": "Summary sheet: peak, pulse, crush, frequencies, provenance",
    "charts": "Charts sheet: the report's figures for this shot",
}

#: Step values each group needs from the kernel.
_NEEDS = {
    "crush": {"crush_factor", "m31", "deflection", "x_plastic"},
    "tracked": set(TRACKED),
    "summary": {"deflection", "v31", "v1"},
    "charts": {"force", "deflection", "x_plastic", "v31", "v1"},
}

#: Rows a sheet holds: 1,048,576 less the header and the final-mass rows below the data.
SHEET_DATA_ROWS = 1_048_576 - 4

#: Default most rows written to a sheet; a longer run writes every N-th row and a sidecar.
#: It is the legacy macro's own limit (a VB Integer row counter), so a sheet never holds more
#: than its users have seen; `max sheet rows` raises it up to the sheet's limit.
DEFAULT_MAX_SHEET_ROWS = 32_767

SIDECAR_MODES = choices.SIDECAR_MODES
SHEET_NAME = "Outputs"


@dataclass(frozen=True)
class Outputs:
    """The selected outputs.

    Attributes
    ----------
    groups : frozenset of str
        Names from :data:`GROUPS`.
    every : int
        Write every N-th time row to the sheets (1 = all).
    max_sheet_rows : int
        Most time rows on a sheet; beyond, ``every`` grows to fit.
    sidecar : str
        ``auto``: write the full history beside the output when the sheets leave rows out;
        ``always`` or ``never``.
    """

    groups: frozenset = field(default_factory=lambda: frozenset(GROUPS))
    every: int = 1
    max_sheet_rows: int = DEFAULT_MAX_SHEET_ROWS
    sidecar: str = "auto"

    def __contains__(self, group):
        return group in self.groups

    def stride(self, rows):
        """Rows step N for a run of ``rows`` time rows: ``every``, raised to fit the sheet."""
        limit = min(self.max_sheet_rows, SHEET_DATA_ROWS)
        return max(self.every, -(-rows // limit))

    def tracked_series(self, sidecar=False):
        """Step values the kernel must record for these outputs (all of them for a sidecar)."""
        if sidecar:
            return frozenset(TRACKED)
        needed = set()
        for group in self.groups:
            needed |= _NEEDS.get(group, set())
        return frozenset(needed)

    def writes_sidecar(self, rows):
        return self.sidecar == "always" or (self.sidecar == "auto" and self.stride(rows) > 1)

    def with_flags(self, only=None, no_charts=False, every=None, max_sheet_rows=None,
                   sidecar=None):
        """These outputs overridden by the CLI flags that were given."""
        out = self
        if only is not None:
            out = replace(out, groups=parse_groups(only))
        if no_charts:
            out = replace(out, groups=out.groups - {"charts"})
        if every is not None:
            out = replace(out, every=positive_int("--every", every))
        if max_sheet_rows is not None:
            out = replace(out, max_sheet_rows=positive_int("--max-sheet-rows", max_sheet_rows))
        if sidecar is not None:
            out = replace(out, sidecar=sidecar)
        return out


def parse_groups(text):
    """``"accel,filtered"`` -> frozenset; unknown names are an :class:`OptionError`."""
    names = [n.strip() for n in str(text).split(",") if n.strip()]
    unknown = [n for n in names if n not in GROUPS]
    if unknown or not names:
        raise OptionError(f"--only: found {text!r}, expected a comma-separated list of "
                          f"{', '.join(GROUPS)}")
    return frozenset(names)


def positive_int(option, value, most=MAX_EVERY):
    """A whole number from 1 to ``most`` from a flag or cell (``3``, ``3.0``, ``"3"``)."""
    number = None
    if not isinstance(value, bool):
        try:
            as_float = float(value)
            number = int(as_float) if as_float.is_integer() else None
        except (TypeError, ValueError, OverflowError):
            number = None
    if number is None or not 1 <= number <= most:
        raise OptionError(f"{option}: found {value!r}, expected a whole number from 1 to "
                          f"{most:,}")
    return number


#: Row labels of the block, as the template writes them, in order.
BLOCK_ROWS = tuple(GROUPS) + ("every", "max sheet rows", "sidecar")


def block_cells(outputs=Outputs()):
    """``[(label, value, description)]`` rows of the Outputs block, for the template."""
    rows = [(g, g in outputs, desc) for g, desc in GROUPS.items()]
    rows += [("every", outputs.every, "write every N-th time row (1 = all)"),
             ("max sheet rows", outputs.max_sheet_rows,
              "beyond this many time rows, write every N-th row and the full history "
              f"to a sidecar (a sheet holds {SHEET_DATA_ROWS:,})"),
             ("sidecar", outputs.sidecar,
              "full history beside the output (.parquet, else .csv): auto, always or never")]
    return rows


def _flag(cell, value):
    """A switch of the block: TRUE or FALSE, or the number 1 or 0 a boolean is stored as in
    an .xls that LibreOffice writes (a number in a boolean format, which the .xls reader does
    not see), or as text."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)) and value in (0, 1):
        return bool(value)
    text = str(value).strip().lower() if value is not None else ""
    if text in ("true", "yes", "1"):
        return True
    if text in ("false", "no", "0"):
        return False
    raise OptionError(f"{cell}: found {value!r}, expected TRUE or FALSE")


def from_sheet(cells):
    """Read the Outputs block from a sheet's ``{(row, col): (value, formula)}`` cells.

    Rows whose column A is not a known label are ignored; a missing row keeps its default.

    Raises
    ------
    OptionError
        Naming the cell (``Outputs!B4 (charts)``) with a value it cannot use.
    """
    out = Outputs()
    groups = set(out.groups)
    for (row, col), (label, _) in sorted(cells.items()):
        if col != 1 or not isinstance(label, str) or label.strip().lower() not in BLOCK_ROWS:
            continue
        name = label.strip().lower()
        value = cells.get((row, 2), (None, None))[0]
        where = f"{SHEET_NAME}!B{row} ({name})"
        if name in GROUPS:
            (groups.add if _flag(where, value) else groups.discard)(name)
        elif name == "every":
            out = replace(out, every=positive_int(where, value))
        elif name == "max sheet rows":
            out = replace(out, max_sheet_rows=positive_int(where, value))
        elif name == "sidecar":
            mode = str(value).strip().lower() if value is not None else ""
            if mode not in SIDECAR_MODES:
                raise OptionError(f"{where}: found {value!r}, expected one of "
                                  f"{', '.join(SIDECAR_MODES)}")
            out = replace(out, sidecar=mode)
    return replace(out, groups=frozenset(groups))
