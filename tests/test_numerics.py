"""Issue 5: stability prediction, divergence detection, extreme cases, the Newmark integrator
and the convergence ladder."""
import math

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE, template_with

import airgun_xl
from airgun_xl import Shot, ShotParams
from airgun_xl.cli import main
from airgun_xl.engine.integrators import run_legacy
from airgun_xl.engine.stability import critical_time_step
from airgun_xl.errors import DivergenceError, OptionError
from airgun_xl.studies.convergence import default_ladder, ladder, parse_duration

SHOT_A = airgun_xl.load(TEMPLATE).params


def _diverges(p):
    try:
        run_legacy(p, track=())
    except DivergenceError:
        return True
    return False


@pytest.mark.parametrize("changes", [dict(k3=-5e11), dict(k2=-5e11), dict(m33=0.05), {},
                                     dict(k3=-5e11, zeta=0.0), dict(k3=-5e11, zeta=0.3)],
                         ids=["k3 stiff", "k2 stiff", "light test item", "shot A",
                              "undamped", "zeta 0.3"])
def test_prediction_within_5_percent_of_the_bisected_threshold(changes):
    """Bisect dt until the legacy scheme actually diverges (14 halvings: 0.01 % of the
    bracket); the prediction must be within 5 % below it (measured: 0.01-1.3 %)."""
    p = SHOT_A.replace(**changes)
    predicted = critical_time_step(p).dt_crit
    lo, hi = predicted * 0.5, predicted * 2
    assert not _diverges(p.replace(delta=lo)) and _diverges(p.replace(delta=hi))
    for _ in range(14):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _diverges(p.replace(delta=mid)) else (mid, hi)
    assert 0.95 <= hi / predicted <= 1.05


def test_single_mode_critical_step_matches_the_formula():
    """One undamped mode: 2/omega; with the macro's backward-difference damper the bound is
    (2 sqrt(1 + zeta^2) - 2 zeta)/omega (Jury's test on the step's characteristic
    polynomial). The chain of m31 alone against a huge m32 is one such mode."""
    from airgun_xl.engine.stability import _critical

    m, k, zeta = 2.0, 8.0e9, 0.05
    M = np.diag([1e12, m])
    K = k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    c = 2 * zeta * math.sqrt(k * m)
    C = c * np.array([[1.0, -1.0], [-1.0, 1.0]])
    omega = math.sqrt(k / m)
    dt, _ = _critical(M, C, K)
    assert dt == pytest.approx((2 * math.sqrt(1 + zeta ** 2) - 2 * zeta) / omega, rel=1e-6)
    dt0, _ = _critical(M, 0 * C, K)
    assert dt0 == pytest.approx(2 / omega, rel=1e-6)


def _stiff_shot(tmp_path, **cells):
    return template_with(tmp_path, **cells)


