"""Integrators behind one small interface.

An integrator is a function ``f(params, track=TRACKED) -> History`` that time-steps the shot
and records the displacements and, for the names in ``track``, the step values; the others are
None, neither computed nor stored. ``legacy`` is the faithful port of ArtSim's
central-difference loop; ``newmark`` is a robust scheme. An integrator registers itself in
:data:`INTEGRATORS` under its own name and is then selectable everywhere.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .. import choices
from ..errors import CellError, DivergenceError, OptionError
from .interface import FINALS, SHOT_FIELDS
from .kernel import legacy_kernel, newmark_kernel

if TYPE_CHECKING:
    from ..params import ShotParams

#: The shot's fields the kernels take, in their order (:mod:`~airgun_xl.engine.interface`).
KERNEL_PARAMS = SHOT_FIELDS


@dataclass
class KernelStats:
    """What the kernel saw, for the checks: final plastic front [m], largest and smallest
    relative velocity while loading [m/s], largest crushed mass [kg], largest mitigator
    deflection (the maximum crush) [m]; the row where a run the unloading quirk threw past
    :func:`displacement_bound` passed it (None: it never did)."""

    x_plastic: float
    max_relative_velocity: float
    min_relative_velocity: float
    max_crushed_mass: float
    max_crush: float
    past_bound: int | None = None  # first row index past displacement_bound (quirk's run)
    unloading_onsets: int = 0  # unloading phases begun
    second_onset: int = -1  # row index of the second (where the macro's force jumps), or -1


def _chain_stable(p: ShotParams, integrator: str) -> bool:
    """Whether the OBR chain is stable at the shot's step (an unstable chain oscillates its
    way through loading and unloading, and no quirk is to blame)."""
    from .stability import critical_time_step

    return bool(critical_time_step(p, chain=integrator == "legacy").ratio <= 1)


def divergence_error(integrator: str, p: ShotParams, row: int,
                     arrays: Sequence[Any]) -> DivergenceError:
    """The :class:`~airgun_xl.errors.DivergenceError` for a run stopped at ``row``; when the
    macro's unloading-force quirk fired before it, the quirk is named as the cause."""
    from .watch import unloading_quirk

    names = ("Y1", "Y31", "Y32", "Y33")
    values = [a[row] for a in arrays[1:5]]
    worst = max(range(4), key=lambda i: abs(values[i]) if values[i] == values[i] else
                float("inf"))
    time_at = arrays[0][row]
    where = (f"the {integrator} scheme diverged at step {row - 1:,} (t = {time_at:.6g} s): "
             f"{names[worst]} = {values[worst]:.3g} m, beyond the {displacement_bound(p):.3g} m "
             "no physical run reaches")
    quirk = (unloading_quirk(History.from_arrays(arrays, np.nan, np.nan, 0.0), stop=row)
             if p.unloading == "macro" and _chain_stable(p, integrator) else None)
    if quirk is not None:
        return DivergenceError(
            f"{where}; the cause is {quirk}; expected --unloading continuous (the same shot "
            "without the quirk)", row, time_at, dict(zip(names, values, strict=True)),
            "unloading quirk")
    return DivergenceError(f"{where}; expected a smaller E2 (Timestep) or the newmark "
                           "integrator", row, time_at, dict(zip(names, values, strict=True)))


