"""Issue 12: the ISO/TS 18571 rating, against cases whose scores follow from the published
formulas by hand, and its dynamic time warping against a brute-force one."""
import numpy as np
import pytest

from airgun_xl.studies import iso18571 as iso

T = np.linspace(0, 0.01, 1001)  # 10 ms at 10 us; resampled to the standard's 10 kHz: 101
HALF_SINE = np.sin(np.pi * T / 0.01)


def test_identical_signals_score_one():
    r = iso.rating(T, HALF_SINE, HALF_SINE)
    assert (r.corridor, r.phase, r.magnitude, r.slope, r.overall) == (1, 1, 1, 1, 1)
    assert r.grade == "excellent"


def test_corridor_of_a_scaled_signal_by_the_formula():
    """C = 1.1 T: |C - T| = 0.1 T, inside the inner corridor (0.05 max) where T < 0.5, else
    ((0.5 - 0.1 T) / 0.45)^2. The slope error is exactly 0.1, so E_S = (2 - 0.1) / 2."""
    r = iso.rating(T, HALF_SINE, 1.1 * HALF_SINE)
    t10 = np.sin(np.pi * np.arange(101) / 100)
    expected = np.where(0.1 * t10 < 0.05, 1.0, ((0.5 - 0.1 * t10) / 0.45) ** 2).mean()
    assert r.corridor == pytest.approx(expected, rel=1e-12)  # the same sums, in another order
    assert r.slope == pytest.approx(0.95, rel=1e-12)
    assert r.phase == 1.0 and r.shift == 0


def test_phase_of_a_shifted_signal_by_the_formula():
    """C lags T by 0.5 ms = 5 samples at 10 kHz: n_eps = 5, E_P = (0.2 N - 5) / (0.2 N) with
    N = 101; the shifted overlaps are the same curve, so magnitude and slope score 1."""
    lagged = np.where(T >= 5e-4, np.sin(np.pi * (T - 5e-4) / 0.01), 0.0)
    r = iso.rating(T, HALF_SINE, lagged)
    assert r.shift == 5
    assert r.phase == pytest.approx((0.2 * 101 - 5) / (0.2 * 101), rel=1e-12)
    assert r.magnitude == pytest.approx(1.0, abs=1e-9)
    assert r.slope == pytest.approx(1.0, abs=1e-9)
    assert r.overall == pytest.approx(0.4 * r.corridor + 0.2 * r.phase + 0.4, rel=1e-12)


def test_an_inverted_signal_rates_poor():
    r = iso.rating(T, HALF_SINE, -HALF_SINE)
    assert r.magnitude == 0.0 and r.overall < 0.1 and r.grade == "poor"


def _brute_dtw_cost(a, b, window):
    """The least summed squared difference over monotone paths with |i - j| < window."""
    n, m = len(a), len(b)
    D = np.full((n + 1, m + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            if abs(i - j) < window:
                D[i, j] = (a[i - 1] - b[j - 1]) ** 2 + min(D[i - 1, j], D[i, j - 1],
                                                           D[i - 1, j - 1])
    return D[n, m]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_warping_is_the_least_cost_path_in_the_band(seed):
    """dtaidistance's path, priced with squared differences, costs what the brute-force
    recursion finds (its band: |i - j| < ceil(0.1 N), the standard's Sakoe-Chiba 10 %)."""
    rng = np.random.default_rng(seed)
    a = np.cumsum(rng.normal(size=40))
    b = np.cumsum(rng.normal(size=40))
    tw, cw = iso.warped(a, b)
    window = int(np.ceil(0.1 * 40))
    assert np.sum((tw - cw) ** 2) == pytest.approx(_brute_dtw_cost(b, a, window), rel=1e-9)


def test_smoothed_slope_ends_and_middle():
    """A ramp's slope is its gradient everywhere (all averages of a constant)."""
    ramp = 3.0 * np.arange(30) / iso.SAMPLE_RATE
    assert np.allclose(iso.smoothed_slope(ramp), 3.0, rtol=1e-12)


def test_dtw_ties_break_diagonal_first_then_along_the_simulation():
    """README: on equal accumulated costs dtaidistance's backtrack (from the last pair) takes
    the diagonal step first, then a step back along the simulation alone, then along the test
    alone. A brute-force DTW with that rule gives the very path of ``warped`` on coarsely
    quantised signals (where ties are common), so the rating is reproducible; two published
    implementations that break ties otherwise differ by up to 0.057 in the overall rating."""
    from airgun_xl.studies.iso18571 import DTW_BAND, warped

    rng = np.random.default_rng(11)
    for _ in range(5):
        test, sim = np.round(rng.normal(size=60)), np.round(rng.normal(size=60))
        n, w = len(test), int(np.ceil(DTW_BAND * 60))
        cost = np.full((n + 1, n + 1), np.inf)
        cost[0, 0] = 0.0
        for i in range(1, n + 1):  # i: simulation, j: test, as warped() calls it
            for j in range(max(1, i - w + 1), min(n, i + w - 1) + 1):
                d = (sim[i - 1] - test[j - 1]) ** 2
                cost[i, j] = d + min(cost[i - 1, j - 1], cost[i - 1, j], cost[i, j - 1])
        i, j, path = n, n, [(n - 1, n - 1)]
        while i > 1 or j > 1:
            steps = [cost[i - 1, j - 1], cost[i - 1, j], cost[i, j - 1]]
            k = int(np.argmin(steps))  # the first of equal costs: diagonal, sim, test
            i, j = ((i - 1, j - 1), (i - 1, j), (i, j - 1))[k]
            path.append((i - 1, j - 1))
        path.reverse()
        t_w, s_w = warped(test, sim)
        assert np.array_equal(t_w, test[[p[1] for p in path]])
        assert np.array_equal(s_w, sim[[p[0] for p in path]])
