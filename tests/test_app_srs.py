"""Issue 44: srs and compare-measured as functions (airgun_xl.app) and as the Python API
(airgun_xl.srs, airgun_xl.compare_measured), driven without the CLI."""
import numpy as np
import pytest
from conftest import TEMPLATE
from scipy import signal

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import OptionError

RECORDING = TEMPLATE.with_name("shot_a_recording.csv")


def test_the_spectrum_is_an_oscillators_response_by_an_independent_solver():
    """The maximax absolute acceleration of a single-degree-of-freedom oscillator (Q = 10)
    driven by shot A's pulse: scipy's lsim, first-order hold, is exact for a pulse linear
    between samples, as Smallwood's ramp-invariant filter is; they agree to round-off
    (measured 2e-10 at 100 Hz, where the response is slowest against the 5 us step)."""
    outcome = airgun_xl.srs(TEMPLATE)
    result = airgun_xl.load(TEMPLATE).run(track=())
    pulse = result.accel_kg[np.isfinite(result.accel_kg)]
    t = np.arange(len(pulse)) * result.params.delta
    zeta = 1 / (2 * 10.0)
    for k in (0, 40, 80):
        w = 2 * np.pi * outcome.frequencies[k]
        oscillator = signal.lti([2 * zeta * w, w * w], [1, 2 * zeta * w, w * w])
        _, response, _ = signal.lsim(oscillator, pulse, t, interp=True)
        assert outcome.levels[k] == pytest.approx(np.abs(response).max(), rel=1e-8)
    assert outcome.frequencies[0] == 100.0 and outcome.frequencies[-1] == pytest.approx(1e4)
    level, frequency = outcome.largest
    assert level == outcome.levels.max() and outcome.files == () and outcome.warnings == ()


def test_srs_keywords_are_the_commands_and_refusals_name_them(tmp_path, capsys):
    out = tmp_path / "s.xlsx"
    outcome = airgun_xl.srs(TEMPLATE, q="20", cfc=1000, lo=200, hi=5000, output=out)
    assert outcome.q == 20.0 and outcome.files == (out,) and out.is_file()
    assert main(["srs", str(TEMPLATE), "--srs-q", "20", "--cfc", "1000", "--from", "200",
                 "--to", "5000", "-o", str(tmp_path / "c.xlsx")]) == 0
    level, frequency = outcome.largest
    assert f"largest {level:.4f} kG at {frequency:,.0f} Hz" in capsys.readouterr().out
    # the function's refusals name its keywords, the command's its options (issue 61)
    for given, said, option in (({"q": 0}, "q: found '0'", ["--srs-q", "0"]),
                                ({"lo": 10, "hi": 5}, "lo/hi: found 10 and 5 Hz",
                                 ["--from", "10", "--to", "5"]),
                                ({"integrator": "rk4"}, "integrator: found 'rk4', expected "
                                                        "one of legacy, newmark", None)):
        with pytest.raises(OptionError) as caught:
            airgun_xl.srs(TEMPLATE, output=tmp_path / "x.xlsx", **given)
        text = str(caught.value)
        assert text.startswith(said), text
        if option is not None:  # the same words, the option named
            assert main(["srs", str(TEMPLATE), "-o", str(tmp_path / "y.xlsx"), *option]) == 2
            flag = "/".join(o for o in option if o.startswith("--"))
            rest = text.partition(": ")[2]
            assert capsys.readouterr().err == f"airgun-xl: error: {flag}: {rest}\n"
    assert not (tmp_path / "x.xlsx").exists() and not (tmp_path / "y.xlsx").exists()


def test_compare_measured_scores_the_recording_against_the_prediction(tmp_path, capsys):
    """The template's recording was made with E40 4 % above the workbook's: the measured peak
    is above the prediction, and each error is the prediction's against the test,
    predicted / measured - 1 (to round-off)."""
    outcome = airgun_xl.compare_measured(TEMPLATE, RECORDING, sign=-1, cfc=1000)
    c = outcome.comparison
    assert c.measured.peak_kg > c.predicted.peak_kg
    assert c.errors["peak_kg"] == pytest.approx(c.predicted.peak_kg / c.measured.peak_kg - 1,
                                                rel=1e-12)
    assert 0.0 < c.iso.overall <= 1.0 and 0.9 < c.correlation <= 1.0
    assert outcome.units == ("ms", "g") and outcome.models == ("4-mass", "rigid")
    assert outcome.files == ()
    assert main(["compare-measured", str(TEMPLATE), str(RECORDING), "--sign", "-1", "--cfc",
                 "1000", "-o", str(tmp_path / "c.xlsx")]) == 0
    assert (f"  peak {c.predicted.peak_kg:.4f} kG predicted, {c.measured.peak_kg:.4f} "
            "measured") in capsys.readouterr().out
    with pytest.raises(OptionError, match="^align: found 'best', expected one of "
                                          "threshold, xcorr$"):
        airgun_xl.compare_measured(TEMPLATE, RECORDING, align="best")
