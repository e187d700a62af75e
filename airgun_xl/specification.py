"""A client's test specification: the pulse's shape, its figures with their tolerances, the
corridor, an SRS requirement and the record judged (issues 25 and 30).

It is declared once here, as :class:`Specification`; it comes from three sources:

- a tolerance profile, a JSON file the lab names and edits (:func:`load_profile`; the
  package's ``profiles/`` folder holds the examples);
- the shot workbook's ``Specification`` sheet (:mod:`airgun_xl.readers.spec_sheet`), which the
  template writes empty;
- command-line options (``--peak 12kG:10%``...).

**The merge** (:func:`combine`): every field is None until a source gives it; each source
overrides the one before it field by field (options over sheet over profile), so a value equal
to a default still overrides; the defaults (:data:`DEFAULTS`) are applied once, after the
merge, and each field remembers where it came from (:meth:`Specification.provenance`).

**The grammar** (:data:`KEYS`): one parser per field for every source. An option's value is
text; a profile key or a sheet cell holds the same text, or a bare number in the key's declared
unit. Units are case-exact (``kg`` is refused: did you mean kG?), a quantity in text needs its
unit, a sign where none is meaningful is refused, and empty values, infinities and values past
the caps (:data:`CAPS`) are refused, each in one line naming the option, cell or key.

Units inside: peaks in kG (the macro's, 9800 m/s^2), times in s, velocities in m/s, tolerances
and percentages as fractions. The judging itself is :mod:`airgun_xl.studies.acceptance`.
"""
from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from decimal import Decimal, localcontext
from pathlib import Path
from typing import Any

from .errors import OptionError
from .units import (
    KG_MS2,
    PEAK_UNITS,
    SHOWN_UNITS,
    SIGNED,
    TIME_UNITS,
    VELOCITY_UNITS,
    quantity,
    quoted,
    refuse,
    scaled,
    split_quantity,
    unit_of,
)

#: The pulse shapes a specification can name; "none" judges the limits only (no corridor).
SHAPES = ("half-sine", "sawtooth", "trapezoid", "none")

#: Where the ideal pulse is placed over the record: by least squares (the default, where the
#: standard gives no rule), or with its peak on the record's peak.
PLACEMENTS = ("least-squares", "peak")

#: The J211 channel frequency classes a record may be judged through (0: unfiltered).
CFC_CLASSES = (60, 180, 600, 1000)

#: The largest SRS requirement read (rows): a spectrum is at most a few hundred.
MAX_SRS_ROWS = 2_000

#: Profiles shipped with the package (examples; the lab keeps its own beside them).
PROFILES = Path(__file__).with_name("profiles")

#: The largest value each quantity may take: past it a value is a typing slip (and 1e308 kG
#: overflows the judge's arithmetic).
CAPS = {
    "peak": 1e4,  # [kG]: about 10^5 g, past any pyroshock
    "duration": 10.0,  # [s]
    "velocity_change": 1e4,  # [m/s]
    "window": 10.0,  # [s], a window's side in time
    "window_d": 100.0,  # a window's side in nominal durations
    "srs_q": 1000.0,  # quality factor
    "db": 60.0,  # |SRS tolerance| [dB]
}

#: The smallest value each quantity may take: below it a value is a typing slip, and a
#: denormal (5e-324 kG) would overflow the judge's quotients into a numpy warning.
FLOORS = {
    "peak": 1e-6,  # [kG], 0.001 g
    "duration": 1e-9,  # [s], 1 ns
    "velocity_change": 1e-6,  # [m/s]
}

#: The duration definitions: each shape's own D (``base``: a half-sine's or a trapezoid's
#: base, a sawtooth's rise), or the width at 10 % of the peak (JEDEC-style).
DURATION_DEFS = ("base", "width@10%")

#: The defaults by :data:`KEYS` name, applied once after the merge
#: (:meth:`Specification.resolved`); the record judged's is the tool's low-pass one
#: (:class:`JudgedRecord`). The corridor's and the decay's defaults apply only with a shape
#: that draws them (:data:`SHAPE_DEFAULTS`).
DEFAULTS: dict[str, Any] = {
    "shape": "none", "time_slack": 0.0, "placement": "least-squares",
    "dv_window": ((0.5, "D"), (0.5, "D")), "monitor": ((1.0, "D"), (1.0, "D")),
    "duration_def": "base",
    "srs_q": 10.0, "srs_lower_db": -3.0, "srs_upper_db": 6.0, "srs_outside": 0.0,
}

#: Defaults that only a named shape takes: the band round its ideal (a shape named is a shape
#: judged), and the sawtooth's decay allowance, a fraction of D.
SHAPE_DEFAULTS: dict[str, Any] = {"corridor": 0.2, "decay": 0.1}

#: Marks the fields of :class:`Specification` that say where it came from, not what it asks.
META = {"meta": True}

#: The kinds of record a verdict can judge (:class:`JudgedRecord`).
RECORD_KINDS = ("default", "unfiltered", "cfc")


