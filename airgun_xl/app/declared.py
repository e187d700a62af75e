"""A command declared once (issue 61): a frozen, keyword-only request whose fields carry
their option.

Each field of a request is a value (a number in its unit, a choice, a path), declared with
:func:`option` or :func:`positional`: its default, how the command line spells it (flags,
metavar, help, old spellings) and its grammar, one function ``read(value, who)`` that takes
what a caller gave (a value, or the text a command line gave) and gives the value, or raises
the project's :class:`~airgun_xl.errors.OptionError` naming ``who``. From that one
declaration:

- the request checks itself (:class:`Checked`): each field read in ``__post_init__``, a
  refusal naming the field as the Python API spells it (``q: found '0', ...``);
- the CLI builds the command's options, in the fields' order
  (:func:`airgun_xl.cli.declared.add_declared`), each read with the same grammar, a refusal
  naming its flag (``--srs-q: found '0', ...``), and the request from the parsed options
  (:func:`airgun_xl.cli.declared.request_of`);
- the Python API function's keywords are the request's fields
  (``tests/test_declared.py`` checks each converted function's signature against them).

The options several commands share are declared once here (:func:`shot`, :func:`output`,
:func:`force`, :func:`integrator`, :func:`model`, :func:`crush_law`, :func:`archive`).
"""
from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from ..choices import INTEGRATORS, MODELS
from ..errors import OptionError
from ..units import quoted

#: A field's grammar: (what the caller gave, who gave it) -> the value.
Read = Callable[[Any, str], Any]

T = TypeVar("T", bound="Checked")


@dataclass(frozen=True)
class Option:
    """How a field is spelt on the command line.

    Attributes
    ----------
    flags : tuple of str
        Its spellings (``("-o", "--output")``); a positional's is its name alone.
    help : str
        Its help line; ``%`` as argparse reads it (``%%`` for a percent sign).
    metavar : str or None
        The value's placeholder in the help.
    kind : str
        ``"value"`` (given once, its value read by the grammar), ``"switch"`` (present or
        not), ``"choice"`` (one of ``choices``), ``"integrators"`` (an integrator, given
        again for each run side by side), ``"repeated"`` (given once for each value, the
        values read together), ``"cfc"`` (a J211 class or ``none``, told apart from a
        specification's), ``"positional"`` or ``"positional?"`` (one that may be left out).
    choices : tuple of str
        For a ``"choice"``.
    aliases : tuple of tuple of str
        Old spellings kept one release, each ``(flag, idea)`` (the idea as
        :data:`airgun_xl.cli.vocabulary.VOCABULARY` names it).
    group : str or None
        Options of one group name exclude each other on the command line (``--scheduler``
        or ``--workers``).
    """

    flags: tuple[str, ...]
    help: str
    metavar: str | None = None
    kind: str = "value"
    choices: tuple[str, ...] = ()
    aliases: tuple[tuple[str, str], ...] = ()
    group: str | None = None


def _keep(value: Any, who: str) -> Any:
    return value


def refusal(template: str, *fields: str, **values: Any) -> OptionError:
    """A refusal naming several fields (``{0}`` ... in ``template``, ``fields`` their names,
    the other fields ``values``): the Python API's line names the keywords, the command
    line's the flags (``refusal("{0}: found it with {1}", "sobol", "mc")``)."""
    return OptionError(template.format(*fields, **values), template, fields, values)


def option(default: Any, *flags: str, help: str, read: Read = _keep,
           metavar: str | None = None, kind: str = "value", choices: tuple[str, ...] = (),
           aliases: tuple[tuple[str, str], ...] = (), group: str | None = None) -> Any:
    """A request's field with a default, spelt ``flags`` on the command line."""
    return dataclasses.field(default=default, metadata={
        "option": Option(tuple(flags), help, metavar, kind, choices, aliases, group),
        "read": read})


def positional(name: str, *, help: str, read: Read = _keep, metavar: str | None = None,
               choices: tuple[str, ...] = ()) -> Any:
    """A request's field without a default: the command's positional argument ``name``
    (one of ``choices`` when given)."""
    return dataclasses.field(metadata={
        "option": Option((name,), help, metavar, "positional", choices), "read": read})


def optional_positional(name: str, *, help: str, read: Read = _keep,
                        metavar: str | None = None) -> Any:
    """A request's field of default None: the command's positional argument ``name``, which
    may be left out."""
    return dataclasses.field(default=None, metadata={
        "option": Option((name,), help, metavar, "positional?"), "read": read})


