"""A measured pulse from a CSV file, a workbook's column range or a recorder's file (TDMS,
MATLAB, MDF, IDE, UFF, MME: :mod:`.formats`): time and acceleration, with units from the
header (``time [ms]``, ``accel (g)``, a channel's unit as its file states it) or given, every
row checked; and a required shock response spectrum (CSV).

The file is read like any untrusted input (:func:`airgun_xl.readers.guard.read_bytes`: a
regular file, size capped). Each fault is one line naming the row: a row that is not two
numbers, NaN, time that does not increase, a gap in a constant sample rate, too few samples,
a unit that cannot be told.
"""
import csv
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import limits, units
from ..errors import AirgunXlError, OptionError, WorkbookError
from ..transaction import display
from . import formats
from .guard import read_bytes

#: Time units [s per unit]: the one table's (:data:`airgun_xl.units.TIME_UNITS`).
TIME_UNITS = {unit: float(scale) for unit, scale in units.TIME_UNITS.items()}

#: Acceleration units [kG per unit], the one table's (:data:`airgun_xl.units.PEAK_UNITS`): a
#: recorder's g is standard gravity (units.G, 9.80665 m/s^2); the kG is the macro's, 9800
#: m/s^2 (its Acceleration (kG's) column), so 1 g is 1.000679e-3 kG. The macro's 9800
#: applies to the macro's columns only.
ACCEL_UNITS = dict(units.PEAK_UNITS)

#: Spellings a recorder's file may state that the options do not take [kG per unit]: ``G``
#: (a recorder's g, as shock labs write it; as an option it would sit a case away from kG),
#: ``mm/ms^2`` (1,000 m/s^2), and ``**`` or ``sec`` for ``^`` and ``s``.
FILE_ACCEL_UNITS = {**ACCEL_UNITS, "G": ACCEL_UNITS["g"],
                    "mm/ms^2": 1e3 * ACCEL_UNITS["m/s^2"], "mm/ms**2": 1e3 * ACCEL_UNITS["m/s^2"],
                    "m/s**2": ACCEL_UNITS["m/s^2"], "m/sec^2": ACCEL_UNITS["m/s^2"],
                    "m/sec**2": ACCEL_UNITS["m/s^2"]}
#: The time units a file may state [s per unit]: the options' and ``sec``, ``msec``.
FILE_TIME_UNITS = {**TIME_UNITS, "sec": 1.0, "msec": 1e-3}

#: A step may differ from the median step by this fraction before the time column is taken
#: for a recorder's clock whose stamps jitter, and fitted (:mod:`.time_base`).
GAP_TOLERANCE = 0.01

#: Fewest samples a pulse may have.
MIN_SAMPLES = 16

EXPECTED = "expected a CSV of time and acceleration (two columns, a header row)"


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


def _stated(header):
    """The unit a header names in brackets or parentheses (``time [ms]`` -> ``ms``; '' for
    none)."""
    found = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]", header)
    return (found.group(1) if found else "").strip()


def _unit(header, table, option, which, named=None):
    """The unit key ``header`` states (in ``table``); one line naming ``option`` otherwise.
    ``named``: the channel of a binary file, whose unit is its own field, not a header."""
    text = _stated(header)
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


def _number(text, decimal_comma):
    text = text.strip()
    return float(text.replace(",", ".") if decimal_comma else text)


def _is_pair(row, decimal_comma):
    """Whether a row starts with two numbers."""
    if len(row) < 2:
        return False
    try:
        _number(row[0], decimal_comma)
        _number(row[1], decimal_comma)
    except ValueError:
        return False
    return True


def _looks_like_data(row):
    """A row that starts with a number: data, where the header should have been followed by
    two numbers."""
    try:
        float(row[0].strip().replace(",", "."))
    except (ValueError, IndexError):
        return False
    return True


def _body(raw, delimiter, comma):
    """The data lines (UTF-8 bytes) as an n x 2 float array by pandas' C parser (no Python
    list a row), or None when a line is not two numbers (the slow path then names it)."""
    import pandas as pd

    try:
        frame = pd.read_csv(io.BytesIO(raw), sep=delimiter, header=None, usecols=[0, 1],
                            decimal="," if comma else ".", dtype=float, engine="c",
                            comment="#", skip_blank_lines=True, skipinitialspace=True)
    except (ValueError, IndexError, pd.errors.ParserError, pd.errors.EmptyDataError):
        return None
    return frame.to_numpy(dtype=float)