@dataclass(frozen=True)
class JudgedRecord:
    """The record a verdict judges (issue 42), one of three kinds:

    - ``default``, the tool's low-pass record, what no source named: through a 4-pole Bessel
      low-pass at K/D both ways, whatever the record's noise (a prediction and a recording
      alike; :mod:`airgun_xl.studies.acceptance`);
    - ``unfiltered``, the record as it is (``--cfc none``, ``unfiltered`` on the sheet);
    - ``cfc``, through SAE J211 channel frequency class ``cfc`` both ways (``--cfc 600``,
      ``cfc600``).

    Its text in the grammar is ``unfiltered`` or ``cfcN``; ``default`` is what no source
    gives, printed so."""

    kind: str = "default"
    cfc: int | None = None  # the class, with the kind "cfc" only

    def __post_init__(self) -> None:
        if self.kind not in RECORD_KINDS or (self.kind == "cfc") != (self.cfc is not None) \
                or (self.cfc is not None and self.cfc not in CFC_CLASSES):
            raise ValueError(f"a judged record of kind {self.kind!r} and class {self.cfc!r}")

    @property
    def is_default(self) -> bool:
        return self.kind == "default"

    @property
    def is_unfiltered(self) -> bool:
        return self.kind == "unfiltered"

    def __str__(self) -> str:
        return f"cfc{self.cfc}" if self.kind == "cfc" else self.kind


#: The tool's low-pass record, and the record as it is.
DEFAULT_RECORD = JudgedRecord("default")
UNFILTERED = JudgedRecord("unfiltered")
DEFAULTS["record"] = DEFAULT_RECORD


def cfc_record(cfc: int | None) -> JudgedRecord:
    """The record through CFC ``cfc``; None: the unfiltered record (``--cfc none``)."""
    return UNFILTERED if cfc is None else JudgedRecord("cfc", cfc)


@dataclass(frozen=True)
class Tolerance:
    """A nominal value with its tolerance: ``nominal * (1 - minus)`` to ``nominal * (1 +
    plus)``. NaN marks a part not given: a profile gives tolerances, the test its nominal
    values (:meth:`Specification.merged` joins them)."""

    nominal: float
    minus: float
    plus: float

    def over(self, base: Tolerance | None) -> Tolerance:
        """This tolerance, its missing parts taken from ``base``."""
        if base is None:
            return self
        given = math.isfinite(self.minus)
        return Tolerance(self.nominal if math.isfinite(self.nominal) else base.nominal,
                         self.minus if given else base.minus,
                         self.plus if given else base.plus)

    @property
    def limits(self) -> tuple[float, float]:
        return self.nominal * (1 - self.minus), self.nominal * (1 + self.plus)


@dataclass(frozen=True)
class SrsRequirement:
    """Required SRS levels at their frequencies (the rows of ``--srs`` or of the sheet); its
    Q and tolerance are fields of the :class:`Specification`."""

    frequencies: tuple[float, ...]  # [Hz]
    levels_kg: tuple[float, ...]  # [kG]