#: (id, cells changed, extra flags, verdict, cells that must be named in the messages)
EXTREME = [
    ("shot A", {}, [], "runs", set()),
    ("stiff k3, 5 us", {"C6": -5e11, "E2": 5e-6}, [], "refuses", {"E2"}),
    ("stiff k3, 5 us, allowed", {"C6": -5e11, "E2": 5e-6}, ["--allow-unstable"],
     "diverges-and-stops", set()),
    ("stiff k3, 5 us, newmark", {"C6": -5e11, "E2": 5e-6}, ["--integrator", "newmark"],
     "runs", set()),
    ("stiff k2, 5 us", {"B6": -5e11, "E2": 5e-6}, [], "refuses", {"E2"}),
    ("stiff k3, 3 us: marginal", {"C6": -5e11, "E2": 3e-6}, [], "warns", {"E2"}),
    ("masses 1e6 apart", {"D2": 1e-5}, [], "refuses", {"E2"}),
    ("masses 1e6 apart, tiny dt", {"D2": 1e-5, "E2": 1e-9, "E6": 5e-5}, [], "warns", {"D2"}),
    ("v0 = 400 m/s", {"A28": 400}, [], "warns", {"A28", "E19"}),
    ("v0 = 300 m/s bottoms out", {"A28": 300}, [], "warns", {"A28", "E19"}),
    ("v0 = 0", {"A28": 0}, [], "runs", set()),
    ("MEM faster than the bird", {"A27": 100, "A28": 60}, [], "runs", set()),
    ("E2 does not divide E6", {"E2": 7e-7}, [], "warns", {"E6"}),
    ("filter below one row", {"E34": 1e7}, [], "warns", {"E34"}),
    ("filter longer than the run", {"E34": 100}, [], "warns", {"E34"}),
    ("fractional samplerate", {"E34": 7000}, [], "warns", {"E34"}),
    ("zeta = 0", {"E43": 0}, [], "runs", set()),
    ("zeta = 0.5", {"E43": 0.5}, [], "runs", set()),
    ("crushed mass beyond the mitigator", {"E25": 1.0}, [], "warns", {"E25"}),
    ("no test item", {"D2": None, "C6": None, "A30": None}, [], "warns", {"D2"}),
    ("OBR as one mass", {"C2": None, "D2": None, "B6": None, "C6": None, "A29": None,
                         "A30": None}, [], "warns", {"C2"}),
    ("tiny wedge", {"E16": 5e-4}, [], "runs", set()),
    # a soft front spring lets the plate unload, reload and unload: the unloading quirk
    ("soft OBR spring", {"B6": -1e6}, [], "warns", {"E31"}),
]


@pytest.mark.parametrize("name,cells,flags,verdict,named", EXTREME,
                         ids=[case[0] for case in EXTREME])
def test_extreme_case(tmp_path, capsys, name, cells, flags, verdict, named):
    shot = _stiff_shot(tmp_path, **cells)
    out = tmp_path / "o.xlsx"
    code = main(["fill", str(shot), "-o", str(out), "--only", "summary", *flags])
    err = capsys.readouterr().err
    warnings = [line for line in err.splitlines() if line.startswith("airgun-xl: warning: ")]
    errors = [line for line in err.splitlines() if line.startswith("airgun-xl: error: ")]
    if verdict == "runs":
        assert code == 0 and not errors and not warnings and out.exists(), err
    elif verdict == "warns":
        assert code == 0 and not errors and warnings and out.exists(), err
    elif verdict == "refuses":
        assert code == 2 and len(errors) == 1 and not out.exists(), err
        assert "the largest safe time step is" in errors[0]
    else:  # diverges-and-stops
        assert code == 2 and len(errors) == 1 and not out.exists(), err
        assert "diverged at step" in errors[0] and "(t = " in errors[0]
    text = "\n".join(warnings + errors)
    for cell in named:
        assert f"{cell} (" in text, (cell, text)


def test_zero_velocity_gives_zero_response(tmp_path):
    result = airgun_xl.load(TEMPLATE).with_params(v31=0.0, v32=0.0, v33=0.0).run()
    assert np.all(result.history.y33 == 0) and result.peak_kg == 0


def test_stiff_case_is_bounded_and_converged_with_newmark():
    """k3 = -5e11 at 5 us: legacy diverges; Newmark stays bounded, and its peak is within
    1 % of the converged legacy answer (legacy at 5 ns): Newmark's own error at 5 us on
    shot A is 0.3 % (the convergence ladder), so 1 % leaves room for the stiffer chain."""
    p = SHOT_A.replace(k3=-5e11, delta=5e-6)
    with pytest.raises(DivergenceError):
        Shot(p).run()
    newmark = Shot(p).run(integrator="newmark")
    assert np.all(np.abs(newmark.history.y33) < 1.0)
    reference = Shot(p.replace(delta=5e-9)).run().peak_kg
    assert abs(newmark.peak_kg - reference) / reference < 0.01
    finer = Shot(p.replace(delta=1e-6)).run(integrator="newmark").peak_kg
    assert abs(finer - reference) < abs(newmark.peak_kg - reference)  # and it converges


