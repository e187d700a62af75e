"""Issues 33 and 42: calibration intervals that mean what they say, whatever the noise's
colour.

The coverage of the printed 95 % intervals is measured on the recorder model over 100 noise
seeds (tests/calibration_coverage.py): white noise (3 % of the peak) and the same variance
all an AR(1) of 0.8; the law unfiltered under both and through CFC 600 under the AR(1), E40
unfiltered under the AR(1) (the study run at 200 seeds, with half-white AR(1) 0.6 noise and
E40 under white noise too, is in docs/studies.md).
The error budget (studies/calibrate.py, error_budget) is checked against closed forms, and
the noise's correlation (noise_acf) against long series. The weakly-pinned flag and the
suggested impact speed are tested on the recorder model's shots."""
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from types import SimpleNamespace

import numpy as np
import pytest
from calibration_coverage import RATES, SEEDS, SPEEDS, STUDIES, one_seed, recordings, setup

from airgun_xl.cli import main
from airgun_xl.studies.calibrate import (
    WEAK_PIN,
    Z95,
    Block,
    calibrate,
    error_budget,
    filter_acf,
    noise_acf,
    through_filter,
)
from airgun_xl.studies.shock import cfc_filter

#: The intervals checked: 7 law nodes in each of 3 studies and 1 E40.
CHECKS = 22

#: The exact binomial band of a 95 % interval's coverage over 100 seeds, family-wise over
#: the 22 intervals checked (each at 1 - 0.05 / 22: scipy.stats.binom(100, 0.95).interval
#: gives (87, 100)): a right interval lands in it on all 22 with 95 % probability. Over 100
#: seeds a node covering 84.5 % (the worst before issue 42) falls below 87 with probability
#: 0.70, and the 7 nodes of that study together were all but certain to show it; 200 seeds
#: (the study as first run, ``python tests/calibration_coverage.py`` with SEEDS = 200) cost
#: CI ten minutes more.
BAND = (87, 100)


@pytest.fixture(scope="module")
def coverage():
    """Each study's estimates, truths, errors and weak flags over the seeds, in 2
    processes."""
    jobs = [(what, cfc, 1000 * seed, noise) for what, cfc, noise in STUDIES
            for seed in range(SEEDS)]
    with ProcessPoolExecutor(2, multiprocessing.get_context("spawn")) as pool:
        results = list(pool.map(one_seed, jobs, chunksize=8))
    out = {}
    for (what, cfc, _, noise), result in zip(jobs, results, strict=True):
        out.setdefault((what, cfc, noise), []).append(result)
    return {key: tuple(np.array([r[k] for r in rows]) if rows[0][k] is not None else None
                       for k in (0, 1, 2, 4))
            for key, rows in out.items()}


def test_the_binomial_band_is_scipys():
    from scipy.stats import binom

    assert binom(SEEDS, 0.95).interval(1 - 0.05 / CHECKS) == BAND


@pytest.mark.parametrize("study", STUDIES, ids=["-".join(map(str, s)) for s in STUDIES])
def test_the_95_percent_intervals_cover_the_truth_95_percent_of_the_time(coverage, study):
    """Each law node's interval and E40's hold the truth on 87 to 100 of the 100 seeds.
    Measured (nodes from the slowest): white [93 96 92 97 96 93 96], AR(1) 0.8
    [94 94 90 96 93 93 91], and through CFC 600 [95 90 92 97 97 96 96]; E40 94. Before
    issue 42 (the residuals' correlation summed until it turned negative, a scalar over the
    filter's), over 200 seeds: AR(1) 0.6 half
    [180 188 188 193 183 183 188], AR(1) 0.8 [169 180 179 184 181 192 187]."""
    estimates, truths, errors, _ = coverage[study]
    inside = np.abs(estimates - truths) <= Z95 * errors
    hits = inside.sum(axis=0)
    assert np.all((hits >= BAND[0]) & (hits <= BAND[1])), hits