@dataclass(frozen=True)
class Specification:
    """What a shot must meet. Every field is None until a source gives it; a criterion is
    judged only when its fields are given. :meth:`resolved` applies :data:`DEFAULTS`.

    Attributes
    ----------
    shape : str or None
        One of :data:`SHAPES` (default none).
    peak : Tolerance or None
        Peak acceleration [kG].
    duration : Tolerance or None
        Pulse duration [s]: the base width of the nominal shape (see
        :func:`airgun_xl.studies.acceptance.duration_definition`).
    velocity_change : Tolerance or None
        Velocity change [m/s], integrated over the pulse and its windows.
    corridor : float or None
        Half-width of the corridor round the ideal pulse, a fraction of the nominal peak.
    time_slack : float or None
        Time slack of the corridor, a fraction of the nominal duration (default 0).
    dv_window, monitor : tuple or None
        The velocity change's window and the corridor's monitoring window, before and after
        the pulse: ((before, unit), (after, unit)), unit "s" or "D" (nominal durations);
        default half a duration each side for the velocity change, a whole one for the
        corridor (a bump after the pulse is judged).
    duration_def : str or None
        One of :data:`DURATION_DEFS` (default base).
    decay : float or None
        The terminal-peak sawtooth's decay allowance, a fraction of D (default 0.1): the
        band admits any decay from none to it.
    record : JudgedRecord or None
        The record judged: the tool's low-pass default, unfiltered, or through SAE J211
        CFC N (:class:`JudgedRecord`); None until a source gives it (:meth:`resolved` then
        gives the default).
    placement : str or None
        One of :data:`PLACEMENTS` (default least-squares).
    srs : SrsRequirement or None
        The required SRS's rows.
    srs_q, srs_lower_db, srs_upper_db, srs_outside : float or None
        Its quality factor (default 10), tolerance [dB] (default -3 and +6) and the fraction
        of its frequencies allowed outside (default 0).
    source : str
        The sources that gave it (profile, sheet, options), as verdicts print it.
    notes : tuple of str
        A profile's notes, printed with every verdict.
    origins : tuple of (str, str)
        Each key's source (:data:`KEYS` names; "default" for a default applied).
    places : tuple of (str, str)
        Each key's option, cell or profile key, as a refusal names it.
    set_aside : tuple of str
        What a source gave that a later one made moot, in words (a verdict prints it).
    units : tuple of (str, str)
        The unit the peak's and the duration's nominal were given in: a verdict reports them
        in it (:func:`shown_unit`).
    """

    shape: str | None = None
    peak: Tolerance | None = None
    duration: Tolerance | None = None
    velocity_change: Tolerance | None = None
    corridor: float | None = None
    time_slack: float | None = None
    dv_window: tuple | None = None
    monitor: tuple | None = None
    duration_def: str | None = None
    decay: float | None = None
    record: JudgedRecord | None = None
    placement: str | None = None
    srs: SrsRequirement | None = None
    srs_q: float | None = None
    srs_lower_db: float | None = None
    srs_upper_db: float | None = None
    srs_outside: float | None = None
    source: str = field(default="", metadata=META)
    notes: tuple[str, ...] = field(default=(), metadata=META)
    origins: tuple[tuple[str, str], ...] = field(default=(), metadata=META)
    places: tuple[tuple[str, str], ...] = field(default=(), metadata=META)
    set_aside: tuple[str, ...] = field(default=(), metadata=META)
    units: tuple[tuple[str, str], ...] = field(default=(), metadata=META)

    @property
    def judged(self) -> JudgedRecord:
        """The record judged: the one a source gave, else the tool's default."""
        return self.record if self.record is not None else DEFAULT_RECORD

    @property
    def empty(self) -> bool:
        """True when nothing is specified: no criterion to judge."""
        return (self.peak is None and self.duration is None and self.velocity_change is None
                and self.srs is None)

    def merged(self, other: Specification) -> Specification:
        """This specification with every field ``other`` gives (not None) taken from it; a
        tolerance's nominal and tolerance separately."""
        changes: dict[str, Any] = {}
        for name in judged_fields():
            value = getattr(other, name)
            if value is not None:
                changes[name] = value.over(getattr(self, name)) if isinstance(
                    value, Tolerance) else value
        sources = " + ".join(s for s in (self.source, other.source) if s)
        return replace(self, **changes, source=sources, notes=self.notes + other.notes,
                       origins=tuple({**dict(self.origins), **dict(other.origins)}.items()),
                       places=tuple({**dict(self.places), **dict(other.places)}.items()),
                       set_aside=self.set_aside + other.set_aside,
                       units=tuple({**dict(self.units), **dict(other.units)}.items()))

    def resolved(self) -> Specification:
        """This specification with :data:`DEFAULTS` in the fields no source gave (the SRS's
        only with an SRS requirement); each default's origin is "default"."""
        changes: dict[str, Any] = {}
        origins = dict(self.origins)
        shaped = self.shape not in (None, "none")
        for key, value in {**DEFAULTS, **SHAPE_DEFAULTS}.items():
            name = KEYS[key].field
            wanted = (self.srs is not None if key.startswith("srs_") else
                      shaped if key == "corridor" else
                      self.shape == "sawtooth" if key == "decay" else True)
            if getattr(self, name) is None and wanted:
                changes[name] = value
                origins[key] = "default"
        if not changes:
            return self
        return replace(self, **changes, origins=tuple(origins.items()))

    def origin(self, key: str) -> str | None:
        """Where a field (a :data:`KEYS` name) came from, or None if no source gave it."""
        return dict(self.origins).get(key)

    def _shown_as_typed(self, key: str) -> str:
        """A key's value to 6 significant digits, a nominal peak or duration in the unit it
        was typed in (``40g``, not ``0.0400271kG``)."""
        value = value_of(self, key)
        typed = dict(self.units).get(key)
        if key in SHOWN_UNITS and typed and value is not None:
            unit, factor = shown_unit(self, key)
            return f"{float(f'{value * factor:.6g}'):g}{unit}"
        return show(self, key, digits=6)

    def provenance(self) -> list[str]:
        """Where each field came from, a line a source, the defaults last: what a verdict
        prints under its criteria."""
        by_source: dict[str, list[str]] = {}
        for key, where in self.origins:
            if key in KEYS:
                by_source.setdefault(where, []).append(
                    f"{key_label(key)} {self._shown_as_typed(key)}")
            elif key == "srs" and self.srs is not None:
                by_source.setdefault(where, []).append(
                    f"SRS requirement ({len(self.srs.frequencies)} rows)")
        lines = [f"{where}: {', '.join(items)}" if where.startswith("derived") else
                 f"from {where}: {', '.join(items)}" for where, items in by_source.items()
                 if where != "default"]
        defaults = by_source.get("default", [])
        if defaults:
            lines.append(f"defaults (the tool's, no source gave them): {', '.join(defaults)}")
        return lines


def judged_fields() -> tuple[str, ...]:
    """The names of :class:`Specification`'s fields that ask something (not its meta)."""
    return tuple(f.name for f in fields(Specification) if not f.metadata.get("meta"))


# -- the grammar -------------------------------------------------------------------------------

