"""Compare-measured: the shot's predicted pulse against a measured one, both filtered alike
(SAE J211), aligned at the impact and scored (peak, its time, the pulse, the velocity change,
their correlation, ISO/TS 18571).

:func:`run` takes a :class:`CompareMeasuredRequest` and returns a
:class:`CompareMeasuredOutcome`; the CLI (``airgun-xl compare-measured``) and the Python API
(:func:`airgun_xl.compare_measured`) are both this."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import declared

if TYPE_CHECKING:  # numpy loads with a comparison, not with the command's parser
    pass


@dataclass(frozen=True, kw_only=True)
class CompareMeasuredRequest(declared.Checked):
    """The shot and its recording, read as the options say; ``align`` ``threshold`` or
    ``xcorr``; ``anti_alias`` the recorder's filter modelled on the prediction [Hz], auto or
    none. ``output`` None writes no workbook (the CLI gives its default,
    ``SHOT.measured.xlsx``). Declared once (:mod:`.declared`): the command's options, in this
    order, and the API's keywords."""

    shot: Path = declared.shot()
    recording: str = declared.recording("the measured pulse: " + declared.RECORDING_HELP)
    output: Path | None = declared.output("scores and traces", "SHOT.measured.xlsx")
    force: bool = declared.force()
    channel: str | None = declared.channel()
    event: int | None = declared.event()
    at: float | None = declared.at()
    cfc: int | None = declared.cfc()
    sign: float = declared.sign()
    time_unit: str | None = declared.time_unit()
    accel_unit: str | None = declared.accel_unit()
    anti_alias: str | float = declared.anti_alias()
    align: str = declared.option(
        "threshold", "--align", kind="choice", choices=("threshold", "xcorr"),
        read=declared.one_of(("threshold", "xcorr")),
        help="impact instant: where the zeroed pulse first holds 5%% of its peak (or 5 sigma "
             "of its pre-trigger noise, if more) for 0.05 ms (default), or the "
             "cross-correlation's best lag; each checks the other")
    integrator: str = declared.integrator()
    model: str = declared.model()
    crush_law: str = declared.crush_law()
    archive: Path | None = declared.archive()  # where a library law is read from


@dataclass(frozen=True)
class CompareMeasuredOutcome:
    """The comparison (studies.measured.Comparison: both pulses' figures, their errors, the
    correlation, the ISO/TS 18571 rating, the baseline, the shift), the recording's name,
    units and the files written."""

    comparison: Any
    recording: str
    units: tuple[str, str]  # (time, acceleration) as read
    models: tuple[str, str]  # the model compared, and the other one shown beside it
    output: Path | None
    files: tuple[Path, ...]

    @property
    def warnings(self) -> tuple[str, ...]:
        return tuple(self.comparison.warnings)

    def to_json(self) -> str:
        """The outcome as one JSON document (``compare-measured --json``): both pulses'
        figures (peaks [kG], times [s], velocity change [m/s]), the prediction's errors
        against the test (predicted / measured - 1), the correlation, the ISO/TS 18571
        rating, the alignment's shift [s]."""
        from .documents import dumps

        c = self.comparison
        return dumps({"recording": self.recording, "units_read": self.units,
                      "models": self.models, "alignment": c.alignment, "shift_s": c.shift,
                      "predicted": c.predicted, "measured": c.measured,
                      "errors": c.errors, "correlation": c.correlation, "iso18571": c.iso,
                      "anti_alias_Hz": c.anti_alias, "warnings": self.warnings,
                      "files": self.files})


def run(request: CompareMeasuredRequest) -> CompareMeasuredOutcome:
    """The prediction against the recording.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written.
    """
    import numpy as np

    from ..archive.laws import shot_with_law
    from ..models import apply_model
    from ..readers.recording import input_file, read_trace
    from ..studies.check import after_run
    from ..studies.measured import ANTI_ALIAS_ORDER, compare
    from ..transaction import check_output

    if request.output is not None:
        check_output(request.output, request.force,
                     inputs=[request.shot, input_file(request.recording)])
    trace = read_trace(request.recording, request.time_unit, request.accel_unit,
                       request.sign, request.channel, request.event, request.at)
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    result = dataclasses.replace(shot, params=apply_model(shot.params, request.model)).run(
        integrator=request.integrator, track=())
    finite = np.isfinite(result.accel_kg)
    other = "rigid" if request.model == "4-mass" else "4-mass"
    rigid = dataclasses.replace(shot, params=apply_model(shot.params, other)).run(
        integrator=request.integrator, track=())
    ok = np.isfinite(rigid.accel_kg)
    c = compare(result.history.time[finite], result.accel_kg[finite], trace, request.cfc,
                request.align, rigid=(rigid.history.time[ok], rigid.accel_kg[ok]),
                anti_alias=request.anti_alias)
    c.warnings[:0] = shot.warnings + [str(f) for f in after_run(result)]
    if request.output is not None:
        from ..reports.measured import write_comparison

        about = [("Shot", str(request.shot)), ("Measured", trace.name),
                 ("Units read", f"time {trace.units[0]}, acceleration {trace.units[1]}"),
                 ("Filter", f"CFC {request.cfc}" if request.cfc else "none"),
                 ("Alignment", f"{request.align} (cross-checked against the other)"),
                 ("Anti-alias model", "none" if c.anti_alias is None else
                  f"{ANTI_ALIAS_ORDER}-pole Butterworth at {c.anti_alias:,.0f} Hz on the "
                  "prediction"),
                 ("Warnings", f"{len(c.warnings)} (below the scores)" if c.warnings
                  else "none")]
        write_comparison(request.output, c, about, request.force,
                         models=(request.model, other), shot=Path(request.shot).name)
    files = (request.output,) if request.output is not None else ()
    return CompareMeasuredOutcome(c, trace.name, tuple(trace.units), (request.model, other),
                                  request.output, files)


def lines(request: CompareMeasuredRequest, outcome: CompareMeasuredOutcome) -> list[str]:
    """What ``compare-measured`` prints: the alignment, each figure predicted against
    measured, the ISO/TS 18571 rating, the baseline and the recorder's filter."""
    c = outcome.comparison
    said = [f"wrote {outcome.output}: {outcome.recording} against {request.shot} "
            f"({len(c.time):,} samples, aligned by {request.align}, shift "
            f"{c.shift * 1e3:.4f} ms)",
            f"  peak {c.predicted.peak_kg:.4f} kG predicted, {c.measured.peak_kg:.4f} measured "
            f"({c.errors['peak_kg']:+.2%}); pulse {c.predicted.pulse_duration * 1e3:.4f} ms, "
            f"{c.measured.pulse_duration * 1e3:.4f} ({c.errors['pulse_duration']:+.2%})",
            f"  velocity change {c.predicted.delta_v:.3f} m/s, {c.measured.delta_v:.3f} "
            f"({c.errors['delta_v']:+.2%}); correlation r = {c.correlation:.4f}"]
    r = c.iso
    if r is not None:
        said.append(f"  ISO/TS 18571 rating {r.overall:.3f} ({r.grade}): corridor "
                    f"{r.corridor:.3f}, phase {r.phase:.3f}, magnitude {r.magnitude:.3f}, "
                    f"slope {r.slope:.3f}")
    said.append(f"  baseline: {c.baseline.words()}; impact at {c.level:.1%} of the peak; "
                "anti-alias model " + (f"{c.anti_alias:,.0f} Hz" if c.anti_alias else "none"))
    return said
