"""airgun-xl: ArtSim (ARL-TR-3559), the air gun impact simulator, as a Python package.

Load a shot from a workbook in the report's layout, run it, and get the result::

    import airgun_xl
    shot = airgun_xl.load("templates/shot_a.xlsx")
    result = shot.run()
    frame = result.to_frame()
"""
from __future__ import annotations

import functools
import inspect
import os
from typing import TYPE_CHECKING, Any, TypeVar

from . import blas  # noqa: F401 - first: OpenBLAS's kernel is pinned before numpy loads
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
    import datetime
    from collections.abc import Sequence
    from pathlib import Path
    from typing import Unpack

    from .app.accept import AcceptOutcome
    from .app.archive import CompareOutcome, HistoryOutcome, ShowOutcome
    from .app.calibrate import CalibrateOutcome
    from .app.campaign import CampaignOutcome
    from .app.check import CheckOutcome
    from .app.compare_measured import CompareMeasuredOutcome
    from .app.convergence import ConvergenceOutcome
    from .app.design import DesignOutcome
    from .app.diff import DiffOutcome
    from .app.fill import FillOutcome
    from .app.next_shot import NextOutcome
    from .app.recording import RecordingOutcome
    from .app.settings import FillSettings
    from .app.specifying import SpecKeywords
    from .app.srs import SrsOutcome
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


_F = TypeVar("_F")


def _paths_checked(function: _F) -> _F:
    """``function`` with each argument its signature types as a path (``os.PathLike``)
    checked before the call: a path given as text or a path, a sequence of them where the
    signature takes one, None where it allows None; anything else is one
    :class:`OptionError` naming the argument (it was a raw TypeError from deep inside)."""
    signature = inspect.signature(function)  # type: ignore[arg-type]
    typed = {name: str(parameter.annotation) for name, parameter in signature.parameters.items()
             if "PathLike" in str(parameter.annotation)}

    def check(name: str, value: object) -> None:
        text = typed[name]
        if value is None and "None" in text:
            return
        values = value if "Sequence" in text and isinstance(value, (list, tuple)) else [value]
        for one in values:
            if not isinstance(one, (str, os.PathLike)):
                raise OptionError(f"{name}: found {one!r}, expected a file's path (text or "
                                  "a path)")

    @functools.wraps(function)  # type: ignore[arg-type]
    def checked(*args: Any, **kwargs: Any) -> Any:
        try:
            bound = signature.bind(*args, **kwargs)
        except TypeError as exc:  # a missing or unknown argument: the caller's own error
            raise TypeError(f"{function.__name__}(): {exc}") from None  # type: ignore[attr-defined]
        for name, value in bound.arguments.items():
            if name in typed:
                kind = signature.parameters[name].kind
                for one in (value if kind is inspect.Parameter.VAR_POSITIONAL else [value]):
                    check(name, one)
        return function(*args, **kwargs)  # type: ignore[operator]

    return checked  # type: ignore[return-value]


def _event(fields: Any) -> dict[str, Any]:
    """``event`` and ``at`` as a request's keywords, read and checked
    (:class:`airgun_xl.app.declared.EventFields`)."""
    return {"event": fields.event, "at": fields.at}


@_paths_checked
def load(path: str | os.PathLike[str]) -> Shot:
    """Read a :class:`Shot` from a workbook (see :meth:`Shot.from_workbook`)."""
    from .shot import Shot

    return Shot.from_workbook(path)


