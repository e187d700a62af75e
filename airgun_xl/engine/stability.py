"""Critical time step of the legacy scheme, predicted before a run, in two tiers.

ArtSim's update, for the linear part of the model, is

    M (y[n+1] - 2 y[n] + y[n-1]) / dt^2 = -K y[n] - C (y[n] - y[n-1]) / dt

(central differences, with the macro's backward-difference velocities in the dampers). Over
one step it maps (y[n], y[n-1]) to (y[n+1], y[n]) by the matrix

    G(dt) = [[2I - dt^2 M^-1 K - dt M^-1 C,  -I + dt M^-1 C],
             [I,                              0            ]]

and the run stays bounded while the spectral radius of G is at most 1. For one undamped mode
the critical step is 2/omega; with the macro's dampers it is (2 sqrt(1 + zeta^2) - 2 zeta)/omega,
where an eigenvalue of G leaves the unit circle through -1. For the whole model the step where
an eigenvalue reaches -1 solves a quadratic eigenvalue problem (eq. 1, :func:`_crossing`): one
eigen-solve, where a bisection on the radius took 60. The radius just below that step is then
checked; should the model lose stability some other way first (a complex pair leaving the
circle), the bisection on the radius decides, as before.

The matrices are the model's:
- the OBR chain's springs k2, k3 and dampers c2, c3 (from the initial masses, as the macro
  computes them once);
- the elastic unloading stiffness A E / L between MEM and front plate, where L is the
  mitigator's remaining length, E16 + E19 less the crush so far (the macro's ``L``);
- the masses over the range the run passes through: m31 grows from B2 as crushed honeycomb
  joins it (at most E25 more), M1 shrinks by as much. The smallest critical step over that
  range is the prediction.

Only the OBR chain's springs act on every step; the unloading stiffness acts only while the
mitigator unloads, and grows as it is crushed. So:
- ``dt_crit``: the critical step of the chain alone (the MEM free). Above it every run is
  unstable from its first steps: refuse.
- ``dt_unloading``: the critical step with the unloading spring at the full length E16 + E19;
  ``dt_compacted``: at the fully compacted length (E16 + E19)(1 - E37), which no run goes
  past. Below ``dt_compacted`` the run is stable throughout. Above it, the step is unstable
  while the mitigator unloads with less than ``unstable_length`` remaining (all of it above
  ``dt_unloading``): the run goes ahead, and :mod:`airgun_xl.engine.watch` stops it where it
  diverges. A run that never unloads there is sane (a shot at 1.02 x ``dt_unloading`` that
  never unloads peaks within 0.3 % of the same shot at a step 8 times smaller).
"""
from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..params import ShotParams

#: Spectral radius above 1 by more than this is growth; below, the rigid-body modes' double
#: eigenvalue 1, which floating-point eigenvalues split by about 1e-8.
RADIUS_TOLERANCE = 1e-6

#: Warn when dt / dt_crit passes this; refuse above 1.
WARN_RATIO = 0.5


@dataclass(frozen=True)
class CriticalStep:
    """The two-tier prediction for a shot.

    Attributes
    ----------
    dt_crit : float
        Largest step stable for the springs that always act, the OBR chain's [s] (infinite
        for Newmark, implicit in them). Above it the run is refused.
    ratio : float
        The shot's dt / dt_crit.
    limiting : str
        What sets ``dt_crit``, in words (the stiffest mode's frequency and the cells behind
        it).
    dt_compacted : float
        Largest step stable with the mitigator unloading fully compacted,
        (E16 + E19)(1 - E37) [s]: at or below it, stable throughout.
    unstable_length : float or None
        Remaining mitigator length [m] below which the shot's step is unstable; None when it
        is stable at every length (or unstable from the first step).
    unstable_crush : float or None
        The crush [m] that leaves ``unstable_length``: E16 + E19 - unstable_length.
    dt_unloading : float
        Largest step stable with the mitigator unloading at its full length E16 + E19 [s].
    """

    dt_crit: float
    ratio: float
    limiting: str
    dt_compacted: float | None = None
    unstable_length: float | None = None
    unstable_crush: float | None = None
    dt_unloading: float | None = None

    @property
    def verdict(self) -> str:
        """"unstable", "unstable while unloading", "marginal" or "stable"."""
        if self.ratio > 1:
            return "unstable"
        if self.unstable_crush is not None:
            return "unstable while unloading"
        return "marginal" if self.ratio > WARN_RATIO else "stable"