def _find_bad_line(shown, text, first, delimiter, comma, columns):
    """Raise the one line naming the first data line that is not two finite numbers."""
    for number, line in enumerate(text.splitlines(), start=first):
        try:
            row = next(csv.reader([line], delimiter=delimiter), [])
        except csv.Error as exc:
            raise WorkbookError(f"{shown}: line {number} is not readable CSV ({exc})") from None
        if not any(cell.strip() for cell in row) or row[0].lstrip().startswith("#"):
            continue
        try:
            a, b = _number(row[0], comma), _number(row[1], comma)
        except (ValueError, IndexError):
            raise WorkbookError(f"{shown}: line {number} holds {row[:2]!r}, expected two "
                                f"numbers ({columns[0]}, {columns[1]})") from None
        if not (math.isfinite(a) and math.isfinite(b)):
            raise WorkbookError(f"{shown}: line {number} holds {row[0].strip()}, "
                                f"{row[1].strip()}, expected finite numbers (no NaN or inf)")
    raise WorkbookError(f"{shown}: is not a readable CSV of two numbers a line")


def _dialect(lines):
    """(delimiter, decimal comma) of a data-acquisition export's data lines: ``;`` or a tab
    with a decimal comma (``1,5;0,25``), or a comma, semicolon or tab with a point."""
    sample = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    sample = sample[-50:]  # data lines, past any metadata and the header
    for delimiter in (";", "\t", ","):
        if sample and all(line.count(delimiter) >= 1 for line in sample):
            comma = delimiter != "," and any("," in line for line in sample)
            return delimiter, comma
    return ",", False


def _table(path, expected, columns):
    """(shown name, header, n x 2 values) of a two-column CSV; every row checked.

    Data-acquisition exports are read as they come: ``#`` comment lines and other metadata
    lines above the header are skipped (the header is the row above the first row of two
    numbers); ``,``, ``;`` or tab delimiters; a decimal comma with ``;`` or tabs."""
    shown = display(Path(path))
    data = read_bytes(path, expected, "CSV")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise WorkbookError(f"{shown}: is not UTF-8 text (byte {exc.start}), {expected}") \
            from None
    count = text.count("\n") + 1
    if count > limits.MAX_SAMPLES + 1000:  # counted before any parsing: a bounded read
        raise WorkbookError(f"{shown}: holds {count:,} lines, expected at most "
                            f"{limits.MAX_SAMPLES:,} samples")
    delimiter, comma = _dialect(text[-20_000:].splitlines()[-50:])
    header, start, numbered = None, None, []  # the lines above the data, parsed one by one
    offset, number = 0, 0
    while offset <= len(text) and start is None:
        end = text.find("\n", offset)
        end = len(text) if end < 0 else end
        number += 1
        line = text[offset:end].rstrip("\r")
        try:
            row = next(csv.reader([line], delimiter=delimiter), [])
        except csv.Error as exc:  # a field past csv's limit, a stray quote
            raise WorkbookError(f"{shown}: line {number} is not readable CSV ({exc}), "
                                f"{expected}") from None
        if any(cell.strip() for cell in row) and not row[0].lstrip().startswith("#"):
            if _is_pair(row, comma):
                start = (offset, number)
                break
            numbered.append((number, row))
            if len(numbered) >= 2 and not _is_pair(numbered[-2][1], comma) and \
                    _looks_like_data(numbered[-1][1]):
                line_no, bad = numbered[-1]  # a header, then a row that is not two numbers
                raise WorkbookError(f"{shown}: line {line_no} holds {bad[:2]!r}, expected two "
                                    f"numbers ({columns[0]}, {columns[1]})")
        offset = end + 1
    if start is None or not numbered:
        got = numbered[0] if numbered else (number, [])
        raise WorkbookError(f"{shown}: line {got[0]} holds {got[1][:3]!r}, {expected}; found "
                            + ("no header row above the numbers" if start is not None else
                               f"no row of two numbers ({delimiter!r}-delimited"
                               + (", decimal comma" if comma else "") + ")"))
    header_line, header = numbered[-1]
    if len(header) < 2:
        raise WorkbookError(f"{shown}: line {header_line} (the header) holds {header!r}, "
                            f"{expected}")
    # the data from their first line, as bytes: pandas reads them without a str copy a row
    head = len(text[:start[0]].encode("utf-8")) + (3 if data.startswith(b"\xef\xbb\xbf") else 0)
    values = _body(data[head:], delimiter, comma)
    if values is None or not np.isfinite(values).all():
        _find_bad_line(shown, text[start[0]:], start[1], delimiter, comma, columns)
    if len(values) > limits.MAX_SAMPLES:
        raise WorkbookError(f"{shown}: holds {len(values):,} rows, expected at most "
                            f"{limits.MAX_SAMPLES:,} samples")
    return shown, header, values