def _percent(text: str, where: str, what: str, low_open: bool, allow_sign: bool = False
             ) -> tuple[str, float]:
    """(sign, fraction) of ``N%``; the fraction from 0 (above 0 with ``low_open``) to
    below 1."""
    expected = f"{what} {'above' if low_open else 'from'} 0% to below 100%, such as 10%"
    sign, magnitude, unit_text = split_quantity(text, where, expected)
    unit_of(unit_text, {"%": 1}, text, where, expected)
    if sign and not allow_sign:
        raise OptionError(f"{where}: found the sign {sign!r} in {quoted(text)}, where none is "
                          f"meaningful; expected {expected}")
    value = scaled(magnitude, "0.01")
    if not (math.isfinite(value) and (value > 0 if low_open else value >= 0) and value < 1):
        raise refuse(where, text, expected)
    return sign, value


TOLERANCE_EXPECTED = ("a tolerance in %: 10% (either side) or -10%,+20% (below and above), "
                      "each from 0% to below 100%")


def parse_tolerance_text(text: str, where: str) -> tuple[float, float]:
    """``10%`` or ``±10%`` -> (0.1, 0.1); ``-10%,+20%`` (either order) -> (0.1, 0.2). A
    single signed tolerance is ambiguous, and refused."""
    parts = str(text).split(",")
    if len(parts) == 1:
        sign, value = _percent(parts[0], where, "a tolerance", False, allow_sign=True)
        if sign in ("-", "+"):
            raise OptionError(f"{where}: found {quoted(text)}, a single signed tolerance, which is "
                              f"ambiguous; expected {TOLERANCE_EXPECTED}")
        return value, value
    if len(parts) != 2:
        raise refuse(where, text, TOLERANCE_EXPECTED)
    signed = [_percent(p, where, "a tolerance", False, allow_sign=True) for p in parts]
    minus = [v for s, v in signed if s == "-"]
    plus = [v for s, v in signed if s == "+"]
    if len(minus) != 1 or len(plus) != 1:
        raise OptionError(f"{where}: found {quoted(text)}, expected the lower tolerance with - and "
                          "the upper with + (-10%,+20%)")
    return minus[0], plus[0]


def _db(text: str, where: str, side: str) -> float:
    """A tolerance in dB: the lower 0 or below (``-3dB``), the upper 0 or above (``+6dB``)."""
    expected = (f"the {side} SRS tolerance in dB, such as {'-3dB' if side == 'lower' else '+6dB'}"
                f", {'from -' if side == 'lower' else 'from 0 to '}"
                f"{CAPS['db']:g}{' to 0' if side == 'lower' else ''} dB")
    sign, magnitude, unit_text = split_quantity(text, where, expected)
    unit_of(unit_text, {"dB": 1}, text, where, expected)
    value = float(-magnitude if sign == "-" else magnitude)
    if sign == "±" or not math.isfinite(value) or abs(value) > CAPS["db"] or (
            value > 0 if side == "lower" else value < 0):
        raise refuse(where, text, expected)
    return value


def parse_db_pair(text: str, where: str = "--srs-tol") -> tuple[float, float]:
    """``-3dB,+6dB`` -> (-3.0, 6.0)."""
    parts = str(text).split(",")
    if len(parts) != 2:
        raise refuse(where, text, "a lower and an upper tolerance in dB, such as -3dB,+6dB")
    return _db(parts[0], where, "lower"), _db(parts[1], where, "upper")


def _name(text: str, where: str, names: tuple, what: str) -> str:
    value = str(text).strip().lower()
    if value not in names:
        raise refuse(where, text, f"{what}: one of {', '.join(names)}")
    return value


def parse_record(text: str, where: str = "record") -> JudgedRecord:
    """``unfiltered``, or ``cfc600`` (``CFC 600``): a :class:`JudgedRecord` (the tool's
    default is what no source gives, not a value to give)."""
    value = str(text).strip().lower()
    match = re.fullmatch(r"cfc\s*(\d{1,5})", value)
    if value == "unfiltered":
        return UNFILTERED
    if match and int(match.group(1)) in CFC_CLASSES:
        return JudgedRecord("cfc", int(match.group(1)))
    raise refuse(where, text, "unfiltered or one of 60, 180, 600, 1000 (cfc600)")


def parse_q(text: str, where: str = "--srs-q") -> float:
    """The SRS's quality factor: a number without a unit, above 0.5."""
    expected = f"a quality factor without a unit or sign, above 0.5 and at most " \
               f"{CAPS['srs_q']:,g}, such as 10"
    sign, magnitude, unit_text = split_quantity(text, where, expected)
    if sign or unit_text:
        raise refuse(where, text, expected)
    value = float(magnitude)
    if not (0.5 < value <= CAPS["srs_q"]):
        raise refuse(where, text, expected)
    return value


@dataclass(frozen=True)
class Key:
    """One key of the grammar: a profile key, a Specification sheet row, and (for most) an
    option.

    Attributes
    ----------
    field : str
        The :class:`Specification` field it gives (a tolerance gives a part of one).
    unit : str
        The unit of a bare number in a profile or a cell ("" for text only): the number is
        read as its text followed by the unit.
    parse : callable
        ``(text, where) -> value``: the text grammar, shared by the three sources.
    show : callable
        ``value -> text`` that parses back to the same value.
    """

    field: str
    unit: str
    parse: Callable[[str, str], Any]
    show: Callable[[Any], str]


