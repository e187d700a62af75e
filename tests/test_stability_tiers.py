"""Issue 10: the two-tier stability verdict, against the macro's own runs.

legacy_reference/unstable_cases.json holds the runs the verdict refuses or stops, each made by
ArtSim in LibreOffice Calc; the runs it lets through (tier2_bounded, chain_just_stable) are
ordinary legacy cases in cases.json, compared column by column by test_legacy_cases.py.
"""
import json

import numpy as np
import pytest
from conftest import (
    CASES,
    LEGACY_RTOL,
    REFERENCE,
    column,
    columns_off_the_macro,
    macro_rows,
    sheet_values,
)

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.engine.integrators import displacement_bound
from airgun_xl.engine.stability import (
    _matrices,
    compacted_length,
    critical_time_step,
    full_length,
    spectral_radius,
)
from airgun_xl.errors import DivergenceError

UNSTABLE = json.loads((REFERENCE / "unstable_cases.json").read_text())


def _peak_kg(p):
    """Peak |acceleration| of the test item [kG], from a run of the legacy scheme."""
    return airgun_xl.Shot(p).run(track=()).peak_kg


def test_tiers_bracket_the_unloading_stiffness():
    """The first tier is the critical step at the full length, the second at the compacted
    length; the unstable length lies between, and the step matrix's spectral radius crosses 1
    there (the bisection's 2^-50 of the length, so 1e-9 is far above its error)."""
    p = airgun_xl.load(REFERENCE / CASES["tier2_bounded"]["input"]).params
    crit = critical_time_step(p)
    assert crit.dt_compacted < p.delta < crit.dt_crit
    assert compacted_length(p) < crit.unstable_length < full_length(p)
    assert crit.unstable_crush == pytest.approx(full_length(p) - crit.unstable_length, rel=1e-15)
    m1, m31 = p.m1 + p.mmitigator, p.m31  # the lightest m31 is the worst (measured)
    longer = _matrices(p, m31, m1, length=crit.unstable_length * (1 + 1e-9))
    shorter = _matrices(p, m31, m1, length=crit.unstable_length * (1 - 1e-9))
    assert spectral_radius(p.delta, *longer) <= 1 + 1e-6 < spectral_radius(p.delta, *shorter)


def test_chain_limited_shot_has_one_tier():
    """Shot A's OBR chain sets its step: the compacted mitigator changes it by under 0.1 %,
    so a step above it is refused, not deferred to a crush."""
    p = airgun_xl.load(REFERENCE / UNSTABLE["chain_just_unstable"]["input"]).params
    crit = critical_time_step(p)
    assert crit.dt_compacted == pytest.approx(crit.dt_crit, rel=1e-3)
    assert crit.ratio > 1 and crit.unstable_crush is None and crit.verdict == "unstable"


def test_bounded_tier2_run_is_accurate():
    """tier2_bounded (1.19 x the compacted step) crushes 0.225 m, short of the 0.438 m where
    its step becomes unstable: its peak is within 1 % of the same shot at E2/8 (measured
    0.6 %; the macro's own first-order error at this coarse step)."""
    p = airgun_xl.load(REFERENCE / CASES["tier2_bounded"]["input"]).params
    result = airgun_xl.Shot(p).run()
    crit = critical_time_step(p)
    assert result.history.stats.max_crush < crit.unstable_crush
    fine = p.replace(delta=p.delta / 8, max_time=p.max_time)
    assert result.peak_kg == pytest.approx(_peak_kg(fine), rel=0.01)


def test_bounded_tier2_fill_warns_with_the_crush(tmp_path, capsys):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / CASES["tier2_bounded"]["input"]), "-o", str(out),
                 "--only", "summary"]) == 0
    err = capsys.readouterr().err
    assert ("E2 (Timestep): 3e-05 s is stable for the OBR chain under the legacy scheme, but not "
            "for the mitigator's unloading spring (E13, E31, E16, E19) while it unloads once "
            "crushed by 0.4384 m (remaining length below 0.4629 m") in err
    assert out.exists()