def test_the_weak_flag_follows_what_the_noise_leaves_unpinned(coverage):
    """The flag (an interval past ±2 %) is raised on the fastest node on at least 80 % of
    the seeds whatever the noise (measured 85-100 %), on the middle node on under 5 % with
    white noise (measured 1 %) and on over half with AR(1) 0.8 noise (measured 90 %), and
    its rate at every node never falls as the noise grows correlated (measured, % of seeds:
    white 3 1 1 1 0 5 85, AR(1) 0.8 100 100 96 90 96 100 100)."""
    rates = {noise: coverage[("law", None, noise)][3].mean(axis=0)
             for noise in ("white", "ar0.8")}
    assert np.all(np.stack([rates[n][-1] for n in rates]) >= 0.8)
    assert rates["white"][3] < 0.05 < 0.5 < rates["ar0.8"][3]
    assert np.all(rates["white"] <= rates["ar0.8"] + 0.02)  # 2 seeds of slack


def test_a_node_stated_below_0_7_percent_is_within_2_percent(coverage):
    """A node whose standard error is below 0.7 % lies within 2 % of the truth on every seed
    (2 % is 2.9 of those errors; measured at most 1.6 %), white noise."""
    estimates, truths, errors, _ = coverage[("law", None, "white")]
    tight = errors / truths < 0.007
    assert tight.sum() > 100  # most of the middle nodes
    assert np.max(np.abs(estimates / truths - 1)[tight]) <= 0.02


def _fit(J, r):
    return SimpleNamespace(jac=np.asarray(J, float), fun=np.asarray(r, float),
                           x=np.zeros(np.shape(J)[1]))


def test_the_error_budget_is_the_sandwich_of_a_linear_fit():
    """A straight line fitted to two shots' blocks: the errors are those of the closed form
    (J^T J)^-1 J^T Sigma J (J^T J)^-1, Sigma holding each block's own noise variance (from its
    residuals, over the degrees of freedom the fit leaves it, its rows less its hat matrix's
    trace there), its filter's MA(1) correlation and a baseline's constant; the shares add up
    to 1. The residuals alternate in sign: a noise of no correlation of its own."""
    rng = np.random.default_rng(3)
    rows = (40, 60)
    J = np.column_stack([np.ones(sum(rows)), rng.uniform(0, 1, sum(rows))])
    sign = np.where(np.arange(sum(rows)) % 2, -1.0, 1.0)  # no correlation of their own
    r = sign * np.concatenate([np.full(rows[0], 0.01), np.full(rows[1], 0.03)])
    acfs = (np.array([1.0, 0.4]), np.array([1.0]))
    offsets = (0.002, 0.0)
    errors, shares = error_budget(_fit(J, r), [Block(n, a, o) for n, a, o in
                                               zip(rows, acfs, offsets, strict=True)])
    sigma = np.zeros((sum(rows), sum(rows)))
    H = np.linalg.inv(J.T @ J)
    start = 0
    for n, acf, offset in zip(rows, acfs, offsets, strict=True):
        block = slice(start, start + n)
        dof = n - np.trace(H @ J[block].T @ J[block])
        s2 = float(r[block] @ r[block]) / dof
        toeplitz = np.eye(n) + acf[1] * (np.eye(n, k=1) + np.eye(n, k=-1)) if len(acf) > 1 \
            else np.eye(n)
        sigma[block, block] = s2 * toeplitz + offset ** 2
        start += n
    expected = np.sqrt(np.diag(H @ J.T @ sigma @ J @ H))
    assert errors == pytest.approx(expected, rel=1e-12)
    assert shares.sum(axis=1) == pytest.approx(1.0, rel=1e-12)


def _ar(rng, phi, n, share=1.0):
    """n samples of unit variance, ``share`` of it an AR(1) of ``phi`` (stationary from its
    first sample), the rest white."""
    from scipy.signal import lfilter

    w = rng.standard_normal(n) * np.sqrt(1 - phi ** 2)
    w[0] = rng.standard_normal()
    return (np.sqrt(1 - share) * rng.standard_normal(n)
            + np.sqrt(share) * lfilter([1.0], [1.0, -phi], w))