def _shortest(value: float, scale: str, unit: str) -> str:
    """The shortest decimal text N + ``unit`` that the grammar reads back as ``value``
    exactly (N x ``scale`` rounded once); 17 significant digits always do."""
    if value == 0:
        return f"0{unit}"
    with localcontext() as ctx:
        ctx.prec = 1_200  # a double's exact decimal expansion, shifted by a power of ten
        exact = Decimal(value) / Decimal(scale)
    for digits in range(1, 18):
        text = _plain_decimal(format(exact, f".{digits - 1}e"))
        if scaled(Decimal(text), scale) == value:
            return text + unit
    raise AssertionError(f"no 17-digit text for {quoted(value)}")  # a double always has one


def _plain_decimal(text: str) -> str:
    """``1.50e+1`` -> ``15``; ``5.0e-7`` -> ``5e-7`` (no trailing zeros)."""
    number = Decimal(text).normalize()
    exponent = number.as_tuple().exponent
    assert isinstance(exponent, int)
    return f"{number:f}" if -7 <= exponent <= 6 and len(f"{number:f}") <= 20 else \
        str(number).replace("E", "e")


def _show_peak(kg: float) -> str:
    return _shortest(kg, "1", "kG")


def _show_time(seconds: float) -> str:
    return _shortest(seconds, TIME_UNITS["ms"], "ms")


def _show_fraction(fraction: float) -> str:
    return _shortest(fraction, "0.01", "%")


def _show_tolerance(pair: tuple[float, float]) -> str:
    minus, plus = pair
    if minus == plus:
        return _show_fraction(minus)
    return f"-{_show_fraction(minus)},+{_show_fraction(plus)}"


def _show_db(db: float) -> str:
    return ("+" if db > 0 else "-" if db < 0 else "") + _shortest(abs(db), "1", "dB")


WINDOW_EXPECTED = ("a window BEFORE,AFTER, each a duration or a multiple of the nominal "
                   "duration D (0.5ms,1ms or 0.4D,0.1D; one value for both sides), from 0 to "
                   f"{CAPS['window']:g} s or {CAPS['window_d']:g}D")


def parse_window(text: str, where: str) -> tuple:
    """``0.4D,0.1D`` -> ((0.4, "D"), (0.1, "D")); ``0.5ms`` -> the same both sides [s]."""
    parts = str(text).split(",")
    if len(parts) not in (1, 2):
        raise refuse(where, text, WINDOW_EXPECTED)
    sides = []
    for part in parts:
        sign, magnitude, unit = split_quantity(part, where, WINDOW_EXPECTED)
        if unit == "D":
            if sign:
                raise OptionError(f"{where}: found the sign {sign!r} in {quoted(text)}, where "
                                  f"none is meaningful; expected {WINDOW_EXPECTED}")
            value = float(magnitude)
            if not (math.isfinite(value) and value <= CAPS["window_d"]):
                raise refuse(where, text, WINDOW_EXPECTED)
            sides.append((value, "D"))
        else:
            sides.append((_time("window", zero=True)(part, where), "s"))
    return tuple(sides * 2) if len(sides) == 1 else tuple(sides)


def parse_target(key: str, text: str, option: str) -> float:
    """A design target (``peak`` [kG], ``duration`` [s]) read by the grammar every quantity
    is read by: the same reading, or the same refusal, as the specification's field.

    Raises
    ------
    airgun_xl.errors.OptionError
        Naming ``option``.
    """
    value: float = KEYS[key].parse(text, option)
    return value


def show_window(window: tuple) -> str:
    return ",".join(_shortest(v, "1", "D") if unit == "D" else _show_time(v)
                    for v, unit in window)


def _peak(text: str, where: str) -> float:
    return quantity(text, where, "a peak", PEAK_UNITS, "12kG, 11750g or 1.2e5m/s^2",
                     CAPS["peak"], f"{CAPS['peak']:,g} kG", floor=FLOORS["peak"],
                     floor_text="1e-6 kG")


def _time(name: str, zero: bool = False) -> Callable[[str, str], float]:
    def parse(text: str, where: str) -> float:
        return quantity(text, where, f"a {name}", TIME_UNITS, "5ms or 500us", CAPS[name],
                         f"{CAPS[name]:g} s", zero, floor=FLOORS["duration"],
                         floor_text="1 ns")
    return parse


def _velocity(text: str, where: str) -> float:
    return quantity(text, where, "a velocity change", VELOCITY_UNITS, "35m/s",
                     CAPS["velocity_change"], f"{CAPS['velocity_change']:,g} m/s",
                     floor=FLOORS["velocity_change"], floor_text="1e-6 m/s")