def option_of(field: dataclasses.Field[Any]) -> Option:
    """The command-line spelling a field was declared with."""
    found = field.metadata.get("option")
    assert isinstance(found, Option), f"{field.name} was not declared with option()"
    return found


class Checked:
    """A request that checks itself: each declared field read by its grammar, a refusal
    naming the field (the Python API's keyword). Its subclasses are frozen, keyword-only
    dataclasses."""

    @classmethod
    def given(cls: type[T], **values: Any) -> T:
        """The request of what a caller gave, each field as the caller gave it (text, a
        number, a path), read by its grammar: the Python API's one line."""
        return cls(**values)

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):  # type: ignore[arg-type]
            read = field.metadata.get("read")
            if read is not None:
                object.__setattr__(self, field.name, read(getattr(self, field.name),
                                                          field.name))
        given: dict[str, str] = {}
        for field in dataclasses.fields(self):  # type: ignore[arg-type]
            spelt = field.metadata.get("option")
            if not isinstance(spelt, Option) or spelt.group is None \
                    or getattr(self, field.name) == field.default:
                continue
            if spelt.group in given:  # what the command line's exclusive group refuses
                raise refusal("{0}: found it with {1}, expected one of them", field.name,
                              given[spelt.group])
            given[spelt.group] = field.name


# -- grammars --------------------------------------------------------------------------


def a_path(value: Any, who: str) -> Path:
    """A path: a ``str`` or ``os.PathLike``, not empty."""
    if isinstance(value, Path):
        return value
    if isinstance(value, str) and value.strip():
        return Path(value)
    if isinstance(value, str):  # "" would be the working folder: a path not given
        raise OptionError(f"{who}: found an empty value, expected a path")
    try:
        return Path(os.fspath(value))
    except TypeError:
        raise OptionError(f"{who}: found {value!r}, expected a path") from None


def a_path_or_none(value: Any, who: str) -> Path | None:
    return None if value is None else a_path(value, who)


def a_recording(value: Any, who: str) -> str:
    """A recording: a file's path, or a workbook's columns as text
    (``trace.xlsx:Sheet1!A:B``), kept as the text given (a path would read its colon as
    a drive's on Windows)."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if isinstance(value, str) and value.strip():
        return value
    raise OptionError(f"{who}: found {value!r}, expected a recording's path")


def a_folder_or_none(value: Any, who: str) -> str | None:
    """A folder's path as text (a path given is its text), or None."""
    if value is None:
        return None
    return str(a_path(value, who))


def a_number(value: Any, who: str) -> float:
    """A number, given as one or as text (``"0.95"``); a bool is no number."""
    if isinstance(value, bool):
        raise OptionError(f"{who}: found {value!r}, expected a number")
    try:
        return float(value if isinstance(value, (int, float)) else str(value))
    except ValueError:
        raise OptionError(f"{who}: found {value!r}, expected a number") from None


def a_switch(value: Any, who: str) -> bool:
    """True or False (a switch)."""
    if not isinstance(value, bool):
        raise OptionError(f"{who}: found {value!r}, expected True or False")
    return value


def one_of(choices: tuple[str, ...]) -> Read:
    """One of ``choices``, as text."""
    def read(value: Any, who: str) -> str:
        if not isinstance(value, str) or value not in choices:
            raise OptionError(f"{who}: found {value!r}, expected one of "
                              f"{', '.join(sorted(choices))}")
        return value
    return read


def some_of(choices: tuple[str, ...]) -> Read:
    """One or more of ``choices``: a text or a sequence of them, each once, in order."""
    pick = one_of(choices)

    def read(value: Any, who: str) -> tuple[str, ...]:
        given = [value] if isinstance(value, str) else value
        if not isinstance(given, (list, tuple)) or not given:
            raise OptionError(f"{who}: found {value!r}, expected one or more of "
                              f"{', '.join(sorted(choices))}")
        return tuple(dict.fromkeys(pick(v, who) for v in given))
    return read


def a_whole(value: Any, who: str, lo: int | None = None, hi: int | None = None) -> int:
    """A whole number, given as one (an ``int``, or a float without a fraction) or as text
    (``"64"``, ``"1e3"``), within ``lo`` to ``hi`` when given; a bool is no number."""
    found: int | None = None
    if isinstance(value, int) and not isinstance(value, bool):
        found = value
    elif isinstance(value, str) and value.strip().lstrip("+-").isdigit():
        try:  # "²" is a digit int() does not read; 4,301 digits pass Python's limit
            found = int(value)
        except ValueError:
            found = None
    else:
        try:
            number = a_number(value, who)
        except OptionError:
            number = math.nan
        if math.isfinite(number) and number.is_integer():
            found = int(number)
    span = ("" if lo is None and hi is None else f" from {lo:,}" if hi is None
            else f" from {lo:,} to {hi:,}" if lo is not None else f" up to {hi:,}")
    if found is None or (lo is not None and found < lo) or (hi is not None and found > hi):
        raise OptionError(f"{who}: found {quoted(value)}, expected a whole number{span}")
    return found