@pytest.mark.parametrize("phi, share, tau", [(0.0, 0.0, 1.0), (0.5, 1.0, 3.0),
                                             (0.6, 0.5, 2.5), (0.8, 1.0, 9.0)])
def test_the_noises_correlation_time_against_closed_forms(phi, share, tau):
    """An AR(1) of phi mixed with white noise has rho_k = share phi^k and the correlation
    time 1 + 2 share phi / (1 - phi): noise_acf finds it from 200,000 samples to 2 %
    (measured 0.6 % at most), white noise exactly 1; and from a stretch of 100 samples and
    one of 40 (a shot's residuals and rest) its median over 400 seeds within 25 % (measured
    2.9, 2.3 and 7.6 against 3, 2.5 and 9: such short stretches cannot tell a long
    correlation whole, and a median of 1.0 for white noise)."""
    rng = np.random.default_rng(1)
    long = noise_acf([_ar(rng, phi, 200_000, share)], 50)
    assert 1 + 2 * long[1:].sum() == pytest.approx(tau, rel=0.02, abs=1e-12)
    short = [1 + 2 * noise_acf([_ar(rng, phi, 100, share), _ar(rng, phi, 40, share)],
                               200)[1:].sum() for _ in range(400)]
    assert np.median(short) == pytest.approx(tau, rel=0.25)


def test_noise_through_a_filter_against_filtered_noise():
    """An AR(1) of 0.6 through CFC 600 at 20 kHz: through_filter's autocorrelation against
    that of 400,000 samples filtered (the estimate's error at these lags about 1 / sqrt(
    400,000 / tau), under 1 %; measured 0.3 %, 1 % allowed)."""
    rng = np.random.default_rng(2)
    y = cfc_filter(_ar(rng, 0.6, 400_000), 1 / 20_000, 600)
    measured = [np.mean(y[k:] * y[:len(y) - k]) / np.mean(y * y) for k in range(12)]
    predicted = through_filter(0.6 ** np.arange(200), filter_acf(600, 1 / 20_000))[:12]
    assert measured == pytest.approx(predicted, abs=0.01)


def test_a_singular_fit_has_infinite_errors():
    J = np.ones((10, 2))
    errors, _ = error_budget(_fit(J, np.zeros(10)), [Block(10, np.ones(1), 0.0)])
    assert np.all(np.isinf(errors))


@pytest.mark.parametrize("rate", RATES)
def test_the_filters_noise_correlation_against_filtered_white_noise(rate):
    """The CFC 600 filter's autocorrelation from its impulse response against that of 400,000
    samples of white noise through it (the estimate's error at these lags is about
    1 / sqrt(400,000 / tau), under 1 %; 3 % allowed)."""
    rng = np.random.default_rng(11)
    noise = cfc_filter(rng.standard_normal(400_000), 1 / rate, 600)
    acf = filter_acf(600, 1 / rate)
    for lag in range(0, 15, 3):
        measured = np.mean(noise[lag:] * noise[:len(noise) - lag]) / np.mean(noise ** 2)
        assert measured == pytest.approx(acf[lag], abs=0.03)
    assert filter_acf(None, 1 / rate).tolist() == [1.0]


@pytest.fixture(scope="module")
def pinned():
    """The three trust-test shots, unfiltered, seed 0: the fastest node is weakly pinned."""
    shot, truth = setup()
    starts = [shot.replace(v31=v, v32=v, v33=v) for v in SPEEDS]
    cal = calibrate(starts, recordings(shot, {"crush_law": truth}, 0), law=True)
    return shot, truth, cal


def test_the_fastest_node_is_flagged_weakly_pinned_by_the_fastest_shot(pinned):
    """Its interval passes +/- 2 % (measured 2.17 %); the shot that pins it is the 243.5 m/s
    one (84 % of its variance); the middle nodes are not flagged (0.9-1.1 %)."""
    _, _, cal = pinned
    nodes = cal.law_intervals
    top = nodes[-1]
    assert top.weak and top.half_width > WEAK_PIN
    assert top.shares[0][:2] == (1, pytest.approx(SPEEDS[0])) and top.shares[0][2] > 0.5
    assert not any(n.weak for n in nodes[1:-2])
    assert top.suggested is not None and top.velocity < top.suggested < SPEEDS[0]