def test_newmark_and_legacy_agree_as_dt_goes_to_zero():
    """At 10 ns and 5 ns the two schemes' difference is within their convergence errors
    (estimated by the change from 10 ns to 5 ns, as each scheme is first order)."""
    values = {}
    for integrator in ("legacy", "newmark"):
        for dt in (1e-8, 5e-9):
            r = Shot(SHOT_A.replace(delta=dt)).run(integrator=integrator)
            values[integrator, dt] = (r.peak_kg, float(np.nanmax(r.history.deflection)))
    for i in (0, 1):  # peak, max crush
        legacy, newmark = values["legacy", 5e-9][i], values["newmark", 5e-9][i]
        error = (abs(legacy - values["legacy", 1e-8][i])
                 + abs(newmark - values["newmark", 1e-8][i]))
        assert abs(legacy - newmark) <= error


def test_check_command(tmp_path, capsys):
    assert main(["check", str(TEMPLATE)]) == 0
    out = capsys.readouterr().out
    assert "ratio 0.019" in out and "stable" in out
    stiff = _stiff_shot(tmp_path, C6=-5e11, E2=5e-6)
    assert main(["check", str(stiff)]) == 2
    assert "unstable" in capsys.readouterr().out
    assert main(["check", str(stiff), "--integrator", "newmark"]) == 0


def test_newmark_is_stated_in_the_summary(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--only", "summary",
                 "--integrator", "newmark"]) == 0
    ws = openpyxl.load_workbook(out)["Summary"]
    rows = {r[0].value: [c.value for c in r[1:4]] for r in ws.iter_rows(min_row=2)}
    assert rows["Integrator"][0] == "newmark"
    # issue 46: n/a in the value column (no unit to cut it), the reason beside it
    assert rows["Critical time step"] == ["n/a", None, "none: the Newmark integrator is "
                                          "implicit in the OBR chain, so no step bounds it"]
    assert rows["Time step / critical"][:2] == ["n/a", None]  # not 0.000
    assert rows["Critical time step, unloading"][0] > 100  # µs: only the mitigator bounds it


def test_damped_relative_motion_against_the_closed_form():
    """No test item: m31 and m32 on the damped spring k2. Their relative motion is a damped
    oscillator, mu u'' + c2 u' + k2 u = 0, mu = m31 m32 / (m31 + m32). The macro's
    backward-difference damper is first order, so the error falls about in proportion to dt:
    below 1 % of the amplitude at 20 ns, and halving with dt."""
    p0 = SHOT_A.replace(m33=0.0, k3=0.0, v1=0.0, v31=0.0, v32=1.0, v33=1.0, max_time=5e-4,
                        sigmay=1e-12, E=1e-12, rho=1e-12)
    m31, m32, k, zeta = p0.m31, p0.m32, -p0.k2, p0.zeta
    mu = m31 * m32 / (m31 + m32)
    c = 2 * zeta * math.sqrt(k * (m31 + m32))
    wn = math.sqrt(k / mu)
    z = c / (2 * math.sqrt(k * mu))
    wd = wn * math.sqrt(1 - z * z)
    errors = []
    for dt in (4e-8, 2e-8):
        h = Shot(p0.replace(delta=dt)).run().history
        t = h.time[1:]
        u = (h.y32 - h.y31)[1:]
        exact = np.exp(-z * wn * t) * (1.0 / wd) * np.sin(wd * t)
        errors.append(np.max(np.abs(u - exact)) / np.max(np.abs(exact)))
    assert errors[1] < 0.01
    assert 1.6 < errors[0] / errors[1] < 2.4  # first order: about 2


def test_ladders_and_durations():
    assert parse_duration("500ns") == 5e-7 and parse_duration("2us") == 2e-6
    assert parse_duration("0.006") == 0.006
    # issue 23.11: an exponent and a unit (it appended "e-6" to "5e0", a regression)
    assert parse_duration("5e0us") == 5e-6 and parse_duration("4.5e0ms") == 0.0045
    with pytest.raises(OptionError):
        parse_duration("fast")
    assert default_ladder(5e-7) == [5e-7, 2e-7, 1e-7, 5e-8, 2e-8, 1e-8, 5e-9]
    assert default_ladder(3e-6)[:2] == [3e-6, 2e-6]


