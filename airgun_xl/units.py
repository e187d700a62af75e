"""Quantities with units on the command line: peaks in kG, g or m/s^2; durations in s, ms,
us (or µs) and ns."""
import math
import re
from decimal import Decimal

from .errors import OptionError

G = 9.80665  # standard gravity [m/s^2]
KG_MS2 = 9800.0  # the macro's kG: a / 9800 (so 1 kG = 9800 m/s^2, not 1000 g)
#: The macro's kG in standard g [g/kG]: shock labs give spectra in g.
G_PER_KG = KG_MS2 / G

_PEAK = {"kg": 1.0, "g": G / KG_MS2, "m/s2": 1 / KG_MS2, "m/s^2": 1 / KG_MS2,
         "m/s²": 1 / KG_MS2}
_TIME = {"s": "e0", "ms": "e-3", "us": "e-6", "µs": "e-6", "ns": "e-9"}
_NUMBER = r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*"


def parse_peak(text, option="--target-peak"):
    """``"12kG"`` -> 12.0; ``"11750g"`` and ``"1.2e5m/s2"`` in kG as the macro defines it."""
    match = re.fullmatch(_NUMBER + r"(kG|g|m/s2|m/s\^2|m/s²)\s*", str(text), re.IGNORECASE)
    if not match:
        raise OptionError(f"{option}: found {text!r}, expected a peak such as 12kG, 11750g "
                          "or 1.2e5m/s2")
    value = float(match.group(1)) * _PEAK[match.group(2).lower()]
    if not (value > 0 and math.isfinite(value)):
        raise OptionError(f"{option}: found {text!r}, expected a positive peak")
    return value


def parse_duration(text, option="--target-duration"):
    """``"5ms"`` -> 0.005 [s] (also s, us, µs, ns); the same double as typing it in seconds."""
    match = re.fullmatch(_NUMBER + r"(s|ms|us|µs|ns)?\s*", str(text))
    if not match:
        raise OptionError(f"{option}: found {text!r}, expected a duration such as 5ms, 500us")
    unit = match.group(2) or "s"
    # the decimal product, rounded once: "5e0us" and "5us" give float("5e-6"), as typed in s
    value = float(Decimal(match.group(1)) * Decimal("1" + _TIME[unit]))
    if not (value > 0 and math.isfinite(value)):
        raise OptionError(f"{option}: found {text!r}, expected a positive duration")
    return value
