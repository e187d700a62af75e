"""The macro's crush-factor law in Python, for messages, checks and the rigid model.

The kernel (``_artsim.c``) evaluates the same polynomial in C, term by term in the macro's
order; this is the same arithmetic in numpy.
"""
import numpy as np

#: Relative velocities [m/s] where the polynomial can be trusted. The test data span about
#: -20..230 m/s (Figs. 6-8) and the fit follows their trend to about 250 m/s (shot A is at
#: 243.5 m/s); beyond, it grows wildly (a factor of 209 at 400 m/s).
CRUSH_FIT_RANGE = (-20.0, 250.0)


def crush_factor(v):
    """Strain-rate amplification of the crush force, Eq. (8) with the macro's coefficients,
    clamped at 1 as the macro does.

    Parameters
    ----------
    v : float or numpy.ndarray
        Relative velocity of OBR front plate and MEM [m/s].

    Returns
    -------
    float or numpy.ndarray
        Crush factor [-], at least 1.
    """
    V = np.asarray(v, dtype=float)
    poly = ((2.627437E-13) * (V * V * V * V * V * V) - (0.000000000125438) * (V * V * V * V * V)
            + (0.0000000159241) * (V * V * V * V) + (0.0000005551838) * (V * V * V)
            - (0.0001897436) * (V * V) + (0.008340218) * (V) + 1.257647)
    out = np.maximum(poly, 1.0)
    return float(out) if out.ndim == 0 else out
