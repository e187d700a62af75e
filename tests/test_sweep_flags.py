"""Issue 18.1 and 18.7: a sweep's and a Monte Carlo's shots carry the warnings a fill of each
would print, in a flags column, a count and a Warnings sheet; a deviation without its % is
refused."""
import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import OptionError
from airgun_xl.studies.check import after_run, before_run
from airgun_xl.studies.sweep import grid, monte_carlo, parse_sd, parse_vary

SHOT = airgun_xl.load(TEMPLATE).params.replace(delta=5e-6, filter_frequency=2e4)


def test_each_shot_says_what_its_fill_says():
    """Over v0 = 100..300 m/s (shot A at 5 us), each shot's flags name the cells its own fill's
    warnings name (before and after the run; the stability verdict is the base shot's)."""
    result = grid(SHOT, [parse_vary("A28=100:300:9")])
    assert sum(1 for f in result.flags if f) >= 2  # 275 and 300 m/s pass the law's 250
    for v, flags in zip(result.values[:, 0], result.flags, strict=True):
        p = SHOT.replace(v31=v, v32=v, v33=v)
        alone = airgun_xl.Shot(p).run()
        said = [str(f) for f in before_run(p)[1] + after_run(alone) if f.level == "warning"]
        assert {t.split(" ")[0] for t in flags} == {t.split(" ")[0] for t in said}, v


def test_a_quirk_in_a_sweep_is_flagged_by_its_row():
    """The soft-spring shot that unloads twice (tests/test_numerics.py) is flagged E31 with
    the row the kernel counted, as the fill's own warning names it."""
    p = SHOT.replace(k2=-1e6, delta=5e-7, filter_frequency=6250.0)
    result = grid(p, [parse_vary("E43=0.02:0.02:1")])
    quirk = [t for t in result.flags[0] if t.startswith("E31")]
    alone = airgun_xl.Shot(p).run()
    row = alone.history.stats.second_onset + 2
    assert len(quirk) == 1 and f"at row {row:,}," in quirk[0]


def test_sweep_workbook_has_the_flags_and_the_terminal_counts_them(tmp_path, capsys):
    out = tmp_path / "s.xlsx"
    assert main(["sweep", str(TEMPLATE), "--vary", "A28=100:260:161", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "airgun-xl: warning: 11 of 161 shots have warnings, naming A28 (11 shots)" in err
    wb = openpyxl.load_workbook(out, read_only=True)
    rows = list(wb["Sweep"].iter_rows(values_only=True))
    head = rows[0]
    count, text = head.index("Warnings (count)"), head.index("Warnings")
    flagged = [r for r in rows[1:] if r[count]]
    assert len(flagged) == 11 and all(r[0] >= 250 for r in flagged)  # 250 passes it crushing
    assert all(r[text].startswith("A28 (") for r in flagged)
    sheet = [r for r in wb["Warnings"].iter_rows(values_only=True)]
    assert sheet[0][1].startswith("11 of 161 shots have warnings")


def test_a_monte_carlo_counts_its_flags(tmp_path):
    result = monte_carlo(SHOT, [parse_sd("A28=5%")], 200, seed=4)
    n, cells = result.flagged()
    over = sum(1 for v in result.values[:, 0] if v > 250)
    assert n == over and (cells == {"A28": over} if over else cells == {})


def test_an_absolute_deviation_without_its_percent_is_refused(tmp_path, capsys):
    """E40=3 is 3 Pa on 2.7e7 Pa: its spread would be 0 to every digit shown."""
    with pytest.raises(OptionError, match=r"--sd: found E40=3, a deviation of 3 Pa on E40's "
                                          r"2\.703e\+07 Pa .*expected a percentage such as "
                                          "E40=3%"):
        monte_carlo(SHOT, [parse_sd("E40=3")], 10, seed=1)
    out = tmp_path / "m.xlsx"
    assert main(["sweep", str(TEMPLATE), "--mc", "10", "--sd", "E40=3", "-o", str(out)]) == 2
    assert not out.exists()
    assert capsys.readouterr().err.count("\n") == 1
    monte_carlo(SHOT, [parse_sd("E40=8e5")], 10, seed=1)  # an absolute spread that moves it