@_paths_checked
def accept(shot: str | os.PathLike[str], recording: str | os.PathLike[str], *,
           output: str | os.PathLike[str] | None = None, force: bool = False,
           archive: str | os.PathLike[str] | None = None, channel: str | None = None,
           sign: float = 1.0, time_unit: str | None = None, accel_unit: str | None = None,
           crush_law: str = "workbook", pdf: str | os.PathLike[str] | None = None,
           reproducible: bool = False, event: int | None = None, at: float | str | None = None,
           client: str | None = None, test_id: str | None = None, item: str | None = None,
           serial: str | None = None, operator: str | None = None, lab: str | None = None,
           decision_rule: str = "simple", **spec: Unpack[SpecKeywords]) -> AcceptOutcome:
    """Judge a recording against the shot's specification, as ``airgun-xl accept`` does.

    The specification is the ``profile``'s, then the shot's Specification sheet's, then
    the fields given here, each overriding the one before field by field; every field is
    text in the command's grammar (``peak="12kG:10%"``, ``duration="5ms:10%"``; the fields:
    :class:`airgun_xl.app.specifying.SpecKeywords`), and a refusal names the option the
    keyword stands for (``--peak``). ``cfc`` is the record judged: a SAE J211 class (60,
    180, 600, 1000) or ``"none"``.

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
    event, at : int or float, optional
        Of a recording of several shocks, the one judged: its number (from 1, as
        :func:`recording` with ``events`` lists them) or an instant of it [s] (``1.25``,
        ``"1250ms"``); the largest by default.
    client, test_id, item, serial, operator, lab : str, optional
        The test's identification on the report (:mod:`airgun_xl.identification`), over
        the shot's Specification sheet's Test block field by field.
    decision_rule : {"simple", "guarded"}
        How a value within its expanded uncertainty U of a limit is called (ILAC-G8):
        as measured, or not accepted.
    crush_law : str
        The law the shot's prediction runs: ``workbook`` (its Crush law sheet's, else the
        macro's), ``legacy`` (the macro's, Eq. 8) or ``NAME[@N]`` of ``archive``'s library.
    pdf : path, optional
        Also write the client's test report as a PDF (needs matplotlib);
        ``reproducible`` leaves its date out (the same run, the same bytes).

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
    from .app.declared import EventFields, ReportFields
    from .app.specifying import keyword_fields

    fields = keyword_fields("accept", dict(spec), accel_unit)
    return run(AcceptRequest(
        Path(shot), os.fspath(recording), fields, Path(output) if output is not None else None,
        force, Path(archive) if archive is not None else None, channel,
        _sign(sign), time_unit, accel_unit, ("accept",), crush_law,
        _path("--pdf", pdf) if pdf is not None else None, bool(reproducible),
        **_event(EventFields.given(event=event, at=at)),
        test=ReportFields.given(client=client, test_id=test_id, item=item, serial=serial,
                                  operator=operator, lab=lab, decision_rule=decision_rule)))


@_paths_checked
def calibrate(*files: str | os.PathLike[str], law: bool = False,
              fit: str | Sequence[str] | None = None, objective: str = "l2",
              degree: int = 6, cfc: int | str | None = None, sign: float = 1.0,
              time_unit: str | None = None, accel_unit: str | None = None,
              channel: str | None = None, anti_alias: str | float = "auto",
              integrator: str = "legacy", output: str | os.PathLike[str] | None = None,
              force: bool = False, archive: str | os.PathLike[str] | None = None,
              name: str | None = None, event: int | None = None,
              at: float | str | None = None) -> CalibrateOutcome:
    """Fit the model to the shots that were fired, as ``airgun-xl calibrate`` does:
    ``files`` are each shot's workbook followed by its recording (``"shot_01.xlsx",
    "rec_01.csv", "shot_02.xlsx", "rec_02.csv"``).

    The crush-factor law is recovered with ``law`` or when ``fit`` names nothing; ``fit``
    names least-squares fits (``"E40"``, ``["E40", "E43"]``, ``"scale"``). ``cfc`` filters
    both pulses (a J211 class, or ``"none"``, the default); ``name`` keeps a trusted law in
    ``archive``'s library, for ``crush_law=NAME``.

    Returns
    -------
    airgun_xl.app.calibrate.CalibrateOutcome
        ``trusted``, ``fitted``, ``warnings``, ``calibration`` (errors, intervals, the scores
        before and after), ``stored``, ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from pathlib import Path

    from .app.calibrate import CalibrateRequest, run
    from .app.declared import EventFields
    from .app.specifying import record_filter

    texts = [os.fspath(f) for f in files]
    if len(texts) % 2:
        raise OptionError(f"calibrate: found {len(texts)} files, expected pairs of "
                          "SHOT.xlsx RECORDING")
    record = record_filter(cfc)
    names = fit if fit is None or isinstance(fit, str) else ",".join(fit)
    return run(CalibrateRequest(
        tuple(zip(texts[::2], texts[1::2], strict=True)), law, names, objective,
        _whole("--degree", degree), record, _sign(sign), time_unit, accel_unit,
        channel, anti_alias, integrator,
        Path(output) if output is not None else None, force,
        Path(archive) if archive is not None else None, name, ("calibrate",),
        **_event(EventFields.given(event=event, at=at))))


