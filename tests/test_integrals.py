"""The trapezoid rule the studies use (airgun_xl/studies/integrals.py: numpy's, for its import
time) against scipy.integrate.trapezoid, on uneven and even grids and a block of rows."""
import numpy as np
from scipy.integrate import trapezoid as scipy_trapezoid

from airgun_xl.studies.integrals import trapezoid


def test_the_trapezoid_rule_is_scipys():
    """The same sums: bit for bit on an even grid and on an uneven one (seed 3), row by row
    on a block, and 0 for one sample."""
    rng = np.random.default_rng(3)
    for x in (np.linspace(0.0, 0.02, 1001), np.cumsum(rng.uniform(1e-6, 3e-6, 777))):
        y = np.sin(900 * x) + rng.normal(0.0, 0.01, len(x))
        assert trapezoid(y, x) == scipy_trapezoid(y, x)
        block = np.vstack([y, 2 * y, -y])
        np.testing.assert_array_equal(trapezoid(block, x), scipy_trapezoid(block, x))
    assert trapezoid(np.array([5.0]), np.array([1.0])) == 0.0