@dataclass
class History:
    """Per-row values of one run; index ``k`` is sheet row ``k + 2`` (index 0 is t = -delta).

    Attributes
    ----------
    time : numpy.ndarray
        Time [s], from -delta, accumulated by repeated addition as the macro does.
    y1, y31, y32, y33 : numpy.ndarray
        Displacements of MEM, OBR front plate, OBR back plate, test item [m].
    crush_factor : numpy.ndarray or None
        Crush factor [-] (NaN where the macro writes nothing).
    m31, m1 : numpy.ndarray or None
        The macro's m31 and M1 [kg] in each step.
    deflection : numpy.ndarray or None
        Mitigator deflection used in the step [m].
    x_plastic : numpy.ndarray or None
        Plastic wave front after its update [m].
    force : numpy.ndarray or None
        Mitigator force [N], after the clamp at 0.
    v1, v31 : numpy.ndarray or None
        MEM and OBR front plate velocities [m/s], central differences (NaN at both ends).
    final_m1, final_m31 : float
        The masses the macro writes below column I [kg].
    kernel_seconds : float
        Wall time of the time-stepping kernel [s].
    """

    time: np.ndarray
    y1: np.ndarray
    y31: np.ndarray
    y32: np.ndarray
    y33: np.ndarray
    crush_factor: np.ndarray | None  # the tracked step values: None when not tracked
    m31: np.ndarray | None
    deflection: np.ndarray | None
    x_plastic: np.ndarray | None
    force: np.ndarray | None
    m1: np.ndarray | None
    v1: np.ndarray | None
    v31: np.ndarray | None
    final_m1: float
    final_m31: float
    kernel_seconds: float
    stats: KernelStats | None = None

    @classmethod
    def from_arrays(cls, arrays: Sequence[Any], final_m1: float, final_m31: float,
                    kernel_seconds: float) -> History:
        """From the kernel's 13 buffers in :data:`COLUMNS` order (time, the four
        displacements, then the tracked step values, None where not tracked)."""
        return cls(**dict(zip(COLUMNS, arrays, strict=True)), final_m1=final_m1,
                   final_m31=final_m31, kernel_seconds=kernel_seconds)


#: The step values an integrator can record, in :class:`History` order.
TRACKED = choices.TRACKED

#: The kernel's buffers, in its order: :class:`History`'s arrays.
COLUMNS = ("time", "y1", "y31", "y32", "y33") + tuple(TRACKED)


def kernel_stats(finals: Mapping[str, Any], past_bound: int | None = None) -> KernelStats:
    """The :class:`KernelStats` of a run's finals (a mapping by name of
    :data:`~airgun_xl.engine.interface.FINALS`)."""
    return KernelStats(float(finals["x_plastic"]), float(finals["max_relative_velocity"]),
                       float(finals["min_relative_velocity"]),
                       float(finals["max_crushed_mass"]), float(finals["max_crush"]),
                       past_bound, int(finals["unloading_onsets"]),
                       int(finals["second_onset"]))


def displacement_bound(p: ShotParams) -> float:
    """Largest |displacement| a physical run can reach [m]: ten times the free flight at the
    fastest initial speed plus the mitigator length, plus 1 m. Beyond it the scheme diverged."""
    v = max(abs(p.v1), abs(p.v31), abs(p.v32), abs(p.v33))
    return float(10 * (v * p.max_time + p.hcone + p.hcylinder) + 1.0)


def no_wedge_error(p: ShotParams, row: int) -> CellError:
    """E16 = 0 and a loading step before the plastic front has moved: the wedge's area is
    0/0 there. The macro stops with "Division by zero"; the kernel gets NaN and stops."""
    from ..cells import BY_NAME

    c = BY_NAME["hcone"]
    return CellError(c.address, c.label,
                     f"0 with the plastic front not yet moved on a loading step (row "
                     f"{row + 2}, t = {(row - 1) * p.delta:.4g} s), where the macro divides 0/0 "
                     "(its 'Division by zero')",
                     "a positive wedge length, or a bird that moves into the MEM from the "
                     "first step")


