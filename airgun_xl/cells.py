"""The cell map: every parameter cell ArtSim reads, as one table.

ArtSim (ARL-TR-3559, Appendix A) reads its inputs from fixed cells of the active sheet and starts
its result columns at H1. This table is the single place that knows those addresses. Each row
gives the cell, the field name used in :class:`airgun_xl.params.ShotParams`, the label the
report's sheet shows next to it, the unit, what it means, and the check applied on reading.

Checks
------
``positive``     finite and > 0
``negative``     finite and < 0 (stiffness cells are negative by the sheet's convention)
``nonnegative``  finite and >= 0
``fraction``     finite, > 0 and <= 1
``any``          finite

``plausible`` is the range of magnitudes a real air gun shot has (a non-zero value outside it
is warned about, naming the cell: a value typed in another unit, such as E40 in psi, is
three orders of magnitude off). ``limit`` bounds the magnitude. The limits are far beyond
any air gun shot; they exist so that a typo such as ``1e300`` is reported on its cell instead
of overflowing somewhere in the kernel.
``floor`` does the same at the other end for cells whose tiny values overflow a quotient: a
mass of 1e-300 kg, a filter frequency of 5e-324 Hz, a radius or wedge of 1e-300 m.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Cell:
    address: str
    name: str
    label: str
    unit: str
    meaning: str
    check: str
    limit: float
    alternative: str = ""  # a second accepted form, for the reduced models
    floor: float = 0.0  # smallest magnitude of a non-zero value (0: none)
    plausible: tuple = ()  # (low, high) magnitudes of a real air gun shot; outside: a warning


#: The parameter cells, in the order the macro reads them (ArtSim.bas, head of the Sub).
CELLS = (
    Cell("A2", "m1", "M1", "kg", "MEM mass, without the mitigator", "positive", 1e9,
         floor=1e-6,
         plausible=(1.0, 100000.0)),
    Cell("B2", "m31", "M31", "kg", "OBR front plate mass", "positive", 1e9, floor=1e-6,
         plausible=(0.001, 1000.0)),
    Cell("C2", "m32", "M32", "kg", "OBR back plate mass", "positive", 1e9,
         "blank or 0 with B6, C6 blank and D2 blank or 0, for an OBR of one mass", 1e-6,
         plausible=(0.001, 1000.0)),
    Cell("D2", "m33", "M33", "kg", "test item mass", "positive", 1e9,
         "blank or 0 with C6 blank, for a scene without a test item", 1e-6,
         plausible=(0.001, 1000.0)),
    Cell("B6", "k2", "K2", "N/m", "spring between m31 and m32, negative by the sheet's convention",
         "negative", 1e16, "blank with C2, C6 and D2 blank, for an OBR of one mass",
         plausible=(10000.0, 1e14)),
    Cell("C6", "k3", "K3", "N/m", "spring between m32 and m33, negative by the sheet's convention",
         "negative", 1e16, "blank with D2 blank or 0, for a scene without a test item",
         plausible=(10000.0, 1e14)),
    Cell("E2", "delta", "Timestep", "s", "time step", "positive", 1.0),
    Cell("E6", "max_time", "Max Time", "s", "simulated duration", "positive", 1e3,
         plausible=(0.0001, 1.0)),
    Cell("E10", "rho", "Density of Honeycomb", "kg/m^3", "honeycomb density", "positive", 1e5,
         plausible=(5.0, 3000.0)),
    Cell("E13", "rcone", "Radius of Mitigator", "m", "mitigator radius", "positive", 10.0,
         floor=1e-6,
         plausible=(0.001, 2.0)),
    Cell("E16", "hcone", "Length of Wedge Part", "m",
         "wedge (cone) length; 0 for a plain cylinder of honeycomb", "nonnegative", 100.0,
         floor=1e-6,
         plausible=(0.0001, 5.0)),
    Cell("E19", "hcylinder", "Length of Cylindrical Part", "m", "cylinder length",
         "nonnegative", 100.0,
         plausible=(0.001, 5.0)),
    Cell("E25", "mmitigator", "Mass of Mitigator", "kg", "mitigator mass, added to M1",
         "nonnegative", 1e9,
         plausible=(0.001, 10000.0)),
    Cell("E28", "vcone", "Volume of Conical Mitigator", "m^3",
         "initial crushed 'volume', used by the macro as a mass term", "nonnegative", 1e3),
    Cell("E31", "E", "Elastic Modulus of Mitigator", "Pa", "elastic modulus for unloading",
         "positive", 1e13,
         plausible=(1e06, 1e12)),
    Cell("E34", "filter_frequency", "Filter Frequency", "Hz",
         "sampling frequency of the filtered acceleration", "positive", 1e12, floor=1e-6,
         plausible=(10.0, 1e08)),
    Cell("E37", "ec", "Compacting Strain", "", "honeycomb compacting strain", "fraction", 1.0),
    Cell("E40", "sigmay", "Yield Stress", "Pa", "honeycomb static crush stress", "positive", 1e12,
         plausible=(10000.0, 1e09)),
    Cell("E43", "zeta", "Damping Factor (Zeta)", "", "damping ratio of the OBR springs",
         "nonnegative", 1e3,
         plausible=(1e-05, 2.0)),
    Cell("A27", "v1", "Initial Velocity Matrix (Y1)", "m/s", "MEM initial velocity", "any", 1e4,
         plausible=(0.001, 1000.0)),
    Cell("A28", "v31", "Initial Velocity Matrix (Y31)", "m/s", "OBR front plate initial velocity",
         "any", 1e4,
         plausible=(0.001, 1000.0)),
    Cell("A29", "v32", "Initial Velocity Matrix (Y32)", "m/s", "OBR back plate initial velocity",
         "any", 1e4,
         plausible=(0.001, 1000.0)),
    Cell("A30", "v33", "Initial Velocity Matrix (Y33)", "m/s", "test item initial velocity",
         "any", 1e4,
         plausible=(0.001, 1000.0)),
)

#: K1 (A6): on the report's sheet, but never read by the macro, which computes k1 from E13,
#: E31, E16 and E19 (ArtSim.bas, head of the Sub); a value there changes nothing.
UNUSED_K1 = "A6"

#: The cell where the macro starts writing (its ActiveCell); it must be blank or hold "Time".
TIME_HEADER = Cell("H1", "time_header", "Time", "", "first result column header", "text", 0.0)

BY_ADDRESS = {c.address: c for c in CELLS}
BY_ADDRESS[UNUSED_K1] = Cell(UNUSED_K1, "k1", "K1", "N/m", "not read by the macro", "any", 0.0)
BY_NAME = {c.name: c for c in CELLS}


def address(name: str) -> str:
    """The cell that holds the shot's field ``name``: ``address("delta") == "E2"``. Code names
    a parameter cell through this (or :data:`BY_NAME`), never by a literal address, so the
    table stays the one place that knows the layout (tests/test_cell_table.py)."""
    return BY_NAME[name].address

#: Most steps a run may take: ~100 bytes a step keep 5e7 steps within a few GB of memory.
MAX_STEPS = 50_000_000

#: Columns of the parameter block copied to the output (the macro writes from H on).
PARAMETER_COLUMNS = 7

_NOUNS = {"kg": "kg", "N/m": "N/m", "s": "seconds", "kg/m^3": "kg/m^3", "m": "metres",
          "m^3": "m^3", "Pa": "Pa", "Hz": "Hz", "m/s": "m/s", "": ""}


def expectation(cell):
    """The 'expected ...' phrase for a cell, e.g. ``'a positive number of seconds'``."""
    noun = _NOUNS[cell.unit]
    of = f" of {noun}" if noun else ""
    base = {
        "positive": f"a positive number{of}",
        "negative": f"a negative number{of} (the sheet's sign convention)",
        "nonnegative": f"zero or a positive number{of}",
        "fraction": "a number greater than 0 and at most 1",
        "any": f"a number{of}",
    }[cell.check]
    if cell.check != "fraction" and cell.floor:
        base = f"{base}, from {cell.floor:g} to {cell.limit:g} in magnitude"
    elif cell.check != "fraction":
        base = f"{base}, at most {cell.limit:g} in magnitude"
    return f"{base}; or {cell.alternative}" if cell.alternative else base