#: The grammar's keys, by name: the profile's keys, the sheet's rows and the options'.
KEYS: dict[str, Key] = {
    "shape": Key("shape", "", lambda t, w: _name(t, w, SHAPES, "a shape"), str),
    "peak": Key("peak", "kG", _peak, _show_peak),
    "peak_tolerance": Key("peak", "%", parse_tolerance_text, _show_tolerance),
    "duration": Key("duration", "ms", _time("duration"), _show_time),
    "duration_tolerance": Key("duration", "%", parse_tolerance_text, _show_tolerance),
    "velocity_change": Key("velocity_change", "m/s", _velocity, lambda v: _shortest(v, "1", "m/s")),
    "velocity_change_tolerance": Key("velocity_change", "%", parse_tolerance_text,
                                     _show_tolerance),
    "corridor": Key("corridor", "%", lambda t, w: _percent(t, w, "a corridor", True)[1],
                    _show_fraction),
    "time_slack": Key("time_slack", "%", lambda t, w: _percent(t, w, "a time slack",
                                                               False)[1], _show_fraction),
    "dv_window": Key("dv_window", "", lambda t, w: parse_window(t, w), show_window),
    "monitor": Key("monitor", "", lambda t, w: parse_window(t, w), show_window),
    "duration_def": Key("duration_def", "", lambda t, w: _name(
        t, w, DURATION_DEFS, "a duration definition"), str),
    "decay": Key("decay", "%", lambda t, w: _percent(t, w, "a decay allowance", False)[1],
                 _show_fraction),
    "record": Key("record", "", parse_record, str),
    "placement": Key("placement", "", lambda t, w: _name(t, w, PLACEMENTS, "a placement"),
                     str),
    "srs_q": Key("srs_q", "", parse_q, lambda q: _shortest(q, "1", "")),
    "srs_lower_db": Key("srs_lower_db", "dB", lambda t, w: _db(t, w, "lower"), _show_db),
    "srs_upper_db": Key("srs_upper_db", "dB", lambda t, w: _db(t, w, "upper"), _show_db),
    "srs_outside": Key("srs_outside", "%", lambda t, w: _percent(
        t, w, "a fraction of the frequencies", False)[1], _show_fraction),
}

#: The option of each key (the tolerances and the dB pair are given with their quantity).
OPTIONS = {"shape": "--shape", "peak": "--peak", "peak_tolerance": "--peak",
           "duration": "--duration", "duration_tolerance": "--duration",
           "velocity_change": "--velocity-change",
           "velocity_change_tolerance": "--velocity-change", "corridor": "--corridor",
           "time_slack": "--time-slack", "dv_window": "--dv-window",
           "monitor": "--monitor", "duration_def": "--duration-def", "decay": "--decay",
           "record": "--cfc",
           "placement": "--placement", "srs_q": "--srs-q", "srs_lower_db": "--srs-tol",
           "srs_upper_db": "--srs-tol", "srs_outside": "--srs-outside"}


def typed_unit(text: str) -> str:
    """The unit a quantity's text ends in (``500g`` -> ``g``)."""
    match = SIGNED.match(text.partition(":")[0])
    return match.group("unit") if match else ""


def shown_unit(spec: Specification, key: str) -> tuple[str, float]:
    """(unit, factor from kG or s) a verdict reports ``key`` (peak, duration) in: the unit its
    nominal was given in, else kG and ms."""
    table = SHOWN_UNITS[key]
    return table.get(dict(spec.units).get(key, ""), table["kG" if key == "peak" else "ms"])


#: Keys kept one release for the old layout: each gives the keys it stands for, unless the
#: same source gives those itself (``window``: both windows, in time, before and after).
ALIASES = {"window": ("dv_window", "monitor")}


#: How a verdict names a key where its name is not plain words.
LABELS = {"dv_window": "velocity-change window", "monitor": "monitoring window",
          "duration_def": "duration definition", "decay": "decay allowance",
          "record": "record judged",
          "srs_q": "SRS Q", "srs_lower_db": "SRS lower tolerance",
          "srs_upper_db": "SRS upper tolerance", "srs_outside": "SRS outside"}


def key_label(key: str) -> str:
    return LABELS.get(key, key.replace("_", " "))


def value_of(spec: Specification, key: str) -> Any:
    """A key's value in a specification (a tolerance's part as the pair (minus, plus)), or
    None when not given."""
    value = getattr(spec, KEYS[key].field)
    if isinstance(value, Tolerance):
        if key.endswith("_tolerance"):
            return (value.minus, value.plus) if math.isfinite(value.minus) else None
        return value.nominal if math.isfinite(value.nominal) else None
    return value


def show(spec: Specification, key: str, digits: int | None = None) -> str:
    """A key's value in the grammar's own text: exact (it parses back to itself), or with
    ``digits`` significant digits, as a verdict prints it."""
    value = value_of(spec, key)
    if value is None:
        return "not given"
    return KEYS[key].show(value if digits is None else _rounded(value, digits))


def _rounded(value: Any, digits: int) -> Any:
    """``value`` with each float in it to ``digits`` significant digits."""
    if isinstance(value, float):
        return float(f"{value:.{digits}g}")
    if isinstance(value, tuple):
        return tuple(_rounded(v, digits) for v in value)
    return value


