"""Issue 12 (first part): the J211 CFC filter and the shock response spectrum, against their
closed forms."""
import math

import numpy as np
import pytest
from scipy import signal

from airgun_xl.errors import OptionError
from airgun_xl.studies.shock import (
    CFC_CLASSES,
    cfc_coefficients,
    cfc_filter,
    default_frequencies,
    srs,
)


@pytest.mark.parametrize("cfc", CFC_CLASSES)
def test_cfc_response_is_in_the_j211_corridor(cfc):
    """Forward and backward, the gain is |H|^2: flat in the pass band (within 0.01 dB at a
    tenth of the class), -0.45 dB at the class (J211 allows +0.5/-1 dB there) and -3 dB at
    5/3 of it (to 0.05 dB), and steep beyond (below -50 dB at ten times the class)."""
    dt = 1e-5
    b, a = cfc_coefficients(cfc, dt)
    _, h = signal.freqz(b, a, worN=[0.1 * cfc, cfc, cfc * 5 / 3, 10 * cfc], fs=1 / dt)
    gain = 20 * np.log10(np.abs(h) ** 2)
    assert abs(gain[0]) < 0.01
    assert -1.0 <= gain[1] <= 0.5
    assert gain[2] == pytest.approx(-3.0, abs=0.05)
    assert gain[3] < -50


def test_cfc_filter_is_phaseless():
    """A symmetric pulse keeps its peak where it was: forward and backward cancel the phase."""
    dt = 1e-5
    t = np.arange(0, 0.02, dt)
    pulse = np.exp(-((t - 0.01) / 1e-3) ** 2)
    out = cfc_filter(pulse + 0.05 * np.sin(2 * np.pi * 20_000 * t), dt, 600)
    assert t[np.argmax(out)] == pytest.approx(0.01, abs=dt)
    assert np.max(out) == pytest.approx(1.0, rel=0.01)  # the 20 kHz ringing is gone


def _half_sine_maximax(amplitude, duration, fn):
    """Undamped maximax SRS of a half-sine pulse, closed form. During the pulse the absolute
    response is A/(1 - b^2) (sin(Wt) - b sin(wn t)), b = W/wn, W = pi/T (evaluated densely);
    after it, the free vibration's amplitude is A 4r |cos(pi r)| / |4r^2 - 1|, r = fn T."""
    W, wn = math.pi / duration, 2 * math.pi * fn
    beta = W / wn
    t = np.linspace(0, duration, 200_001)
    primary = np.max(np.abs(amplitude / (1 - beta ** 2) * (np.sin(W * t) - beta
                                                           * np.sin(wn * t))))
    r = fn * duration
    residual = amplitude * 4 * r * abs(math.cos(math.pi * r)) / abs(4 * r * r - 1)
    return max(primary, residual)


def test_srs_of_a_half_sine_matches_the_closed_form():
    """A 1 ms half-sine of 10 kG sampled at 1 MHz, Q = 1e4 (nearly undamped): the SRS is within
    0.5 % of the undamped closed form from 50 Hz to 20 kHz (the ramp-invariant filter is exact
    for a piecewise-linear input; the 0.5 % covers the light damping and the sampling)."""
    dt, duration, amplitude = 1e-6, 1e-3, 10.0
    t = np.arange(0, duration + dt / 2, dt)
    pulse = amplitude * np.sin(np.pi * t / duration)
    freqs = np.array([50.0, 200.0, 400.0, 700.0, 1_000.0, 2_000.0, 5_000.0, 20_000.0])
    got = srs(pulse, dt, freqs, q=1e4)
    expected = [_half_sine_maximax(amplitude, duration, f) for f in freqs]
    np.testing.assert_allclose(got, expected, rtol=5e-3)


