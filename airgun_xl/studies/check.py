"""Checks of a shot before and after its run: stability, and cases where the model is
stretched past what it was built for. Each finding names the cell that causes it."""
import math
from dataclasses import dataclass

from ..cells import BY_ADDRESS
from ..engine.stability import WARN_RATIO, critical_time_step, full_length

#: Bird masses differing by this factor or more make a stiff, badly scaled system.
MASS_RATIO_WARNING = 1e6


@dataclass(frozen=True)
class Finding:
    """One result of a check: ``level`` is "error", "warning" or "note"."""

    level: str
    cell: str
    message: str

    def __str__(self):
        label = BY_ADDRESS[self.cell].label if self.cell in BY_ADDRESS else ""
        where = f"{self.cell} ({label})" if label else self.cell
        return f"{where}: {self.message}"


def _fmt(dt):
    return f"{dt:.3g} s"


def stability(p, integrator="legacy"):
    """The critical steps of the chosen scheme and its finding (None when comfortably stable).

    Newmark is implicit in the OBR chain; only the mitigator's unloading stiffness, which it
    treats explicitly, bounds its step. Two tiers (:mod:`airgun_xl.engine.stability`): an
    error above the step stable at the mitigator's full length; a warning, with the crush
    past which the step is unstable, between that and the fully compacted one.
    """
    crit = critical_time_step(p, chain=integrator == "legacy")
    safe = f"the largest safe time step is {_fmt(crit.dt_crit)}"
    if crit.ratio > 1:
        return crit, Finding("error", "E2", f"{_fmt(p.delta)} is {crit.ratio:.3g} x the "
                                            f"critical time step of the {integrator} scheme, "
                                            f"set by {crit.limiting}; {safe}")
    if crit.unstable_crush is not None:
        return crit, Finding("warning", "E2", unstable_crush_message(p, crit, integrator)
                             + "; the run stops if it crushes that far")
    if crit.ratio > WARN_RATIO:
        return crit, Finding("warning", "E2", f"{_fmt(p.delta)} is {crit.ratio:.2f} x the "
                                              f"critical time step ({_fmt(crit.dt_crit)}) of "
                                              f"the {integrator} scheme: close to unstable")
    return crit, None


def unstable_crush_message(p, crit, integrator="legacy"):
    """The second tier in words: how far the shot may crush before its step is unstable."""
    return (f"{_fmt(p.delta)} is stable for the {integrator} scheme until the mitigator is "
            f"crushed by {crit.unstable_crush:.4g} m (remaining length "
            f"{crit.unstable_length:.4g} m of E16 + E19 = {full_length(p):.4g} m): shorter, "
            "its unloading stiffness needs a step below "
            f"{_fmt(crit.dt_compacted)} (fully compacted)")


def crush_reached(result, crit, integrator="legacy"):
    """The error for a run whose largest crush passed the second tier's limit, or None."""
    stats = result.history.stats
    if crit.unstable_crush is None or stats is None or not (
            stats.max_crush > crit.unstable_crush):
        return None
    return Finding("error", "E2", unstable_crush_message(result.params, crit, integrator)
                   + f"; the run crushed it by {stats.max_crush:.4g} m, where the step is "
                   "unstable and its numbers are not to be trusted")


def impact_speed_finding(p):
    """The warning for an impact speed past the crush-factor fit, or None.

    (A bird slower than the MEM crushes nothing at first: no warning.)"""
    lo, hi = p.crush_law.v_range
    v_rel = p.v31 - p.v1
    if v_rel <= hi:
        return None
    return Finding("warning", "A28", f"the bird meets the MEM at {v_rel:.4g} m/s, outside "
                   f"{lo:g}..{hi:g} m/s where {_law_words(p)} holds: it is "
                   f"extrapolated there (crush factor {p.crush_law(v_rel):.3g})")


def _law_words(p):
    return ("the crush-factor polynomial (Eq. 8)" if p.crush_law.is_legacy else
            "the fitted crush law (Crush law sheet)")


