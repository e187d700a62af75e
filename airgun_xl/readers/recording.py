"""A measured pulse from a CSV file, a workbook's column range or a recorder's file (TDMS,
MATLAB, MDF, IDE, UFF, MME: :mod:`.formats`): time and acceleration, with units from the
header (``time [ms]``, ``accel (g)``, a channel's unit as its file states it) or given, every
row checked; and a required shock response spectrum (CSV).

The file is read like any untrusted input (:func:`airgun_xl.readers.guard.read_bytes`: a
regular file, size capped). Each fault is one line naming the row: a row that is not two
numbers, NaN, time that does not increase, a gap in a constant sample rate, too few samples,
a unit that cannot be told.
"""
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import limits
from ..errors import OptionError, WorkbookError
from ..transaction import display
from . import formats
from .events import EVENT_SHARE, EVENT_SIGMAS
from .formats import delimited, workbook_range
from .formats.channels import (  # noqa: F401 (the readers' tables, kept at their old path)
    ACCEL_UNITS,
    FILE_ACCEL_UNITS,
    FILE_TIME_UNITS,
    TIME_UNITS,
    stated,
)
from .formats.delimited import EXPECTED  # noqa: F401 (a CSV recording's, at its old path)
from .formats.workbook_range import EXPECTED_RANGE, RANGE  # noqa: F401 (at their old path)

#: A step may differ from the median step by this fraction before the time column is taken
#: for a recorder's clock whose stamps jitter, and fitted (:mod:`.time_base`).
GAP_TOLERANCE = 0.01

#: Fewest samples a pulse may have.
MIN_SAMPLES = 16


@dataclass
class Trace:
    """A measured pulse, in the model's units.

    Attributes
    ----------
    time : numpy.ndarray
        [s], increasing, at a constant step.
    accel_kg : numpy.ndarray
        [kG], positive as the macro's Acceleration (kG's) column (after ``sign``).
    dt : float
        The step [s] (the median of the steps).
    name : str
        Where it came from.
    units : tuple
        (time unit, acceleration unit) as read or given.
    notes : list of str
        What the reading found that the figures depend on (a unit given over the one the
        file states): warnings, carried into every report of this recording.
    """

    time: np.ndarray
    accel_kg: np.ndarray
    dt: float
    name: str
    units: tuple
    notes: list = field(default_factory=list)


def _unit(header, table, option, which, named=None):
    """The unit key ``header`` states (in ``table``); one line naming ``option`` otherwise.
    ``named``: the channel of a binary file, whose unit is its own field, not a header."""
    text = stated(header)
    key = _key(text)
    near = [k for k in table if k.lower() == key.lower()]
    if named is not None and key not in table and not near:
        found = "none" if not text else repr(text)
        raise OptionError(f"{option}: {named} states the unit {found}, which is no "
                          f"{which} unit I know; expected one of {', '.join(table)}, or "
                          f"{option} (or --channel for another channel)")
    if key not in table and near:  # units are case sensitive: [Kg] is kilograms, [MS] not ms
        where = named if named is not None else f"the {which} header {header!r}"
        raise OptionError(f"{option}: {where} names {text!r}, a case "
                          f"away from {near[0]!r}; units are case sensitive (Kg is a mass, MS "
                          f"megasiemens), expected exactly one of {', '.join(table)}, or "
                          f"{option}")
    if key not in table:
        raise OptionError(f"{option}: the {which} header {header!r} names no unit I know "
                          f"({text or 'none'}); expected one of {', '.join(table)} in the "
                          f"header, e.g. '{which} [{next(iter(table))}]', or {option}")
    return key


def input_file(spec):
    """The file a measured source names (the workbook of ``trace.xlsx:Sheet1!A:B``)."""
    found = RANGE.match(str(spec)) if workbook_range.claims(spec) else None
    return str(found["file"]) if found is not None else str(spec)


def _key(text):
    """A unit as the tables key it (``g's`` -> ``g``, ``m/s²`` -> ``m/s^2``)."""
    return text.replace("'s", "").replace("²", "^2").replace(" ", "")