def test_srs_limits_and_bad_arguments():
    """At high frequency the SRS is the pulse's peak; a frequency past a tenth of the sample
    rate, or Q <= 0.5, is refused."""
    dt = 1e-6
    t = np.arange(0, 1e-3, dt)
    pulse = np.sin(np.pi * t / 1e-3)
    assert srs(pulse, dt, [50_000.0])[0] == pytest.approx(1.0, rel=0.01)
    with pytest.raises(OptionError, match="a tenth of the pulse.s sample rate"):
        srs(pulse, dt, [200_000.0])
    with pytest.raises(OptionError, match="quality factor"):
        srs(pulse, dt, [1000.0], q=0.4)
    f = default_frequencies(100, 10_000, 12)
    assert f[0] == 100 and f[-1] == pytest.approx(10_000) and len(f) == 81  # 6.64 octaves


def test_srs_command_writes_the_spectrum_of_the_predicted_pulse(tmp_path, capsys):
    import openpyxl
    from conftest import TEMPLATE

    import airgun_xl
    from airgun_xl.cli import main

    out = tmp_path / "srs.xlsx"
    assert main(["srs", str(TEMPLATE), "-o", str(out), "--cfc", "1000"]) == 0
    ws = openpyxl.load_workbook(out)["SRS table"]
    cells = list(ws.iter_rows(min_row=2, values_only=True))
    # three column groups of (frequency, g, kG), 27 rows each
    rows = [(r[c], r[c + 2]) for c in (0, 4, 8) for r in cells if r[c] is not None]
    freqs = np.array([r[0] for r in rows], dtype=float)
    result = airgun_xl.load(TEMPLATE).run(track=())
    pulse = cfc_filter(result.accel_kg[np.isfinite(result.accel_kg)], 5e-7, 1000)
    expected = srs(pulse, 5e-7, freqs)
    # xlsxwriter writes 16 significant digits: 1e-15 covers it
    np.testing.assert_allclose([r[1] for r in rows], expected, rtol=1e-15)
    assert len(rows) == 81 and freqs[0] == 100 and "largest" in capsys.readouterr().out


@pytest.mark.parametrize("args,start", [
    (["--cfc", "7"], "srs: argument --cfc: found '7', expected a J211 class (60, 180, 600 or "
                        "1000) or none"),
    (["--from", "5000", "--to", "100"], "--from/--to: found 5000 and 100 Hz"),
])
def test_srs_command_refuses_bad_options(tmp_path, capsys, args, start):
    from conftest import TEMPLATE

    from airgun_xl.cli import main

    out = tmp_path / "srs.xlsx"
    assert main(["srs", str(TEMPLATE), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"airgun-xl: error: {start}"] or err[0].startswith(
        f"airgun-xl: error: {start}")
    assert len(err) == 1 and not out.exists()


def test_srs_command_leaves_an_existing_output_alone(tmp_path, capsys):
    from conftest import TEMPLATE

    from airgun_xl.cli import main

    out = tmp_path / "srs.xlsx"
    out.write_bytes(b"an earlier result")
    assert main(["srs", str(TEMPLATE), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "already exists" in err[0] and "--force" in err[0]
    assert out.read_bytes() == b"an earlier result"


def test_the_srs_workbook_carries_the_runs_warnings(tmp_path, capsys):
    """The srs command gives the warnings a fill of the shot gives (here: E34 = 6,000 Hz makes
    1/(E2 E34) fractional), on the terminal and on the SRS sheet."""
    import openpyxl
    from conftest import template_with

    from airgun_xl.cli import main

    shot = template_with(tmp_path, E34=6000.0)
    out = tmp_path / "s.xlsx"
    assert main(["srs", str(shot), "-o", str(out)]) == 0
    printed = [line.removeprefix("airgun-xl: warning: ")
               for line in capsys.readouterr().err.splitlines()]
    assert any("E34" in w for w in printed)
    texts = [c for r in openpyxl.load_workbook(out)["SRS"].iter_rows(values_only=True)
             for c in r if isinstance(c, str)]
    assert all(w in texts for w in printed) and f"Warnings ({len(printed)})" in texts
