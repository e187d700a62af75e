"""Calibrate: the model fitted to the shots that were fired. The crush-factor law recovered
(the report's iteration, then least squares), and/or E40, E43 or the law's scale fitted; the
calibrated workbook written (a Crush law sheet fill runs) and, when trusted, the law kept in
an archive's library by name.

:func:`run` takes a :class:`CalibrateRequest` and returns a :class:`CalibrateOutcome`; the
CLI (``airgun-xl calibrate``) and the Python API (:func:`airgun_xl.calibrate`) are both
this."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import OptionError


@dataclass(frozen=True)
class CalibrateRequest:
    """The shots fired and their recordings, what to fit, and where the result goes.
    ``fit`` names least-squares fits (``"E40,E43"``; E40, E43, scale); the law is recovered
    with ``law`` or when nothing is named. ``output`` None writes no workbook (the CLI gives
    its default, ``SHOT.calibrated.xlsx``); ``name`` keeps a trusted law in ``archive``'s
    library (else $AIRGUN_XL_ARCHIVE's)."""

    pairs: tuple[tuple[str, str], ...]  # (SHOT.xlsx, RECORDING)
    law: bool = False
    fit: str | None = None
    objective: str = "l2"  # or "iso18571"
    degree: int = 6  # of the law's polynomial, 1-6
    cfc: int | None = None  # the J211 class both pulses are filtered through
    sign: float = 1.0
    time_unit: str | None = None
    accel_unit: str | None = None
    channel: str | None = None
    anti_alias: str | float = "auto"  # the recorder's filter modelled [Hz], auto or none
    integrator: str = "legacy"
    output: Path | None = None
    force: bool = False
    archive: Path | None = None
    name: str | None = None
    argv: tuple[str, ...] = ()  # the command, as the law's record keeps it
    event: int | None = None  # of each recording of several shocks, the one judged (from 1)
    at: float | None = None  # [s] or the one at this instant of each recording


@dataclass(frozen=True)
class CalibrateOutcome:
    """The calibration (studies.calibrate.Calibration: the fitted values, their errors, the
    law and its intervals, the scores before and after), whether it can be vouched for,
    where the law was kept, and the files written."""

    calibration: Any
    stored: str | None  # the law's reference in the archive (NAME@N), if kept
    archive: Path | None
    output: Path | None
    files: tuple[Path, ...]

    @property
    def archive_shown(self) -> str | None:
        """The archive as messages show it (relative to the working folder where inside)."""
        from ..transaction import display

        return None if self.archive is None else str(display(self.archive))

    @property
    def trusted(self) -> bool:
        """Every fitted value identified and within its bounds, every residual improved."""
        return not self.calibration.warnings

    @property
    def warnings(self) -> tuple[str, ...]:
        """Why it cannot be vouched for (the shots' own warnings first)."""
        return tuple(self.calibration.warnings)

    def to_json(self) -> str:
        """The outcome as one JSON document (``calibrate --json``): trusted or not and why,
        the fitted values (E40 [Pa], E43 [-], scale [-]) with their standard errors and
        bounds, the law's 95 % intervals at its nodes [m/s], each shot's RMS error and
        ISO/TS 18571 rating before and after, and the law's reference if kept."""
        from .documents import dumps

        cal = self.calibration
        law = cal.params[0].crush_law
        return dumps({"trusted": self.trusted, "fitted": cal.fitted, "start": cal.start,
                      "standard_errors": cal.errors, "bounds": cal.bounds,
                      "law": None if cal.law_calibration is None else {
                          "coefficients": law.coefficients, "v_range_m_s": law.v_range,
                          "converged": cal.law_calibration.converged,
                          "intervals": cal.law_intervals},
                      "scores": [{"before": b, "after": a}
                                 for b, a in zip(cal.before, cal.after, strict=True)],
                      "runs": cal.runs, "seconds": cal.seconds, "notes": cal.notes,
                      "warnings": self.warnings, "stored": self.stored,
                      "files": self.files})

    @property
    def fitted(self) -> dict[str, float]:
        """{name: value} fitted by least squares (E40 [Pa], E43 [-], scale [-])."""
        return dict(self.calibration.fitted)


def _checked(request: CalibrateRequest) -> tuple[list[str], bool]:
    """The fits named, and whether a law is fitted; refused before any run."""
    from ..studies.calibrate import check_fit
    from ..studies.shock import CFC_CLASSES, cfc_coefficients

    if not request.pairs:
        raise OptionError("calibrate: found 0 files, expected pairs of SHOT.xlsx RECORDING")
    if request.sign not in (1.0, -1.0):
        raise OptionError(f"--sign: found {request.sign!r}, expected 1 or -1")
    if request.cfc is not None and request.cfc not in CFC_CLASSES:
        cfc_coefficients(request.cfc, 1.0)  # its one-line error, before any run
    if not 1 <= request.degree <= 6:
        raise OptionError(f"--degree: found {request.degree}, expected 1 to 6 (Eq. 8 is of "
                          "degree 6)")
    names = [n.strip() for n in (request.fit or "").split(",") if n.strip()]
    if request.fit is not None:
        names = check_fit(names, request.objective)
    return names, request.law or not names


def _law_library(request: CalibrateRequest, fits_a_law: bool) -> Path | None:
    """The archive the law goes to (``name``), checked before any run; None without it."""
    from ..archive import Archive, archive_dir, safe_name

    name = request.name
    if name is None:
        if request.archive is not None:
            raise OptionError("--archive: found without --name, expected --name NAME for the "
                              "law's name in the archive's library")
        return None
    if not fits_a_law:
        raise OptionError("--name: found with --fit of no law, expected a law to keep (the "
                          "default, --law, or --fit scale)")
    if not name or safe_name(name) != name or name.lower() in ("workbook", "legacy"):
        raise OptionError(f"--name: found {name!r}, expected a law name of letters, "
                          "digits, '-', '_' and '.' (such as LOT-2026-07), not workbook or "
                          "legacy")
    root = archive_dir(request.archive)
    Archive(root, create=True, dry_run=True)  # a foreign folder is refused now
    return Path(root)


def run(request: CalibrateRequest) -> CalibrateOutcome:
    """Calibrate on ``request.pairs``.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written.
    """
    from ..readers.recording import input_file, read_trace
    from ..shot import Shot
    from ..studies.calibrate import calibrate
    from ..transaction import check_output

    names, law = _checked(request)
    root = _law_library(request, law or "scale" in names)
    if request.output is not None:
        check_output(request.output, request.force,
                     inputs=[input_file(f) for pair in request.pairs for f in pair])
    shots = [Shot.from_workbook(s) for s, _ in request.pairs]
    traces = [read_trace(m, request.time_unit, request.accel_unit, request.sign,
                         request.channel, request.event, request.at) for _, m in request.pairs]
    cal = calibrate([s.params for s in shots], traces, law=law, fit=names, cfc=request.cfc,
                    degree=request.degree, objective=request.objective,
                    integrator=request.integrator, anti_alias=request.anti_alias)
    cal.warnings[:0] = [w for s in shots for w in s.warnings]
    if request.output is not None:
        from ..reports.calibration import write_calibration

        write_calibration(request.output, shots[0], cal, list(request.pairs), request,
                          request.force)
    stored = None
    if root is not None and not cal.warnings:  # only a trusted law is kept
        stored = _store(request, root, cal)
    files = (request.output,) if request.output is not None else ()
    return CalibrateOutcome(cal, stored, root, request.output, files)


def _store(request: CalibrateRequest, root: Path, cal: Any) -> str:
    """The law into the archive's library: its reference (NAME@N)."""
    from ..archive.laws import store_law
    from ..transaction import display

    def plain(value: float) -> float | None:
        return None if math.isnan(value) else value  # NaN (too short a pulse): null

    shots_record = [{"workbook": display(w), "recording": display(m), "v0": p.v31}
                    for (w, m), p in zip(request.pairs, cal.params, strict=True)]
    scores = [{"rms_before": b.rms, "rms_after": a.rms, "iso_before": plain(b.iso),
               "iso_after": plain(a.iso)}
              for b, a in zip(cal.before, cal.after, strict=True)]
    intervals = [n.record() for n in cal.law_intervals]
    assert request.name is not None
    return str(store_law(root, request.name, cal.params[0].crush_law, shots_record, scores,
                         [display(a) for a in request.argv], intervals))


#: The exit status of a calibration that was written but cannot be vouched for (a value at a
#: bound or not identified, a law not converged, a residual made worse): its warnings say why.
UNTRUSTED = 3


def lines(request: CalibrateRequest, outcome: CalibrateOutcome) -> list[str]:
    """What ``calibrate`` prints: the workbook, the law recovered (its nodes' intervals), each
    value fitted with its interval, each shot's residual before and after, the verdict, where
    the law was stored."""
    cal, output, n = outcome.calibration, outcome.output, len(outcome.calibration.before)
    said = [f"wrote {output}: calibrated on {n} shot{'s' * (n > 1)} "
            f"({cal.runs} runs, {cal.seconds:.2f} s)", *_law_lines(cal)]
    for name, value in cal.fitted.items():
        error = cal.errors[name]
        said.append(f"  {name}: {cal.start[name]:.6g} -> {value:.6g} +/- {error:.3g} "
                    f"(1 standard error; 95 %: {value - 1.96 * error:.6g} to "
                    f"{value + 1.96 * error:.6g})")
    for i, (before, after) in enumerate(zip(cal.before, cal.after, strict=True), start=1):
        said.append(f"  shot {i}: RMS error {before.rms:.2%} -> {after.rms:.2%}; "
                    f"ISO/TS 18571 {before.iso:.3f} -> {after.iso:.3f}")
    said += [f"  note: {text}" for text in cal.notes]
    if not outcome.trusted:
        return said + [f"  verdict: NOT TRUSTED ({len(cal.warnings)} warning"
                       f"{'s' * (len(cal.warnings) > 1)}, also in {output}); exit {UNTRUSTED}"]
    said.append("  verdict: every fitted value identified, within its bounds, and every "
                "shot's residual improved")
    if outcome.stored is not None:
        root = outcome.archive_shown
        said.append(f"  stored the law as {outcome.stored} in {root} (fill --crush-law "
                    f"{request.name} --archive {root})")
    return said


def _law_lines(cal: Any) -> list[str]:
    """The law recovered: its convergence, range and intervals at its nodes."""
    if cal.law_calibration is None:
        return []
    lc = cal.law_calibration
    lo, hi = cal.params[0].crush_law.v_range
    said = [f"  crush law: {'converged' if lc.converged else 'NOT converged'} in "
            f"{len(lc.iterations)} iterations (last change {lc.iterations[-1].change:.2%}), "
            f"then least squares; valid {lo:.1f} to {hi:.1f} m/s (the samples' span)",
            "  crush law at its nodes, 95 % intervals (noise, baselines and alignment; not "
            "model error):"]
    for node in cal.law_intervals:
        line = (f"    {node.velocity:6.1f} m/s: {node.value:.4f} ({node.low:.4f} to "
                f"{node.high:.4f}, +/- {node.half_width:.1%})")
        if node.weak:
            line += f" WEAKLY PINNED by {node.pinned_by() or 'no shot in particular'}"
            if node.suggested is not None:
                line += f"; a shot at about {node.suggested:.0f} m/s would pin it best"
        said.append(line)
    return said
