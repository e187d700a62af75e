"""What a run did, read back from its displacement columns: when the mitigator unloads, where
the macro's unloading-force quirk fires, and where the unloading spring makes it diverge.

These read the arrays after (or up to where) the kernel stopped; they change no number.

The macro's unloading force (ArtSim.bas, the ``forceCounter`` branch) is elastic from the
force it had when unloading began: at the first unloading step it sets
``dforce = A E / L (d - hcone) - F_last_loading``, so that the force stays continuous. But
``forceCounter`` is never reset, and every loading step sets ``dforce = F``. After an
unload, reload, unload sequence the second unloading therefore uses
``F = A E / L (d - hcone) - F_last_loading``: the full elastic force of the whole deflection,
a jump of up to 1e10 N, or a drop to 0 when d < hcone. :func:`unloading_quirk` names the
first such step; ``ShotParams(unloading="continuous")`` runs the shot without it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .integrators import History

#: Consecutive unloading steps whose second difference of the deflection alternates in sign
#: and grows, before the run is said to diverge: the central-difference scheme's unstable
#: mode has an eigenvalue below -1 (period two steps), where a physical response changes
#: smoothly over many steps. Six growing alternations are a factor (rho)^6 of growth.
DIVERGING_STEPS = 6


def deflection(history: History) -> np.ndarray:
    """The mitigator deflection each step used [m] (index k: step k; NaN for k < 2).

    The tracked column when there is one, else Y31 - Y1 of the row before, as the legacy
    scheme computes it."""
    if history.deflection is not None:
        return np.asarray(history.deflection, dtype=float)
    d = np.asarray(history.y31, dtype=float) - np.asarray(history.y1, dtype=float)
    out = np.full(len(d), np.nan)
    out[2:] = d[1:-1]
    return out


def unloading(defl: np.ndarray) -> np.ndarray:
    """True at each step the macro takes its unloading branch: the deflection below the
    largest one so far (``maxmitdef``, from 0)."""
    d = np.where(np.isfinite(defl), defl, -np.inf)
    d[:2] = -np.inf
    before = np.maximum.accumulate(np.concatenate(([0.0], np.maximum(d, 0.0))))[:-1]
    return (d < before) & np.isfinite(defl)


def unloading_onsets(defl: np.ndarray) -> np.ndarray:
    """Steps where an unloading phase begins (a loading step, or none, before it)."""
    u = unloading(defl)
    starts = u.copy()
    starts[1:] &= ~u[:-1]
    return np.flatnonzero(starts)


@dataclass(frozen=True)
class UnloadingQuirk:
    """The first unloading after a reload, where the macro's force jumps.

    Attributes
    ----------
    step : int
        Array index of the step (sheet row ``step + 2``).
    time : float
        Its time [s].
    force_before, force_after : float
        The mitigator force the step before and at the step [N] (NaN when not tracked).
    onsets : int
        Unloading phases in the run.
    """

    step: int
    time: float
    force_before: float
    force_after: float
    onsets: int

    @property
    def row(self) -> int:
        return self.step + 2

    def __str__(self) -> str:
        jump = ("" if not np.isfinite(self.force_after) else
                f", and the force jumps from {self.force_before:.4g} N to "
                f"{self.force_after:.4g} N")
        return (f"the macro's unloading-force quirk (forceCounter is set at the first unloading "
                f"and never reset): the mitigator unloads again after reloading at row "
                f"{self.row:,} (t = {self.time * 1e3:.4g} ms){jump}; the figures from there on "
                "follow the quirk, not the physics")


def unloading_quirk(history: History, stop: int | None = None) -> UnloadingQuirk | None:
    """The :class:`UnloadingQuirk` of a run (its steps before ``stop``), or None."""
    defl = deflection(history)[:stop]
    onsets = unloading_onsets(defl)
    if len(onsets) < 2:
        return None
    k = int(onsets[1])
    force = history.force
    before, after = ((float(force[k - 1]), float(force[k])) if force is not None
                     else (np.nan, np.nan))
    return UnloadingQuirk(k, float(history.time[k]), before, after, len(onsets))


def unloading_divergence(history: History, steps: int = DIVERGING_STEPS) -> int | None:
    """The first step [index] by which the deflection has oscillated with growing amplitude,
    alternating each step, for ``steps`` unloading steps in a row (the unstable mode of an
    unloading spring too stiff for the step); None when it never does."""
    defl = deflection(history)
    d = np.where(np.isfinite(defl), defl, 0.0)
    e = np.zeros(len(d))
    e[1:-1] = d[2:] - 2 * d[1:-1] + d[:-2]
    grows = np.zeros(len(d), dtype=bool)
    grows[1:] = (e[1:] * e[:-1] < 0) & (np.abs(e[1:]) > np.abs(e[:-1]))
    grows &= unloading(defl)
    run = np.zeros(len(d), dtype=np.int64)
    count = 0
    for k in np.flatnonzero(grows):  # few candidates: a loop over them is cheap
        count = count + 1 if k > 0 and run[k - 1] else 1
        run[k] = count
        if count >= steps:
            return int(k)
    return None