def parse_key(key: str, value: object, where: str) -> Any:
    """A profile key's or a sheet cell's value: text in the grammar, or a bare number in the
    key's unit (a record's number is its CFC class).

    Raises
    ------
    OptionError
        Naming ``where``.
    """
    k = KEYS[key]
    if isinstance(value, str):
        return k.parse(value, where)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise refuse(where, value, f"text or a number in {k.unit}" if k.unit else "text")
    if isinstance(value, int) and not -10**18 <= value <= 10**18:  # past a float's integers
        raise OptionError(f"{where}: found an integer of more than 18 digits, expected "
                          f"{'a number in ' + k.unit if k.unit else 'text'}")
    number = float(value)
    if not math.isfinite(number):
        raise refuse(where, value, f"a finite number{' in ' + k.unit if k.unit else ''}")
    if key == "record":
        return k.parse(f"cfc{int(number)}" if number.is_integer() and number else
                       ("unfiltered" if number == 0 else repr(number)), where)
    if not k.unit:
        if key == "srs_q":
            return k.parse(_plain(number), where)
        raise refuse(where, value, "text")
    sign = "-" if number < 0 else ""
    if key.endswith("_tolerance") and sign:
        raise OptionError(f"{where}: found {quoted(value)}, a single signed tolerance, which is "
                          f"ambiguous; expected {TOLERANCE_EXPECTED}")
    if key == "srs_upper_db" and number > 0:
        sign = "+"
    return k.parse(f"{sign}{_plain(abs(number))}{k.unit}", where)


def _plain(number: float) -> str:
    return repr(float(number)).replace("inf", "1e999")


# -- the sources ---------------------------------------------------------------------------------

def from_keys(values: dict[str, Any], where: str, key_where: Callable[[str], str],
              srs: SrsRequirement | None = None) -> Specification:
    """A specification from :data:`KEYS` values (a profile's or a sheet's), each read by
    :func:`parse_key`; ``key_where(key)`` names a key in messages. Blank values give
    nothing."""
    unknown = sorted(k for k in values if k not in KEYS and k not in ALIASES)
    if unknown:
        raise OptionError(f"{key_where(unknown[0])}: is not a specification field, expected "
                          f"fields from {', '.join(KEYS)}")
    given = {key: value for key, value in values.items()
             if value is not None and not (isinstance(value, str) and not value.strip())}
    places = {}
    parsed: dict[str, Any] = {}
    for key, value in given.items():
        if key in ALIASES:
            window = parse_window(value if isinstance(value, str) else
                                  _alias_number(value, key_where(key)), key_where(key))
            for target in ALIASES[key]:
                if target not in given:
                    parsed[target], places[target] = window, key_where(key)
        else:
            parsed[key], places[key] = parse_key(key, value, key_where(key)), key_where(key)
    units = {key: typed_unit(value) for key, value in given.items()
             if key in SHOWN_UNITS and isinstance(value, str)}
    return spec_of_keys(parsed, where, srs, places, units)


def _alias_number(value: object, where: str) -> str:
    """The old ``window`` key's bare number: ms."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(
            value) or (isinstance(value, int) and abs(value) > 10**18):
        raise refuse(where, value, "a number in ms, or " + WINDOW_EXPECTED)
    return f"{'-' if value < 0 else ''}{_plain(abs(float(value)))}ms"


def spec_of_keys(parsed: dict[str, Any], source: str, srs: SrsRequirement | None = None,
                 places: dict[str, str] | None = None, units: dict[str, str] | None = None
                 ) -> Specification:
    """A specification from parsed key values (:func:`parse_key`'s or an option's), from
    ``source``; ``places`` names each key's option, cell or profile key."""
    kwargs: dict[str, Any] = {}
    for name in ("peak", "duration", "velocity_change"):
        nominal, tol = parsed.get(name), parsed.get(f"{name}_tolerance")
        if nominal is not None or tol is not None:
            minus, plus = tol if tol is not None else (math.nan, math.nan)
            kwargs[name] = Tolerance(math.nan if nominal is None else nominal, minus, plus)
    for key, value in parsed.items():
        if KEYS[key].field not in ("peak", "duration", "velocity_change"):
            kwargs[KEYS[key].field] = value
    given = list(parsed) + (["srs"] if srs is not None else [])
    return Specification(**kwargs, srs=srs, source=source,
                         origins=tuple((key, source) for key in given),
                         places=tuple((key, (places or {}).get(key, source)) for key in given),
                         units=tuple((units or {}).items()))


def load_profile(name: str) -> Specification:
    """A tolerance profile: a JSON object of :data:`KEYS` (and ``notes``), by path or by the
    name of one in :data:`PROFILES`, read by the bounded reader
    (:func:`airgun_xl.untrusted_json.read_json`: a regular file, capped in size, depth and
    integers, its schema checked).

    Raises
    ------
    OptionError
        For a missing, special, oversized or malformed profile, naming it and the key at
        fault.
    """
    from .untrusted_json import read_json

    path = Path(name)
    if not path.suffix and not path.exists():
        path = PROFILES / f"{name}.json"
    shown = f"--profile {name}"
    if not os.path.lexists(path):
        known = ", ".join(sorted(p.stem for p in PROFILES.glob("*.json")))
        raise OptionError(f"{shown}: no such profile file, expected a JSON file or one of "
                          f"{known}")
    data = dict(read_json(path, "profile", shown, OptionError))
    notes = data.pop("notes", [])
    spec = from_keys(data, f"profile {path.stem}", lambda key: f"{shown}: {key}")
    return replace(spec, notes=tuple([notes] if isinstance(notes, str) else notes))


