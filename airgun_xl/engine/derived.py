"""Columns the macro derives from Y33 after the position loop (S, T, U).

Sheet row ``r`` (array index ``k = r - 2``) gets central differences of Y33 over rows
``r-1, r, r+1``; the macro fills rows 3..rows, i.e. indices 1..rows-2.
"""
import numpy as np

#: The macro's divisor from m/s^2 to kG's (a / -9800).
KG_DIVISOR = -9800


def test_item_derivatives(y33: np.ndarray, delta: float
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Acceleration, velocity and kG of the test item by central differences.

    Parameters
    ----------
    y33 : numpy.ndarray
        Test-item displacement [m], one entry per time row.
    delta : float
        Time step [s].

    Returns
    -------
    accel, vel, kg : numpy.ndarray
        Arrays as long as ``y33``, NaN where the macro writes nothing (first and last row):
        acceleration [m/s^2], velocity [m/s] and acceleration [kG], with kG = a / -9800.
    """
    n = len(y33)
    accel = np.full(n, np.nan)
    vel = np.full(n, np.nan)
    if n >= 3:
        un, un1, un2 = y33[:-2], y33[1:-1], y33[2:]
        accel[1:-1] = (1.0 / (delta * delta)) * (un2 + un - 2 * un1)
        vel[1:-1] = (un2 - un) / (2 * delta)
    kg = accel / KG_DIVISOR
    return accel, vel, kg