def _first_acceleration(path, fmt, data):
    """The name of the first channel of a file of several whose unit is an acceleration, and
    the note that says it was chosen; None for a file of one channel, or whose first channel
    is one (the default it always was).

    Raises
    ------
    OptionError
        When several channels state no acceleration unit: naming each with its unit, and
        ``--channel``.
    """
    infos = fmt.channels(path, data)
    if len(infos) < 2:
        return None
    for k, info in enumerate(infos):
        if _key(info.unit) in FILE_ACCEL_UNITS:
            if k == 0:
                return None
            return info.name, (f"{display(Path(path))}: channel {info.name!r} is judged, the "
                               f"first of its {len(infos)} channels whose unit is an "
                               f"acceleration ({info.unit}); --channel names another")
    listed = "; ".join(f"{k}. {i.name!r} [{i.unit or 'no unit'}]"
                       for k, i in enumerate(infos[:8], start=1))
    more = f"; and {len(infos) - 8} more" if len(infos) > 8 else ""
    raise OptionError(f"--channel: {display(Path(path))} holds {len(infos)} channels and none "
                      f"states an acceleration unit ({listed}{more}), expected --channel "
                      "naming the one to judge (and --accel-unit its unit)")


def _source_table(path, channel=None, choose_acceleration=False):
    """Any measured source as a :class:`~.formats.Table` (its format from the registry,
    :func:`.formats.detect`), and whether its format holds several channels; with
    ``choose_acceleration`` and no ``channel``, a file of several channels whose first is no
    acceleration gives its first that is (said in the table's notes; the channels are listed
    only then, so the usual file is parsed once)."""
    fmt = formats.detect(path)
    data = formats.source(fmt, path)
    table = fmt.read(path, data, channel)
    if fmt.SEVERAL and channel is None and choose_acceleration \
            and _key(stated(table.header[1])) not in FILE_ACCEL_UNITS:
        chosen = _first_acceleration(path, fmt, data)
        if chosen is not None:
            table = fmt.read(path, data, chosen[0])
            table = table._replace(notes=(*table.notes, chosen[1]))
    return table, fmt.SEVERAL


def list_channels(path):
    """The channels of the recording at ``path`` (:class:`~.formats.ChannelInfo`): a CSV or
    a workbook range has one, its second column."""
    fmt = formats.detect(path)
    return fmt.channels(path, formats.source(fmt, path))


#: Frequency units [Hz per unit] of a required spectrum.
FREQUENCY_UNITS = {"Hz": 1.0, "kHz": 1e3}

EXPECTED_SPECTRUM = ("expected a CSV of natural frequency and required SRS level (two "
                     "columns, a header row such as 'frequency [Hz],srs [g]')")


def read_spectrum(path, accel_unit=None, option="--target-srs"):
    """A required shock response spectrum: (frequencies [Hz], levels [kG]), from a CSV whose
    header gives the units (``frequency [Hz]``, ``srs [g]``); frequencies increasing and
    positive, levels positive. Raises WorkbookError or OptionError naming the row or unit
    (``option``: the one that named the file, ``--srs`` or ``--target-srs``)."""
    if accel_unit is not None and accel_unit not in ACCEL_UNITS:
        raise OptionError(f"--accel-unit: found {accel_unit!r}, expected one of "
                          f"{', '.join(ACCEL_UNITS)}")
    shown, header, values = delimited.table(path, EXPECTED_SPECTRUM, ("frequency", "level"))
    f_unit = _unit(header[0], FREQUENCY_UNITS, option, "frequency")
    a_unit = accel_unit or _unit(header[1], ACCEL_UNITS, "--accel-unit", "level")
    f = values[:, 0] * FREQUENCY_UNITS[f_unit]
    for k in range(len(f)):
        if f[k] <= 0 or (k and f[k] <= f[k - 1]):
            raise WorkbookError(f"{shown}: row {k + 2}: frequency {values[k, 0]:g}, expected "
                                "positive frequencies, increasing")
        if values[k, 1] <= 0:
            raise WorkbookError(f"{shown}: row {k + 2}: level {values[k, 1]:g}, expected a "
                                "positive SRS level")
    return f, values[:, 1] * ACCEL_UNITS[a_unit]


