"""The trapezoid rule the studies integrate a pulse by: numpy's own (``numpy.trapezoid``, named
``numpy.trapz`` before numpy 2.0), not scipy.integrate's, whose import (0.4 to 0.6 s: it loads
scipy.stats) was a sixth of ``accept``'s time on a 500,000-sample recording
(benchmarks/bench_events.py). tests/test_integrals.py checks it against
scipy.integrate.trapezoid."""
from __future__ import annotations

from typing import Any

import numpy as np

#: ``trapezoid(y, x)``: the integral of ``y`` over ``x`` by the trapezoid rule.
trapezoid: Any = getattr(np, "trapezoid", None) or np.trapz  # type: ignore[attr-defined]
