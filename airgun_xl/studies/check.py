"""Checks of a shot before and after its run: stability, and cases where the model is
stretched past what it was built for. Each finding names the cell that causes it."""
import math
from dataclasses import dataclass

from ..cells import BY_ADDRESS, CELLS, address
from ..engine.filtered import fractional_rows
from ..engine.stability import WARN_RATIO, critical_time_step, full_length

#: Bird masses differing by this factor or more make a stiff, badly scaled system.
MASS_RATIO_WARNING = 1e6


@dataclass(frozen=True)
class Finding:
    """One result of a check: ``level`` is "error", "warning" or "note"."""

    level: str
    cell: str
    message: str

    @classmethod
    def on(cls, level, field, message):
        """A finding on the cell of the shot's field ``field`` (``"delta"``: E2)."""
        return cls(level, address(field), message)

    def __str__(self):
        label = BY_ADDRESS[self.cell].label if self.cell in BY_ADDRESS else ""
        where = f"{self.cell} ({label})" if label else self.cell
        return f"{where}: {self.message}"


def _fmt(dt):
    return f"{dt:.3g} s"


def stability(p, integrator="legacy"):
    """The critical steps of the chosen scheme and its finding (None when comfortably stable).

    Only the springs that act on every step, the OBR chain's, can refuse a step (Newmark is
    implicit in them). The mitigator's unloading spring acts only while it unloads: a step
    unstable for it is a warning here, and the run is watched (:func:`unloading_diverged`).
    """
    crit = critical_time_step(p, chain=integrator == "legacy")
    if crit.ratio > 1:
        return crit, Finding.on("error", "delta", f"{_fmt(p.delta)} is {crit.ratio:.3g} x the "
                                            f"critical time step of the {integrator} scheme, "
                                            f"set by {crit.limiting}; the largest safe time "
                                            f"step is {_fmt(crit.dt_crit)}")
    if crit.unstable_length is not None:
        return crit, Finding.on("warning", "delta", unloading_limit(p, crit, integrator)
                             + "; the run is watched and stops where it diverges")
    if crit.ratio > WARN_RATIO:
        return crit, Finding.on("warning", "delta", f"{_fmt(p.delta)} is {crit.ratio:.2f} x the "
                                              f"critical time step ({_fmt(crit.dt_crit)}) of "
                                              f"the {integrator} scheme: close to unstable")
    return crit, None


def unloading_limit(p, crit, integrator="legacy"):
    """Where the shot's step is unstable for the unloading spring, in words."""
    where = ("at any length" if crit.unstable_length >= full_length(p) else
             f"once crushed by {crit.unstable_crush:.4g} m (remaining length below "
             f"{crit.unstable_length:.4g} m of E16 + E19 = {full_length(p):.4g} m)")
    return (f"{_fmt(p.delta)} is stable for the OBR chain under the {integrator} scheme, but "
            f"not for the mitigator's unloading spring (E13, E31, E16, E19) while it unloads "
            f"{where}: that needs a step below {_fmt(crit.dt_unloading)} at full length, "
            f"{_fmt(crit.dt_compacted)} fully compacted")


def unloading_diverged(result, crit, integrator="legacy"):
    """The error for a run whose unloading spring diverged (:mod:`airgun_xl.engine.watch`),
    naming the row; None when it did not (or cannot: the step is stable unloading)."""
    from ..engine.watch import DIVERGING_STEPS, unloading_divergence

    if crit.unstable_length is None:
        return None
    k = unloading_divergence(result.history)
    if k is None:
        return None
    return Finding.on("error", "delta", f"the run diverges at row {k + 2:,} (t = "
                   f"{result.history.time[k] * 1e3:.4g} ms): while the mitigator unloads, its "
                   f"deflection has oscillated with growing amplitude, alternating every step, "
                   f"for {DIVERGING_STEPS} steps; "
                   + unloading_limit(result.params, crit, integrator))


