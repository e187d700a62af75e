"""The legacy kernel against closed-form answers.

With no relative motion between bird and MEM the mitigator carries no force, and with zeta = 0
the OBR chain m31-m32-m33 is a free, undamped two-spring system. The central-difference scheme
solves such a linear system exactly at a shifted frequency, omega_h = (2/dt) asin(omega dt / 2),
so its output can be checked against a formula to rounding error.
"""
import math

import numpy as np
import pytest

from airgun_xl import Shot, ShotParams
from airgun_xl.engine import derived
from airgun_xl.engine.filtered import filtered_acceleration

BASE = dict(m1=680.388555, m31=4.8761179775, m32=5.488467677, m33=5.5111472955, k2=-6.084e9,
            k3=-1.2084e10, delta=5e-7, max_time=2e-3, rho=385.0, rcone=0.08811,
            hcone=0.098298, hcylinder=0.803, mmitigator=8.754836, vcone=9.94838e-05,
            E=4.06e9, filter_frequency=6250.0, ec=0.64, sigmay=2.703e7, zeta=0.0,
            v1=0.0, v31=0.0, v32=0.0, v33=0.0)


def run(**changes):
    return Shot(ShotParams(**dict(BASE, **changes)).check()).run()


def test_free_flight_is_exact_uniform_motion():
    """All four masses at 50 m/s: nothing touches, every Y is v*t.

    Tolerance 1e-12 of the largest |Y|: each step adds a rounding of a few ulps to a value that
    grows linearly, over 4,000 steps.
    """
    v = 50.0
    result = run(v1=v, v31=v, v32=v, v33=v)
    h = result.history
    expected = v * (h.time + 0.0)
    for y in (h.y1, h.y31, h.y32, h.y33):
        assert np.max(np.abs(y - expected)) <= 1e-12 * np.max(np.abs(expected))
    assert np.all(h.force[2:] == 0)
    assert np.all(h.x_plastic[2:] == 0)
    assert np.nanmax(np.abs(result.accel)) < 1e-6  # m/s^2: second differences of rounding


