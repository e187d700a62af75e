"""SRS: the shock response spectrum (maximax, Smallwood's ramp-invariant filter) of the
shot's predicted pulse, as a table and a log-log chart.

:func:`run` takes an :class:`SrsRequest` and returns an :class:`SrsOutcome`; the CLI
(``airgun-xl srs``) and the Python API (:func:`airgun_xl.srs`) are both this."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import OptionError


@dataclass(frozen=True)
class SrsRequest:
    """The shot, the spectrum's band [Hz] and quality factor [-], the filter the pulse goes
    through first (a J211 class, None for none). ``output`` None writes no workbook (the CLI
    gives its default, ``SHOT.srs.xlsx``)."""

    shot: Path
    q: float = 10.0
    cfc: int | None = None
    lo: float = 100.0  # [Hz]
    hi: float = 10_000.0  # [Hz]
    integrator: str = "legacy"
    model: str = "4-mass"
    output: Path | None = None
    force: bool = False
    crush_law: str = "workbook"
    archive: Path | None = None  # where a library law is read from


@dataclass(frozen=True)
class SrsOutcome:
    """The spectrum, the warnings a fill of the shot gives, and the files written."""

    frequencies: np.ndarray  # [Hz], 1/12-octave
    levels: np.ndarray  # [kG], maximax absolute acceleration
    q: float
    output: Path | None
    files: tuple[Path, ...]
    warnings: tuple[str, ...]

    def to_json(self) -> str:
        """The outcome as one JSON document (``srs --json``)."""
        from .documents import dumps

        level, frequency = self.largest
        return dumps({"q": self.q, "frequencies_Hz": self.frequencies,
                      "levels_kG": self.levels,
                      "largest": {"level_kG": level, "frequency_Hz": frequency},
                      "warnings": self.warnings, "files": self.files})

    @property
    def largest(self) -> tuple[float, float]:
        """(level [kG], frequency [Hz]) of the spectrum's largest level."""
        k = int(np.argmax(self.levels))
        return float(self.levels[k]), float(self.frequencies[k])


def run(request: SrsRequest) -> SrsOutcome:
    """The spectrum of the shot's predicted pulse.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        Bad input, named; nothing is written.
    """
    from ..archive.laws import shot_with_law
    from ..models import apply_model
    from ..specification import parse_q
    from ..studies.check import after_run, before_run
    from ..studies.shock import cfc_filter, default_frequencies, srs
    from ..transaction import check_output

    q = parse_q(str(request.q), "--srs-q")  # the one grammar, whoever gave it
    if not (0 < request.lo < request.hi < float("inf")):
        raise OptionError(f"--from/--to: found {request.lo:g} and {request.hi:g} Hz, expected "
                          "0 < FROM < TO")
    shot = shot_with_law(request.shot, request.crush_law, request.archive)
    if request.output is not None:  # before the run, not after
        check_output(request.output, request.force, inputs=[request.shot])
    model_params = apply_model(shot.params, request.model)
    _, findings = before_run(model_params, request.integrator)
    result = dataclasses.replace(shot, params=model_params).run(integrator=request.integrator,
                                                                track=())
    # the warnings a fill of the shot gives, with the spectrum of its run (Summary-like),
    # each once (the checks and the run say a fractional 1/(E2*E34) in the same words)
    warnings = list(dict.fromkeys(
        [str(w) for w in shot.warnings] + [str(f) for f in findings if f.level != "note"]
        + [str(w) for w in result.warnings[len(shot.warnings):]]
        + [str(f) for f in after_run(result)]))
    pulse = result.accel_kg[np.isfinite(result.accel_kg)]
    dt = shot.params.delta
    if request.cfc is not None:
        pulse = cfc_filter(pulse, dt, request.cfc)
    freqs = default_frequencies(request.lo, request.hi)
    spectrum = srs(pulse, dt, freqs, q)
    if request.output is not None:
        from ..reports.srs import write_srs

        about = [("Shot", str(request.shot)), ("Quality factor Q", f"{q:g}"),
                 ("Filter", f"CFC {request.cfc}" if request.cfc else "none"),
                 ("Model, integrator", f"{request.model}, {request.integrator}")]
        write_srs(request.output, freqs, spectrum, about, request.force,
                  shot=Path(request.shot).name, warnings=warnings)
    files = (request.output,) if request.output is not None else ()
    return SrsOutcome(freqs, spectrum, q, request.output, files, tuple(warnings))


def lines(request: SrsRequest, outcome: SrsOutcome) -> list[str]:
    """What ``srs`` prints: the workbook, the band, Q and the largest level."""
    level, frequency = outcome.largest
    return [f"wrote {outcome.output}: SRS at {len(outcome.frequencies)} frequencies, "
            f"{request.lo:g}-{request.hi:g} Hz, Q = {outcome.q:g}; largest {level:.4f} kG at "
            f"{frequency:,.0f} Hz"]
