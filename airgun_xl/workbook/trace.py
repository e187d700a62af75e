"""A measured pulse from a CSV file: a time column and an acceleration column, with units
from the header (``time [ms]``, ``accel (g)``) or given, every row checked.

The file is read like any untrusted input (:func:`airgun_xl.workbook.guard.read_bytes`: a
regular file, size capped). Each fault is one line naming the row: a row that is not two
numbers, NaN, time that does not increase, a gap in a constant sample rate, too few samples,
a unit that cannot be told.
"""
import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import OptionError, WorkbookError
from ..transaction import display
from .guard import read_bytes

#: Time units [s per unit].
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}

#: Acceleration units [kG per unit]. 1 kG is 9800 m/s^2, as the macro's Acceleration (kG's).
ACCEL_UNITS = {"g": 1e-3, "kg": 1.0, "m/s^2": 1 / 9800, "m/s2": 1 / 9800}

#: A step may differ from the median step by this fraction before it is a gap.
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
    """

    time: np.ndarray
    accel_kg: np.ndarray
    dt: float
    name: str
    units: tuple


def _unit(header, table, option, which):
    found = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]", header)
    text = (found.group(1) if found else "").strip()
    key = text.replace("'s", "").replace("²", "^2").replace(" ", "")
    key = key if key in table else key.lower() if key.lower() in table else None
    if key is None:
        raise OptionError(f"{option}: the {which} header {header!r} names no unit I know "
                          f"({text or 'none'}); expected one of {', '.join(table)} in the "
                          f"header, e.g. '{which} [{next(iter(table))}]', or {option}")
    return key


def _table(path, expected, columns):
    """(shown name, header, n x 2 values) of a two-column CSV; every row checked."""
    shown = display(Path(path))
    data = read_bytes(path, expected, "CSV")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise WorkbookError(f"{shown}: is not UTF-8 text (byte {exc.start}), {expected}") \
            from None
    try:
        dialect = csv.Sniffer().sniff(text[:4096], delimiters=",;\t")
    except csv.Error:
        dialect = csv.excel
    rows = list(csv.reader(io.StringIO(text), dialect))
    rows = [r for r in rows if any(cell.strip() for cell in r)]
    if len(rows) < 2 or len(rows[0]) < 2:
        raise WorkbookError(f"{shown}: holds {len(rows)} rows of {len(rows[0]) if rows else 0} "
                            f"columns, {expected}")
    values = np.empty((len(rows) - 1, 2))
    for i, row in enumerate(rows[1:], start=2):
        try:
            a, b = float(row[0]), float(row[1])
        except (ValueError, IndexError):
            raise WorkbookError(f"{shown}: row {i} holds {row[:2]!r}, expected two numbers "
                                f"({columns[0]}, {columns[1]})") from None
        if not (math.isfinite(a) and math.isfinite(b)):
            raise WorkbookError(f"{shown}: row {i} holds {row[0].strip()}, {row[1].strip()}, "
                                "expected finite numbers (no NaN or inf)")
        values[i - 2] = a, b
    return shown, rows[0], values


#: Frequency units [Hz per unit] of a required spectrum.
FREQUENCY_UNITS = {"Hz": 1.0, "kHz": 1e3}

EXPECTED_SPECTRUM = ("expected a CSV of natural frequency and required SRS level (two "
                     "columns, a header row such as 'frequency [Hz],srs [g]')")


def read_spectrum(path, accel_unit=None):
    """A required shock response spectrum: (frequencies [Hz], levels [kG]), from a CSV whose
    header gives the units (``frequency [Hz]``, ``srs [g]``); frequencies increasing and
    positive, levels positive. Raises WorkbookError or OptionError naming the row or unit."""
    if accel_unit is not None and accel_unit not in ACCEL_UNITS:
        raise OptionError(f"--accel-unit: found {accel_unit!r}, expected one of "
                          f"{', '.join(ACCEL_UNITS)}")
    shown, header, values = _table(path, EXPECTED_SPECTRUM, ("frequency", "level"))
    f_unit = _unit(header[0], FREQUENCY_UNITS, "--target-srs", "frequency")
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


def read_trace(path, time_unit=None, accel_unit=None, sign=1.0):
    """Read a measured pulse from a CSV file.

    Parameters
    ----------
    path : path
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
    shown, header, values = _table(path, EXPECTED, ("time", "acceleration"))
    t_unit = time_unit or _unit(header[0], TIME_UNITS, "--time-unit", "time")
    a_unit = accel_unit or _unit(header[1], ACCEL_UNITS, "--accel-unit", "acceleration")
    if len(values) < MIN_SAMPLES:
        raise WorkbookError(f"{shown}: holds {len(values)} samples, expected at least "
                            f"{MIN_SAMPLES}")
    time = values[:, 0] * TIME_UNITS[t_unit]
    steps = np.diff(time)
    if not (steps > 0).all():
        k = int(np.argmax(steps <= 0))
        raise WorkbookError(f"{shown}: row {k + 3}: time {values[k + 1, 0]:g} does not "
                            f"follow {values[k, 0]:g}, expected increasing time")
    dt = float(np.median(steps))
    off = np.abs(steps - dt) > GAP_TOLERANCE * dt
    if off.any():
        k = int(np.argmax(off))
        raise WorkbookError(f"{shown}: row {k + 3}: a step of {steps[k]:.4g} s, expected the "
                            f"constant {dt:.4g} s of the other rows (a gap or a changed rate)")
    return Trace(time, sign * values[:, 1] * ACCEL_UNITS[a_unit], dt, shown, (t_unit, a_unit))