def before_run(p, integrator="legacy"):
    """Findings that need no run. Returns (CriticalStep, list of Finding)."""
    crit, finding = stability(p, integrator)
    found = [finding] if finding else []
    speed = impact_speed_finding(p)
    if speed is not None:
        found.append(speed)
    if p.v1 == p.v31 == p.v32 == p.v33:
        found.append(Finding("note", "A28", f"all masses start at {p.v31:g} m/s: nothing "
                             "crushes the mitigator, the response is free flight"))
    steps = p.max_time / p.delta
    if abs(steps - round(steps)) > 1e-9 * steps:
        found.append(Finding("warning", "E6", f"E6/E2 = {steps!r} is not a whole number of "
                             f"steps; the macro's row count floor(E6/E2 + 2) gives {p.rows:,} "
                             "rows, ending before E6"))
    elif steps != round(steps):
        found.append(Finding("note", "E6", f"E6/E2 = {steps!r} rounds below {round(steps)}: "
                             f"the macro's row count gives {p.rows:,} rows, not "
                             f"{round(steps) + 2:,}"))
    s = p.samplerate
    if s < 1:
        pass  # the sub-row filter quirk: named by the run (engine.filtered.sub_row_warning)
    elif 2 * s >= p.rows - 2:
        found.append(Finding("warning", "E34", f"1/(E2*E34) = {s:.6g} rows: the filter needs "
                             f"2 x that within the run's {p.rows:,} rows, so there is no "
                             "filtered column"))
    elif not float(s).is_integer():
        found.append(Finding("warning", "E34", f"1/(E2*E34) = {s:.6g} is not a whole number "
                             "of rows: the legacy filtered column is ill-defined (Excel "
                             "drifts a row per sample, LibreOffice writes zeros)"))
    masses = {c: m for c, m in (("B2", p.m31), ("C2", p.m32), ("D2", p.m33)) if m > 0}
    light = min(masses, key=masses.get)
    heavy = max(list(masses.values()) + [p.m1 + p.mmitigator])
    if heavy / masses[light] >= MASS_RATIO_WARNING:
        found.append(Finding("warning", light, f"{masses[light]:.3g} kg is "
                             f"{heavy / masses[light]:.2g} times lighter than the heaviest "
                             "mass: a stiff, badly scaled system (see the critical time step)"))
    if p.zeta == 0:
        found.append(Finding("note", "E43", "zeta = 0: the OBR chain is undamped"))
    return crit, found


def after_run(result):
    """Findings from what the kernel saw during the run."""
    p, stats = result.params, result.history.stats
    found = []
    if stats is None:
        return found
    lo, hi = p.crush_law.v_range
    said = p.v31 - p.v1 > hi  # before_run already warned about the impact speed
    if not said and (stats.max_relative_velocity > hi or stats.min_relative_velocity < lo):
        worst = (stats.max_relative_velocity if stats.max_relative_velocity > hi
                 else stats.min_relative_velocity)
        found.append(Finding("warning", "A28", f"while crushing, the relative velocity reached "
                             f"{worst:.4g} m/s, outside {lo:g}..{hi:g} m/s where "
                             f"{_law_words(p)} holds (crush factor "
                             f"{p.crush_law(worst):.3g} there)"))
    length = p.hcone + p.hcylinder
    if stats.x_plastic > length:
        found.append(Finding("warning", "E19", f"the plastic front reached {stats.x_plastic:.4g}"
                             f" m, past the end of the mitigator (E16 + E19 = {length:.4g} m): "
                             "it bottoms out, where the model no longer holds"))
    if stats.max_crushed_mass > p.mmitigator:
        found.append(Finding("warning", "E25", f"the crushed honeycomb joining m31 reached "
                             f"{stats.max_crushed_mass:.4g} kg, more than the mitigator's "
                             f"{p.mmitigator:.4g} kg: more mass than the MEM can give"))
    if not math.isfinite(result.peak_kg):
        found.append(Finding("warning", "E6", "no acceleration rows: the run is too short"))
    return found