def a_whole_or_none(value: Any, who: str) -> int | None:
    """A whole number, or None."""
    return None if value is None else a_whole(value, who)


def a_seed(value: Any, who: str) -> int:
    """A seed of random draws: a whole number from 0 to 2**128 - 1 (numpy's)."""
    try:
        return a_whole(value, who, 0, 2**128 - 1)
    except OptionError:
        raise OptionError(f"{who}: found {quoted(value)}, expected a whole number from 0 to "
                          "2**128 - 1") from None


def texts(value: Any, who: str) -> tuple[str, ...]:
    """One text or several (None: none), as a tuple of text; anything else refused."""
    if value is None:
        return ()
    given = [value] if isinstance(value, str) else value
    if not isinstance(given, (list, tuple)) or not all(isinstance(t, str) for t in given):
        raise OptionError(f"{who}: found {value!r}, expected a text or a list of texts")
    return tuple(given)


def a_text_or_none(value: Any, who: str) -> str | None:
    """A name as text (a number given is its text: ``channel=2`` is ``"2"``), or None."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise OptionError(f"{who}: found {value!r}, expected a name or a number as text")
    return str(value)


def a_sign(value: Any, who: str) -> float:
    """1 or -1 (``"+1"``, ``1.0`` and ``"-1.0"`` read the same) [-]."""
    try:
        found = a_number(value, who)
    except OptionError:
        found = math.nan
    if found not in (1.0, -1.0):
        raise OptionError(f"{who}: found {value!r}, expected 1 or -1")
    return found


def an_anti_alias(value: Any, who: str) -> str | float:
    """The recorder's anti-alias filter modelled: ``"auto"``, ``"none"`` or a frequency [Hz]
    (checked against the rates once they are known)."""
    if isinstance(value, str) and value.strip().lower() in ("auto", "none"):
        return value.strip().lower()
    try:
        found = a_number(value, who)
    except OptionError:
        found = math.nan
    if not 0 < found < math.inf:
        raise OptionError(f"{who}: found {value!r}, expected auto, none or a frequency in Hz")
    return found


def a_law(value: Any, who: str) -> str:
    """A crush law's name: ``workbook``, ``legacy`` or ``NAME[@N]`` (checked against the
    archive where it is read)."""
    if not isinstance(value, str) or not value.strip():
        raise OptionError(f"{who}: found {value!r}, expected workbook, legacy or a law's "
                          "NAME or NAME@N")
    return value


def a_cfc(value: Any, who: str) -> int | None:
    """A SAE J211 class (60, 180, 600, 1000; ``"600"``), or None / ``"none"`` for none."""
    if value is None:
        return None
    from .specifying import cfc_class

    if isinstance(value, bool) or (isinstance(value, float) and not math.isfinite(value)):
        raise OptionError(f"{who}: found {value!r}, expected a SAE J211 class (60, 180, 600 "
                          "or 1000) or none")
    try:
        return cfc_class(str(value))
    except ValueError as exc:
        raise OptionError(f"{who}: {exc}") from None


def a_quality_factor(value: Any, who: str) -> float:
    """The SRS's quality factor (:func:`airgun_xl.specification.parse_q`'s grammar)."""
    from ..specification import parse_q

    if isinstance(value, bool):
        raise OptionError(f"{who}: found {value!r}, expected a quality factor")
    return parse_q(str(value), who)


# -- the options several commands share -------------------------------------------------

#: The help of every command's positional shot workbook.
SHOT_HELP = "the shot's workbook, in the report's layout (.xlsx, .xlsm or .xls)"
INTEGRATOR_HELP = ("legacy: ArtSim's scheme (the default); newmark: average-acceleration "
                   "Newmark, unconditionally stable for the OBR chain")
MODEL_HELP = "4-mass: ArtSim (the default); rigid: the previous rigid-body model"
CRUSH_LAW_HELP = ("workbook: the law the workbook's Crush law sheet names (a calibrated "
                  "workbook's fitted law), else the macro's (default); legacy: the macro's "
                  "polynomial, Eq. (8), whatever the workbook says; NAME or NAME@N: a law of "
                  "the --archive's library (calibrate --archive --name)")
RECORDING_HELP = ("a CSV (time, acceleration, units in the header), a workbook's columns "
                  "(trace.xlsx:Sheet1!A:B), a LabVIEW TDMS file, a MATLAB .mat file, an "
                  "ASAM MDF file, a Universal File (dataset 58) or an ISO 13499 MME test")
ARCHIVE_HELP = ("the archive whose library --crush-law NAME is read from (default: "
                "$AIRGUN_XL_ARCHIVE when set)")


def shot(help: str = SHOT_HELP) -> Any:
    """The shot's workbook (``SHOT.xlsx``)."""
    return positional("shot", help=help, metavar="SHOT.xlsx", read=a_path)


