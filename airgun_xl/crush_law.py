"""The crush-factor law: the macro's polynomial (the default), or one fitted by calibration.

The kernel (``_artsim.c``) evaluates a law's polynomial in C, term by term in the macro's
order; :meth:`CrushLaw.__call__` is the same arithmetic in numpy, for messages, checks,
calibration and the rigid model.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Relative velocities [m/s] where the polynomial can be trusted. The test data span about
#: -20..230 m/s (Figs. 6-8) and the fit follows their trend to about 250 m/s (shot A is at
#: 243.5 m/s); beyond, it grows wildly (a factor of 209 at 400 m/s).
CRUSH_FIT_RANGE = (-20.0, 250.0)

#: Eq. (8) with the macro's coefficients, constant term first: 1.257647 + 0.008340218 V - ...
#: The C kernel adds c[5] V^5 where the macro subtracts 0.000000000125438 V^5; a + (-b) c
#: rounds exactly as a - b c, so the legacy run is unchanged bit for bit.
LEGACY_COEFFICIENTS = (1.257647, 0.008340218, -0.0001897436, 0.0000005551838, 0.0000000159241,
                       -0.000000000125438, 2.627437E-13)

DEGREE = 6


def speeds_text(v_range: tuple[float, float] | list[float]) -> str:
    """Where a law holds, said in speeds a shot has [m/s]: from 0, where the polynomial's span
    starts below it (the report's figures' axes start at -20 m/s; no bird meets the honeycomb
    at a negative speed), to its top."""
    lo, hi = (float(v) for v in v_range)
    return f"{max(lo, 0.0):.4g} to {hi:.4g} m/s"


def chebyshev_nodes(lo, hi, n):
    """``n`` Chebyshev nodes of [``lo``, ``hi``], ascending: where a polynomial through
    them strays least from the function sampled."""
    k = np.arange(n)
    return (lo + hi) / 2 + (hi - lo) / 2 * np.cos((2 * k + 1) * np.pi / (2 * n))[::-1]


@dataclass(frozen=True)
class CrushLaw:
    """A strain-rate amplification law of the crush force, Eq. (8): a polynomial of degree 6
    or less in the relative velocity, clamped at 1 as the macro does.

    Attributes
    ----------
    coefficients : tuple of float
        c0 .. c6, constant term first [-, s/m, s^2/m^2, ...].
    v_range : tuple of float
        Relative velocities [m/s] the law was fitted over (where it can be trusted).
    name : str
        ``"legacy"`` (the macro's) or ``"fitted"``.
    source : str
        Where a fitted law came from, for the record: ``"the Crush law sheet"``, or an
        archive's law library entry such as ``"LOT-2026-07@1"`` (not compared: the same
        coefficients are the same law).
    named : str
        The archive's law version a workbook's Crush law sheet says it holds (``next``
        writes it), unchecked: it becomes ``source`` only once the archive's version of that
        name has the same values (:func:`airgun_xl.archive.laws.shot_with_law`).
    """

    coefficients: tuple[float, ...] = LEGACY_COEFFICIENTS
    v_range: tuple[float, float] = CRUSH_FIT_RANGE
    name: str = "legacy"
    source: str = field(default="", compare=False)
    named: str = field(default="", compare=False)

    def __post_init__(self):
        c = tuple(float(x) for x in self.coefficients)
        if len(c) > DEGREE + 1 or not c or not np.isfinite(c).all():
            raise ValueError(f"coefficients: found {len(c)} values, expected 1 to "
                             f"{DEGREE + 1} finite numbers (constant term first)")
        object.__setattr__(self, "coefficients", c + (0.0,) * (DEGREE + 1 - len(c)))
        object.__setattr__(self, "v_range", (float(self.v_range[0]), float(self.v_range[1])))

    def poly(self, v):
        """The unclamped polynomial at relative velocity ``v`` [m/s], in the kernel's order."""
        c = self.coefficients
        V = np.asarray(v, dtype=float)
        return ((c[6]) * (V * V * V * V * V * V) + (c[5]) * (V * V * V * V * V)
                + (c[4]) * (V * V * V * V) + (c[3]) * (V * V * V) + (c[2]) * (V * V)
                + (c[1]) * (V) + c[0])

    def __call__(self, v):
        """Crush factor [-] at relative velocity ``v`` [m/s], at least 1."""
        out = np.maximum(self.poly(v), 1.0)
        return float(out) if out.ndim == 0 else out

    def scaled(self, scale):
        """The law times ``scale`` (every coefficient), named fitted."""
        return CrushLaw(tuple(scale * c for c in self.coefficients), self.v_range, "fitted")

    def tilted(self, scale, tilt, v_ref):
        """The law times ``scale`` (1 + ``tilt`` (V - ``v_ref``) / ``v_ref``) [-, -, m/s]: a
        lot stronger or weaker, and more or less so with speed; the polynomial of the same
        degree through the product at the Chebyshev nodes of its range (a degree-7 product
        kept at 6, as the archive and the kernel hold a law), named fitted. A tilt of 0 is
        :meth:`scaled`, exactly."""
        if tilt == 0:
            return self.scaled(scale)
        from numpy.polynomial import Polynomial

        lo, hi = self.v_range
        nodes = chebyshev_nodes(lo, hi, len(self.coefficients))
        values = self.poly(nodes) * scale * (1 + tilt * (nodes - v_ref) / v_ref)
        poly = Polynomial.fit(nodes, values, len(nodes) - 1).convert()
        coefficients = tuple(float(c) for c in poly.coef)
        coefficients += (0.0,) * (len(self.coefficients) - len(coefficients))
        return CrushLaw(coefficients, self.v_range, "fitted")

    @property
    def is_legacy(self):
        """The macro's law: its coefficients, range and name."""
        return (self.coefficients == LEGACY_COEFFICIENTS and self.v_range == CRUSH_FIT_RANGE
                and self.name == "legacy")


LEGACY_LAW = CrushLaw()


def crush_factor(v, law=LEGACY_LAW):
    """Strain-rate amplification of the crush force, Eq. (8), clamped at 1 as the macro does.

    Parameters
    ----------
    v : float or numpy.ndarray
        Relative velocity of OBR front plate and MEM [m/s].
    law : CrushLaw
        The macro's polynomial by default.

    Returns
    -------
    float or numpy.ndarray
        Crush factor [-], at least 1.
    """
    return law(v)


def law_name(law):
    """How a record (an archive entry, a campaign's row) names the law a run used."""
    if law.is_legacy:
        return "legacy (Eq. 8)"
    return f"fitted ({law.source})" if law.source else "fitted"
