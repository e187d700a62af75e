"""SRS: the shock response spectrum (maximax, Smallwood's ramp-invariant filter) of the
shot's predicted pulse, as a table and a log-log chart.

:func:`run` takes an :class:`SrsRequest` and returns an :class:`SrsOutcome`; the CLI
(``airgun-xl srs``) and the Python API (:func:`airgun_xl.srs`) are both this."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import OptionError
from . import declared

if TYPE_CHECKING:  # numpy loads with the run, not with the command's parser (its request)
    import numpy as np


@dataclass(frozen=True, kw_only=True)
class SrsRequest(declared.Checked):
    """The shot, the spectrum's band [Hz] and quality factor [-], the filter the pulse goes
    through first (a J211 class, None for none). ``output`` None writes no workbook (the CLI
    gives its default, ``SHOT.srs.xlsx``). Declared once (:mod:`.declared`): the command's
    options, in this order, and the API's keywords."""

    shot: Path = declared.shot()
    output: Path | None = declared.output("the SRS workbook", "SHOT.srs.xlsx")
    force: bool = declared.force()
    q: float = declared.option(10.0, "--srs-q", metavar="Q", read=declared.a_quality_factor,
                               help="quality factor (default 10: 5 %% damping)",
                               aliases=(("--q", "SRS quality factor"),))
    cfc: int | None = declared.option(None, "--cfc", metavar="N|none", kind="cfc",
                                      read=declared.a_cfc,
                                      help="filter the pulse first: SAE J211 class 60, 180, "
                                           "600 or 1000, or none (the default)")
    lo: float = declared.option(100.0, "--from", metavar="HZ", read=declared.a_number,
                                help="lowest natural frequency (default 100)")  # [Hz]
    hi: float = declared.option(10_000.0, "--to", metavar="HZ", read=declared.a_number,
                                help="highest natural frequency (default 10000)")  # [Hz]
    integrator: str = declared.integrator()
    model: str = declared.model()
    crush_law: str = declared.crush_law()
    archive: Path | None = declared.archive()  # where a library law is read from

    def __post_init__(self) -> None:
        super().__post_init__()
        if not (0 < self.lo < self.hi < float("inf")):
            raise OptionError(f"lo/hi: found {self.lo:g} and {self.hi:g} Hz, expected "
                              "0 < FROM < TO")


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
        import numpy as np

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
    from ..studies.check import after_run, before_run
    from ..studies.shock import cfc_filter, default_frequencies, srs
    from ..transaction import check_output

    q = request.q  # read by the one grammar when the request was made
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
    import numpy as np

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