def test_check_prints_both_tiers(capsys):
    assert main(["check", str(REFERENCE / CASES["tier2_bounded"]["input"])]) == 0
    out = capsys.readouterr().out
    assert "critical 0.0002635 s for the OBR chain" in out
    assert "critical 4.178e-05 s at full length" in out
    assert "2.513e-05 s fully compacted (length 0.3245 m" in out
    assert "unstable while unloading once crushed by 0.4384 m" in out


def test_quirk_not_the_crush_is_named_in_tier2_reached(tmp_path, capsys):
    """Issue 18.3: tier2_reached crushes 0.502 m, past the 0.438 m where its step is unstable
    unloading, and its macro peak is far from the same shot at E2/8. The cause is not the crush:
    it unloads, reloads and unloads again at row 177, where the macro's force jumps by 1e10 N.
    fill runs it as the macro does (equal to the macro's columns), names the quirk and the row,
    never the crush, and puts the run without the quirk beside it."""
    case = UNSTABLE["tier2_reached"]
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "unloading-force quirk" in err and "row 177 " in err
    assert "the run crushed" not in err and "the run diverges at" not in err
    legacy, new = sheet_values(REFERENCE / case["legacy_output"]), sheet_values(out)
    assert columns_off_the_macro(legacy, new) == []
    rows = macro_rows(legacy)
    p = airgun_xl.load(REFERENCE / case["input"]).params
    macro_peak = np.nanmax(np.abs(column(legacy, "U", rows)))
    assert macro_peak > 1.4 * _peak_kg(p.replace(delta=p.delta / 8))


def test_without_the_quirk_the_coarse_step_is_sane():
    """The same shot with a continuous unloading force: at its own coarse step (1.19 x the
    compacted critical step) it peaks within 2 % of the run at E2/8 (measured 1.1 %, the
    scheme's first-order error), where the macro's quirk gives 336 times that."""
    p = airgun_xl.load(REFERENCE / UNSTABLE["tier2_reached"]["input"]).params
    smooth = p.replace(unloading="continuous")
    coarse, fine = _peak_kg(smooth), _peak_kg(smooth.replace(delta=p.delta / 8))
    assert coarse == pytest.approx(fine, rel=0.02)
    assert _peak_kg(p) > 300 * coarse


def test_first_tier_refusal_is_where_the_macro_overflows(tmp_path, capsys):
    """chain_just_unstable (1.025 x the chain's step): fill refuses before running. The port,
    run anyway, detects divergence at a row where it still equals the macro's finite output
    (to 1e-12), beyond any physical displacement; the macro itself went on to overflow."""
    import openpyxl

    case = UNSTABLE["chain_just_unstable"]
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("airgun-xl: error: E2 (Timestep): 2.7e-05 s is 1.02 x the critical "
                          "time step of the legacy scheme") and not out.exists()
    legacy_wb = openpyxl.load_workbook(REFERENCE / case["legacy_output"], read_only=True)
    assert legacy_wb.worksheets[0]["AZ1"].value == case["macro_error"]
    legacy_wb.close()
    p = airgun_xl.load(REFERENCE / case["input"]).params
    with pytest.raises(DivergenceError) as caught:
        airgun_xl.Shot(p).run()
    legacy = sheet_values(REFERENCE / case["legacy_output"])
    row = caught.value.row + 2  # sheet row of the kernel's index
    for name, letter in (("Y1", "I"), ("Y31", "J"), ("Y32", "K"), ("Y33", "L")):
        assert caught.value.values[name] == pytest.approx(legacy[(row, letter)],
                                                          rel=LEGACY_RTOL, abs=1e-300)
    assert max(abs(v) for v in caught.value.values.values()) > displacement_bound(p)
