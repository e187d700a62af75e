"""A client's test specification: the pulse's shape, its figures with their tolerances, the
corridor, an SRS requirement and the record judged (issue 25).

It is declared once here, as :class:`Specification`; it comes from three places, which all
build one through :func:`from_fields`:

- the shot workbook's ``Specification`` sheet (:mod:`airgun_xl.workbook.spec_sheet`), which the
  template writes empty;
- a tolerance profile, a JSON file the lab names and edits (:func:`load_profile`; the
  package's ``profiles/`` folder holds the examples);
- command-line options (``--peak 12kG:10%``...), which override the other two field by field.

Units: peaks in kG (the macro's, 9800 m/s^2), times in s, velocities in m/s, tolerances as
fractions. The judging itself is :mod:`airgun_xl.studies.acceptance`.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from .errors import OptionError

#: The pulse shapes a specification can name; "none" judges the limits only (no corridor).
SHAPES = ("half-sine", "sawtooth", "trapezoid", "none")

#: Where the ideal pulse is placed over the record: by least squares (the default, where the
#: standard gives no rule), or with its peak on the record's peak.
PLACEMENTS = ("least-squares", "peak")

#: The largest SRS requirement read (rows): a spectrum is at most a few hundred.
MAX_SRS_ROWS = 2_000

#: Profiles shipped with the package (examples; the lab keeps its own beside them).
PROFILES = Path(__file__).with_name("profiles")


@dataclass(frozen=True)
class Tolerance:
    """A nominal value with its tolerance: ``nominal * (1 - minus)`` to ``nominal * (1 +
    plus)``. NaN marks a part not given yet: a profile gives tolerances, the test its nominal
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
    """Required SRS levels at their frequencies, with the tolerance in dB either side and the
    fraction of frequencies that may fall outside it."""

    frequencies: tuple[float, ...]  # [Hz]
    levels_kg: tuple[float, ...]  # [kG]
    q: float = 10.0
    lower_db: float = -3.0
    upper_db: float = 6.0
    outside_fraction: float = 0.0


@dataclass(frozen=True)
class Specification:
    """What a shot must meet. Every field may be left out (None); a criterion is judged only
    when its fields are given.

    Attributes
    ----------
    shape : str
        One of :data:`SHAPES`.
    peak : Tolerance or None
        Peak acceleration [kG].
    duration : Tolerance or None
        Pulse duration [s]: the base width of the nominal shape (see
        :func:`airgun_xl.studies.acceptance.duration_definition`).
    velocity_change : Tolerance or None
        Velocity change [m/s], integrated over the pulse and its windows.
    corridor : float or None
        Half-width of the corridor round the ideal pulse, a fraction of the nominal peak.
    time_slack : float
        Time slack of the corridor, a fraction of the nominal duration.
    window : float or None
        Monitoring window before and after the pulse [s] (None: half the duration).
    srs : SrsRequirement or None
    cfc : int or None
        The record judged: unfiltered (None, or 0 where an option says so over a sheet's
        class) or through SAE J211 CFC ``cfc``.
    placement : str
        One of :data:`PLACEMENTS`.
    source : str
        Where the specification came from (profile, sheet, options), as verdicts print it.
    """

    shape: str = "none"
    peak: Tolerance | None = None
    duration: Tolerance | None = None
    velocity_change: Tolerance | None = None
    corridor: float | None = None
    time_slack: float = 0.0
    window: float | None = None
    srs: SrsRequirement | None = None
    cfc: int | None = None
    placement: str = "least-squares"
    source: str = ""
    notes: tuple[str, ...] = field(default_factory=tuple)

    @property
    def empty(self) -> bool:
        """True when nothing is specified: no criterion to judge."""
        return (self.peak is None and self.duration is None and self.velocity_change is None
                and self.srs is None)

    def merged(self, other: Specification) -> Specification:
        """This specification with every field ``other`` gives (not None) taken from it."""
        changes = {f.name: getattr(other, f.name) for f in fields(self)
                   if f.name not in ("source", "notes")
                   and getattr(other, f.name) != getattr(Specification(), f.name)}
        for name in ("peak", "duration", "velocity_change"):
            if name in changes:
                changes[name] = changes[name].over(getattr(self, name))
        sources = " + ".join(s for s in (self.source, other.source) if s)
        return replace(self, **changes, source=sources, notes=self.notes + other.notes)


