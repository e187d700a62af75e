"""Quantities, decided once: their units (peaks in kG, g or m/s^2; durations in s, ms, us (or
µs) and ns; velocities in m/s; the macro's kG and standard gravity), the grammar that reads a
quantity with them (:func:`quantity`: the options, profiles, the Specification sheet,
design's targets and convergence's time steps all read by it; the specification's keys
build on it in :mod:`airgun_xl.specification`), and the units a verdict shows a figure in
(:data:`SHOWN_UNITS`). Recordings' headers read the same tables
(:mod:`airgun_xl.readers.recording`)."""
import math
import re
from decimal import Decimal, InvalidOperation
from typing import Any

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
# -- the grammar every quantity is read by (options, profiles, sheets, targets, ladders) ----

#: A number as the grammar reads it: digits, a point, an exponent; its sign is read apart.
NUMBER = r"(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
#: A quantity's text: a sign, a number, a unit.
SIGNED = re.compile(r"^\s*(?P<sign>[-+±]?)\s*" + NUMBER + r"\s*(?P<unit>.*?)\s*$")


def quoted(text: object) -> str:
    """A value as a message quotes it: its repr, cut to a readable length."""
    shown = repr(text)
    return shown if len(shown) <= 60 else f"{shown[:50]}... ({len(shown):,} characters)"


def refuse(where: str, text: object, expected: str) -> OptionError:
    """The one line of a refusal: ``WHERE: found TEXT, expected EXPECTED``."""
    return OptionError(f"{where}: found {quoted(text)}, expected {expected}")


def split_quantity(text: str, where: str, expected: str) -> tuple[str, Decimal, str]:
    """(sign, magnitude, unit text) of a number with an optional sign and unit."""
    if not text.strip():
        raise OptionError(f"{where}: found an empty value, expected {expected}")
    match = SIGNED.match(text)
    if not match:
        raise refuse(where, text, expected)
    try:
        magnitude = Decimal(match.group("num"))
    except InvalidOperation:
        raise refuse(where, text, expected) from None
    return match.group("sign"), magnitude, match.group("unit")


def unit_of(unit: str, units: dict, text: str, where: str, expected: str) -> Any:
    """``units[unit]``; a unit missing, or a case away from one (the one meant named),
    refused."""
    if unit in units:
        return units[unit]
    if not unit:
        raise OptionError(f"{where}: found {quoted(text)} without a unit, expected {expected}")
    near = [u for u in units if u.lower() == unit.lower()]
    hint = f" (did you mean {near[0]}?)" if near else ""
    raise OptionError(f"{where}: found the unit {quoted(unit)} in {quoted(text)}{hint}, "
                      f"expected {expected}")


def scaled(magnitude: Decimal, scale: str) -> float:
    """A decimal times a power of ten (``"1e-3"``), rounded once to a float: how the grammar
    reads a time in ms or a percentage."""
    return float(magnitude * Decimal(scale))


def quantity(text: str, where: str, what: str, units: dict, example: str, cap: float,
             cap_text: str, zero: bool = False, floor: float = 0.0,
             floor_text: str = "") -> float:
    """A positive (or, with ``zero``, non-negative) quantity with its unit, at least
    ``floor`` and at most ``cap`` in the inside unit; times scaled exactly in decimal, then
    rounded once."""
    low = "from 0" if zero else f"from {floor_text}" if floor else "above 0"
    expected = (f"{what} such as {example} (units "
                f"{', '.join(u for u in units if u in NAMED_UNITS)}), "
                f"{low} and at most {cap_text}")
    sign, magnitude, unit_text = split_quantity(text, where, expected)
    factor = unit_of(unit_text, units, text, where, expected)
    if sign:
        raise OptionError(f"{where}: found the sign {sign!r} in {quoted(text)}, where none is "
                          f"meaningful; expected {expected}")
    if isinstance(factor, str):  # a time: "5e0us" and "5us" give float("5e-6")
        value = scaled(magnitude, factor)
    else:
        value = float(magnitude) * factor
    if not (math.isfinite(value) and (value >= 0 if zero else value > 0 and value >= floor)
            and value <= cap):
        raise refuse(where, text, expected)
    return value


def parse_duration(text, option="--target-duration"):
    """``"5ms"`` -> 0.005 [s] (also s, us, µs, ns) by the grammar every quantity is read by
    (:func:`quantity`: the same double as typing it in seconds), from 1 ns to 10 s; a bare
    number is seconds (a time step, ``"5e-6"``)."""
    text = str(text)
    match = SIGNED.match(text)
    if match is not None and not match.group("unit") and not match.group("sign"):
        text = text.strip() + "s"
    return quantity(text, option, "a duration", TIME_UNITS, "5ms or 500us", 10.0, "10 s",
                    floor=1e-9, floor_text="1 ns")


def instant(text: Any, where: str) -> float:
    """An instant of a recording [s] (``--at``): a number of seconds or a time with its unit
    (``"1.25"``, ``"1250ms"``, ``"-2ms"`` before a trigger), read by the grammar; finite, of
    either sign."""
    expected = "an instant of the recording such as 1.25 or 1250ms (units s, ms, us, ns)"
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        sign, magnitude, unit = split_quantity(str(text), where, expected)
        if sign == "±":
            raise refuse(where, text, expected)
        value = scaled(magnitude, unit_of(unit or "s", TIME_UNITS, str(text), where, expected))
        value = -value if sign == "-" else value
    if not math.isfinite(value):
        raise refuse(where, text, expected)
    return value


#: The units a verdict reports the peak and the duration in, as their nominal was given:
#: unit typed -> (unit shown, factor from the inside unit, kG or s).
SHOWN_UNITS = {
    "peak": {"kG": ("kG", 1.0), "g": ("g", KG_MS2 / G), "m/s^2": ("m/s^2", KG_MS2),
             "m/s2": ("m/s^2", KG_MS2), "m/s²": ("m/s^2", KG_MS2)},
    "duration": {"s": ("s", 1.0), "ms": ("ms", 1e3), "us": ("us", 1e6), "µs": ("us", 1e6),
                 "ns": ("ns", 1e9)},
}