def test_convergence_ladder_on_a_short_shot():
    """Peak and crush converge: errors shrink toward the finest level, and the observed order
    of the crush is about 1 (the backward-difference damper and plastic front)."""
    shot = airgun_xl.load(TEMPLATE).with_params(max_time=1e-3)
    lad = ladder(shot, [4e-6, 2e-6, 1e-6, 5e-7, 2.5e-7])
    crush = [lv.errors["max_crush"] for lv in lad.levels[:-1]]
    assert all(a > b for a, b in zip(crush, crush[1:], strict=False))
    orders = [lv.order["max_crush"] for lv in lad.levels if "max_crush" in lv.order]
    assert 0.7 < np.median(orders) < 1.5
    assert not math.isnan(lad.recommended)  # some level meets 0.1 %


def test_convergence_command(tmp_path, capsys):
    shot = _stiff_shot(tmp_path, E6=1e-3)
    out = tmp_path / "c.xlsx"
    assert main(["convergence", str(shot), "-o", str(out), "--levels", "2us,1us,500ns,250ns",
                 "--integrator", "legacy", "--integrator", "newmark"]) == 0
    printed = capsys.readouterr().out
    assert "legacy integrator:" in printed and "newmark integrator:" in printed
    assert "coarsest dt with peak within 0.1%" in printed
    ws = openpyxl.load_workbook(out)["Convergence"]
    assert ws["A1"].value == "Integrator" and ws["B1"].value == "Time step (µs)"
    assert ws["B2"].value == pytest.approx(2.0, rel=1e-12)  # µs, as shown
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote {out} and {tmp_path / 'c.png'}" in printed


def test_convergence_without_matplotlib_says_it_wrote_no_png(tmp_path, capsys, monkeypatch):
    """Issue 44: without matplotlib (an extra) the workbook is written, the PNG is not, and
    the command says so instead of naming a PNG it did not write."""
    import sys

    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib raises
    out = tmp_path / "c.xlsx"
    assert main(["convergence", str(TEMPLATE), "-o", str(out), "--levels", "10us,5us"]) == 0
    captured = capsys.readouterr()
    assert f"wrote {out}\n" in captured.out and ".png" not in captured.out
    assert "matplotlib is not installed: no PNG" in captured.err
    assert out.is_file() and not (tmp_path / "c.png").exists()


def test_shot_params_for_the_reduced_model_check():
    p = ShotParams(**dict(SHOT_A.as_dict(), m33=0.0, k3=0.0)).check()
    assert p.bird_masses == 2


def test_the_closed_form_critical_step_agrees_with_the_bisection():
    """Issue 24.11: the critical step from eq. 1 (one eigen-solve) against the bisection on the
    spectral radius it replaced (60), over 200 random shots (stiffnesses and masses over four
    decades, zeta 0-0.6) at the three lengths the tiers use. The bisection stops where the
    radius passes 1 + RADIUS_TOLERANCE (1e-6), a little past the crossing: it may only be
    above the closed form, by at most 1e-6 relative."""
    from airgun_xl.engine import stability as st

    rng = np.random.default_rng(20261124)
    gaps = []
    for _ in range(200):
        p = SHOT_A.replace(k2=SHOT_A.k2 * 10 ** rng.uniform(-2, 2),
                           k3=SHOT_A.k3 * 10 ** rng.uniform(-2, 2), zeta=rng.uniform(0, 0.6),
                           m32=SHOT_A.m32 * 10 ** rng.uniform(-1, 1),
                           m33=SHOT_A.m33 * 10 ** rng.uniform(-2, 2))
        for length in (math.inf, st.full_length(p), st.compacted_length(p)):
            for m31, m1 in st._mass_range(p, 3):
                M, C, K = st._matrices(p, m31, m1, True, length)
                dt, omega = st._critical(M, C, K)
                gaps.append(st._bisected(M, C, K, omega) / dt - 1)
    assert len(gaps) == 1800
    assert -1e-12 <= min(gaps) and max(gaps) <= 1e-6
