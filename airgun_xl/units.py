"""Quantities' units, decided once: peaks in kG, g or m/s^2; durations in s, ms, us (or µs)
and ns; velocities in m/s; the macro's kG and standard gravity. The grammar that reads a
quantity with them is :mod:`airgun_xl.specification`'s (options, profiles, sheets, design's
targets); recordings' headers read the same tables (:mod:`airgun_xl.readers.recording`)."""
import math
import re
from decimal import Decimal

from .errors import OptionError

G = 9.80665  # standard gravity [m/s^2]
KG_MS2 = 9800.0  # the macro's kG: a / 9800 (so 1 kG = 9800 m/s^2, not 1000 g)
#: The macro's kG in standard g [g/kG]: shock labs give spectra in g.
G_PER_KG = KG_MS2 / G

#: The one table of each quantity's units, used by every reader of a quantity (the options,
#: profiles, the Specification sheet, the design targets, recordings' headers): name ->
#: the factor to the inside unit, exactly as typed. Units are case sensitive (``Kg`` is a
#: mass, ``MS`` megasiemens): a unit a case away is refused with the one meant.
PEAK_UNITS = {"kG": 1.0, "g": G / KG_MS2, "m/s^2": 1 / KG_MS2, "m/s2": 1 / KG_MS2,
              "m/s²": 1 / KG_MS2}  # [kG per unit]
TIME_UNITS = {"s": "1", "ms": "1e-3", "us": "1e-6", "µs": "1e-6", "ns": "1e-9"}  # [s], decimal
VELOCITY_UNITS = {"m/s": 1.0}  # [m/s per unit]
#: The units a message names (the others are spellings of these).
NAMED_UNITS = ("kG", "g", "m/s^2", "s", "ms", "us", "ns", "m/s")
_TIME = {unit: "e" + scale.partition("e")[2] if "e" in scale else "e0"
         for unit, scale in TIME_UNITS.items()}
_NUMBER = r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*"


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
