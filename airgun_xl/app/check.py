"""Check: can this shot's run be trusted? The scheme's critical time step, and what the shot
stretches (the crush-factor range, the filter, the row count, the masses); no run, no output.

:func:`run` takes a :class:`CheckRequest` and returns a :class:`CheckOutcome`; the CLI
(``airgun-xl check``) is this."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class CheckRequest:
    shot: Path
    integrator: str = "legacy"


@dataclass(frozen=True)
class CheckOutcome:
    """The critical time steps (engine.stability's Critical: ``dt_crit`` [s], ``ratio``,
    ``verdict``, the unloading's), the findings, the shot's warnings, and the mitigator's
    lengths [m] the unloading's steps are taken at."""

    params: Any  # the shot's ShotParams
    critical: Any
    findings: tuple[Any, ...]
    warnings: tuple[str, ...]
    full_length: float  # [m]
    compacted_length: float  # [m]

    @property
    def stable(self) -> bool:
        """The time step is not above the critical step of the OBR chain."""
        return not self.critical.ratio > 1


def run(request: CheckRequest) -> CheckOutcome:
    """Check the shot at ``request.shot``.

    Raises
    ------
    airgun_xl.errors.AirgunXlError
        A bad workbook or cell, named.
    """
    from ..engine.stability import compacted_length, full_length
    from ..shot import Shot
    from ..studies.check import before_run

    shot = Shot.from_workbook(request.shot)
    p = shot.params
    critical, findings = before_run(p, request.integrator)
    return CheckOutcome(p, critical, tuple(findings), tuple(str(w) for w in shot.warnings),
                        full_length(p), compacted_length(p))