def _chain():
    m = np.diag([BASE["m31"], BASE["m32"], BASE["m33"]])
    k2, k3 = -BASE["k2"], -BASE["k3"]
    K = np.array([[k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    return m, K


@pytest.mark.parametrize("mode", [1, 2])
def test_undamped_chain_follows_the_discrete_normal_mode(mode):
    """Start the OBR chain in one normal mode; the scheme gives an exact discrete sinusoid.

    The bird's mean velocity equals the MEM's (both 0) only on average, so the front plate
    touches the mitigator and crushes it a little; sigmay = E = 1e-12 Pa keep that contact
    force below 1e-12 N, far under the spring forces (1e3 N), and rho = 1e-12 kg/m^3 keeps
    the crushed mass that joins m31 below 1e-14 kg. Tolerance 1e-9 of the amplitude: the
    rounding of 4,000 steps (seen: 8e-12); with the continuous omega instead of omega_h the
    error is 1e-3, so the check tells the two apart.
    """
    m, K = _chain()
    w2, vecs = np.linalg.eig(np.linalg.solve(m, K))
    order = np.argsort(w2)
    omega = math.sqrt(w2[order][mode])
    phi = vecs[:, order][:, mode]
    phi = phi / np.max(np.abs(phi))
    amp_v = 0.5  # m/s of the largest mass velocity
    v31, v32, v33 = amp_v * phi
    dt = BASE["delta"]
    result = run(v31=v31, v32=v32, v33=v33, sigmay=1e-12, E=1e-12, rho=1e-12)
    h = result.history
    omega_h = 2 / dt * math.asin(omega * dt / 2)
    # q(-dt) = -dt v, q(0) = 0, q(t) = A sin(omega_h t) with A sin(omega_h dt) = dt v
    shape = dt / math.sin(omega_h * dt) * np.sin(omega_h * h.time)
    for y, v in ((h.y31, v31), (h.y32, v32), (h.y33, v33)):
        expected = v * shape
        assert np.max(np.abs(y - expected)) <= 1e-9 * (amp_v / omega)
    # and the frequency is the chain's own: the numerical shift is below 0.01% at this dt
    assert omega_h / omega - 1 < 1e-4


def test_undamped_chain_keeps_its_energy():
    """Energy of the free OBR chain (zeta = 0) stays constant.

    Central differences conserve a modified energy exactly; the plain energy computed with
    central-difference velocities oscillates by O((omega dt)^2) = O(3e-4) here, so it must
    stay within 1e-3 of its initial value.
    """
    m, K = _chain()
    result = run(v31=0.0, v32=0.0, v33=1.0, sigmay=1e-12, E=1e-12, rho=1e-12)
    h = result.history
    dt = BASE["delta"]
    y = np.vstack([h.y31, h.y32, h.y33])
    v = (y[:, 2:] - y[:, :-2]) / (2 * dt)
    yc = y[:, 1:-1]
    kinetic = 0.5 * np.einsum("i,ij->j", np.diag(m), v ** 2)
    potential = 0.5 * np.einsum("ij,ik,kj->j", yc, K, yc)
    energy = kinetic + potential
    e0 = 0.5 * m[2, 2] * 1.0 ** 2
    assert np.max(np.abs(energy / e0 - 1)) < 1e-3


def test_derivatives_of_a_parabola_are_exact():
    """Central differences of y = t^2 give a = 2 and v = 2t (to rounding)."""
    dt = 1e-3
    t = np.arange(-1, 10) * dt
    accel, vel, kg = derived.test_item_derivatives(t * t, dt)
    assert np.isnan(accel[0]) and np.isnan(accel[-1])
    np.testing.assert_allclose(accel[1:-1], 2.0, rtol=1e-9)  # 1e-9: (t^2) rounding / dt^2
    np.testing.assert_allclose(vel[1:-1], 2 * t[1:-1], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(kg[1:-1], 2.0 / -9800, rtol=1e-9)


def test_filtered_samples_every_samplerate_plus_one_rows():
    """Integer samplerate s: a sample every s+1 rows, centred stencil of half-width s."""
    y = np.arange(40.0) ** 2
    f = filtered_acceleration(y, 1.0, 2.0)
    # rows 0..; loop runs while counter <= 40 - 4: 34 iterations, a sample every 3rd
    assert f.rows.tolist() == list(range(2, 35, 3))
    r = f.rows[0]
    assert f.values[0] == (y[r - 2] + y[r + 2] - 2 * y[r]) / 4.0
    assert f.warnings == []


def test_filtered_excel_rounds_fractional_offsets_and_drifts():
    """s = 2.5: Excel moves -2, +5, -2 (halves to even), so each sample is written one row
    below the row it centred on, from a one-sided stencil."""
    y = np.arange(40.0) ** 3
    f = filtered_acceleration(y, 1.0, 2.5, host="excel")
    # first sample on iteration 3 (innercounter 3 > 2.5): cursor at index 2
    assert f.rows[0] == 3
    assert f.values[0] == (y[0] + y[5] - 2 * y[2]) / 6.25
    # the cursor continues from index 4, next sample 2 iterations later at index 6 -> row 7
    assert f.rows[1] == 7
    assert any("ill-defined" in w for w in f.warnings)


def test_filtered_calc_ignores_fractional_offsets():
    """s = 33.33 (the shared case): Calc does not move, so every sample is exactly 0."""
    y = np.random.default_rng(1).normal(size=400)
    f = filtered_acceleration(y, 1.0, 100 / 3, host="calc")
    assert len(f.values) and np.all(f.values == 0)
    assert f.rows.tolist() == list(range(33, 33 + 34 * len(f.rows), 34))


def test_filter_below_one_row_half_writes_first_differences_every_other_row():
    """Issue 18.5, s = 0.5 (2s whole): both hosts leave Offset(-0.5) in place (Calc ignores
    it, Excel rounds half to even: 0) and move Offset(1): each visited row reads Y at the
    cursor twice and one row on, and writes one row on; the cursor then skips a row. Matched
    on the runner's case ab_half_row by test_legacy_cases.py."""
    y = np.arange(20.0) ** 2
    for host in ("excel", "calc"):
        f = filtered_acceleration(y, 1.0, 0.5, host=host)
        # counter 3..20 - 1: 17 visits, two rows each, so the writes run past the 20 rows
        # (reading empty cells as 0 there), as the runner's case shows to row 599 of 302
        assert f.rows.tolist() == list(range(1, 35, 2))
        assert f.values.tolist() == [(y[r] - y[r - 1]) / 0.25 for r in f.rows[:10]] + [
            0.0] * 7
        assert any("sub-row filter quirk" in w for w in f.warnings)


def test_filter_below_one_row_fractional_differs_by_host():
    """s = 0.3: Calc ignores both fractional Offsets (zeros on every row, as the runner's
    ab_third_row); Excel rounds 0.6 to 1 and -0.3 to 0, so it writes differences on every
    other row, as at s = 0.5 but scaled by 1/0.09."""
    y = np.arange(20.0) ** 2
    calc = filtered_acceleration(y, 1.0, 0.3, host="calc")
    # counter 3..19.4: 17 visits
    assert calc.rows.tolist() == list(range(17)) and np.all(calc.values == 0)
    excel = filtered_acceleration(y, 1.0, 0.3, host="excel")
    assert excel.rows.tolist() == list(range(1, 35, 2))
    np.testing.assert_allclose(excel.values[:10], [(y[r] - y[r - 1]) / 0.09
                                                   for r in excel.rows[:10]],
                               rtol=1e-15)  # 1/(0.3^2) rounds apart from 1/0.09
    assert "zeros on every row" in calc.warnings[0]
    assert "every other row" in excel.warnings[0]