def recording(help: str = RECORDING_HELP) -> Any:
    """A recording file (``RECORDING``)."""
    return positional("recording", help=help, metavar="RECORDING", read=a_recording)


CHANNEL_HELP = ("the channel of a file of several (TDMS, .mat, .mf4, .uff, .mme): its name, "
                "or its number as 'airgun-xl recording FILE' lists it (default: the first)")
CFC_BOTH_HELP = ("filter both pulses: SAE J211 class 60, 180, 600 or 1000, or none (the "
                 "default) (refused where the filter is unstable, below 4.155 x the class in "
                 "samples a second; a warning below J211's 10 x)")


def channel(help: str = CHANNEL_HELP) -> Any:
    """``--channel NAME|N``: which channel of a file of several (None: the first)."""
    return option(None, "--channel", metavar="NAME|N", help=help, read=a_text_or_none)


EVENT_HELP = ("the event judged in a recording of several shocks: its number as "
              "'airgun-xl recording FILE --events' lists it (default: the largest, "
              "said)")
AT_HELP = ("the event judged: the one whose stretch holds TIME [s] of the recording (1.25, "
           "1250ms); in a recording of no event, the samples within 0.5 s of it")


def an_event(value: Any, who: str) -> int | None:
    """An event's number, from 1, or None."""
    return None if value is None else a_whole(value, who, 1)


def an_instant(value: Any, who: str) -> float | None:
    """An instant of a recording [s], or None."""
    from ..units import instant

    return None if value is None else instant(value, who)


def event() -> Any:
    """``--event N``: which event of a recording of several is judged (None: the largest)."""
    return option(None, "--event", metavar="N", help=EVENT_HELP, read=an_event,
                  group="event")


def at() -> Any:
    """``--at TIME``: the event at an instant of the recording [s]."""
    return option(None, "--at", metavar="TIME", help=AT_HELP, read=an_instant, group="event")


@dataclasses.dataclass(frozen=True, kw_only=True)
class EventFields(Checked):
    """Which event of a recording of several shocks is judged (the commands that read a
    recording without declaring every option yet take these two: accept, calibrate, next)."""

    event: int | None = event()
    at: float | None = at()


def a_test_text(value: Any, who: str) -> str | None:
    """A test's field (:mod:`airgun_xl.identification`): text on one line, at most its
    length, or None; an empty one refused."""
    from ..identification import MAX_CHARS, text_of

    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (str, int, float)) \
            or not str(value).strip():
        raise OptionError(f"{who}: found {quoted(value)}, expected a text (the test's "
                          "identification)")
    text = text_of(value)
    if len(str(value)) > MAX_CHARS:
        raise OptionError(f"{who}: found a text of {len(str(value)):,} characters, expected "
                          f"at most {MAX_CHARS}")
    return text


def _test_option(flag: str, what: str) -> Any:
    return option(None, flag, metavar="TEXT", read=a_test_text,
                  help=f"the test's {what}, on the report (over the Specification sheet's "
                       "Test block)")