def _run(kernel: Callable[..., Any], name: str, p: ShotParams,
         track: Collection[str]) -> History:
    rows = p.rows
    arrays: list[Any] = [np.zeros(rows) for _ in range(5)] + [
        np.full(rows, np.nan) if key in track else None for key in TRACKED]
    values = kernel_params(p) + [displacement_bound(p)]
    started = time.perf_counter()
    f = dict(zip((name for name, _ in FINALS), kernel(values, rows, *arrays), strict=True))
    elapsed = time.perf_counter() - started
    bad = f["bad_row"]
    if bad >= 0 and p.hcone == 0 and not f["x_plastic"] > 0:
        raise no_wedge_error(p, bad)
    past_bound = None
    if bad >= 0:
        error = divergence_error(name, p, bad, arrays)
        if error.cause != "unloading quirk":
            raise error
        # the macro's quirk threw the run past the physical bound: run on as the macro
        # does, stopping only where a value stops being finite (the checks name the quirk)
        values[-1] = math.inf
        f = dict(zip((name for name, _ in FINALS), kernel(values, rows, *arrays), strict=True))
        elapsed = time.perf_counter() - started
        if f["bad_row"] >= 0:
            raise divergence_error(name, p, f["bad_row"], arrays)
        past_bound = error.row
    history = History.from_arrays(arrays, f["final_m1"], f["final_m31"], elapsed)
    history.stats = kernel_stats(f, past_bound)
    return blank_left_out(history, p)


def run_legacy(p: ShotParams, track: Collection[str] = TRACKED) -> History:
    """Time-step the shot with ArtSim's own scheme (the compiled port in ``_artsim.c``).

    Parameters
    ----------
    p : airgun_xl.params.ShotParams
        The checked parameters.
    track : collection of str
        Names from :data:`TRACKED` to record.

    Returns
    -------
    History

    Raises
    ------
    DivergenceError
        When a displacement stops being finite or passes :func:`displacement_bound`.
    """
    return _run(legacy_kernel, "legacy", p, track)


def run_newmark(p: ShotParams, track: Collection[str] = TRACKED) -> History:
    """Time-step with the average-acceleration Newmark scheme (beta = 1/4, gamma = 1/2).

    Implicit, so unconditionally stable, for the OBR chain's springs and dampers; the
    mitigator force law is the macro's, evaluated at the Newmark predictor. Same interface as
    :func:`run_legacy`.
    """
    return _run(newmark_kernel, "newmark", p, track)


def kernel_params(p: ShotParams) -> list[float]:
    """The kernel's parameter list, then the crush law's seven coefficients and the unloading
    variant (0 the macro's, 1 continuous); the caller appends the bound. A left-out mass
    (reduced model) gets a stand-in of 1 kg.

    Its spring is 0, so the stand-in moves freely and exerts no force (c = 2 zeta sqrt(0) = 0).
    """
    values = {name: getattr(p, name) for name in KERNEL_PARAMS}
    if p.bird_masses < 3:
        values["m33"] = 1.0
    if p.bird_masses < 2:
        values["m32"] = 1.0
    return ([values[name] for name in KERNEL_PARAMS] + list(p.crush_law.coefficients)
            + [float(p.unloading == "continuous")])


def blank_left_out(history: History, p: ShotParams) -> History:
    """NaN for the displacements of masses the model leaves out."""
    if p.bird_masses < 3:
        history.y33[:] = np.nan
    if p.bird_masses < 2:
        history.y32[:] = np.nan
    return history


class Integrator(Protocol):
    """An integrator: time-steps the checked shot ``p``, recording the displacements and,
    for the names in ``track`` (of :data:`TRACKED`), the step values."""

    def __call__(self, p: ShotParams, track: Collection[str] = ...) -> History: ...


#: The integrators by name (:data:`airgun_xl.choices.INTEGRATORS`, the options' choices).
INTEGRATORS: dict[str, Integrator] = {"legacy": run_legacy, "newmark": run_newmark}


def get_integrator(name: str) -> Integrator:
    """The integrator registered under ``name``.

    Raises
    ------
    OptionError
        For an unknown name, listing the known ones.
    """
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise OptionError(f"integrator: found {name!r}, expected one of "
                          f"{', '.join(sorted(INTEGRATORS))}") from None
