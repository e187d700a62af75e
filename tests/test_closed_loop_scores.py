"""Issue 45: the arithmetic of the predictions' record (studies/closed_loop.py): the Brier
score and the reliability bands, against hand-computed cases, and the law's posterior as a
scatter entry."""
import math

import numpy as np
import pytest

from airgun_xl.crush_law import LEGACY_LAW
from airgun_xl.studies.acceptance import wilson_interval
from airgun_xl.studies.closed_loop import Band, LawUpdate, brier, law_scatter, reliability
from airgun_xl.studies.first_shot import LAW_FIELDS, LAW_SCALE


def test_the_brier_score_is_the_mean_squared_miss():
    assert brier([1.0, 0.0, 0.5], [True, False, True]) == pytest.approx(0.25 / 3, rel=1e-15)
    assert brier([0.9] * 10, [True] * 9 + [False]) == pytest.approx(
        (9 * 0.01 + 0.81) / 10, rel=1e-15)
    assert math.isnan(brier([], []))


def test_reliability_bands_count_each_prediction_once_and_close_the_last_band():
    predicted = [0.1, 0.55, 0.65, 0.9, 0.95, 1.0, 1.0]
    passed = [False, True, False, True, True, True, False]
    bands = reliability(predicted, passed)
    assert sum(b.shots for b in bands) == len(predicted)
    last = bands[-1]  # [0.95, 1.0], 1.0 included
    assert (last.low, last.high, last.shots, last.passed) == (0.95, 1.0, 3, 2)
    assert last.interval == wilson_interval(2, 3)
    assert last.mean_predicted == pytest.approx((0.95 + 1 + 1) / 3, rel=1e-15)
    assert bands[0].shots == 1 and bands[0].passed == 0


def test_a_band_is_honest_when_its_mean_prediction_is_inside_the_observed_interval():
    assert Band(0.9, 0.95, 100, 92, 0.92).honest
    assert not Band(0.9, 0.95, 100, 60, 0.92).honest
    assert not Band(0.9, 0.95, 0, 0, math.nan).honest


def test_the_laws_posterior_is_a_relative_scatter_of_its_scale():
    update = LawUpdate(LEGACY_LAW.scaled(1.1), LEGACY_LAW, 1.1, 0.011, 1, (243.5, 243.5),
                       None, "")
    assert law_scatter(update) == (LAW_SCALE, LAW_FIELDS, pytest.approx(0.01, rel=1e-12), True)
    unknown = LawUpdate(LEGACY_LAW, LEGACY_LAW, 1.0, math.nan, 1, (1.0, 1.0), None, "")
    assert law_scatter(unknown)[2] == 0.0
    assert update.warnings == [] and "optimistic" in unknown.warnings[0]


def test_design_confidence_judges_as_a_recording_is_judged_and_says_its_model_error():
    """Without a record named, P(PASS) judges every prediction through the default low-pass,
    as a recording of the shot is judged (issue 60: one rule, whatever the noise): nothing is
    said of quiet recordings; the study says the model's own error it drew (the prior: no
    archive given)."""
    from conftest import TEMPLATE

    import airgun_xl

    spec = {"peak": "9kG:10%", "duration": "5.3ms:10%"}
    found = airgun_xl.design(TEMPLATE, confidence=0.9, sd=["A28=1.5%"], shots=200, **spec)
    assert not any("quiet recording" in w for w in found.warnings)
    assert any("P(PASS) includes the model's own error, the prior" in line
               for line in found.lines)


def test_the_guns_scatter_is_the_factors_spread_less_the_fits_errors():
    """gun_scatter against the formula written out: s^2 = var(f, ddof 1) - mean(se^2), its
    95 % interval from the chi-square quantiles (scipy.stats.chi2) with n - 1 degrees of
    freedom; none under GUN_SHOTS; a factor at the fit's bound named in a warning."""
    from types import SimpleNamespace

    from scipy.stats import chi2

    from airgun_xl.studies.calibrate import VELOCITY_REACH
    from airgun_xl.studies.closed_loop import GUN_SHOTS, gun_scatter

    factors = np.array([1.012, 0.991, 1.004, 0.978, 1.021, 0.999, 1.008, 0.985])
    errors = np.full(8, 0.004)
    update = SimpleNamespace(launch=tuple((230.0, f, e) for f, e in zip(factors, errors,
                                                                        strict=True)))
    gun = gun_scatter(update)
    var = np.var(factors, ddof=1)
    assert gun.sd == pytest.approx(np.sqrt(var - 0.004 ** 2), rel=1e-12)
    assert gun.interval[0] == pytest.approx(np.sqrt(7 * var / chi2.ppf(0.975, 7) - 0.004 ** 2),
                                            rel=1e-12)
    assert gun.interval[1] == pytest.approx(np.sqrt(7 * var / chi2.ppf(0.025, 7) - 0.004 ** 2),
                                            rel=1e-12)
    assert gun.bias == pytest.approx(factors.mean() - 1, abs=1e-15) and not gun.warnings
    assert gun_scatter(SimpleNamespace(launch=update.launch[:GUN_SHOTS - 1])) is None
    off = SimpleNamespace(launch=(*update.launch[:7], (230.0, 1 + VELOCITY_REACH, 0.004)))
    said = gun_scatter(off).warnings
    assert len(said) == 1 and "shot 8 of the lot fitted a launch velocity 15%" in said[0]
