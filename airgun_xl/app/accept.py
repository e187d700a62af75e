"""Accept: did the fired shot meet its specification? The recording read (its quality
assessed before it is judged), judged criterion by criterion, the verdict workbook written
and the verdict archived.

:func:`run` takes an :class:`AcceptRequest` and returns an :class:`AcceptOutcome`; the CLI
(``airgun-xl accept``) and the Python API (:func:`airgun_xl.accept`) are both this."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import OptionError
from .specifying import SpecFields, require, resolve

if TYPE_CHECKING:
    from ..shot import Shot
    from ..specification import Specification
    from ..studies.acceptance import Criterion, Verdict


@dataclass(frozen=True)
class AcceptRequest:
    """What to judge, and what to write.

    ``output`` None writes no workbook (the CLI gives its default, ``SHOT.accept.xlsx``);
    ``archive`` keeps the verdict in that archive, naming the workbook (so needs one).
    ``sign`` is 1 or -1 [-]; the units, where given, override the recording's header.
    ``crush_law`` is the law the shot's prediction runs (what the recording is expected to
    show): a library law is read from ``archive`` (else $AIRGUN_XL_ARCHIVE)."""

    shot: Path
    recording: str
    spec: SpecFields = field(default_factory=SpecFields)
    output: Path | None = None
    force: bool = False
    archive: Path | None = None
    channel: str | None = None
    sign: float = 1.0
    time_unit: str | None = None
    accel_unit: str | None = None
    argv: tuple[str, ...] = ()  # the command, as the archive records it
    crush_law: str = "workbook"  # workbook, legacy or NAME[@N] of the archive's library
    pdf: Path | None = None  # the client's test report, as a PDF
    reproducible: bool = False  # the PDF without a date: the same run, the same bytes
    event: int | None = None  # of a recording of several shocks, the one judged (from 1)
    at: float | None = None  # [s] or the one at this instant of the recording
    test: Any = None  # declared.ReportFields: the test's fields over the sheet's Test block


@dataclass(frozen=True)
class AcceptOutcome:
    """The verdict, and everything the command wrote and said."""

    verdict: Verdict
    shot: Path
    recording: str  # the recording's name, as read (a TDMS file's channel included)
    output: Path | None  # the verdict workbook, if one was written
    archived: Path | None  # the verdict's archive record, if kept
    equivalent_half_sine: tuple[float, float]  # (peak [kG], duration [s]) whose SRS envelops
    peak_pseudo_velocity: float  # [m/s], the record's SRS's highest
    files: tuple[Path, ...]  # every file written
    record: dict[str, Any]  # the verdict as the archive keeps it (archive/verdicts.py)

    @property
    def passed(self) -> bool:
        """True when every criterion passed."""
        return self.verdict.passed

    @property
    def word(self) -> str:
        """``PASS`` or ``FAIL``."""
        return self.verdict.word

    @property
    def criteria(self) -> list[Criterion]:
        """The criteria judged, a line each."""
        return self.verdict.criteria

    @property
    def warnings(self) -> tuple[str, ...]:
        """Every warning the verdict carries (read them before relying on it)."""
        return tuple(self.verdict.warnings)

    def to_json(self) -> str:
        """The outcome as one JSON document (``accept --json``, for a LIMS): the archive's
        record of the verdict (criteria with value, limits and margin in their unit, the
        tolerances, definitions, warnings, the workbook's SHA-256, the recording and what it
        said of itself; not the trace of the record judged, which the archive keeps to draw
        it), the equivalent half-sine, and the files written. A value that is not finite is
        null; the text is ASCII, a file's control characters escaped (never sent to a
        terminal)."""
        def finite(value: float) -> float | None:
            return value if math.isfinite(value) else None

        peak, duration = self.equivalent_half_sine
        document = {**{k: v for k, v in self.record.items() if k != "trace"},
                    "passed": self.passed,
                    "equivalent_half_sine": {"peak_kG": finite(peak),
                                             "duration_s": finite(duration)},
                    "peak_pseudo_velocity_m_s": finite(self.peak_pseudo_velocity),
                    "archived": str(self.archived) if self.archived is not None else None,
                    "files": [str(p) for p in self.files]}
        return json.dumps(document, indent=1, allow_nan=False)


def verdict_lines(verdict: Verdict, what: str) -> list[str]:
    """The verdict as the command says it: its word (and how many warnings), a line a
    criterion with the tolerances used, the definitions, a profile's notes. What files gave
    (a profile's notes, names) is made printable text, never control codes."""
    from ..studies.acceptance import limits_text
    from ..untrusted_json import printable

    n = len(verdict.warnings)
    lines = [f"{verdict.word}: {what}" + (
        f" (with {n} warning{'s' * (n != 1)}: read them before relying on it)" if n else "")]
    for c in verdict.criteria:
        margin = f"{c.margin:+.2f} {c.margin_unit}"
        u = f" ± {c.expanded:.2g}" if math.isfinite(c.expanded) else ""
        lines.append(f"  {c.word}  {c.name}: {c.value:.5g}{u} {c.unit} "
                     f"(limits {limits_text(c)}; margin {margin})"
                     + (f"; {c.detail}" if c.detail else ""))
    lines += [f"  {line}" for line in verdict.definitions]
    lines += [f"  note: {line}" for line in verdict.spec.notes]  # a profile's caveats
    return [printable(line) for line in lines]


def run(request: AcceptRequest) -> AcceptOutcome:
    """Judge ``request.recording`` against the shot's specification.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input (a file, a field, an option), named; nothing is written.
    """
    from ..archive.laws import shot_with_law
    from ..archive.verdicts import verdict_record
    from ..identification import Identification
    from ..readers.recording import input_file, read_trace
    from ..studies.acceptance import apply_decision_rule, expectations, judge_record
    from ..studies.measured import prepare
    from ..studies.shock import check_cfc
    from ..transaction import check_output

    if request.sign not in (1.0, -1.0):
        raise OptionError(f"--sign: found {request.sign!r}, expected 1 or -1")
    if request.output is not None:
        check_output(request.output, request.force,
                     inputs=[request.shot, input_file(request.recording)])
    if request.pdf is not None:
        from ..reports.pdf_report import check_pdf

        check_pdf(request.pdf, request.force, [request.shot, input_file(request.recording)],
                  beside=request.output)
    if request.archive is not None:  # a folder that is not an archive: refused before work
        if request.output is None:
            raise OptionError("--archive: found no verdict workbook to name, expected an "
                              "output too")
        from ..archive import Archive

        Archive(request.archive, create=True, dry_run=True)
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    spec = require(resolve(shot, request.spec), request.shot)
    cfc = spec.judged.cfc  # --cfc is the specification's record field, over the sheet's
    trace = read_trace(request.recording, request.time_unit, request.accel_unit, request.sign,
                       request.channel, request.event, request.at)
    filtering = check_cfc(cfc, trace.dt) if cfc else []
    expected, notes = expectations(shot, spec)
    # zeroed and its quality read; the record judged is made below
    rec = prepare(trace, None, anti_alias="none", flat_top=spec.shape == "trapezoid",
                  expected=expected,
                  nominal_duration=spec.duration.nominal if spec.duration else None)
    verdict = judge_record(rec.trace.time, rec.corrected, spec, trace.name,
                           noise=rec.base.noise,
                           warnings=shot.warnings + filtering + rec.warnings,
                           quality=rec.quality)
    verdict.definitions += notes
    apply_decision_rule(verdict, request.test.decision_rule if request.test else "simple")
    test = Identification.merged(shot.test, request.test.fields() if request.test else {})
    verdict.test, verdict.definitions = test.given(), verdict.definitions + list(test.notes)
    assert verdict.record is not None
    time, kg = verdict.record
    pulse, spectra = report_data(time, kg, spec, verdict)
    archived = None
    if request.output is not None or request.pdf is not None:
        archived = _write(request, shot, verdict, trace, rec, pulse, spectra)
    eq = spectra["equivalent"]
    files = tuple(p for p in (archived, request.output, request.pdf) if p is not None)
    record = verdict_record(verdict, shot, request.recording,
                            request.output if request.output is not None else "", request.argv)
    return AcceptOutcome(verdict, Path(request.shot), trace.name, request.output, archived,
                         (float(eq[0]), float(eq[1])), float(np.max(spectra["pv"])), files,
                         record)


def _about(request: AcceptRequest, shot: Shot, verdict: Verdict, trace: Any, rec: Any
           ) -> list[
        tuple[str, str]]:
    """What the verdict's pages say of the test (its identification, every field, a blank
    line where none was given; the gun's setting), the shot and the recording read."""
    from ..cells import address
    from ..identification import Identification

    return [*Identification(verdict.test).rows(),
            ("Gun setting", f"{address('v31')} = {float(shot.params.v31):.6g} m/s"),
            ("Shot", str(request.shot)), ("Recording", trace.name),
            ("Units read", f"time {trace.units[0]}, acceleration {trace.units[1]}"),
            ("Record judged", verdict.definitions[0].removeprefix("record judged: ")),
            ("Baseline", rec.base.words()), ("Verdict", verdict.word)]


def _write_pdf(request: AcceptRequest, shot: Shot, verdict: Verdict, trace: Any, rec: Any,
               pulse: dict[str, Any], spectra: dict[str, Any], path: Path) -> None:
    """The client's test report (``--pdf``), written at ``path`` (a staged temp file)."""
    from ..reports.pdf_report import write_verdict_pdf
    from ..untrusted_json import printable

    about = [(label, printable(text))
             for label, text in _about(request, shot, verdict, trace, rec)]
    heading = (printable(Path(request.shot).name), printable(Path(trace.name).name),
               printable(verdict.spec.source or "options"))  # the names: a page's width
    write_verdict_pdf(path, verdict, about, pulse, spectra,
                      [printable(w) for w in verdict.warnings], heading, request.reproducible)


def _write(request: AcceptRequest, shot: Shot, verdict: Verdict, trace: Any, rec: Any,
           pulse: dict[str, Any], spectra: dict[str, Any]) -> Path | None:
    """The verdict's record first (if asked), then the workbook and the PDF staged and
    published together: a failure or a signal leaves none of them (the record taken back,
    the archive too if this made it), and ``--force`` replaces both or neither. The
    record's path."""
    from ..reports.acceptance import write_acceptance
    from ..transaction import Publication, commit_after, for_file, signals_held

    stored = None
    pub = later = Publication(request.force)
    try:
        with pub:
            if request.output is not None:
                if request.archive is not None:
                    from ..archive.verdicts import store_verdict

                    with signals_held():  # a signal comes once the record is whole
                        stored = store_verdict(request.archive, shot, verdict,
                                               request.recording, request.output,
                                               request.argv)
                write_acceptance(request.output, verdict,
                                 _about(request, shot, verdict, trace, rec), pulse, spectra,
                                 request.force, shot=Path(request.shot).name, publication=pub)
            if request.pdf is not None:  # in another folder: published after the workbook
                later = for_file(pub, request.pdf, request.force)
                _write_pdf(request, shot, verdict, trace, rec, pulse, spectra,
                           later.stage(request.pdf))
            pub.commit()
    except BaseException:
        if later is not pub:  # pub aborted itself on leaving its block
            later.abort()
        if stored is not None:
            stored.take_back()
        raise
    commit_after(pub, later)
    return stored.path if stored is not None else None


def report_data(time: np.ndarray, kg: np.ndarray, spec: Specification,
                verdict: Verdict) -> tuple[dict[str, Any], dict[str, Any]]:
    """The pulse with its corridor, and the spectra, for the verdict workbook: time [s],
    acceleration [kG], frequencies [Hz], SRS levels [kG], pseudo-velocity [m/s]."""
    from ..studies.acceptance import (
        corridor_limits,
        equivalent_half_sine,
        ideal,
        pseudo_velocity,
    )
    from ..studies.shock import decimated_for, default_frequencies, srs

    pulse: dict[str, Any] = {"time": time, "kg": kg}
    if spec.corridor is not None and verdict.onset is not None:
        assert spec.peak is not None and spec.duration is not None and verdict.window
        tau = time - verdict.onset
        upper, lower = corridor_limits(spec, tau)
        lo, hi = verdict.window
        inside = (time >= lo) & (time <= hi)
        pulse["ideal"] = ideal(spec.shape, tau, spec.peak.nominal, spec.duration.nominal)
        pulse["upper"] = np.where(inside, upper, np.nan)
        pulse["lower"] = np.where(inside, lower, np.nan)
    dt = time[1] - time[0]
    q = spec.srs_q if spec.srs is not None and spec.srs_q is not None else 10.0
    top = 0.1 / dt  # the SRS's highest frequency at this rate
    if spec.srs is not None:  # the requirement's band on a 1/12-octave grid, and its rows
        required_f = np.array(spec.srs.frequencies)
        lo, hi = required_f.min(), min(required_f.max(), top)
        grid = default_frequencies(lo, hi) if hi > lo else np.array([lo])
        frequencies = np.unique(np.concatenate([grid, required_f[required_f <= top]]))
    else:  # 100 Hz to 10 kHz, or below a tenth of a slow record's rate
        hi = min(10_000.0, top)
        frequencies = default_frequencies(min(100.0, hi / 16), hi)
    # on the record decimated to what the frequencies need: a 1 GHz record's would take
    # minutes and gigabytes at its own step, for the same spectrum
    if verdict.srs_record is not None:  # the record the SRS criterion was computed on (at
        kg = np.asarray(verdict.srs_record[1], dtype=float)  # the same rate)
    spectral, step, factor = decimated_for(kg, dt, float(np.max(frequencies)))
    levels = srs(spectral, step, frequencies, q)
    spectra: dict[str, Any] = {
        "frequencies": frequencies, "srs": levels, "q": q,
        "pv": pseudo_velocity(frequencies, levels),
        "equivalent": equivalent_half_sine(step * np.arange(len(spectral)), spectral,
                                           frequencies, q),
        "step": (step, factor)}
    if spec.srs is not None:  # log-log between the requirement's rows
        assert spec.srs_lower_db is not None and spec.srs_upper_db is not None  # resolved
        required = np.exp(np.interp(np.log(frequencies), np.log(required_f),
                                    np.log(np.array(spec.srs.levels_kg))))
        spectra.update(required=required, lower=required * 10 ** (spec.srs_lower_db / 20),
                       upper=required * 10 ** (spec.srs_upper_db / 20))
    return pulse, spectra


def lines(request: AcceptRequest, outcome: AcceptOutcome) -> list[str]:
    """What ``accept`` prints: where the verdict was kept, the verdict (a line a criterion),
    the workbook, the equivalent half-sine and the pseudo-velocity."""
    said = [] if outcome.archived is None else [f"  archived the verdict as {outcome.archived}"]
    said += verdict_lines(outcome.verdict, f"{outcome.recording} against {request.shot}")
    peak, duration = outcome.equivalent_half_sine
    return said + [f"  wrote {outcome.output}",
                   f"  equivalent half-sine (its SRS envelops the record's): {peak:.4f} kG, "
                   f"{duration * 1e3:.4f} ms; pseudo-velocity up to "
                   f"{outcome.peak_pseudo_velocity:.3f} m/s"]
