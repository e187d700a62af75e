"""Issue 18.3-4: the macro's unloading-force quirk, named where it fires, and the unloading
spring watched instead of refused. Legacy cases made with the runner: quirk_unload_jump,
quirk_unload_diverges (cases.json) and tier2_reached (unstable_cases.json)."""
import json

import numpy as np
import pytest
from conftest import CASES, REFERENCE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.engine.integrators import History
from airgun_xl.engine.stability import critical_time_step
from airgun_xl.engine.watch import (
    DIVERGING_STEPS,
    unloading_divergence,
    unloading_onsets,
    unloading_quirk,
)


def _params(name):
    return airgun_xl.load(REFERENCE / CASES[name]["input"]).params


def _history(defl, force=None):
    n = len(defl)
    none = [None] * 8
    h = History(np.arange(n) * 1e-6, np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                *none, np.nan, np.nan, 0.0)
    h.deflection = np.asarray(defl, dtype=float)
    h.force = None if force is None else np.asarray(force, dtype=float)
    return h


def test_onsets_follow_the_macros_branch():
    """Unloading is a deflection below the largest so far (maxmitdef, from 0): steps 0 and 1
    are not stepped; a plateau at the maximum is loading (d >= maxmitdef)."""
    defl = [np.nan, np.nan, 0.1, 0.2, 0.15, 0.1, 0.2, 0.25, 0.25, 0.2, 0.3, 0.29]
    assert unloading_onsets(np.array(defl)).tolist() == [4, 9, 11]


def test_quirk_names_the_second_onset_and_its_jump():
    defl = [np.nan, np.nan, 0.1, 0.2, 0.15, 0.2, 0.25, 0.2]
    force = [0, 0, 1e6, 1.1e6, 1.1e6, 1.2e6, 1.3e6, 5e9]
    quirk = unloading_quirk(_history(defl, force))
    assert (quirk.step, quirk.row, quirk.onsets) == (7, 9, 2)
    assert "row 9 " in str(quirk) and "from 1.3e+06 N to 5e+09 N" in str(quirk)
    assert unloading_quirk(_history(defl[:7], force[:7])) is None  # one unloading: no quirk


def test_divergence_is_growing_alternation_while_unloading():
    """A mode that alternates each step and grows by 1.5 a step, from step 20 of an unloading
    ramp, is found after DIVERGING_STEPS steps of it; the same alternation while loading, or
    one that decays, is not."""
    k = np.arange(60)
    ramp = np.where(k < 10, 0.01 * k, 0.1 - 0.001 * (k - 10))  # loads, then unloads
    wobble = np.where(k >= 20, 1e-6 * (-1.5) ** (k - 20), 0.0)
    found = unloading_divergence(_history(ramp + wobble))
    assert found is not None and 20 + DIVERGING_STEPS - 2 <= found <= 20 + DIVERGING_STEPS + 1
    decaying = np.where(k >= 20, 1e-6 * (-0.9) ** (k - 20), 0.0)
    assert unloading_divergence(_history(ramp + decaying)) is None
    loading = 0.01 * k + np.where(k >= 20, 1e-6 * (-1.5) ** (k - 20), 0.0) * 1e-3
    assert unloading_divergence(_history(loading)) is None


@pytest.mark.parametrize("name", sorted(CASES))
def test_no_legacy_case_is_said_to_diverge(name):
    """No run the macro completed sanely oscillates the watch's way."""
    try:
        result = airgun_xl.load(REFERENCE / CASES[name]["input"]).run(track=())
    except airgun_xl.AirgunXlError:
        return  # the error cases are refused before the watch
    assert unloading_divergence(result.history) is None


