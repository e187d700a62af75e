"""The trapezoid rule the studies use (airgun_xl/studies/integrals.py: numpy's, for its import
time) against scipy.integrate.trapezoid, on uneven and even grids and a block of rows."""
import numpy as np
from scipy.integrate import trapezoid as scipy_trapezoid

from airgun_xl.studies.integrals import trapezoid


def test_the_trapezoid_rule_is_scipys():
    """The same sums on an even grid and on an uneven one (seed 3), row by row on a block,
    and 0 for one sample: to 1e-14 relative (the same rule; a version of either library may
    add its terms in another order, a few units in the last place)."""
    rng = np.random.default_rng(3)
    for x in (np.linspace(0.0, 0.02, 1001), np.cumsum(rng.uniform(1e-6, 3e-6, 777))):
        y = np.sin(900 * x) + rng.normal(0.0, 0.01, len(x))
        np.testing.assert_allclose(trapezoid(y, x), scipy_trapezoid(y, x), rtol=1e-14, atol=0)
        block = np.vstack([y, 2 * y, -y])
        np.testing.assert_allclose(trapezoid(block, x), scipy_trapezoid(block, x), rtol=1e-14,
                                   atol=0)
    assert trapezoid(np.array([5.0]), np.array([1.0])) == 0.0