def test_a_shot_at_the_suggested_speed_pins_the_node(pinned):
    """A fourth recording at the suggested speed (about 225 m/s, at 20 kHz) takes the top node
    inside +/- 2 % (measured 1.88 %); a fourth at 200 or 150 m/s, the speeds already below
    it, leaves it outside (2.10 % and 2.05 %). (A repeat of the fastest shot pins it too, but
    moves the law's range and so its top node, to 221 m/s.)"""
    shot, truth, cal = pinned
    suggested = cal.law_intervals[-1].suggested
    widths = {}
    for extra in (suggested, 200.0, 150.0):
        shots = (*zip(SPEEDS, RATES, strict=True), (extra, 20_000.0))
        starts = [shot.replace(v31=v, v32=v, v33=v) for v, _ in shots]
        again = calibrate(starts, recordings(shot, {"crush_law": truth}, 0, shots), law=True)
        widths[extra] = again.law_intervals[-1].half_width
    assert widths[suggested] <= WEAK_PIN < min(widths[200.0], widths[150.0])


def test_the_terminal_and_the_calibration_page_show_each_nodes_interval(tmp_path, capsys):
    """calibrate on the three shots' CSV exports: the terminal and the Calibration page list
    each of the 7 nodes with its 95 % interval, and the weakly pinned one is flagged in both,
    with the shot that pins it and the suggested speed."""
    import openpyxl
    from conftest import TEMPLATE

    from airgun_xl.studies.recorder import Recorder

    shot, truth = setup()
    argv = []
    for i, (trace, v) in enumerate(zip(recordings(shot, {"crush_law": truth}, 0), SPEEDS,
                                       strict=True)):
        wb = openpyxl.load_workbook(TEMPLATE)
        wb.worksheets[0]["E2"] = 1e-6
        wb.worksheets[0]["A28"] = v
        wb.save(tmp_path / f"shot{i}.xlsx")
        Recorder().csv(trace, tmp_path / f"m{i}.csv")
        argv += [str(tmp_path / f"shot{i}.xlsx"), str(tmp_path / f"m{i}.csv")]
    out = tmp_path / "cal.xlsx"
    main(["calibrate", *argv, "-o", str(out)])
    printed = capsys.readouterr().out
    lines = [line for line in printed.splitlines() if " m/s: " in line and "+/- " in line]
    assert len(lines) == 7
    assert sum("WEAKLY PINNED by shot 1 (243.5 m/s" in line for line in lines) >= 1
    assert "would pin it best" in printed
    cells = [c for r in openpyxl.load_workbook(out)["Calibration"].iter_rows(values_only=True)
             for c in r if c is not None]
    assert "Node velocity (m/s)" in cells and cells.count("WEAKLY") >= 1
    assert any(isinstance(c, str) and "weakly pinned" in c and "would pin it best" in c
               for c in cells)


def test_a_tilt_not_pinned_is_named_as_the_laws_tilt_not_as_an_option():
    """The tilt is fitted by next's law update, not by a --fit name: a tilt at its bound
    or not pinned is named as the law's tilt with speed (it read '--fit tilt', an option
    that does not exist), and a --fit parameter keeps its option's name."""
    from types import SimpleNamespace

    from airgun_xl.studies.calibrate import TILT_REACH, verdict

    cal = SimpleNamespace(fitted={"tilt": TILT_REACH, "scale": 1.1},
                          bounds={"tilt": (-TILT_REACH, TILT_REACH), "scale": (0.5, 2.0)},
                          errors={"tilt": 0.01, "scale": 0.9}, law_calibration=None,
                          before=[], after=[])
    found, _ = verdict(cal, None, "l2", None)
    assert found == [
        f"the law's tilt with speed: {TILT_REACH:.6g} is at its bound "
        f"({-TILT_REACH:.4g}..{TILT_REACH:.4g}): not identified by these pulses",
        "--fit scale: 1.1 +/- 0.9 (1 standard error): the pulses do not pin it down (not "
        "identified)"]