@_paths_checked
def design(shot: str | os.PathLike[str], *, target_peak: str | None = None,
           target_duration: str | None = None,
           target_srs: str | os.PathLike[str] | None = None, vary: str | Sequence[str] = (),
           range: str | None = None, filtered: bool = False,
           confidence: float | None = None, sd: str | Sequence[str] = (),
           shots: int = 10_000, seed: int = 1, accel_unit: str | None = None,
           integrator: str = "legacy", model: str = "4-mass",
           output: str | os.PathLike[str] | None = None, force: bool = False,
           crush_law: str = "workbook", archive: str | os.PathLike[str] | None = None,
           scheduler: str | None = None, workers: int | None = None,
           chunk: int | None = None, pdf: str | os.PathLike[str] | None = None,
           **spec: Unpack[SpecKeywords]) -> DesignOutcome:
    """Design a shot, as ``airgun-xl design`` does: to ``target_peak`` (with
    ``target_duration``, two cells in ``vary``) or ``target_srs``; without a target, to the
    middle of the specification (the profile's, the shot's sheet's, then the fields given
    here, as :func:`accept` takes them, and ``srs_q`` a target SRS's Q); with
    ``confidence`` and the scatter ``sd``
    (``"A28=1.5%"``), the setting most likely to pass on the first shot.

    Parameters
    ----------
    shot : path
        The shot's workbook, in the report's layout.
    vary : str or sequence of str
        The cell(s) solved for (A28, the default, stands for A28..A30).
    range : str, optional
        ``LO:HI`` of the (first) cell, in its unit.
    output : path, optional
        The designed shot's workbook, filled (none is written if not given).

    Returns
    -------
    airgun_xl.app.design.DesignOutcome
        ``values`` ({cell: value}), ``reached``, ``confidence`` (P(PASS) and its interval),
        ``designed`` (a :class:`Shot`), ``warnings``, ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from pathlib import Path

    from .app.design import DesignRequest, run
    from .app.specifying import keyword_fields

    fields = keyword_fields("design", dict(spec), accel_unit)
    return run(DesignRequest(
        Path(shot), None if target_peak is None else str(target_peak),
        None if target_duration is None else str(target_duration),
        os.fspath(target_srs) if target_srs is not None else None, _texts(vary),
        None if range is None else str(range), filtered, fields,
        None if confidence is None else _number("--confidence", confidence), _texts(sd),
        _whole("--shots", shots), _whole("--seed", seed), integrator, model,
        Path(output) if output is not None else None, force, crush_law,
        Path(archive) if archive is not None else None, scheduler, workers, chunk,
        ("design",), None if pdf is None else _path("--pdf", pdf)))


@_paths_checked
def srs(shot: str | os.PathLike[str], *, q: float | str = 10.0, cfc: int | str | None = None,
        lo: float = 100.0, hi: float = 10_000.0, integrator: str = "legacy",
        model: str = "4-mass", output: str | os.PathLike[str] | None = None,
        force: bool = False, crush_law: str = "workbook",
        archive: str | os.PathLike[str] | None = None) -> SrsOutcome:
    """The shock response spectrum of the shot's predicted pulse, as ``airgun-xl srs``
    does: maximax absolute acceleration [kG] at 1/12-octave frequencies from ``lo`` to ``hi``
    [Hz] (``--from``, ``--to``), quality factor ``q`` [-], the pulse through ``cfc`` first (a
    J211 class, or ``"none"``, the default).

    Returns
    -------
    airgun_xl.app.srs.SrsOutcome
        ``frequencies``, ``levels``, ``largest``, ``warnings``, ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from .app.srs import SrsRequest, run

    return run(SrsRequest.given(shot=shot, q=q, cfc=cfc, lo=lo, hi=hi, integrator=integrator,
                                model=model, output=output, force=force,
                                crush_law=crush_law, archive=archive))