def _samples(path, time_unit, accel_unit, channel):
    """The recording's name as shown, its (time, acceleration) units, its times [s]
    (increasing, at a step within the recorders' range) and its raw values (in the
    acceleration unit), and what the reading said."""
    for option, given, table in (("--time-unit", time_unit, TIME_UNITS),
                                 ("--accel-unit", accel_unit, ACCEL_UNITS)):
        if given is not None and given not in table:
            raise OptionError(f"{option}: found {given!r}, expected one of {', '.join(table)}")
    (shown, header, values, said), binary = _source_table(
        path, channel, choose_acceleration=accel_unit is None)
    named = f"channel {shown.rpartition(' (')[2].rstrip(')')!r} of {display(Path(path))}" \
        if binary else None
    t_unit = time_unit or _unit(header[0], FILE_TIME_UNITS, "--time-unit", "time",
                                None if named is None else f"the time of {named}")
    a_unit = accel_unit or _unit(header[1], FILE_ACCEL_UNITS, "--accel-unit", "acceleration",
                                 named)
    notes = [_override(shown, option, given, stated, table)
             for option, given, stated, table in (
                 ("--time-unit", time_unit, header[0], FILE_TIME_UNITS),
                 ("--accel-unit", accel_unit, header[1], FILE_ACCEL_UNITS))
             if given is not None]
    notes = [note for note in notes if note] + list(said)
    if len(values) < MIN_SAMPLES:
        raise WorkbookError(f"{shown}: holds {len(values)} samples, expected at least "
                            f"{MIN_SAMPLES}")
    time = values[:, 0] * FILE_TIME_UNITS[t_unit]
    steps = np.diff(time)
    if not (steps > 0).all():
        k = int(np.argmax(steps <= 0))
        raise WorkbookError(f"{shown}: row {k + 3}: time {values[k + 1, 0]:g} does not "
                            f"follow {values[k, 0]:g}, expected increasing time")
    dt = float(np.median(steps))
    # before any use of it; a step on a bound to its float rounding is on it (1 ns as
    # k x 1e-9 s reads 0.9999999999999999e-9 between some samples)
    if not limits.MIN_SAMPLE_STEP * (1 - 1e-9) <= dt <= limits.MAX_SAMPLE_STEP * (1 + 1e-9):
        raise WorkbookError(f"{shown}: its sample step is {dt:.4g} s ({1 / dt:.4g} Hz), "
                            f"expected a step of {limits.MIN_SAMPLE_STEP:g} to "
                            f"{limits.MAX_SAMPLE_STEP:g} s (a recorder of 1 Hz to 1 GHz)")
    return shown, (t_unit, a_unit), time, values[:, 1], notes


def list_events(path, channel=None, time_unit=None, accel_unit=None):
    """The events of a recording's channel (:mod:`.events`), as :func:`read_trace` chooses
    among them: (its name as shown, its acceleration unit, its times [s], the events)."""
    from .events import find_events

    shown, (_t_unit, a_unit), time, raw, _notes = _samples(path, time_unit, accel_unit,
                                                           channel)
    return shown, a_unit, time, find_events(time, raw)


def read_trace(path, time_unit=None, accel_unit=None, sign=1.0, channel=None, event=None,
               at=None):
    """Read a measured pulse: a CSV file, a column range of a workbook
    (``trace.xlsx:Sheet1!A:B``, time then acceleration, a header row first), or a LabVIEW
    TDMS file (a waveform channel; needs the ``tdms`` extra, npTDMS).

    Parameters
    ----------
    path : str or path
    channel : str, optional
        TDMS only: ``GROUP/CHANNEL``; the first waveform channel by default.
    time_unit, accel_unit : str, optional
        Keys of :data:`TIME_UNITS` / :data:`ACCEL_UNITS`; read from the header when None.
    sign : float
        +1 or -1: multiplies the acceleration (the recorder's axis against the macro's).
    event : int, optional
        Of a recording of several shocks (:mod:`.events`), the one judged, from 1: the
        stretch of the recording that holds it is read. None: the largest (said when there
        are several).
    at : float, optional
        [s] Instead of ``event``: the event whose stretch holds this instant of the
        recording; in a recording of no event, the samples within
        :data:`~.formats.channels.WINDOW_SECONDS` of it.

    Raises
    ------
    WorkbookError
        For the file or a row, naming it.
    OptionError
        For a unit that cannot be told or is not known.
    """
    shown, (t_unit, a_unit), time, raw, notes = _samples(path, time_unit, accel_unit, channel)
    dt = float(np.median(np.diff(time)))
    first, stop, centre, said = _event_stretch(shown, time, raw, event, at, a_unit)
    notes += said
    steps = np.diff(time)
    if (np.abs(steps - dt) > GAP_TOLERANCE * dt).any():  # a recorder's clock: fitted
        from .time_base import fit_clock

        # over the whole recording (the recorder's one clock), centred on the event judged
        clock = fit_clock(shown, time, raw, centre, named=event is not None or at is not None)
        notes += list(clock.notes)
        time = np.concatenate([np.full(clock.first, np.nan), clock.time,
                               np.full(len(raw) - clock.stop, np.nan)])
        first, stop = max(first, clock.first), min(stop, clock.stop)
        dt = clock.dt
    time, raw = time[first:stop], raw[first:stop]
    if len(raw) < MIN_SAMPLES:
        where = said[0] if said else "on one clock around its largest excursion (between " \
            "the gaps in its time)"
        raise WorkbookError(f"{shown}: holds {len(raw)} samples {where}, expected at least "
                            f"{MIN_SAMPLES}")
    accel = sign * raw * FILE_ACCEL_UNITS[a_unit]
    peak = float(np.max(np.abs(accel)))
    if not peak >= limits.MIN_RECORDED_PEAK_KG:
        raise WorkbookError(f"{shown}: the recording is flat (its largest acceleration is "
                            f"{peak:.3g} kG), expected a pulse of at least "
                            f"{limits.MIN_RECORDED_PEAK_KG:g} kG (about 0.001 g)")
    return Trace(time, accel, dt, shown,
                 (t_unit, a_unit),
                 notes)