_TOLERANCE = re.compile(r"^(?P<value>[^:]+)(?::(?P<tol>.+))?$")
_PERCENT = re.compile(r"^\s*([-+]?)\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*%\s*$")


def _fraction(text: str, option: str, whole: str) -> tuple[str, float]:
    match = _PERCENT.match(text)
    if not match:
        raise OptionError(f"{option}: found {whole!r}, expected a tolerance in %, such as "
                          "10% or -10%,+20%")
    value = float(match.group(2)) / 100
    if not (math.isfinite(value) and 0 <= value < 1):
        raise OptionError(f"{option}: found {whole!r}, expected a tolerance from 0% to below "
                          "100%")
    return match.group(1), value


def parse_tolerance(text: str, option: str, parse_value) -> Tolerance:
    """``12kG:10%`` (either side), ``12kG:-10%,+20%``: a :class:`Tolerance`."""
    match = _TOLERANCE.match(str(text).strip())
    if not match:
        raise OptionError(f"{option}: found {text!r}, expected VALUE:TOLERANCE such as "
                          "12kG:10%")
    nominal = parse_value(match.group("value"), option)
    if match.group("tol") is None:  # the tolerance from the profile or the sheet
        return Tolerance(nominal, math.nan, math.nan)
    parts = [p for p in match.group("tol").split(",")]
    if len(parts) == 1:
        _, tol = _fraction(parts[0], option, text)
        return Tolerance(nominal, tol, tol)
    if len(parts) != 2:
        raise OptionError(f"{option}: found {text!r}, expected one tolerance or two "
                          "(-10%,+20%)")
    signs = [_fraction(p, option, text) for p in parts]
    minus = next((v for s, v in signs if s == "-"), None)
    plus = next((v for s, v in signs if s == "+"), None)
    if minus is None or plus is None:
        raise OptionError(f"{option}: found {text!r}, expected the lower tolerance with - and "
                          "the upper with + (-10%,+20%)")
    return Tolerance(nominal, minus, plus)


def parse_velocity(text: str, option: str = "--velocity-change") -> float:
    """``35m/s`` -> 35.0 [m/s]."""
    match = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(m/s)?\s*", str(text))
    value = float(match.group(1)) if match else math.nan
    if not (value > 0 and math.isfinite(value)):
        raise OptionError(f"{option}: found {text!r}, expected a positive velocity such as "
                          "35m/s")
    return value


def parse_db_pair(text: str, option: str = "--srs-tol") -> tuple[float, float]:
    """``-3dB,+6dB`` -> (-3.0, 6.0)."""
    parts = [p.strip() for p in str(text).split(",")]
    values = []
    for part in parts:
        match = re.fullmatch(r"([-+]?[0-9]*\.?[0-9]+)\s*(dB)?", part, re.IGNORECASE)
        values.append(float(match.group(1)) if match else math.nan)
    if len(values) != 2 or not all(math.isfinite(v) for v in values) or not (
            values[0] <= 0 <= values[1]):
        raise OptionError(f"{option}: found {text!r}, expected a lower and an upper tolerance"
                          " in dB, such as -3dB,+6dB")
    return values[0], values[1]