def test_quirk_jump_case_warns_and_compares_continuous(tmp_path, capsys):
    """quirk_unload_jump (equal to the macro, test_legacy_cases.py): the terminal names the
    quirk and its row; the Summary carries the same warnings and the peak without it."""
    import openpyxl

    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / CASES["quirk_unload_jump"]["input"]), "-o",
                 str(out), "--host", "calc"]) == 0
    err = capsys.readouterr().err
    assert "unloading-force quirk" in err and "row 1,036 " in err
    assert "from 1.619e+06 N to 5.13e+09 N" in err
    ws = openpyxl.load_workbook(out, read_only=True)["Summary"]
    cells = [c for row in ws.iter_rows(values_only=True) for c in row if c is not None]
    assert any(isinstance(c, str) and "unloading-force quirk" in c for c in cells)
    i = cells.index("Peak acceleration, continuous unloading")
    smooth = _params("quirk_unload_jump").replace(unloading="continuous")
    assert cells[i + 1] == pytest.approx(airgun_xl.Shot(smooth).run(track=()).peak_kg,
                                         rel=1e-12)


def test_continuous_unloading_has_no_jump():
    """With unloading="continuous" the force at every unloading onset is within the crush law's
    step-to-step change of the step before (here 2 %), where the macro's jumps 3,000-fold."""
    p = _params("quirk_unload_jump")
    for unloading, bound in (("continuous", 1.02), ("macro", None)):
        h = airgun_xl.Shot(p.replace(unloading=unloading)).run().history
        ratios = [h.force[k] / h.force[k - 1] for k in unloading_onsets(h.deflection)]
        if bound is None:
            assert max(ratios) > 3000
        else:
            assert len(ratios) >= 2 and max(ratios) <= bound


def test_quirk_that_diverges_runs_on_as_the_macro_and_is_named(capsys, tmp_path):
    """quirk_unload_diverges passes the physical bound at row 618 after the quirk at row 486:
    fill runs on as the macro does (equal to it, test_legacy_cases.py) and names the quirk as
    the cause, never the crush, and says that the run without it diverges too."""
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / CASES["quirk_unload_diverges"]["input"]), "-o",
                 str(out), "--host", "calc", "--only", "summary"]) == 0
    err = capsys.readouterr().err
    assert "unloading-force quirk" in err and "row 486 " in err
    assert "from row 618 the displacements pass" in err and "the run crushed" not in err
    # the same shot without the quirk diverges as well: the quirk is not blamed alone
    assert "fails too, so the quirk is not the only cause" in err


def test_a_shot_unstable_only_while_unloading_that_never_unloads_runs():
    """unloading_unstable_never_unloads: E2 is 1.2 x the unloading spring's critical step at
    full length, 0.19 x the OBR chain's. It used to be refused; the macro's run is sane, and
    fill runs it (equal to the macro, test_legacy_cases.py) with the tier's warning."""
    p = _params("unloading_unstable_never_unloads")
    crit = critical_time_step(p)
    assert crit.ratio < 0.2 and p.delta > 1.19 * crit.dt_unloading
    assert crit.verdict == "unstable while unloading"
    run = airgun_xl.Shot(p).run()
    assert len(unloading_onsets(run.history.deflection)) == 0
    fine = airgun_xl.Shot(p.replace(delta=p.delta / 8)).run(track=())
    assert run.peak_kg == pytest.approx(fine.peak_kg, rel=0.03)  # measured 2.3 %: first order


def test_chain_unstable_is_still_refused_first(capsys, tmp_path):
    """The OBR chain acts on every step: above its critical step nothing runs."""
    case = json.loads((REFERENCE / "unstable_cases.json").read_text())["chain_just_unstable"]
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(tmp_path / "o.xlsx")]) == 2
    assert "set by the OBR chain's stiffest mode" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(CASES))
def test_kernel_counts_the_onsets_the_watch_finds(name):
    """The kernel's own count of unloading phases and the row of the second (for sweeps, whose
    batch keeps no deflection column) equal what the watch reads from the columns."""
    try:
        h = airgun_xl.load(REFERENCE / CASES[name]["input"]).run().history
    except airgun_xl.AirgunXlError:
        return
    onsets = unloading_onsets(h.deflection)
    assert h.stats.unloading_onsets == len(onsets)
    assert h.stats.second_onset == (onsets[1] if len(onsets) > 1 else -1)
