"""Issue 63: each figure's uncertainty, from what the recording shows, and the decision rule
a verdict applies (ILAC-G8: simple or guarded acceptance).

The standard uncertainty u of the peak and the duration (airgun_xl/studies/acceptance.py,
standard_uncertainties) is checked by Monte Carlo: on 200 simulated recordings of a known
pulse at a known noise, its expanded U = 2u covers the true value (the noise-free pulse judged
on a grid of 0.1 us) at about 95 %, inside the binomial 95 % band of 200 draws."""
import math

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE
from scipy.signal import bessel, sosfreqz
from scipy.stats import binom

import airgun_xl
from airgun_xl.specification import from_keys
from airgun_xl.studies.acceptance import (
    LOWPASS_ORDER,
    judge_record,
    lowpass_hz,
    noise_gain,
)

RECORDING = TEMPLATE.parent / "shot_a_recording.csv"
SPEC = from_keys({"peak": "12kG", "peak_tolerance": "10%", "duration": "5ms",
                  "duration_tolerance": "10%"}, "test", lambda key: key, None)
D, P = 5e-3, 12.0


def _half_sine(t):
    return np.where((t >= 0) & (t <= D), P * np.sin(np.pi * np.clip(t / D, 0, 1)), 0.0)


@pytest.mark.parametrize("rate, noise", [(50_000.0, 0.12), (20_000.0, 0.36)])
def test_the_expanded_uncertainty_covers_the_true_value_at_95_percent(rate, noise):
    """A 12 kG, 5 ms half-sine, recorded at ``rate`` with white noise of ``noise`` kG (1 %
    and 3 % of its peak) from a random sampling phase (seed 11), 200 times: the count whose
    value lies within U of the truth lies in binom(200, 0.95)'s 95 % interval, for the peak
    and the duration alike."""
    fine = np.arange(-0.005, 0.015, 1e-7)
    truth = {c.name: c.value for c in judge_record(fine, _half_sine(fine), SPEC, "truth",
                                                   noise=0.0).criteria}
    rng = np.random.default_rng(11)
    covered = {"peak": 0, "duration": 0}
    for _ in range(200):
        t = np.arange(-0.005 + rng.uniform(0, 1) / rate, 0.015, 1 / rate)
        x = _half_sine(t) + rng.normal(0.0, noise, len(t))
        for c in judge_record(t, x, SPEC, "r", noise=noise).criteria:
            assert math.isfinite(c.expanded) and c.expanded > 0
            covered[c.name] += abs(c.value - truth[c.name]) <= c.expanded
    low, high = binom.interval(0.95, 200, 0.95)
    for name, count in covered.items():
        assert low <= count <= high, (name, count, (low, high))


@pytest.mark.parametrize("rate", [20_000.0, 51_200.0, 1e6])
def test_the_noise_gain_is_the_filters_white_noise_gain(rate):
    """sqrt(sum h^2) of the default low-pass run both ways, against the frequency domain:
    sqrt(mean |H|^4) over 2^18 frequencies up to Nyquist (scipy's sosfreqz); 1e-3 relative
    (the grid's quadrature). The unfiltered record keeps all of it."""
    dt = 1 / rate
    hz = lowpass_hz(SPEC, D)
    sos = bessel(LOWPASS_ORDER, hz, fs=rate, output="sos", norm="mag")
    _w, h = sosfreqz(sos, worN=2 ** 18)
    expected = math.sqrt(float(np.mean(np.abs(h) ** 4)))
    assert noise_gain(SPEC, dt, D) == pytest.approx(expected, rel=1e-3)
    raw = from_keys({"peak": "12kG", "record": "unfiltered"}, "test", lambda key: key, None)
    assert noise_gain(raw, dt, D) == 1.0


def test_the_decision_rule_calls_a_value_within_u_of_its_limit(tmp_path):
    """Shot A's recording against 9 kG ±3 %: its peak (8.7757 kG, 0.046 kG above the low
    limit) lies within its U (0.14 kG): simple acceptance passes it, marked; guarded fails
    it, said; the duration, far from its limits, passes under both. The rule is stated; U
    is on the terminal and in the Verdict sheet."""
    kw = {"sign": -1, "peak": "9kG:3%", "duration": "4.8ms:10%"}
    simple = airgun_xl.accept(TEMPLATE, RECORDING, output=tmp_path / "s.xlsx", **kw)
    guarded = airgun_xl.accept(TEMPLATE, RECORDING, decision_rule="guarded", **kw)
    for outcome, word in ((simple, "PASS"), (guarded, "FAIL")):
        peak, duration = outcome.verdict.criteria
        assert peak.gap() < peak.expanded < 4 * peak.gap()
        assert peak.word == word and duration.word == "PASS"
        assert duration.gap() > duration.expanded
    assert "judged as measured (simple acceptance)" in simple.verdict.criteria[0].detail
    assert "not accepted (guarded acceptance)" in guarded.verdict.criteria[0].detail
    assert any(d.startswith("decision rule: simple acceptance (ILAC-G8)")
               for d in simple.verdict.definitions)
    assert any(d.startswith("decision rule: guarded acceptance (ILAC-G8)")
               for d in guarded.verdict.definitions)
    sheet = openpyxl.load_workbook(tmp_path / "s.xlsx")["Verdict"]
    details = [r[7].value for r in sheet.iter_rows() if r[0].value == "peak"]
    assert details and details[0].startswith(
        f"U = {simple.verdict.criteria[0].expanded:.3g} kG (k = 2)")