def check(spec: Specification, where: str) -> Specification:
    """Refuse a specification that cannot be judged (fields that do not go together),
    naming ``where`` it came from. Each field's own value was checked by the grammar.

    Raises
    ------
    OptionError
    """
    for name in ("peak", "duration", "velocity_change"):
        tol = getattr(spec, name)
        words = name.replace("_", " ")
        if tol is not None and not math.isfinite(tol.nominal):
            raise OptionError(f"{where}: found a {words} tolerance without its nominal value, "
                              f"expected one (--{words.replace(' ', '-')} VALUE)")
        if tol is not None and not (math.isfinite(tol.minus) and math.isfinite(tol.plus)):
            raise OptionError(f"{where}: found a {words} of {tol.nominal:g} without a "
                              f"tolerance, expected one (VALUE:10%, a profile or the sheet)")
    if spec.shape not in (None, "none") and (spec.peak is None or spec.duration is None):
        raise OptionError(f"{where}: found the shape {spec.shape} without a nominal peak and "
                          "duration, expected both (a named shape is judged: its ideal pulse "
                          "is drawn from them), or the shape none")
    if spec.corridor is not None:
        if spec.shape in (None, "none"):
            raise OptionError(f"{where}: found a corridor with the shape none, expected a "
                              f"shape ({', '.join(SHAPES[:3])}) to draw it round")
        if spec.peak is None or spec.duration is None:
            raise OptionError(f"{where}: found a corridor without a nominal peak and "
                              "duration, expected both (the ideal pulse is drawn from them)")
    if spec.srs is None:
        given = [k for k in ("srs_q", "srs_lower_db", "srs_upper_db", "srs_outside")
                 if spec.origin(k) not in (None, "default")
                 and not str(spec.origin(k)).startswith("profile")]
        if given:
            named = dict(spec.places).get(given[0], str(spec.origin(given[0])))
            raise OptionError(f"{named}: found {show(spec, given[0])} with no SRS requirement"
                              ", expected the requirement it applies to (--srs, or rows in "
                              "the Specification sheet's F and G)")
    elif not 0 < len(spec.srs.frequencies) <= MAX_SRS_ROWS:
        raise OptionError(f"{where}: found {len(spec.srs.frequencies)} SRS rows, expected 1 "
                          f"to {MAX_SRS_ROWS:,}")
    return spec


def combine(profile: str | Specification | None, sheet: Specification | None,
            options: Specification | None) -> Specification | None:
    """The specification a shot is judged by: the profile (a name, a file or one already
    loaded), then the shot's sheet, then the command's options, each overriding the one
    before field by field; checked, and its defaults applied. None when nothing is specified.
    """
    spec = Specification()
    loaded = load_profile(profile) if isinstance(profile, str) else profile
    parts = [part for part in (loaded, sheet, options) if part is not None]
    for part in parts:
        spec = spec.merged(part)
    spec = _shape_none_over_a_corridor(spec, [part.source for part in parts])
    spec = _derived_velocity_change(spec)
    spec = check(spec, "the specification")
    if spec.empty:
        return None
    return spec.resolved()


def _derived_velocity_change(spec: Specification) -> Specification:
    """A half-sine's nominal velocity change where a source gives its tolerance only: it
    follows from the peak and the duration, 2 A T / pi [m/s] (A in kG x 9800 m/s^2)."""
    dv, peak, duration = spec.velocity_change, spec.peak, spec.duration
    if dv is None or math.isfinite(dv.nominal) or spec.shape != "half-sine" or peak is None \
            or duration is None or not math.isfinite(peak.nominal * duration.nominal) or \
            spec.duration_def not in (None, "base"):
        return spec
    nominal = 2 * peak.nominal * KG_MS2 * duration.nominal / math.pi
    origins = {**dict(spec.origins),
               "velocity_change": "derived (2AT/pi of the half-sine's nominal peak and duration)"}
    return replace(spec, velocity_change=Tolerance(nominal, dv.minus, dv.plus),
                   origins=tuple(origins.items()))


def _shape_none_over_a_corridor(spec: Specification, order: list[str]) -> Specification:
    """``--shape none`` (or the sheet's) over a profile's corridor: the later source asks for
    limits only, so the corridor is set aside, and the verdict says so; from one source, the
    two are refused together by :func:`check`."""
    shape_from, corridor_from = spec.origin("shape"), spec.origin("corridor")
    if spec.shape != "none" or spec.corridor is None or shape_from is None or \
            corridor_from is None or order.index(shape_from) <= order.index(corridor_from):
        return spec
    said = (f"not judged: the corridor {show(spec, 'corridor')} from {corridor_from} (the "
            f"shape is none, from {shape_from}: limits only)")
    origins = tuple((k, w) for k, w in spec.origins if k != "corridor")
    return replace(spec, corridor=None, origins=origins, set_aside=spec.set_aside + (said,))


def unjudged(spec: Specification) -> list[str]:
    """What a source gave that no criterion judges, in words: a verdict says it (a profile's
    SRS tolerance with no SRS requirement)."""
    keys = [k for k in ("srs_q", "srs_lower_db", "srs_upper_db", "srs_outside")
            if spec.srs is None and spec.origin(k) not in (None, "default")]
    said = list(spec.set_aside)
    if keys:
        said.append(f"not judged: {', '.join(key_label(k) for k in keys)} from "
                    f"{spec.origin(keys[0])} (no SRS requirement was given)")
    return said