#: ``FILE:SHEET!COL:COL``: a column range of a workbook.
RANGE = re.compile(r"^(?P<file>.+\.(?:xlsx|xlsm|xls)):(?P<sheet>[^!]+)!(?P<a>[A-Za-z]{1,3})"
                   r"(?:\d*)?:(?P<b>[A-Za-z]{1,3})(?:\d*)?$", re.IGNORECASE)

EXPECTED_RANGE = ("expected a column range of time and acceleration with a header row, "
                  "e.g. trace.xlsx:Sheet1!A:B")


def input_file(spec):
    """The file a measured source names (the workbook of ``trace.xlsx:Sheet1!A:B``)."""
    found = RANGE.match(str(spec))
    return found["file"] if found and not Path(str(spec)).exists() else str(spec)


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
    """Any measured source as a :class:`~.formats.Table`, and whether a binary format read it;
    with ``choose_acceleration`` and no ``channel``, a file of several channels whose first is
    no acceleration gives its first that is (said in the table's notes; the channels are
    listed only then, so the usual file is parsed once)."""
    text = str(path)
    found = RANGE.match(text)
    if found and not Path(text).exists():
        if channel is not None:
            raise OptionError("--channel: found with a workbook range, expected it only "
                              "with a file of several channels (TDMS, MATLAB .mat, MDF, IDE, UFF, "
                              "MME)")
        return formats.Table(*_range_table(found)), False
    fmt = formats.detect(path)
    if fmt is not None:
        data = formats.source(fmt, path)
        table = fmt.read(path, data, channel)
        if channel is None and choose_acceleration \
                and _key(_stated(table.header[1])) not in FILE_ACCEL_UNITS:
            chosen = _first_acceleration(path, fmt, data)
            if chosen is not None:
                table = fmt.read(path, data, chosen[0])
                table = table._replace(notes=(*table.notes, chosen[1]))
        return table, True
    if channel is not None:
        raise OptionError("--channel: found with a CSV file, expected it only with a file of "
                          "several channels (TDMS, MATLAB .mat, MDF, IDE, UFF, MME)")
    return formats.Table(*_table(path, EXPECTED, ("time", "acceleration"))), False


def list_channels(path):
    """The channels of the recording at ``path`` (:class:`~.formats.ChannelInfo`): a CSV or
    a workbook range has one, its second column."""
    text = str(path)
    found = RANGE.match(text)
    fmt = None if found and not Path(text).exists() else formats.detect(path)
    if fmt is not None:
        return fmt.channels(path, formats.source(fmt, path))
    shown, header, values = (_range_table(found) if found and not Path(text).exists()
                             else _table(path, EXPECTED, ("time", "acceleration")))
    scale = FILE_TIME_UNITS.get(_stated(header[0]))
    time = values[:, 0]
    rate = ((len(time) - 1) / ((time[-1] - time[0]) * scale)
            if scale and len(time) > 1 and time[-1] > time[0] else None)
    return [formats.ChannelInfo(header[1], _stated(header[1]), rate, len(values),
                                float(time[0]) * scale if scale else None)]


def _column(letters):
    n = 0
    for ch in letters.upper():
        n = n * 26 + ord(ch) - 64
    return n - 1


