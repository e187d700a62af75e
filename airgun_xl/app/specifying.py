"""The specification fields a command is given (the CLI's options, the Python API's keyword
arguments), each as text in the specification's grammar
(:data:`airgun_xl.specification.KEYS`, the one the profile and the sheet use), and the
specification a shot is judged by.

A field given overrides the sheet's and the profile's even when it equals the default
(``time_slack="0%"``)."""
from __future__ import annotations

import dataclasses
import difflib
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypedDict

from ..errors import OptionError
from ..specification import (
    ALIASES,
    CFC_CLASSES,
    KEYS,
    OPTIONS,
    SrsRequirement,
    cfc_record,
    combine,
    parse_db_pair,
    parse_window,
    spec_of_keys,
    typed_unit,
)
from ..units import SHOWN_UNITS

if TYPE_CHECKING:
    from ..shot import Shot
    from ..specification import Specification

#: The fields with the grammar keys they give, from the one table
#: (:data:`airgun_xl.specification.OPTIONS`): a quantity's field gives its tolerance too
#: (``peak="12kG:10%"``), ``srs_tol`` gives the two dB sides, every other field one key.
QUANTITY_OPTIONS = tuple((key, option) for key, option in OPTIONS.items()
                         if f"{key}_tolerance" in OPTIONS)
PLAIN_OPTIONS = tuple((key, option) for key, option in OPTIONS.items()
                      if option not in dict(QUANTITY_OPTIONS).values()
                      and option not in ("--srs-tol", "--cfc"))

#: Every text field with the option that gives it, as refusals name it.
TEXT_OPTIONS = (*QUANTITY_OPTIONS, *PLAIN_OPTIONS, ("window", "--window"), ("srs", "--srs"),
                ("srs_tol", "--srs-tol"), ("profile", "--profile"))


def not_empty(option: str, value: object) -> None:
    """An option (or keyword) given an empty text is refused: it would stand for none.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    if isinstance(value, str) and not value.strip():
        raise OptionError(f"{option}: found an empty value, expected one")


#: What a record's filter takes, said by every refusal of it.
CFC_EXPECTED = "a J211 class (60, 180, 600 or 1000) or none"


def cfc_class(text: str) -> int | None:
    """A record's filter: a SAE J211 class, or None for ``none`` (no filter).

    Raises
    ------
    ValueError
        Saying what was found and what is expected (the caller names the option).
    """
    if str(text).strip().lower() == "none":
        return None
    try:
        value: int | None = int(text)
    except ValueError:
        value = None
    if value not in CFC_CLASSES:
        raise ValueError(f"found {text!r}, expected {CFC_EXPECTED}")
    return value


def record_filter(cfc: object) -> int | None:
    """``cfc`` as a keyword gives it (a class, ``"600"``, ``"none"``; None: not given), as
    :func:`cfc_class` reads it; refused naming ``--cfc``.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    if cfc is None:
        return None
    try:
        return cfc_class(str(cfc))
    except ValueError as exc:
        raise OptionError(f"--cfc: {exc}") from None


@dataclass(frozen=True)
class SpecFields:
    """The specification fields given, as text (None: not given). The names are the
    specification's keys (:data:`~airgun_xl.specification.OPTIONS`, tied to it by
    tests/test_app_accept.py); ``cfc`` is the record judged, given by the option (or keyword)
    ``cfc_given`` names."""

    profile: str | None = None
    shape: str | None = None
    peak: str | None = None  # nominal [kG, g, m/s^2] and tolerance: 12kG:10%
    duration: str | None = None  # nominal [s, ms, us, ns] and tolerance: 5ms:10%
    velocity_change: str | None = None  # nominal [m/s] and tolerance: 35m/s:10%
    corridor: str | None = None  # [% of the nominal peak]
    time_slack: str | None = None  # [% of the duration]
    dv_window: str | None = None
    monitor: str | None = None
    window: str | None = None  # the old alias of both windows
    duration_def: str | None = None
    decay: str | None = None  # [% of the duration]
    placement: str | None = None
    srs: str | None = None  # a requirement's CSV file
    srs_tol: str | None = None  # [dB] lower,upper
    srs_q: str | None = None  # [-]
    srs_outside: str | None = None  # [% of the frequencies]
    cfc: int | None = None  # the J211 class of the record judged (None: none, when given)
    cfc_given: str | None = None  # the option that gave ``cfc`` (None: not given)
    accel_unit: str | None = None  # the requirement's unit where its file says none

    @classmethod
    def of(cls, source: Any) -> SpecFields:
        """The fields an object holds as attributes of these names (an argparse namespace),
        missing ones not given."""
        return cls(**{f.name: getattr(source, f.name, None)
                      for f in dataclasses.fields(cls)})


