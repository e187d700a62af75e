"""Issue 33: calibration intervals that mean what they say.

The coverage of the printed 95 % intervals is measured on the recorder model over 100 noise
seeds (tests/calibration_coverage.py), and the error budget (studies/calibrate.py,
error_budget) is checked against closed forms. The weakly-pinned flag and the suggested
impact speed are tested on the recorder model's shots."""
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from types import SimpleNamespace

import numpy as np
import pytest
from calibration_coverage import RATES, SPEEDS, one_seed, recordings, setup

from airgun_xl.cli import main
from airgun_xl.studies.calibrate import (
    WEAK_PIN,
    Z95,
    Block,
    calibrate,
    error_budget,
    filter_acf,
)
from airgun_xl.studies.shock import cfc_filter

SEEDS = 100

#: The 95 % binomial band of a 95 % interval's coverage over 100 seeds: 90 to 99 hits
#: (scipy.stats.binom(100, 0.95).interval(0.95) gives (90, 99)).
BAND = (0.90, 0.99)


@pytest.fixture(scope="module")
def coverage():
    """Each (what, cfc)'s estimates, truths and errors over the seeds, in 2 processes."""
    jobs = [(what, cfc, 1000 * seed) for what in ("law", "E40") for cfc in (None, 600)
            for seed in range(SEEDS)]
    with ProcessPoolExecutor(2, multiprocessing.get_context("spawn")) as pool:
        results = list(pool.map(one_seed, jobs))
    out = {}
    for (what, cfc, _), result in zip(jobs, results, strict=True):
        out.setdefault((what, cfc), []).append(result)
    return {key: tuple(np.array([r[k] for r in rows]) for k in range(3))
            for key, rows in out.items()}


def test_the_binomial_band_is_scipys():
    from scipy.stats import binom

    assert binom(SEEDS, 0.95).interval(0.95) == (BAND[0] * SEEDS, BAND[1] * SEEDS)


@pytest.mark.parametrize("what", ["law", "E40"])
@pytest.mark.parametrize("cfc", [None, 600])
def test_the_95_percent_intervals_cover_the_truth_95_percent_of_the_time(coverage, what, cfc):
    """Each law node's interval and E40's, unfiltered and with CFC 600, hold the truth on 90
    to 99 of the 100 seeds. Measured: the law's nodes 93-98 unfiltered and 94-97 with CFC
    600; E40 97 and 99. Before the error budget (one pooled noise level, no baseline term,
    the fit's own Jacobian, the alignment of E40's fit fixed): 85 and 88 at the fastest
    nodes unfiltered, E40 86 unfiltered."""
    estimates, truths, errors = coverage[(what, cfc)]
    inside = np.abs(estimates - truths) <= Z95 * errors
    rates = inside.mean(axis=0)
    assert np.all((rates >= BAND[0]) & (rates <= BAND[1])), rates


@pytest.mark.parametrize("cfc", [None, 600])
def test_a_node_stated_below_0_7_percent_is_within_2_percent(coverage, cfc):
    """A node whose standard error is below 0.7 % lies within 2 % of the truth on every seed
    (2 % is 2.9 of those errors; measured at most 1.6 %)."""
    estimates, truths, errors = coverage[("law", cfc)]
    tight = errors / truths < 0.007
    assert tight.sum() > 100  # most of the middle nodes
    assert np.max(np.abs(estimates / truths - 1)[tight]) <= 0.02


def _fit(J, r):
    return SimpleNamespace(jac=np.asarray(J, float), fun=np.asarray(r, float),
                           x=np.zeros(np.shape(J)[1]))


def test_the_error_budget_is_the_sandwich_of_a_linear_fit():
    """A straight line fitted to two shots' blocks: the errors are those of the closed form
    (J^T J)^-1 J^T Sigma J (J^T J)^-1, Sigma holding each block's own noise variance (from its
    residuals, over its share of the degrees of freedom), its MA(1) correlation and a
    baseline's constant; the shares add up to 1."""
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
    start = 0
    for n, acf, offset in zip(rows, acfs, offsets, strict=True):
        block = slice(start, start + n)
        dof = n - 2 * n / sum(rows)
        s2 = float(r[block] @ r[block]) / dof
        toeplitz = np.eye(n) + acf[1] * (np.eye(n, k=1) + np.eye(n, k=-1)) if len(acf) > 1 \
            else np.eye(n)
        sigma[block, block] = s2 * toeplitz + offset ** 2
        start += n
    H = np.linalg.inv(J.T @ J)
    expected = np.sqrt(np.diag(H @ J.T @ sigma @ J @ H))
    assert errors == pytest.approx(expected, rel=1e-12)
    assert shares.sum(axis=1) == pytest.approx(1.0, rel=1e-12)


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
