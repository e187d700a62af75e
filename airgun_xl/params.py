"""A shot's parameters, checked in one place.

:class:`ShotParams` holds the values of the cells in :data:`airgun_xl.cells.CELLS`, in SI units,
with the sign conventions of the legacy sheet. :func:`check_value` and :meth:`ShotParams.check`
are the only input checks; readers and the API call them, the kernel trusts them.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from .cells import BY_NAME, CELLS, MAX_STEPS, address, expectation
from .choices import UNLOADINGS
from .crush_law import LEGACY_LAW, CrushLaw
from .errors import CellError, OptionError


class Found(str):
    """A reader's own description of what a cell holds, used verbatim in messages."""


def describe(raw):
    """How a raw cell value is named in an error message."""
    if isinstance(raw, Found):
        return str(raw)
    if raw is None or (isinstance(raw, str) and raw.strip() == ""):
        return "a blank cell"
    if isinstance(raw, bool):
        return "TRUE" if raw else "FALSE"
    if isinstance(raw, str) and raw.startswith("#"):
        return f"the error {raw}"
    if isinstance(raw, str):
        return repr(raw)
    if isinstance(raw, float) and not math.isfinite(raw):
        return f"the non-finite value {raw}"
    return repr(raw)


def check_value(cell, raw):
    """Check one raw cell value against its row of the cell map.

    Parameters
    ----------
    cell : airgun_xl.cells.Cell
        The cell's row of the map.
    raw : object
        The value as read: a number, a string, None for blank, or an error string like ``#DIV/0!``.

    Returns
    -------
    float
        The value, as a float.

    Raises
    ------
    CellError
        When the value is not a number, not finite, or outside the cell's check.
    """
    if isinstance(raw, bool) or not isinstance(raw, (int, float)):
        raise CellError(cell.address, cell.label, describe(raw), expectation(cell))
    value = float(raw)
    ok = math.isfinite(value) and abs(value) <= cell.limit and (
        value == 0 or abs(value) >= cell.floor)
    if ok:
        ok = {
            "positive": value > 0,
            "negative": value < 0,
            "nonnegative": value >= 0,
            "fraction": 0 < value <= 1,
            "any": True,
        }[cell.check]
    if not ok:
        raise CellError(cell.address, cell.label, describe(raw), expectation(cell))
    return value


def _absent(value):
    return value is None or (isinstance(value, str) and not value.strip()) or (
        isinstance(value, (int, float)) and not isinstance(value, bool) and value == 0)


def _blank(value):
    return value is None or (isinstance(value, str) and not value.strip())


def bird_masses(raw):
    """The bird model a sheet's raw cells describe: 3, 2 or 1 masses (see ShotParams)."""
    if _absent(raw.get(address("m33"))) and _blank(raw.get(address("k3"))):
        if _absent(raw.get(address("m32"))) and _blank(raw.get(address("k2"))):
            return 1
        return 2
    return 3