def _range_table(found):
    from . import guard

    path = Path(found["file"])
    shown = f"{display(path)}:{found['sheet']}!{found['a'].upper()}:{found['b'].upper()}"
    data, kind = guard.read_input(path)
    if kind == "zip":
        zf = guard.open_zip(path, data)  # sizes, ratios and entities, before any parser
        member = guard.sheet_member(path, zf, found["sheet"])
        if member is not None:  # its extent, before calamine makes it dense (issue 23.1)
            rows, columns = guard.sheet_extent(path, zf, member, cap=limits.MAX_DIFF_CELLS,
                                               what=f"sheet {found['sheet']!r}")
            guard.check_extent(path, f"sheet {found['sheet']!r}", rows, columns,
                               limits.MAX_DIFF_CELLS)
        zf.close()
    else:
        for k, (rows, columns) in enumerate(guard.xls_extents(path, data)):
            guard.check_extent(path, f"sheet {k + 1}", rows, columns, limits.MAX_XLS_CELLS)
    a, b = _column(found["a"]), _column(found["b"])
    if a == b:
        raise OptionError(f"{shown}: names one column, {EXPECTED_RANGE}")
    try:
        from python_calamine import CalamineWorkbook

        wb = CalamineWorkbook.from_filelike(io.BytesIO(data))
        if found["sheet"] not in wb.sheet_names:
            raise WorkbookError(f"{shown}: has no sheet {found['sheet']!r} (it has "
                                f"{', '.join(map(repr, wb.sheet_names[:5]))}), "
                                f"{EXPECTED_RANGE}")
        rows = wb.get_sheet_by_name(found["sheet"]).to_python(skip_empty_area=False)
    except AirgunXlError:
        raise
    except Exception as exc:  # noqa: BLE001 - any parser failure on untrusted bytes: one line
        raise WorkbookError(f"{shown}: is not a readable workbook ({type(exc).__name__}), "
                            f"{EXPECTED_RANGE}") from None
    rows = [r for r in rows if len(r) > max(a, b) and (r[a] != "" or r[b] != "")]
    if len(rows) < 2:
        raise WorkbookError(f"{shown}: holds {len(rows)} rows, {EXPECTED_RANGE}")
    header = [str(rows[0][a]), str(rows[0][b])]
    values = np.empty((len(rows) - 1, 2))
    for i, row in enumerate(rows[1:], start=2):
        cells = (row[a], row[b])
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in cells) \
                or not all(math.isfinite(v) for v in cells):
            raise WorkbookError(f"{shown}: row {i} holds {list(cells)!r}, expected two finite "
                                "numbers (time, acceleration)")
        values[i - 2] = cells
    return shown, header, values


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
    shown, header, values = _table(path, EXPECTED_SPECTRUM, ("frequency", "level"))
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


def read_trace(path, time_unit=None, accel_unit=None, sign=1.0, channel=None):
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

    Raises
    ------
    WorkbookError
        For the file or a row, naming it.
    OptionError
        For a unit that cannot be told or is not known.
    """
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
    raw = values[:, 1]
    if (np.abs(steps - dt) > GAP_TOLERANCE * dt).any():  # a recorder's clock: fitted
        from .time_base import fit_clock

        clock = fit_clock(shown, time, raw)
        time, raw, dt = clock.time, raw[clock.first:clock.stop], clock.dt
        notes += list(clock.notes)
        if len(raw) < MIN_SAMPLES:
            raise WorkbookError(f"{shown}: holds {len(raw)} samples on one clock around its "
                                f"largest excursion (between the gaps in its time), expected "
                                f"at least {MIN_SAMPLES}")
    accel = sign * raw * FILE_ACCEL_UNITS[a_unit]
    peak = float(np.max(np.abs(accel)))
    if not peak >= limits.MIN_RECORDED_PEAK_KG:
        raise WorkbookError(f"{shown}: the recording is flat (its largest acceleration is "
                            f"{peak:.3g} kG), expected a pulse of at least "
                            f"{limits.MIN_RECORDED_PEAK_KG:g} kG (about 0.001 g)")
    return Trace(time, accel, dt, shown,
                 (t_unit, a_unit),
                 notes)


def _override(shown, option, given, header, table):
    """The warning when ``option``'s unit replaces a different one the file states in
    ``header`` ('' when the file states none, or the same unit)."""
    stated = _stated(header)
    key = stated.replace("'s", "").replace("²", "^2").replace(" ", "")
    if not stated or (key in table and table[key] == table[given]):
        return ""
    return (f"{shown}: {option} {given} replaces the unit the file states ({stated}): its "
            f"values are read as {given}")