def check(spec: Specification, where: str) -> Specification:
    """Refuse a specification that cannot be judged, naming ``where`` it came from.

    Raises
    ------
    OptionError
    """
    if spec.shape not in SHAPES:
        raise OptionError(f"{where}: found the shape {spec.shape!r}, expected one of "
                          f"{', '.join(SHAPES)}")
    if spec.placement not in PLACEMENTS:
        raise OptionError(f"{where}: found the placement {spec.placement!r}, expected one of "
                          f"{', '.join(PLACEMENTS)}")
    for name in ("peak", "duration", "velocity_change"):
        tol = getattr(spec, name)
        words = name.replace("_", " ")
        if tol is not None and not math.isfinite(tol.nominal):
            raise OptionError(f"{where}: found a {words} tolerance without its nominal value, "
                              f"expected one (--{words.replace(' ', '-')} VALUE)")
        if tol is not None and not tol.nominal > 0:
            raise OptionError(f"{where}: found a {words} of {tol.nominal!r}, expected a "
                              "positive number")
        if tol is not None and not (math.isfinite(tol.minus) and math.isfinite(tol.plus)):
            raise OptionError(f"{where}: found a {words} of {tol.nominal:g} without a "
                              f"tolerance, expected one (VALUE:10%, a profile or the sheet)")
    if spec.corridor is not None:
        if spec.shape == "none":
            raise OptionError(f"{where}: found a corridor with the shape none, expected a "
                              f"shape ({', '.join(SHAPES[:3])}) to draw it round")
        if spec.peak is None or spec.duration is None:
            raise OptionError(f"{where}: found a corridor without a nominal peak and "
                              "duration, expected both (the ideal pulse is drawn from them)")
        if not (0 < spec.corridor < 1):
            raise OptionError(f"{where}: found a corridor of {spec.corridor!r}, expected a "
                              "fraction of the peak from 0 to 1 (0.2 for ±20 %)")
    if not (0 <= spec.time_slack < 1):
        raise OptionError(f"{where}: found a time slack of {spec.time_slack!r}, expected a "
                          "fraction of the duration from 0 to below 1")
    if spec.window is not None and not (math.isfinite(spec.window) and spec.window >= 0):
        raise OptionError(f"{where}: found a window of {spec.window!r} s, expected 0 or more")
    if spec.cfc not in (None, 0, 60, 180, 600, 1000):  # 0: unfiltered, said explicitly
        raise OptionError(f"{where}: found the record CFC {spec.cfc!r}, expected unfiltered "
                          "or one of 60, 180, 600, 1000")
    if spec.srs is not None:
        r = spec.srs
        if not (0 < len(r.frequencies) <= MAX_SRS_ROWS):
            raise OptionError(f"{where}: found {len(r.frequencies)} SRS rows, expected 1 to "
                              f"{MAX_SRS_ROWS:,}")
        if not (r.q > 0.5 and r.lower_db <= 0 <= r.upper_db and 0 <= r.outside_fraction < 1):
            raise OptionError(f"{where}: found the SRS Q {r.q!r}, tolerance {r.lower_db!r} / "
                              f"{r.upper_db!r} dB and outside fraction {r.outside_fraction!r},"
                              " expected Q above 0.5, a lower tolerance <= 0 <= the upper, "
                              "and a fraction from 0 to below 1")
    return spec


#: The fields of a profile file and of the Specification sheet, by name: (kind, unit).
FIELDS = {
    "shape": ("text", ""),
    "peak": ("number", "kG"),
    "peak_tolerance": ("percent", "%"),
    "duration": ("number", "ms"),
    "duration_tolerance": ("percent", "%"),
    "velocity_change": ("number", "m/s"),
    "velocity_change_tolerance": ("percent", "%"),
    "corridor": ("percent", "% of peak"),
    "time_slack": ("percent", "% of duration"),
    "window": ("number", "ms"),
    "record": ("text", ""),
    "placement": ("text", ""),
    "srs_q": ("number", ""),
    "srs_lower_db": ("number", "dB"),
    "srs_upper_db": ("number", "dB"),
    "srs_outside": ("percent", "%"),
}


def _tol(values: dict, name: str, scale: float, where: str) -> Tolerance | None:
    nominal = values.get(name)
    tol = values.get(f"{name}_tolerance")
    if nominal is None and tol is None:
        return None
    if tol is not None and not 0 <= tol < 100:
        raise OptionError(f"{where}: found {name}_tolerance = {tol!r} %, expected 0 to below 100")
    return Tolerance(math.nan if nominal is None else nominal * scale,
                     math.nan if tol is None else tol / 100,
                     math.nan if tol is None else tol / 100)