@_paths_checked
def compare_measured(shot: str | os.PathLike[str], recording: str | os.PathLike[str], *,
                     cfc: int | str | None = None, align: str = "threshold",
                     anti_alias: str | float = "auto", sign: float = 1.0,
                     time_unit: str | None = None, accel_unit: str | None = None,
                     channel: str | None = None, integrator: str = "legacy",
                     model: str = "4-mass", output: str | os.PathLike[str] | None = None,
                     force: bool = False, crush_law: str = "workbook",
                     archive: str | os.PathLike[str] | None = None, event: int | None = None,
                     at: float | str | None = None) -> CompareMeasuredOutcome:
    """The shot's predicted pulse against a measured one, as ``airgun-xl compare-measured``
    does: both through ``cfc`` (a J211 class, or ``"none"``, the default), aligned at the
    impact (``align``: threshold or xcorr), scored.

    Returns
    -------
    airgun_xl.app.compare_measured.CompareMeasuredOutcome
        ``comparison`` (both pulses' figures, their errors, the correlation, the ISO/TS 18571
        rating), ``warnings``, ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from .app.compare_measured import CompareMeasuredRequest, run

    return run(CompareMeasuredRequest.given(
        shot=shot, recording=recording, cfc=cfc, align=align, anti_alias=anti_alias,
        sign=sign, time_unit=time_unit, accel_unit=accel_unit, channel=channel,
        integrator=integrator, model=model, output=output, force=force, crush_law=crush_law,
        archive=archive, event=event, at=at))


@_paths_checked
def convergence(shot: str | os.PathLike[str], levels: str | Sequence[str] | None = None, *,
                integrators: str | Sequence[str] = ("legacy",), rtol: float | str = 1e-3,
                output: str | os.PathLike[str] | None = None, force: bool = False,
                crush_law: str = "workbook",
                archive: str | os.PathLike[str] | None = None) -> ConvergenceOutcome:
    """Run the shot over a ladder of time steps, as ``airgun-xl convergence`` does:
    ``levels`` as typed (``"10us,5us,2us"`` or a list of them; None: the sheet's E2, then
    1-2-5 steps down to 5 ns), with each of ``integrators``; ``rtol`` the tolerance on the
    peak [-].

    Returns
    -------
    airgun_xl.app.convergence.ConvergenceOutcome
        ``ladders`` (each level's figures, errors, orders and run times [s], the Richardson
        extrapolation), ``recommended`` ({integrator: time step [s]}), ``warnings``,
        ``files``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written.
    """
    from .app.convergence import ConvergenceRequest, run

    return run(ConvergenceRequest.given(shot=shot, levels=levels, integrators=integrators,
                                        rtol=rtol, output=output, force=force,
                                        crush_law=crush_law, archive=archive))


@_paths_checked
def check(shot: str | os.PathLike[str], *, integrator: str = "legacy") -> CheckOutcome:
    """Can this shot's run be trusted, as ``airgun-xl check`` says: the scheme's critical
    time step (``critical.dt_crit`` [s], ``critical.ratio``, ``stable``) and what the shot
    stretches (``findings``, ``warnings``). No run, nothing written.

    Raises
    ------
    AirgunXlError
        A bad workbook or cell, named.
    """
    from .app.check import CheckRequest, run

    return run(CheckRequest.given(shot=shot, integrator=integrator))


@_paths_checked
def diff(legacy: str | os.PathLike[str], new: str | os.PathLike[str], *,
         rtol: float = 1e-12, atol: float = 0.0,
         report: str | os.PathLike[str] | None = None, force: bool = False) -> DiffOutcome:
    """Compare a workbook the macro filled with one airgun-xl filled, as ``airgun-xl diff``
    does: the parameter cells, then every result column, each within ``rtol`` of the
    column's largest magnitude (or ``atol``); ``report`` also writes the error table and the
    worst column's curves.

    Returns
    -------
    airgun_xl.app.diff.DiffOutcome
        ``same``, ``report`` (each column's largest difference), ``files``.

    Raises
    ------
    AirgunXlError
        A file that cannot be read, named.
    """
    from .app.diff import DiffRequest, run

    return run(DiffRequest.given(legacy=legacy, new=new, rtol=rtol, atol=atol, report=report,
                                 force=force))


@_paths_checked
def recording(path: str | os.PathLike[str], *, events: bool = False, channel: str | None = None,
              time_unit: str | None = None,
              accel_unit: str | None = None) -> RecordingOutcome:
    """What a recording file holds, as ``airgun-xl recording`` lists it: its ``format`` and
    its ``channels`` (each one's ``name``, ``unit`` as the file states it, ``rate`` [Hz],
    ``samples`` and ``start`` [s]), in the file's order: ``channel="2"`` in the reading
    functions is the second, ``channel=NAME`` the one of that name. No samples judged.
    With ``events``, also the shocks of ``channel`` (by default the first acceleration
    channel; ``time_unit`` and ``accel_unit`` where the file states none): ``events`` holds
    the channel's name, its unit, its times [s] and the events found
    (:class:`airgun_xl.readers.events.Events`), numbered for ``event=N`` in the reading
    functions.

    Raises
    ------
    AirgunXlError
        A file that cannot be read as a recording, named.
    """
    from .app.recording import RecordingRequest, run

    return run(RecordingRequest.given(path=path, events=events, channel=channel,
                                      time_unit=time_unit, accel_unit=accel_unit))


@_paths_checked
def serve(archive: str | os.PathLike[str] | None = None, *, host: str = "127.0.0.1",
          port: int | str = 8765) -> None:
    """Serve the archive's read-only view in a browser until Ctrl-C, as ``airgun-xl serve``
    does (needs the ``web`` extra): ``archive`` (None: $AIRGUN_XL_ARCHIVE), on the loopback
    address unless ``host`` says otherwise (the page has no login); ``port`` 0 takes any
    free port. The address is printed once it listens.

    Raises
    ------
    AirgunXlError
        No such archive, a port in use, or the extra missing, named.
    """
    from .web.command import ServeRequest, run

    return run(ServeRequest.given(archive=archive, host=host, port=port))


@_paths_checked
def template(output: str | os.PathLike[str], *, force: bool = False) -> os.PathLike[str]:
    """Write a fresh shot A workbook in the report's layout, as ``airgun-xl template``
    does; the path written."""
    from .app.template import TemplateRequest, run

    return run(TemplateRequest.given(output=output, force=force))


def _texts(value: str | Sequence[str] | None) -> tuple[str, ...]:
    """One text or several (None: none), as a tuple."""
    if value is None:
        return ()
    if isinstance(value, str):
        return (value,)
    try:
        return tuple(str(v) for v in value)
    except TypeError:  # one value of another type: read as text, refused by the grammar
        return (str(value),)


def _path(option: str, value: object) -> Path:
    """A file's path given as text or a path; else one line naming the option."""
    from pathlib import Path

    if not isinstance(value, (str, os.PathLike)):
        raise OptionError(f"{option}: found {value!r}, expected a file's path")
    return Path(value)


def _number(option: str, value: object) -> float:
    """A number given as a number or text (``"0.95"``); else one line naming the option."""
    try:
        return float(value if isinstance(value, (int, float)) else str(value))
    except ValueError:
        raise OptionError(f"{option}: found {value!r}, expected a number") from None


def _sign(value: object) -> float:
    """``sign``: 1 or -1, read as every converted request reads it
    (:func:`airgun_xl.app.declared.a_sign`), a refusal naming the keyword."""
    from .app.declared import a_sign

    return a_sign(value, "sign")


def _whole(option: str, value: object) -> int:
    """A whole number given as one or as text (``"64"``); else one line naming the option."""
    number = _number(option, value)
    if not number.is_integer():
        raise OptionError(f"{option}: found {value!r}, expected a whole number")
    return int(number)


@_paths_checked
def sweep(shot: str | os.PathLike[str], vary: str | Sequence[str] = (), *,
          mc: int | str | None = None, sd: str | Sequence[str] = (),
          sobol: int | str | None = None, seed: int | str = 1, integrator: str = "legacy",
          model: str = "4-mass", output: str | os.PathLike[str] | None = None,
          force: bool = False, scheduler: str | None = None, workers: int | None = None,
          chunk: int | None = None, crush_law: str = "workbook",
          archive: str | os.PathLike[str] | None = None) -> SweepOutcome:
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
    from .app.sweep import SweepRequest, run

    return run(SweepRequest.given(
        shot=shot, vary=vary, mc=mc, sd=sd, sobol=sobol, seed=seed, integrator=integrator,
        model=model, output=output, force=force, scheduler=scheduler, workers=workers,
        chunk=chunk, crush_law=crush_law, archive=archive))


def _fill_settings(command: str, output: str | os.PathLike[str] | None,
                   archive: str | os.PathLike[str] | None, options: dict[str, object],
                   spec: dict[str, object]) -> FillSettings:
    """The :class:`~airgun_xl.app.settings.FillSettings` of :func:`fill`'s and
    :func:`campaign`'s keywords (the specification's fields read as ``accept`` reads them)."""
    from .app.archive import archive_root
    from .app.settings import FillSettings
    from .app.specifying import keyword_fields, options_spec
    from .specification import load_profile

    fields = keyword_fields(command, dict(spec))
    profile = load_profile(fields.profile) if fields.profile else None
    return FillSettings(
        output=os.fspath(output) if output is not None else None,
        archive=archive_root(os.fspath(archive) if archive is not None else None),
        profile=profile, spec=options_spec(fields), argv=(command,),
        **options)  # type: ignore[arg-type]


@_paths_checked
def fill(shot: str | os.PathLike[str], *, output: str | os.PathLike[str] | None = None,
         force: bool = False, host: str = "excel", only: str | None = None,
         no_charts: bool = False, every: int | str | None = None,
         max_sheet_rows: int | str | None = None, sidecar: str | None = None,
         integrator: str = "legacy", allow_unstable: bool = False, model: str = "4-mass",
         crush_law: str = "workbook", unloading: str = "macro", compare_models: bool = False,
         archive: str | os.PathLike[str] | None = None, name: str | None = None,
         reproducible: bool = False, pdf: str | os.PathLike[str] | None = None,
         **spec: Unpack[SpecKeywords]) -> FillOutcome:
    """Run the shot in a workbook and write a new filled workbook, as ``airgun-xl fill``
    does (``output`` defaults to SHOT.out.xlsx beside the shot; the shot is never changed;
    ``pdf`` also writes its report as a PDF, which needs matplotlib).

    The keywords are the command's options (``only="summary,charts"``, ``every=10``); the
    specification fields (``peak="12kG:10%"``, ``profile=``) judge the prediction, over the
    shot's Specification sheet. With ``archive`` (or ``$AIRGUN_XL_ARCHIVE``) the run is also
    stored as a new entry.

    Returns
    -------
    airgun_xl.app.fill.FillOutcome
        ``result`` (the :class:`Result`), ``summary``, ``verdict``, ``warnings``, ``files``,
        ``lines`` (what the command prints).

    Raises
    ------
    AirgunXlError
        Bad input or an unstable run, named; nothing is written.
    """
    from .app.fill import FillRequest, run

    settings = _fill_settings("fill", output, archive, {
        "force": force, "host": host, "only": only, "no_charts": no_charts,
        "every": None if every is None else str(every),
        "max_sheet_rows": None if max_sheet_rows is None else str(max_sheet_rows),
        "sidecar": sidecar, "integrator": integrator, "allow_unstable": allow_unstable,
        "model": model, "crush_law": crush_law, "unloading": unloading,
        "compare_models": compare_models, "name": name, "reproducible": reproducible,
        "pdf": None if pdf is None else os.fspath(_path("--pdf", pdf))}, dict(spec))
    return run(FillRequest(os.fspath(shot), settings))


@_paths_checked
def campaign(shots: str | os.PathLike[str] | Sequence[str | os.PathLike[str]], *,
             jobs: int | str | None = None, summary: str | os.PathLike[str] | None = None,
             force: bool = False, integrator: str = "legacy", model: str = "4-mass",
             crush_law: str = "workbook", archive: str | os.PathLike[str] | None = None,
             reproducible: bool = False, **spec: Unpack[SpecKeywords]) -> CampaignOutcome:
    """Fill many shots (workbooks, or folders of them), each its own transaction, in ``jobs``
    worker processes, as ``airgun-xl fill a.xlsx b.xlsx day/ --jobs N --summary DAY.xlsx``
    does. A bad shot is its row's status; the others go on.

    Returns
    -------
    airgun_xl.app.campaign.CampaignOutcome
        ``rows`` (one a shot: status, figures, warnings), ``counts``, ``failure`` (why it is
        not a success, or None), ``files``.
    """
    from .app.campaign import CampaignRequest, run

    given = [shots] if isinstance(shots, (str, os.PathLike)) else list(shots)
    settings = _fill_settings("fill", None, archive, {
        "force": force, "integrator": integrator, "model": model, "crush_law": crush_law,
        "reproducible": reproducible}, dict(spec))
    return run(CampaignRequest(tuple(os.fspath(p) for p in given), settings, jobs,
                               os.fspath(summary) if summary is not None else None))


@_paths_checked
def history(archive: str | os.PathLike[str] | None = None, *, shot: str | None = None,
            since: str | datetime.date | None = None, where: str | Sequence[str] = (),
            output: str | os.PathLike[str] | None = None,
            force: bool = False) -> HistoryOutcome:
    """The runs stored in an archive (default ``$AIRGUN_XL_ARCHIVE``), as ``airgun-xl
    history`` lists them: ``rows`` (one a run: its figures and provenance, what its records
    could not give named), the archive's ``laws`` and ``verdicts``; ``where`` selects by
    input cell (``"E40=2.6e7:2.8e7"``); ``output`` also writes the table."""
    from .app.archive import HistoryRequest, history as run  # noqa: I001 (one import)

    return run(HistoryRequest.given(archive=archive, shot=shot, since=since, where=where,
                                    output=output, force=force))


@_paths_checked
def show(entry: str, archive: str | os.PathLike[str] | None = None) -> ShowOutcome:
    """One archived run (``"SHOT"``, ``"SHOT@VERSION"`` or ``"#ID"``): ``doc`` holds its
    inputs, figures, provenance and files as stored; refused when ``archive verify`` would
    report it."""
    from .app.archive import ShowRequest, show as run  # noqa: I001 (one import, as each)

    return run(ShowRequest.given(entry=entry, archive=archive))


@_paths_checked
def compare(entry1: str, entry2: str, archive: str | os.PathLike[str] | None = None, *,
            rtol: float = 1e-12, atol: float = 0.0,
            report: str | os.PathLike[str] | None = None,
            force: bool = False) -> CompareOutcome:
    """Two archived runs compared, inputs first, then every series of their histories, as
    ``airgun-xl compare`` does: ``same``, ``report`` (the error table), ``files``."""
    from .app.archive import CompareRequest, compare as run  # noqa: I001 (one import)

    return run(CompareRequest.given(entry1=entry1, entry2=entry2, archive=archive, rtol=rtol,
                                    atol=atol, report=report, force=force))


@_paths_checked
def next_shot(shot: str | os.PathLike[str], recording: str | os.PathLike[str], *,
              archive: str | os.PathLike[str], lot: str, new_lot: bool = False,
              sd: str | Sequence[str] = (), confidence: float = 0.9, shots: int = 2000,
              seed: int = 1, output: str | os.PathLike[str] | None = None, force: bool = False,
              channel: str | None = None, sign: float = 1.0, time_unit: str | None = None,
              accel_unit: str | None = None, integrator: str = "legacy",
              vary: str | None = None, scheduler: str | None = None,
              workers: int | None = None, chunk: int | None = None,
              pdf: str | os.PathLike[str] | None = None, gun: str | None = None,
              step: str | Sequence[str] = (), event: int | None = None,
              at: float | str | None = None, **spec: Unpack[SpecKeywords]) -> NextOutcome:
    """The closed loop, as ``airgun-xl next`` runs it: judge the fired ``shot``'s
    ``recording``, update ``lot``'s law in ``archive`` on every shot of the lot, choose the
    A28 (with ``vary``, also a second knob: ``"E13"``, ``"E16"`` or ``"A2"``) most likely to
    pass with the gun's scatter (``sd=["A28=1.5%"]``) and the law drawn from its update
    (on a Dask cluster with ``scheduler`` or ``workers``, ``chunk`` shots a task; with
    ``gun``, the gun's scatter estimated from every lot that gun fired; with ``step``, such
    as ``["A28=0.5"]``, the best setting the knobs can be set to), write the
    next shot's workbook (``output``, else SHOT.next.xlsx) and keep the verdict, the law's
    version and the proposal in the archive.

    Returns
    -------
    airgun_xl.app.next_shot.NextOutcome
        ``verdict`` (the fired shot's), ``update`` (the law's scale and its standard error),
        ``law`` (its new version), ``setting`` [m/s], ``second`` (with ``vary``: its cell,
        unit and value), ``best`` (P(PASS) with its interval), ``reached``, ``files``,
        ``warnings``.

    Raises
    ------
    AirgunXlError
        Bad input, named; nothing is written or recorded.
    """
    from pathlib import Path

    from .app.declared import EventFields
    from .app.next_shot import NextRequest, run
    from .app.specifying import keyword_fields

    fields = keyword_fields("next", dict(spec), accel_unit)
    return run(NextRequest(
        Path(shot), os.fspath(recording), Path(archive), lot, fields, new_lot, _texts(sd),
        _number("--confidence", confidence), _whole("--shots", shots), _whole("--seed", seed),
        channel, _sign(sign), time_unit, accel_unit, integrator,
        Path(output) if output is not None else None, force, ("next",),
        None if vary is None else str(vary), None if scheduler is None else str(scheduler),
        None if workers is None else _whole("--workers", workers),
        None if chunk is None else _whole("--chunk", chunk),
        None if pdf is None else _path("--pdf", pdf), None if gun is None else str(gun),
        _texts(step), **_event(EventFields.given(event=event, at=at))))


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
    "calibrate",
    "campaign",
    "check",
    "compare",
    "compare_measured",
    "convergence",
    "design",
    "diff",
    "fill",
    "history",
    "load",
    "next_shot",
    "recording",
    "serve",
    "show",
    "srs",
    "sweep",
    "template",
]