@dataclass(frozen=True)
class ShotParams:
    """The inputs of one shot, as ArtSim reads them.

    Attributes
    ----------
    m1 : float
        MEM mass without the mitigator [kg]; A2. The macro's M1 is ``m1 + mmitigator``.
    m31, m32, m33 : float
        OBR front plate, OBR back plate and test item masses [kg]; B2, C2, D2.
    k2 : float
        Spring between m31 and m32 [N/m], negative as in the legacy sheet; B6, Eq. (1).
    k3 : float
        Spring between m32 and m33 [N/m], negative as in the legacy sheet; C6, Eq. (1).
    delta : float
        Time step [s]; E2.
    max_time : float
        Simulated duration [s]; E6.
    rho : float
        Honeycomb density [kg/m^3]; E10.
    rcone : float
        Mitigator radius [m]; E13.
    hcone, hcylinder : float
        Wedge and cylinder lengths [m]; E16, E19.
    mmitigator : float
        Mitigator mass [kg]; E25.
    vcone : float
        "Volume of conical mitigator" [m^3]; E28. The macro adds it to a mass (a quirk).
    E : float
        Elastic modulus of the mitigator [Pa]; E31, Eq. (9).
    filter_frequency : float
        Sampling frequency of the filtered acceleration [Hz]; E34.
    ec : float
        Compacting strain [-]; E37, Eq. (4).
    sigmay : float
        Static crush (yield) stress [Pa]; E40, Eq. (6).
    zeta : float
        Damping ratio [-]; E43, Eq. (18).
    v1, v31, v32, v33 : float
        Initial velocities of Y1, Y31, Y32, Y33 [m/s]; A27..A30.
    crush_law : CrushLaw
        The crush factor's law, Eq. (8): the macro's polynomial unless a calibration fitted
        another (the workbook's "Crush law" sheet).
    unloading : {"macro", "continuous"}
        The unloading force: the macro's (its offset is set at the first unloading only, so
        a later one jumps; :mod:`airgun_xl.engine.quirks`), or continuous at every unloading.
    """

    m1: float
    m31: float
    m32: float
    m33: float
    k2: float
    k3: float
    delta: float
    max_time: float
    rho: float
    rcone: float
    hcone: float
    hcylinder: float
    mmitigator: float
    vcone: float
    E: float
    filter_frequency: float
    ec: float
    sigmay: float
    zeta: float
    v1: float
    v31: float
    v32: float
    v33: float
    crush_law: CrushLaw = LEGACY_LAW
    unloading: str = "macro"

    @classmethod
    def from_cells(cls, raw_by_address: Mapping[str, object]) -> ShotParams:
        """Build from raw cell values keyed by address; every value is checked.

        Raises
        ------
        CellError
            On the first cell (in the macro's reading order) that fails its check.
        """
        raw = dict(raw_by_address)
        masses = bird_masses(raw)
        left_out = {3: (), 2: ("m33", "k3"), 1: ("m32", "m33", "k2", "k3")}[masses]
        reduced = tuple(address(name) for name in left_out)
        for cell in reduced:
            raw[cell] = 0.0  # the model leaves these masses and springs out
        for mass, velocity, previous in ((address(m), address(v), address(w)) for m, v, w in
                                         (("m32", "v32", "v31"), ("m33", "v33", "v32"))):
            if mass in reduced and raw.get(velocity) is None:
                raw[velocity] = raw.get(previous)  # a left-out mass moves with its neighbour
        values: dict[str, Any] = {
            c.name: 0.0 if c.address in reduced else check_value(c, raw.get(c.address))
            for c in CELLS}
        return cls(**values)

    def __post_init__(self) -> None:
        self.check()  # a ShotParams is always checked: built, replaced or read

    def check(self) -> ShotParams:
        """Check each field and the relations between fields; return self.

        Raises
        ------
        CellError
            Naming the cell at fault.
        """
        if self.unloading not in UNLOADINGS:
            raise OptionError(f"unloading: found {self.unloading!r}, expected one of "
                              f"{', '.join(UNLOADINGS)}")
        left_out = {3: (), 2: ("m33", "k3"), 1: ("m32", "m33", "k2", "k3")}[self.bird_masses]
        for f in fields(self):
            if f.name not in left_out and f.name in BY_NAME:
                check_value(BY_NAME[f.name], getattr(self, f.name))
        if self.hcone == 0 and self.hcylinder == 0:
            c = BY_NAME["hcone"]
            raise CellError(c.address, c.label, "0 with E19 (Length of Cylindrical Part) 0",
                            "a mitigator of some length: E16 or E19 above 0 (the macro "
                            "divides 0/0)")
        if self.delta > self.max_time:
            c = BY_NAME["delta"]
            raise CellError(c.address, c.label, repr(self.delta),
                            f"a time step no longer than E6 (Max Time) = {self.max_time!r} s")
        steps = self.max_time / self.delta
        if steps > MAX_STEPS:
            c = BY_NAME["max_time"]
            raise CellError(c.address, c.label, f"{self.max_time!r} s, {steps:.3g} steps of E2",
                            f"at most {MAX_STEPS:,} steps (E6/E2)")
        return self

    @property
    def bird_masses(self) -> int:
        """Masses in the bird's chain: 3 (ArtSim), 2 (no test item) or 1 (OBR as one mass).

        A left-out mass and its spring are 0; any other zero is caught by :meth:`check`.
        """
        if self.m33 == 0 and self.k3 == 0:
            return 1 if (self.m32 == 0 and self.k2 == 0) else 2
        return 3

    @property
    def model(self) -> str:
        """Which model runs, in words."""
        return {3: "4-mass (ArtSim: MEM, OBR front plate, OBR back plate, test item)",
                2: "3-mass (no test item: MEM, OBR front plate, OBR back plate)",
                1: "2-mass (OBR as one mass: MEM, OBR)"}[self.bird_masses]

    @property
    def rows(self) -> int:
        """Number of time rows the macro writes (t = -delta first).

        The macro's ``For i = 1 To delCounter + 2`` compares the counter with the double
        ``E6/E2 + 2``, so 5e-3/5e-6 = 999.9999999999999 gives 1,001 rows, not 1,002.
        """
        return math.floor(self.max_time / self.delta + 2)

    @property
    def samplerate(self) -> float:
        """Rows between filtered samples, ``1/(E2*E34)``, a double as in the macro."""
        return 1 / (self.delta * self.filter_frequency)

    def replace(self, **changes: Any) -> ShotParams:
        """A copy with some fields changed, checked again (on construction)."""
        return replace(self, **changes)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)