@dataclasses.dataclass(frozen=True, kw_only=True)
class ReportFields(Checked):
    """What a verdict's report says beyond the criteria: the test it is of, as options give
    it (:mod:`airgun_xl.identification`: over the Specification sheet's Test block, field by
    field), and the decision rule applied (ILAC-G8)."""

    client: str | None = _test_option("--client", "client")
    test_id: str | None = _test_option("--test-id", "number")
    item: str | None = _test_option("--item", "item (what was tested)")
    serial: str | None = _test_option("--serial", "item's serial number")
    operator: str | None = _test_option("--operator", "operator (who fired it)")
    lab: str | None = _test_option("--lab", "laboratory")
    decision_rule: str = option(
        "simple", "--decision-rule", kind="choice", choices=("simple", "guarded"),
        read=one_of(("simple", "guarded")),
        help="how a value near a limit is called (ILAC-G8): simple (the default: on or "
             "inside its limits passes, its expanded uncertainty U stated) or guarded (it "
             "passes only inside its limits by U)")

    def fields(self) -> dict[str, str | None]:
        """Each identification field, by its name in
        :data:`airgun_xl.identification.FIELDS`."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if f.name != "decision_rule"}


def cfc(help: str = CFC_BOTH_HELP) -> Any:
    """``--cfc N|none``: a SAE J211 class, or None for none."""
    return option(None, "--cfc", metavar="N|none", kind="cfc", help=help, read=a_cfc)


def sign() -> Any:
    """``--sign 1|-1``: the recorder's axis against the macro's."""
    return option(1.0, "--sign", metavar="1|-1", read=a_sign,
                  help="1 (the default), or -1 when the recorder's axis is opposite to the "
                       "macro's")


def time_unit() -> Any:
    return option(None, "--time-unit", help="s, ms or us (default: from the header)",
                  read=a_text_or_none)


def accel_unit() -> Any:
    return option(None, "--accel-unit", read=a_text_or_none,
                  help="g, kG or m/s^2 (default: from the header); g is standard gravity, "
                       "9.80665 m/s^2")


def anti_alias() -> Any:
    """``--anti-alias HZ``: the recorder's filter modelled on a prediction."""
    return option("auto", "--anti-alias", metavar="HZ", read=an_anti_alias,
                  help="the recorder's anti-alias filter, modelled on the prediction as a "
                       "4-pole Butterworth at HZ: auto (a fifth of the record's rate, the "
                       "default), a frequency, or none")


def output(what: str, default: str, metavar: str = "OUT.xlsx") -> Any:
    """``-o``/``--output``: ``what`` the file holds; None writes none (the command line
    gives the command's ``default`` name)."""
    return option(None, "-o", "--output", help=f"{what} (default: {default})",
                  metavar=metavar, read=a_path_or_none)


def force(metavar: str = "OUT.xlsx") -> Any:
    """``--force``: overwrite the output."""
    return option(False, "--force", help=f"overwrite {metavar} if it exists", kind="switch",
                  read=a_switch)


def integrator() -> Any:
    return option("legacy", "--integrator", help=INTEGRATOR_HELP, kind="choice",
                  choices=tuple(sorted(INTEGRATORS)), read=one_of(tuple(INTEGRATORS)))


def integrators() -> Any:
    """``--integrator``, given once for each integrator run side by side."""
    return option(("legacy",), "--integrator", kind="integrators",
                  metavar="{" + ",".join(sorted(INTEGRATORS)) + "}",
                  help=INTEGRATOR_HELP + "; give it again to run another side by side: "
                                         "--integrator legacy --integrator newmark",
                  read=some_of(tuple(INTEGRATORS)))


def model() -> Any:
    return option("4-mass", "--model", help=MODEL_HELP, kind="choice",
                  choices=tuple(MODELS), read=one_of(tuple(MODELS)))


def crush_law() -> Any:
    return option("workbook", "--crush-law", help=CRUSH_LAW_HELP, metavar="LAW", read=a_law)


def the_archive() -> Any:
    """``--archive DIR``: the archive a command reads (None: $AIRGUN_XL_ARCHIVE)."""
    return option(None, "--archive", help="the archive folder", metavar="DIR",
                  read=a_folder_or_none)


def archive() -> Any:
    """``--archive DIR``, where a library law is read from (None: $AIRGUN_XL_ARCHIVE)."""
    return option(None, "--archive", help=ARCHIVE_HELP, metavar="DIR", read=a_path_or_none)


def seed(help: str) -> Any:
    """``--seed``: of a study's random draws (default 1)."""
    return option(1, "--seed", help=help, read=a_seed)


def scheduler() -> Any:
    """``--scheduler ADDRESS``: the Dask cluster a study runs on (or ``--workers``)."""
    return option(None, "--scheduler", metavar="ADDRESS", group="cluster", read=a_text_or_none,
                  help="run the shots on a Dask cluster: the address of its scheduler, e.g. "
                       "tcp://10.0.0.5:8786 (docs/studies.md, 'Studies on several machines')")


def workers() -> Any:
    """``--workers N``: a local Dask cluster of N processes (or ``--scheduler``)."""
    return option(None, "--workers", metavar="N", group="cluster", read=a_whole_or_none,
                  help="run the shots on a local Dask cluster of N worker processes")


def chunk() -> Any:
    """``--chunk SHOTS``: shots a cluster task."""
    return option(None, "--chunk", metavar="SHOTS", read=a_whole_or_none,
                  help="shots a cluster task (default 512)")
