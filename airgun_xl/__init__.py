"""airgun-xl: ArtSim (ARL-TR-3559), the air gun impact simulator, as a Python package.

Load a shot from a workbook in the report's layout, run it, and get the result::

    import airgun_xl
    shot = airgun_xl.load("templates/shot_a.xlsx")
    result = shot.run()
    frame = result.to_frame()
"""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

from .errors import (
    AirgunXlError,
    ArchiveError,
    CampaignError,
    CellError,
    DesignError,
    DivergenceError,
    OptionError,
    OutputError,
    ResourceError,
    StabilityError,
    WorkbookError,
)
from .version import __version__

if TYPE_CHECKING:
    from collections.abc import Sequence

    from .app.accept import AcceptOutcome
    from .app.sweep import SweepOutcome
    from .params import ShotParams
    from .result import Result
    from .shot import Shot

#: Loaded on first use (PEP 562), so that ``airgun-xl`` can set up its signal handling before
#: numpy and the engine load.
_LAZY = {"ShotParams": "params", "Result": "result", "Shot": "shot"}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def load(path: str | os.PathLike[str]) -> Shot:
    """Read a :class:`Shot` from a workbook (see :meth:`Shot.from_workbook`)."""
    from .shot import Shot

    return Shot.from_workbook(path)


def accept(shot: str | os.PathLike[str], recording: str | os.PathLike[str], *,
           peak: str | None = None, duration: str | None = None,
           velocity_change: str | None = None, shape: str | None = None,
           corridor: str | None = None, time_slack: str | None = None,
           dv_window: str | None = None, monitor: str | None = None,
           duration_def: str | None = None, decay: str | None = None,
           placement: str | None = None, srs: str | os.PathLike[str] | None = None,
           srs_tol: str | None = None, srs_q: str | None = None,
           srs_outside: str | None = None, profile: str | os.PathLike[str] | None = None,
           cfc: int | str | None = None, output: str | os.PathLike[str] | None = None,
           force: bool = False, archive: str | os.PathLike[str] | None = None,
           channel: str | None = None, sign: float = 1.0, time_unit: str | None = None,
           accel_unit: str | None = None, crush_law: str = "workbook") -> AcceptOutcome:
    """Judge a recording against the shot's specification, as ``airgun-xl accept`` does.

    The specification is the ``profile``'s, then the shot's Specification sheet's, then
    the fields given here, each overriding the one before field by field; every field is
    text in the command's grammar (``peak="12kG:10%"``, ``duration="5ms:10%"``), and a
    refusal names the option the keyword stands for (``--peak``). ``cfc`` is the record
    judged: a SAE J211 class (60, 180, 600, 1000) or ``"none"``.

    Parameters
    ----------
    shot : path
        The shot's workbook, in the report's layout.
    recording : path
        The recorded pulse: a CSV (time, acceleration, units in the header), a workbook's
        columns (``trace.xlsx:Sheet1!A:B``) or a LabVIEW TDMS file.
    output : path, optional
        The verdict workbook to write (none is written if not given).
    archive : path, optional
        Keep the verdict in this archive (needs ``output``, which the record names).
    sign : float
        1, or -1 when the recorder's axis is opposite to the macro's [-].
    crush_law : str
        The law the shot's prediction runs: ``workbook`` (its Crush law sheet's, else the
        macro's), ``legacy`` (the macro's, Eq. 8) or ``NAME[@N]`` of ``archive``'s library.

    Returns
    -------
    airgun_xl.app.accept.AcceptOutcome
        ``passed``, ``criteria``, ``warnings``, the files written.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from pathlib import Path

    from .app.accept import AcceptRequest, run
    from .app.specifying import SpecFields, cfc_class

    def text(value: object) -> str | None:
        return None if value is None else os.fspath(value) if isinstance(
            value, os.PathLike) else str(value)

    record = None
    if cfc is not None:
        try:
            record = cfc_class(str(cfc))
        except ValueError as exc:
            raise OptionError(f"--cfc: {exc}") from None
    fields = SpecFields(
        profile=text(profile), shape=text(shape), peak=text(peak), duration=text(duration),
        velocity_change=text(velocity_change), corridor=text(corridor),
        time_slack=text(time_slack), dv_window=text(dv_window), monitor=text(monitor),
        duration_def=text(duration_def), decay=text(decay), placement=text(placement),
        srs=text(srs), srs_tol=text(srs_tol), srs_q=text(srs_q), srs_outside=text(srs_outside),
        cfc=record, cfc_given="--cfc" if cfc is not None else None, accel_unit=accel_unit)
    return run(AcceptRequest(
        Path(shot), os.fspath(recording), fields, Path(output) if output is not None else None,
        force, Path(archive) if archive is not None else None, channel, float(sign), time_unit,
        accel_unit, ("accept",), crush_law))


def sweep(shot: str | os.PathLike[str], vary: str | Sequence[str] = (), *,
          mc: int | str | None = None, sd: str | Sequence[str] = (),
          sobol: int | str | None = None, seed: int = 1, integrator: str = "legacy",
          model: str = "4-mass", output: str | os.PathLike[str] | None = None,
          force: bool = False, crush_law: str = "workbook",
          archive: str | os.PathLike[str] | None = None, scheduler: str | None = None,
          workers: int | None = None, chunk: int | None = None) -> SweepOutcome:
    """Run a grid of shots, a Monte Carlo or Sobol indices, as ``airgun-xl sweep`` does.

    Parameters
    ----------
    shot : path
        The shot's workbook, in the report's layout.
    vary : str or sequence of str
        ``CELL=LO:HI:N`` (``"A28=150:250:3"``); several make a grid.
    mc, sobol : int, optional
        A Monte Carlo of this many shots, or Sobol indices (N, a power of 2, times the
        inputs + 2 shots), over the spreads ``sd`` (``"E40=3%"``), drawn from ``seed``.
    output : path, optional
        The sweep's workbook to write (none is written if not given).
    scheduler, workers, chunk
        Run the shots on a Dask cluster (its scheduler's address), or a local one of
        ``workers`` processes, ``chunk`` shots a task.

    Returns
    -------
    airgun_xl.app.sweep.SweepOutcome
        ``to_frame()`` gives a row a shot; ``stats``, ``sensitivity``, ``warnings``,
        ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from pathlib import Path

    from .app.sweep import SweepRequest, run

    def texts(value: str | Sequence[str]) -> tuple[str, ...]:
        return (value,) if isinstance(value, str) else tuple(str(v) for v in value)

    return run(SweepRequest(
        Path(shot), texts(vary), None if mc is None else str(mc), texts(sd),
        None if sobol is None else str(sobol), seed, integrator, model,
        Path(output) if output is not None else None, force, crush_law,
        Path(archive) if archive is not None else None, scheduler, workers, chunk))


__all__ = [
    "AirgunXlError",
    "ArchiveError",
    "CampaignError",
    "CellError",
    "DesignError",
    "DivergenceError",
    "OptionError",
    "OutputError",
    "ResourceError",
    "StabilityError",
    "Result",
    "Shot",
    "ShotParams",
    "WorkbookError",
    "__version__",
    "accept",
    "load",
    "sweep",
]