def _event_stretch(shown, time, raw, event, at, unit):
    """Where the event judged lies in the recording ``shown`` (its stamps ``time`` [s], its
    ``raw`` values in ``unit``; :mod:`.events`): the samples ``first`` to ``stop`` (from 0,
    ``stop`` excluded) that hold it, the sample a recorder's clock is fitted round (None: the
    largest excursion), and what to say of it. The whole recording when it holds one event,
    or none and no ``at``."""
    from .events import find_events, judged_span, stretch
    from .formats.channels import WINDOW_SECONDS

    found = find_events(time, raw)
    events = found.events
    size = (f"past {found.threshold:.4g} {unit} from its rest of {found.rest:.4g} {unit}, "
            f"the larger of {EVENT_SIGMAS:g} x its noise and {EVENT_SHARE:.0%} of its largest "
            "excursion")
    if at is not None and not time[0] <= at <= time[-1]:
        raise OptionError(f"--at: found {at:g} s, expected an instant of {shown}, which runs "
                          f"{float(time[0]):.6g} to {float(time[-1]):.6g} s")
    if event is not None and event > len(events):
        held = (f"holds {len(events)} event{'s' * (len(events) != 1)} ({size})" if events
                else f"holds no event (no sample {size})")
        raise OptionError(f"--event: found {event}, expected an event of {shown}, which "
                          f"{held}: airgun-xl recording --events lists them")
    if not events:
        if at is None:
            return 0, len(raw), None, [
                f"{shown}: holds no event standing out of its noise (no sample {size}): its "
                "largest excursion is judged, which may be noise"]
        keep = np.flatnonzero(np.abs(time - at) <= WINDOW_SECONDS)
        if len(keep) < MIN_SAMPLES:
            raise WorkbookError(f"{shown}: holds {len(keep)} samples within "
                                f"{WINDOW_SECONDS:g} s of --at {at:g} s, expected at least "
                                f"{MIN_SAMPLES}")
        first, stop = int(keep[0]), int(keep[-1]) + 1
        centre = first + int(np.argmax(np.abs(raw[first:stop] - found.rest)))
        return first, stop, centre, [
            f"{shown}: holds no event standing out of its noise (no sample {size}): the "
            f"samples within {WINDOW_SECONDS:g} s of --at {at:g} s, {float(time[first]):.6g} "
            f"to {float(time[stop - 1]):.6g} s, are judged"]
    if at is not None:
        chosen = next(e for e in events
                      if at < time[stretch(found, e, len(raw))[1] - 1] or e is events[-1])
    elif event is not None:
        chosen = events[event - 1]
    else:
        largest = found.largest()
        assert largest is not None  # the recording holds events
        chosen = largest
    centre = chosen.peak  # the clock is fitted round it
    if len(events) == 1:
        return 0, len(raw), centre, []
    first, stop = judged_span(found, chosen, time)
    how = ("the largest" if event is None and at is None
           else f"--event {event}" if event is not None else f"--at {at:g} s")
    if chosen.cut:
        how += (", cut by the recording's " + ("start" if chosen.first == 0 else "end")
                + ": its rest there is missing")
    peak = f"{chosen.height:+.5g} {unit} as recorded at {float(time[chosen.peak]):.6g} s"
    return first, stop, centre, [
        f"{shown}: holds {len(events)} events ({size}): event {chosen.number} ({how}), "
        f"peak {peak}, is judged on {float(time[first]):.6g} to {float(time[stop - 1]):.6g} "
        "s as stamped (airgun-xl recording --events lists them; --event N judges another)"]


def _override(shown, option, given, header, table):
    """The warning when ``option``'s unit replaces a different one the file states in
    ``header`` ('' when the file states none, or the same unit)."""
    said = stated(header)
    key = said.replace("'s", "").replace("²", "^2").replace(" ", "")
    if not said or (key in table and table[key] == table[given]):
        return ""
    return (f"{shown}: {option} {given} replaces the unit the file states ({said}): its "
            f"values are read as {given}")