class SpecKeywords(TypedDict, total=False):
    """The specification's fields as the Python API's keywords (:func:`airgun_xl.accept`,
    :func:`airgun_xl.design`): the options' names, each text in the grammar
    (``peak="12kG:10%"``), a file's as its path; ``cfc`` a J211 class or ``"none"``."""

    profile: str | os.PathLike[str]
    shape: str
    peak: str
    duration: str
    velocity_change: str
    corridor: str
    time_slack: str
    dv_window: str
    monitor: str
    duration_def: str
    decay: str
    placement: str
    srs: str | os.PathLike[str]
    srs_tol: str
    srs_q: str
    srs_outside: str
    cfc: int | str


def keyword_fields(command: str, given: dict[str, Any],
                   accel_unit: str | None = None) -> SpecFields:
    """The :class:`SpecFields` a function's keywords give; a keyword that is not a field is
    refused naming the nearest (``accept: found the keyword 'peek', expected a field of the
    specification (did you mean peak?)``).

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    known = tuple(SpecKeywords.__annotations__)
    for key in given:
        if key not in known:
            near = difflib.get_close_matches(key, known, 1, 0.75)
            raise OptionError(f"{command}: found the keyword {key!r}, expected a field of the "
                              "specification" + (f" (did you mean {near[0]}?)" if near else
                                                 f" ({', '.join(known)})"))
    cfc = given.get("cfc")
    record = record_filter(cfc)
    text = {key: None if value is None else os.fspath(value) if isinstance(
        value, os.PathLike) else str(value) for key, value in given.items() if key != "cfc"}
    return SpecFields(**text, cfc=record, cfc_given="--cfc" if cfc is not None else None,
                      accel_unit=accel_unit)


def options_spec(fields: SpecFields) -> Specification | None:
    """The specification the fields give, without the profile; None when they give none.

    Raises
    ------
    airgun_xl.errors.OptionError
        Naming the option and what it expects.
    """
    from ..readers.recording import read_spectrum

    for key, option in TEXT_OPTIONS:  # as the command line refuses them, whoever gave them
        not_empty(option, getattr(fields, key))
    parsed: dict[str, Any] = {}
    for key, option in QUANTITY_OPTIONS:
        text = getattr(fields, key)
        if text is not None:
            parsed.update(_quantity_option(key, option, text))
    for key, option in PLAIN_OPTIONS:
        text = getattr(fields, key)
        if text is not None:
            parsed[key] = KEYS[key].parse(text, option)
    if fields.window is not None:  # the alias: what the options do not say
        window = parse_window(fields.window, "--window")
        for key in ALIASES["window"]:
            parsed.setdefault(key, window)
    if fields.cfc_given:  # --cfc none: the unfiltered record, said
        parsed["record"] = cfc_record(fields.cfc)
    if fields.srs_tol is not None:
        parsed["srs_lower_db"], parsed["srs_upper_db"] = parse_db_pair(fields.srs_tol)
    srs = None
    if fields.srs is not None:
        freqs, levels = read_spectrum(fields.srs, fields.accel_unit, "--srs")
        srs = SrsRequirement(tuple(map(float, freqs)), tuple(map(float, levels)))
    if not parsed and srs is None:
        return None
    units = {key: typed_unit(getattr(fields, key)) for key, _ in QUANTITY_OPTIONS
             if key in SHOWN_UNITS and getattr(fields, key) is not None}
    places = {key: option for key, option in OPTIONS.items() if key in parsed}
    if "record" in parsed:
        places["record"] = str(fields.cfc_given)  # --cfc, or its old spelling as typed
    if fields.window is not None:
        places.update({k: "--window" for k in ALIASES["window"] if k not in places or
                       getattr(fields, k) is None})
    return spec_of_keys(parsed, "options", srs, {**places, "srs": "--srs"}, units)


def _quantity_option(key: str, option: str, text: str) -> dict[str, Any]:
    """``12kG:10%`` -> {key: 12.0, key_tolerance: (0.1, 0.1)}; ``12kG`` -> the nominal only
    (its tolerance from the sheet or the profile)."""
    value, sep, tolerance = str(text).partition(":")
    parsed = {key: KEYS[key].parse(value, option)}
    if sep:
        parsed[f"{key}_tolerance"] = KEYS[f"{key}_tolerance"].parse(tolerance, option)
    return parsed


def resolve(shot: Shot, fields: SpecFields) -> Specification | None:
    """The specification a command judges by: the profile, then the shot's sheet, then the
    fields, each overriding the one before field by field; None when nothing is specified.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    not_empty("--profile", fields.profile)
    return combine(fields.profile, shot.spec, options_spec(fields))


def require(spec: Specification | None, shot: object) -> Specification:
    """``spec``, or the refusal of a judgement with nothing to judge by."""
    if spec is None:
        raise OptionError(f"{shot}: its Specification sheet is empty and no option gives"
                          " a criterion; expected --peak, --duration, --velocity-change, --srs"
                          " or --profile")
    return spec