def impact_speed_finding(p):
    """The warning for an impact speed past the crush-factor fit, or None.

    (A bird slower than the MEM crushes nothing at first: no warning.)"""
    lo, hi = p.crush_law.v_range
    v_rel = p.v31 - p.v1
    if v_rel <= hi:
        return None
    return Finding.on("warning", "v31", f"the bird meets the MEM at {v_rel:.4g} m/s, outside "
                   f"{lo:g}..{hi:g} m/s where {_law_words(p)} holds: it is "
                   f"extrapolated there (crush factor {p.crush_law(v_rel):.3g})")


def _law_words(p):
    if p.crush_law.is_legacy:
        return "the crush-factor polynomial (Eq. 8)"
    return f"the fitted crush law ({p.crush_law.source or 'Crush law sheet'})"


def before_run(p, integrator="legacy"):
    """Findings that need no run. Returns (CriticalStep, list of Finding)."""
    crit, finding = stability(p, integrator)
    found = [finding] if finding else []
    speed = impact_speed_finding(p)
    if speed is not None:
        found.append(speed)
    if p.v1 == p.v31 == p.v32 == p.v33:
        found.append(Finding.on("note", "v31", f"all masses start at {p.v31:g} m/s: nothing "
                             "crushes the mitigator, the response is free flight"))
    steps = p.max_time / p.delta
    if abs(steps - round(steps)) > 1e-9 * steps:
        found.append(Finding.on("warning", "max_time",
                                f"E6/E2 = {steps!r} is not a whole number of "
                             f"steps; the macro's row count floor(E6/E2 + 2) gives {p.rows:,} "
                             "rows, ending before E6"))
    elif steps != round(steps):
        found.append(Finding.on("note", "max_time",
                                f"E6/E2 = {steps!r} rounds below {round(steps)}: "
                             f"the macro's row count gives {p.rows:,} rows, not "
                             f"{round(steps) + 2:,}"))
    s = p.samplerate
    # below one row (s < 1) is the sub-row filter quirk, named by the run (engine.filtered)
    if 1 <= s and 2 * s >= p.rows - 2:
        found.append(Finding.on("warning", "filter_frequency",
                                f"1/(E2*E34) = {s:.6g} rows: the filter needs "
                             f"2 x that within the run's {p.rows:,} rows, so there is no "
                             "filtered column"))
    elif 1 <= s and not float(s).is_integer():
        found.append(Finding.on("warning", "filter_frequency", fractional_rows(s)))
    masses = {address(name): getattr(p, name) for name in ("m31", "m32", "m33")
              if getattr(p, name) > 0}
    light = min(masses, key=lambda cell: masses[cell])
    heavy = max(list(masses.values()) + [p.m1 + p.mmitigator])
    if heavy / masses[light] >= MASS_RATIO_WARNING:
        found.append(Finding("warning", light, f"{masses[light]:.3g} kg is "
                             f"{heavy / masses[light]:.2g} times lighter than the heaviest "
                             "mass: a stiff, badly scaled system (see the critical time step)"))
    if p.zeta == 0:
        found.append(Finding.on("note", "zeta", "zeta = 0: the OBR chain is undamped"))
    found += plausibility(p)
    if p.bird_masses < 3:
        cells = "D2 and C6 are" if p.bird_masses == 2 else "C2, D2, B6 and C6 are"
        found.append(Finding("warning", address("m33") if p.bird_masses == 2 else address("m32"),
                             f"{cells} blank: airgun-xl runs the {p.model.split(' (')[0]} "
                             "model, where the macro itself stops with 'Division by zero', so "
                             "there is no legacy output to compare with"))
    return crit, found


def plausibility(p):
    """A warning for each cell whose non-zero value lies outside the magnitudes of a real air
    gun shot (:data:`airgun_xl.cells.CELLS`, ``plausible``): a value in another unit, such as
    E40 typed in psi, or a slip of a few orders of magnitude."""
    found = []
    for cell in CELLS:
        value = getattr(p, cell.name)
        if not cell.plausible or value == 0:
            continue
        lo, hi = cell.plausible
        if not lo <= abs(value) <= hi:
            side = "below" if abs(value) < lo else "above"
            found.append(Finding("warning", cell.address, f"{value:.4g} {cell.unit} is {side} "
                                 f"the {lo:g}..{hi:g} {cell.unit} of a real shot's "
                                 f"{cell.meaning.split(',')[0]}: an implausible order of "
                                 "magnitude (a value in another unit?)"))
    return found


