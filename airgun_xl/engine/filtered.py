"""The macro's filtered acceleration (column AB), cursor moves followed literally.

The macro walks a cursor down AB from the t = -delta row, ``counter = 3 To rows - 2*samplerate``.
Every time an inner counter exceeds ``samplerate`` it reads Y33 at the cursor, moves the cursor by
``Offset(-samplerate)``, ``Offset(2*samplerate)``, ``Offset(-samplerate)``, reading at each stop,
and writes a second difference where the cursor ends; other visited rows get "".

Spreadsheet hosts disagree on a fractional Offset argument: Excel rounds it half to even (the OLE
conversion to Long), so the stencil turns one-sided and the cursor drifts a row per sample;
LibreOffice Calc ignores the move, so every sample is 0. ``host`` picks which one to reproduce.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from .. import choices

HOSTS = choices.HOSTS


@dataclass
class Filtered:
    """Filtered samples: ``rows`` are array indices (sheet row - 2), ``values`` in m/s^2."""

    rows: np.ndarray
    values: np.ndarray
    warnings: list = field(default_factory=list)


def _offset(n: float, host: str) -> int:
    """Rows a macro ``Offset(n, 0)`` moves by, in the given host."""
    if float(n).is_integer():
        return int(n)
    if host == "calc":
        return 0  # Calc ignores a fractional Offset argument
    return round(n)  # Excel: nearest integer, halves to even (Python's round does the same)


def sub_row_warning(samplerate: float, host: str) -> str:
    """The quirk of a filter step below one row, by name (the macro's column AB then holds
    zeros, or first differences divided by a second difference's step: no acceleration)."""
    both, back = _offset(2 * samplerate, host), _offset(-samplerate, host)
    shape = ("(Y33 one row on - Y33) / (E2*samplerate)^2 on every other row, a velocity "
             "change over a time squared" if (both, back) == (1, 0) else
             "zeros on every row" if both == back == 0 else "one-sided differences of Y33")
    return (f"E34 (Filter Frequency): 1/(E2*E34) = {samplerate:.3g} rows is below one row "
            f"(sub-row filter quirk): the macro's column AB then holds {shape} ({host}), not "
            "an acceleration; it is reproduced, and no filtered peak is reported")


@dataclass
class Stencils:
    """Where the macro's filter reads and writes, for a run of ``n`` rows.

    ``write[i]`` is the row a sample lands on, computed from Y33 at rows ``centre[i]``,
    ``before[i]`` and ``after[i]`` (rows at or past ``n`` read as 0, empty cells).
    """

    centre: np.ndarray
    before: np.ndarray
    after: np.ndarray
    write: np.ndarray
    warnings: list


def fractional_rows(samplerate: float) -> str:
    """What a fractional 1/(E2*E34) does, in one sentence: the run's warning (this module's)
    and the check before it (:mod:`airgun_xl.studies.check`) say it in the same words, so a
    fill records it once."""
    return (f"1/(E2*E34) = {samplerate:.6g} is not a whole number of rows: the legacy "
            "filtered column is ill-defined (Excel rounds the offsets and drifts a row per "
            "sample, LibreOffice writes zeros; --host chooses which is reproduced)")


def filter_stencils(n: int, samplerate: float, host: str = "excel") -> Stencils:
    """Follow the macro's cursor over ``n`` rows; see the module docstring.

    Returns
    -------
    Stencils
    """
    if host not in HOSTS:
        raise ValueError(f"host must be one of {HOSTS}")
    warnings: list[str] = []
    if samplerate < 1:  # every visited row writes; Offset(-sr) is fractional in both hosts
        warnings.append(sub_row_warning(samplerate, host))
    elif not float(samplerate).is_integer():
        warnings.append(f"E34 (Filter Frequency): {fractional_rows(samplerate)}")
    # The loop visits `iterations` rows from index 0 (sheet row 2).
    last = n - (2 * samplerate)  # `introwcount - (2 * samplerate)`, a double
    iterations = max(0, math.floor(last) - 3 + 1)
    period = math.floor(samplerate) + 1  # innercounter > samplerate, innercounter an Integer
    up, both = _offset(-samplerate, host), _offset(2 * samplerate, host)
    # row written -> (centre, before, after); a later "" write empties it again
    written: dict[int, tuple[int, int, int]] = {}
    cursor = 0  # array index of the cursor
    done = 0
    top = -1  # highest row holding a sample
    while done + period <= iterations:
        if written and top >= cursor:  # rows written "" before the sample
            for blank in range(cursor, cursor + period - 1):
                written.pop(blank, None)
        cursor += period - 1
        done += period
        r0 = cursor
        r1 = r0 + up
        r2 = r1 + both
        r3 = r2 + up
        if min(r1, r2, r3) < 0:  # index -1 is the header row: a type mismatch in the macro
            warnings.append("the filter stencil reaches the header row, where the legacy macro "
                            "stops with an error; later samples are left out")
            break
        written[r3] = (r0, r1, r2)
        top = max(top, r3)
        cursor = r3 + 1
    rows = sorted(written)
    parts = np.array([written[r] for r in rows], dtype=np.int64).reshape(-1, 3)
    return Stencils(parts[:, 0], parts[:, 1], parts[:, 2], np.array(rows, dtype=np.int64),
                    warnings)


def filtered_values(y: np.ndarray, delta: float, samplerate: float,
                    stencils: Stencils) -> np.ndarray:
    """The samples' values [m/s^2] for displacement rows ``y`` (1-D, or 2-D: one run a row).

    ``scale * (un2 + un - 2 * un1)`` in the macro's order, so a 2-D batch gives each run's
    values to the last bit.
    """
    scale = 1.0 / (delta * delta * samplerate * samplerate)
    y = np.asarray(y)
    n = y.shape[-1]
    padded = np.concatenate((y, np.zeros(y.shape[:-1] + (1,))), axis=-1)  # row n reads 0

    def at(rows: np.ndarray) -> np.ndarray:
        return padded[..., np.minimum(rows, n)]

    un1, un2, un = at(stencils.centre), at(stencils.before), at(stencils.after)
    return scale * (un2 + un - 2 * un1)


def filtered_acceleration(y33: np.ndarray, delta: float, samplerate: float,
                          host: str = "excel") -> Filtered:
    """Resample the test-item acceleration as ArtSim's last loop does.

    Parameters
    ----------
    y33 : numpy.ndarray
        Test-item displacement [m], one entry per time row (index 0 is t = -delta).
    delta : float
        Time step [s].
    samplerate : float
        ``1 / (E2 * E34)`` [rows], kept as a double.
    host : {"excel", "calc"}
        Whose Offset rounding to reproduce.

    Returns
    -------
    Filtered
        The sample rows and values; ``warnings`` says when the column is ill-defined.
    """
    stencils = filter_stencils(len(y33), samplerate, host)
    values = filtered_values(y33, delta, samplerate, stencils)
    return Filtered(stencils.write, np.asarray(values, dtype=float), stencils.warnings)
