"""Check: can this shot's run be trusted? The scheme's critical time step, and what the shot
stretches (the crush-factor range, the filter, the row count, the masses); no run, no output.

:func:`run` takes a :class:`CheckRequest` and returns a :class:`CheckOutcome`; the CLI
(``airgun-xl check``) is this."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import declared


@dataclass(frozen=True, kw_only=True)
class CheckRequest(declared.Checked):
    """The shot and the scheme whose critical step is predicted. Declared once
    (:mod:`.declared`): the command's options and the API's keywords."""

    shot: Path = declared.shot("workbook in the report's layout")
    integrator: str = declared.integrator()


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

    def lines(self, shown: str, integrator: str) -> list[str]:
        """What ``check`` prints of the shot ``shown``."""
        p, crit = self.params, self.critical
        lines = [
            f"{shown}: {p.model}, {integrator} integrator",
            f"  time step E2 = {p.delta:.4g} s, critical {crit.dt_crit:.4g} s for the OBR chain "
            f"(the springs that always act), ratio {crit.ratio:.3g}: {crit.verdict}",
            f"  set by {crit.limiting}",
            f"  while the mitigator unloads: critical {crit.dt_unloading:.4g} s at full length "
            f"{self.full_length:.4g} m, {crit.dt_compacted:.4g} s fully compacted (length "
            f"{self.compacted_length:.4g} m, E37 = {p.ec:g})"]
        if crit.unstable_crush is not None:
            lines.append(f"  unstable while unloading once crushed by {crit.unstable_crush:.4g} "
                         f"m (length below {crit.unstable_length:.4g} m): the run is watched "
                         "and stops where it diverges")
        lines += [f"  warning: {message}" for message in self.warnings]
        lines += [f"  {f.level}: {f}" for f in self.findings]
        return lines

    def to_json(self) -> str:
        """The outcome as one JSON document (``check --json``): the critical time steps [s]
        and their ratio, what sets them, whether the step is stable, the mitigator's lengths
        [m], every finding with its level, and the shot's warnings."""
        from .documents import dumps

        crit = self.critical
        return dumps({
            "stable": self.stable, "time_step_s": self.params.delta,
            "critical_time_step_s": crit.dt_crit, "ratio": crit.ratio,
            "verdict": crit.verdict, "limiting": crit.limiting,
            "critical_unloading_s": crit.dt_unloading,
            "critical_compacted_s": crit.dt_compacted,
            "unstable_crush_m": crit.unstable_crush,
            "full_length_m": self.full_length, "compacted_length_m": self.compacted_length,
            "findings": [{"level": f.level, "text": str(f)} for f in self.findings],
            "warnings": self.warnings})


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