def from_fields(values: dict, where: str, srs_rows=None) -> Specification:
    """A specification from named fields in the units of :data:`FIELDS` (percentages in %),
    e.g. a profile's or the sheet's; ``srs_rows`` are (frequency [Hz], level [kG]) pairs.

    Raises
    ------
    OptionError
        Naming ``where`` and the field.
    """
    unknown = sorted(set(values) - set(FIELDS))
    if unknown:
        raise OptionError(f"{where}: found the field {unknown[0]!r}, expected fields from "
                          f"{', '.join(FIELDS)}")
    clean: dict = {}
    for name, value in values.items():
        kind, unit = FIELDS[name]
        if value is None or value == "":
            continue
        if kind == "text":
            if not isinstance(value, str):
                raise OptionError(f"{where}: found {name} = {value!r}, expected text")
            clean[name] = value.strip().lower()
        else:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not \
                    math.isfinite(value):
                raise OptionError(f"{where}: found {name} = {value!r}, expected a number"
                                  + (f" in {unit}" if unit else ""))
            clean[name] = float(value)
    record = clean.get("record", "unfiltered")
    cfc = None
    if record != "unfiltered":
        match = re.fullmatch(r"(?:cfc\s*)?(\d+)", record)
        if not match:
            raise OptionError(f"{where}: found record = {record!r}, expected unfiltered or "
                              "CFC 60, 180, 600 or 1000")
        cfc = int(match.group(1))
    srs = None
    if srs_rows:
        freqs, levels = zip(*srs_rows, strict=True)
        srs = SrsRequirement(tuple(float(f) for f in freqs), tuple(float(v) for v in levels),
                             clean.get("srs_q", 10.0), clean.get("srs_lower_db", -3.0),
                             clean.get("srs_upper_db", 6.0),
                             clean.get("srs_outside", 0.0) / 100)
    corridor = clean.get("corridor")
    window = clean.get("window")
    spec = Specification(
        shape=clean.get("shape", "none"), peak=_tol(clean, "peak", 1.0, where),
        duration=_tol(clean, "duration", 1e-3, where),
        velocity_change=_tol(clean, "velocity_change", 1.0, where),
        corridor=None if corridor is None else corridor / 100,
        time_slack=clean.get("time_slack", 0.0) / 100,
        window=None if window is None else window * 1e-3, srs=srs, cfc=cfc,
        placement=clean.get("placement", "least-squares"), source=where)
    return spec


#: A profile file is read only up to this size: it is a few hundred bytes of JSON.
MAX_PROFILE_BYTES = 65_536


def load_profile(name: str) -> Specification:
    """A tolerance profile: a JSON file of :data:`FIELDS` (and ``notes``), by path or by the
    name of one in :data:`PROFILES`.

    Raises
    ------
    OptionError
        For a missing, oversized or malformed profile, naming it.
    """
    path = Path(name)
    if not path.suffix and not path.exists():
        path = PROFILES / f"{name}.json"
    shown = f"--profile {name}"
    try:
        size = path.stat().st_size
    except OSError:
        known = ", ".join(sorted(p.stem for p in PROFILES.glob("*.json")))
        raise OptionError(f"{shown}: no such profile file, expected a JSON file or one of "
                          f"{known}") from None
    if size > MAX_PROFILE_BYTES:
        raise OptionError(f"{shown}: found {size:,} bytes, expected a profile of at most "
                          f"{MAX_PROFILE_BYTES:,}")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise OptionError(f"{shown}: is not readable JSON ({type(exc).__name__}), expected "
                          "an object of specification fields") from None
    if not isinstance(data, dict):
        raise OptionError(f"{shown}: found {type(data).__name__}, expected an object of "
                          "specification fields")
    notes = data.pop("notes", [])
    if isinstance(notes, str):
        notes = [notes]
    if not isinstance(notes, list) or not all(isinstance(n, str) for n in notes):
        raise OptionError(f"{shown}: found notes that are not text, expected a list of text")
    spec = from_fields(data, f"profile {path.stem}")
    return replace(spec, notes=tuple(notes))


def combine(profile: str | None, sheet: Specification | None,
            options: Specification | None) -> Specification | None:
    """The specification a shot is judged by: the profile (a name or file), then the shot's
    sheet, then the command's options, each overriding the one before field by field; checked.
    None when nothing is specified."""
    spec = load_profile(profile) if profile else Specification()
    for part in (sheet, options):
        if part is not None:
            spec = spec.merged(part)
    spec = check(spec, "the specification")
    return None if spec.empty else spec