def after_run(result):
    """Findings from what the kernel saw during the run."""
    p, stats = result.params, result.history.stats
    if stats is None:
        return []
    found = stats_findings(p, stats, quirk=False)
    if not math.isfinite(result.peak_kg):
        found.append(Finding.on("warning", "max_time",
                                "no acceleration rows: the run is too short"))
    return found + quirk_findings(result)


def stats_findings(p, stats, quirk=True):
    """Findings from the kernel's statistics of a run alone (what a sweep's batch keeps):
    the crush law's range, a mitigator crushed past its end, more crushed mass than it has,
    and, with ``quirk``, the unloading quirk's row (:func:`quirk_findings` says more from the
    columns)."""
    found = []
    lo, hi = p.crush_law.v_range
    said = p.v31 - p.v1 > hi  # before_run already warned about the impact speed
    if not said and (stats.max_relative_velocity > hi or stats.min_relative_velocity < lo):
        worst = (stats.max_relative_velocity if stats.max_relative_velocity > hi
                 else stats.min_relative_velocity)
        found.append(Finding.on("warning", "v31", f"while crushing, the relative velocity reached "
                             f"{worst:.4g} m/s, outside {lo:g}..{hi:g} m/s where "
                             f"{_law_words(p)} holds (crush factor "
                             f"{p.crush_law(worst):.3g} there)"))
    length = p.hcone + p.hcylinder
    if stats.x_plastic > length:
        found.append(Finding.on("warning", "hcylinder",
                                f"the plastic front reached {stats.x_plastic:.4g}"
                             f" m, past the end of the mitigator (E16 + E19 = {length:.4g} m): "
                             "it bottoms out, where the model no longer holds"))
    if stats.max_crushed_mass > p.mmitigator:
        found.append(Finding.on("warning", "mmitigator",
                                f"the crushed honeycomb joining m31 reached "
                             f"{stats.max_crushed_mass:.4g} kg, more than the mitigator's "
                             f"{p.mmitigator:.4g} kg: more mass than the MEM can give"))
    if stats.max_crush > length:
        found.append(Finding.on("warning", "hcylinder", f"the mitigator is crushed by "
                             f"{stats.max_crush:.4g} m, more than its length E16 + E19 = "
                             f"{length:.4g} m: the final length {length - stats.max_crush:.4g} m "
                             "is negative, which no real mitigator reaches"))
    if quirk and p.unloading == "macro" and stats.second_onset >= 0:
        found.append(Finding.on("warning", "E", f"the macro's unloading-force quirk: the "
                             f"mitigator unloads again after reloading at row "
                             f"{stats.second_onset + 2:,}, where its force jumps; the figures "
                             "follow the quirk, not the physics"))
    return found


def shot_findings(p, stats):
    """The warnings of one shot of a study, from its parameters and its kernel statistics
    (no eigen-solve: a study's shots share the base shot's stability verdict)."""
    found = plausibility(p)
    speed = impact_speed_finding(p)
    if speed is not None:
        found.append(speed)
    return found + stats_findings(p, stats)


def quirk_fired(result):
    """Whether the macro's unloading-force quirk fired in a run (the kernel's count)."""
    stats = result.history.stats
    return (result.params.unloading == "macro" and stats is not None
            and stats.second_onset >= 0)


def quirk_findings(result):
    """The macro's quirks a run met, named (:mod:`airgun_xl.engine.watch`)."""
    from ..engine.watch import unloading_quirk

    p, stats, found = result.params, result.history.stats, []
    quirk = unloading_quirk(result.history) if p.unloading == "macro" else None
    if quirk is not None:
        found.append(Finding.on("warning", "E", str(quirk)))
    if stats is not None and stats.past_bound is not None:
        found.append(Finding.on("warning", "delta", f"from row {stats.past_bound + 2:,} the "
                             "displacements pass what any physical run reaches (the unloading "
                             "quirk's force): the run goes on as the macro's does, and its "
                             "figures are not to be trusted"))
    return found