def full_length(p: ShotParams) -> float:
    """The mitigator's length before the shot, E16 + E19 [m]."""
    return float(p.hcone + p.hcylinder)


def compacted_length(p: ShotParams) -> float:
    """The mitigator's length fully compacted, (E16 + E19)(1 - E37) [m]; the wedge E16 when
    that is 0 (E37 = 1)."""
    return float(full_length(p) * (1 - p.ec) or p.hcone or full_length(p))


def _matrices(p: ShotParams, m31: float, m1: float, chain: bool = True,
              length: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, C, K of the 4-DOF linear model (MEM, m31, m32, m33) with the unloading stiffness
    A E / ``length`` (fully compacted when None); with ``chain=False``, without the OBR
    springs and dampers (what Newmark treats explicitly)."""
    kk2, kk3 = (-p.k2, -p.k3) if chain else (0.0, 0.0)
    c2 = 2 * p.zeta * math.sqrt(kk2 * (p.m31 + p.m32))
    c3 = 2 * p.zeta * math.sqrt(kk3 * (p.m32 + p.m33))
    area = math.pi * p.rcone ** 2
    k_mit = area * p.E / (compacted_length(p) if length is None else length)  # inf: none
    masses = [m1, m31, p.m32 or 1.0, p.m33 or 1.0]  # a left-out mass: its stand-in
    K = np.zeros((4, 4))
    C = np.zeros((4, 4))
    for (i, j), k, c in (((0, 1), k_mit, 0.0), ((1, 2), kk2, c2), ((2, 3), kk3, c3)):
        block = np.array([[1.0, -1.0], [-1.0, 1.0]])
        K[np.ix_((i, j), (i, j))] += k * block
        C[np.ix_((i, j), (i, j))] += c * block
    return np.diag(masses), C, K


def spectral_radius(dt: float, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> float:
    """Spectral radius of the legacy scheme's step matrix G(dt)."""
    n = len(M)
    Minv = np.diag(1 / np.diag(M))
    eye = np.eye(n)
    G = np.block([[2 * eye - dt * dt * Minv @ K - dt * Minv @ C, -eye + dt * Minv @ C],
                  [eye, np.zeros((n, n))]])
    return float(np.max(np.abs(np.linalg.eigvals(G))))


def _stable(dt: float, M: np.ndarray, C: np.ndarray, K: np.ndarray) -> bool:
    return spectral_radius(dt, M, C, K) <= 1 + RADIUS_TOLERANCE


#: Relative distance below the -1 crossing where the radius is checked, and the relative
#: imaginary part up to which a root of eq. 1 counts as real.
CROSSING_CHECK, REAL_ROOT = 1e-9, 1e-9


def _crossing(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> float:
    """Smallest step [s] where an eigenvalue of G(dt) is -1, or inf.

    With y[n] = (-1)^n v the update gives (4 M - 2 dt C - dt^2 K) v = 0, so nu = 1/dt solves

        -4 M nu^2 v + 2 C nu v + K v = 0,                                        (1)

    a quadratic eigenvalue problem; its companion matrix [[0, I], [M^-1 K / 4, M^-1 C / 2]]
    has nu among its eigenvalues. The largest real positive nu is the first crossing.
    """
    n = len(M)
    Minv = np.diag(1 / np.diag(M))
    companion = np.block([[np.zeros((n, n)), np.eye(n)], [Minv @ K / 4, Minv @ C / 2]])
    nu = np.linalg.eigvals(companion)
    real = nu[(np.abs(nu.imag) <= REAL_ROOT * np.abs(nu)) & (nu.real > 0)].real
    return float(1 / real.max()) if real.size else math.inf


def _critical(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> tuple[float, float]:
    if not (np.isfinite(M).all() and np.isfinite(C).all() and np.isfinite(K).all()):
        return 0.0, math.inf  # the inputs overflow: no step is stable
    if not K.any():
        return math.inf, 0.0  # no spring: free flight is stable at any step
    omega_max = math.sqrt(max(np.max(np.real(np.linalg.eigvals(np.linalg.solve(M, K)))),
                              1e-300))
    crossing = _crossing(M, C, K)
    if math.isfinite(crossing) and _stable(crossing * (1 - CROSSING_CHECK), M, C, K):
        return crossing, omega_max
    return _bisected(M, C, K, omega_max), omega_max


def _bisected(M: np.ndarray, C: np.ndarray, K: np.ndarray, omega_max: float) -> float:
    """The critical step [s] by bisection on the spectral radius."""
    lo, hi = 0.0, 4.0 / omega_max  # the damped bound is below 2/omega, so hi is unstable
    while _stable(hi, M, C, K):
        hi *= 2
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _stable(mid, M, C, K):
            lo = mid
        else:
            hi = mid
    return lo


def _mass_range(p: ShotParams, samples: int) -> Iterator[tuple[float, float]]:
    """(m31, M1) pairs over the range the run passes through."""
    for m31 in np.linspace(p.m31, p.m31 + p.mmitigator, samples):
        m1 = p.m1 + p.mmitigator - (m31 - p.m31)
        yield float(m31), max(float(m1), 1e-9)


def _worst(p: ShotParams, samples: int, chain: bool, length: float | None
           ) -> tuple[float, float, float]:
    """(dt_crit, omega, m31) at the mass where the step is smallest, for one length."""
    best = None
    for m31, m1 in _mass_range(p, samples):
        dt, omega = _critical(*_matrices(p, m31, m1, chain, length))
        if best is None or dt < best[0]:
            best = (dt, omega, m31)
    assert best is not None, samples  # samples >= 1: a mass at least
    return best


def _stable_at(p: ShotParams, dt: float, length: float, samples: int, chain: bool) -> bool:
    return all(_stable(dt, *_matrices(p, m31, m1, chain, length))
               for m31, m1 in _mass_range(p, samples))


def unstable_length(p: ShotParams, dt: float, samples: int = 5, chain: bool = True
                    ) -> float | None:
    """The remaining mitigator length [m] below which ``dt`` is unstable.

    Bisection between the compacted and the full length (the unloading stiffness A E / L, and
    so the stiffest mode, grows as L shrinks). Returns None when ``dt`` is stable at the
    compacted length, and the full length when it is unstable from the start.
    """
    lo, hi = compacted_length(p), full_length(p)
    if _stable_at(p, dt, lo, samples, chain):
        return None
    if not _stable_at(p, dt, hi, samples, chain):
        return hi
    for _ in range(50):  # 2^-50 of the length: far below any digit printed
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _stable_at(p, dt, mid, samples, chain) else (mid, hi)
    return hi


def critical_time_step(p: ShotParams, samples: int = 5, chain: bool = True) -> CriticalStep:
    """Predict the legacy scheme's critical time steps for a shot (both tiers).

    Parameters
    ----------
    p : airgun_xl.params.ShotParams
    samples : int
        Points over the range of m31 (from B2 to B2 + E25) where it is evaluated.
    chain : bool
        Include the OBR chain (the legacy scheme); False for Newmark, which is implicit in it.

    Returns
    -------
    CriticalStep
    """
    if chain:
        dt, omega, m31 = _worst(p, samples, True, math.inf)  # the chain alone, MEM free
        f = omega / (2 * math.pi)
        limiting = (f"the OBR chain's stiffest mode, {f:,.0f} Hz (springs B6, C6, masses "
                    f"B2..D2), with m31 = {m31:.4g} kg")
    else:
        dt, limiting = math.inf, "nothing: Newmark is implicit in the OBR chain"
    dt_unloading = _worst(p, samples, chain, full_length(p))[0]
    dt_compacted = _worst(p, samples, chain, compacted_length(p))[0]
    length: float | None = None
    crush: float | None = None
    if dt_compacted < p.delta <= dt:
        length = unstable_length(p, p.delta, samples, chain)
        crush = full_length(p) - length if length is not None else None
    return CriticalStep(dt, p.delta / dt, limiting, dt_compacted, length, crush, dt_unloading)
