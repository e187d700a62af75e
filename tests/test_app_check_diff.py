"""Issue 44: check, diff and template as functions (airgun_xl.app) and as the Python API
(airgun_xl.check, airgun_xl.diff, airgun_xl.template), driven without the CLI.

The legacy case is the report's appendix run as the macro filled it (legacy_reference/,
its input beside it): airgun-xl's fill of the input equals it to 1e-12 of each column's
largest magnitude, the brief's "equal"."""
import openpyxl
import pytest
from conftest import ROOT, TEMPLATE, template_with

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import OptionError

LEGACY = ROOT / "legacy_reference"


def test_check_says_shot_a_is_stable_and_a_coarse_step_is_not(tmp_path, capsys):
    fine = airgun_xl.check(TEMPLATE)
    assert fine.stable and fine.critical.ratio < 1
    assert fine.critical.ratio == pytest.approx(fine.params.delta / fine.critical.dt_crit,
                                                rel=1e-12)
    coarse = airgun_xl.check(template_with(tmp_path, E2=2 * fine.critical.dt_crit))
    assert not coarse.stable and coarse.critical.ratio == pytest.approx(2.0, rel=1e-9)
    assert main(["check", str(tmp_path / "shot.xlsx")]) == 2
    assert f"critical {coarse.critical.dt_crit:.4g} s" in capsys.readouterr().out


def test_diff_of_the_appendix_run_and_its_fill_is_the_same(tmp_path):
    out = tmp_path / "new.xlsx"
    assert main(["fill", str(LEGACY / "shot_a_appendix_5us_input.xlsx"), "-o", str(out)]) == 0
    outcome = airgun_xl.diff(LEGACY / "shot_a_appendix_5us_legacy.xlsx", out,
                             report=tmp_path / "r.xlsx")
    assert outcome.same and outcome.files == (tmp_path / "r.xlsx",)
    assert all(c.max_rel <= 1e-12 for c in outcome.report.columns)
    # a changed cell is seen: the run differs, and its input is named
    book = openpyxl.load_workbook(out)
    book.worksheets[0]["A28"] = 200
    book.save(tmp_path / "changed.xlsx")
    changed = airgun_xl.diff(LEGACY / "shot_a_appendix_5us_legacy.xlsx",
                             tmp_path / "changed.xlsx")
    assert not changed.same and changed.report.inputs
    with pytest.raises(OptionError, match=r"^rtol: found 'x', expected a number >= 0$"):
        airgun_xl.diff(out, out, rtol="x")


def test_template_writes_the_shot_a_workbook(tmp_path):
    written = airgun_xl.template(tmp_path / "t.xlsx")
    assert airgun_xl.load(written).params == airgun_xl.load(TEMPLATE).params
