"""Issue 13: Sobol indices (SALib) of the peak, pulse and crush, and the Monte Carlo band's
convergence with the number of shots."""
import zipfile

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.studies.sensitivity import band_convergence, sobol
from airgun_xl.studies.sweep import parse_sd

pytest.importorskip("SALib")

SHOT = airgun_xl.load(TEMPLATE).params


def test_an_input_without_effect_has_zero_indices_and_the_other_takes_all():
    """E34 (the filter frequency) changes none of the raw peak, the pulse or the crush: its
    S1 and ST are exactly 0 (the estimators difference runs that equal each other). E40 is then
    the only active input: its S1 and ST are 1, within their 95 % confidence half-widths plus
    5 % for the estimator's own bias at N = 64."""
    found = sobol(SHOT, [parse_sd("E34=10%"), parse_sd("E40=3%")], 64, seed=3)
    assert found.cells == ["E34", "E40"] and len(found.shots.values) == 64 * 4
    for name, idx in found.indices.items():
        assert idx["S1"][0] == 0 and idx["ST"][0] == 0, name
        assert abs(idx["S1"][1] - 1) <= idx["S1_conf"][1] + 0.05, name
        assert abs(idx["ST"][1] - 1) <= idx["ST_conf"][1] + 0.05, name


def test_indices_rank_the_inputs_of_shot_a(tmp_path, capsys):
    """E40 +-3 %, E37 +-2 %, A28 +-1 %: the crush answers to the yield stress above all (its S1
    is the largest), and the indices of the peak add up to about 1 (the response is close to
    additive over these small spreads: within 0.15)."""
    out = tmp_path / "s.xlsx"
    assert main(["sweep", str(TEMPLATE), "--sobol", "128", "--sd", "E40=3%", "--sd", "E37=2%",
                 "--sd", "A28=1%", "--seed", "1", "-o", str(out)]) == 0
    ws = openpyxl.load_workbook(out)["Sensitivity"]
    assert ws["A1"].value.endswith("Seed of the draws: 1.")  # the study repeats from it
    rows = {}
    block = None
    for r in ws.iter_rows(min_row=3, values_only=True):
        if r[1] == "S1":
            block = r[0]
        elif block and r[0]:
            rows[(block, r[0].split()[0])] = r[1:5]
    crush = {cell: rows[("Maximum crush", cell)][0] for cell in ("E40", "E37", "A28")}
    assert max(crush, key=crush.get) == "E40"
    peak_sum = sum(rows[("Peak acceleration", c)][0] for c in ("E40", "E37", "A28"))
    assert abs(peak_sum - 1) < 0.15
    with zipfile.ZipFile(out) as z:
        charts = [z.read(n).decode() for n in z.namelist() if n.startswith("xl/charts/chart")]
    bars = [c for c in charts if "Sobol indices" in c]
    assert len(bars) == 3 and all("<c:errBars>" in c for c in bars)
    # issue 18.6: the error bars point at the +/- cells (columns C and E of each block), not
    # literal numbers; the peak's block is rows 4-6 of the sheet
    peak = next(c for c in bars if "Peak acceleration" in c)
    for column in ("C", "E"):
        ref = f"<c:f>'Sensitivity'!${column}$4:${column}$6</c:f>"
        assert peak.count(ref) == 2, column  # plus and minus
    assert "<c:numLit>" not in peak
    assert "Sobol indices of the peak: E40 S1" in capsys.readouterr().out


def test_band_convergence_is_the_percentiles_of_the_first_shots():
    values = np.random.default_rng(2).normal(12.0, 0.3, 1000)
    rows = band_convergence(values)
    assert rows[0, 0] == 10 and rows[-1, 0] == 1000 and np.all(np.diff(rows[:, 0]) > 0)
    for n, mean, p5, p95 in rows:
        first = values[:int(n)]
        assert (mean, p5, p95) == (first.mean(), np.percentile(first, 5),
                                   np.percentile(first, 95))


def test_monte_carlo_workbook_has_the_band_sheet(tmp_path):
    out = tmp_path / "mc.xlsx"
    assert main(["sweep", str(TEMPLATE), "--mc", "200", "--sd", "E40=3%", "--seed", "4",
                 "-o", str(out)]) == 0
    ws = openpyxl.load_workbook(out)["Band convergence"]
    rows = list(ws.iter_rows(min_row=2, values_only=True))
    assert rows[0][0] == 10 and rows[-1][0] == 200


@pytest.mark.parametrize("args,start", [
    (["--sobol", "100", "--sd", "E40=3%", "--sd", "E37=2%"], "--sobol: found 100, expected a "
                                                             "power of 2"),
    (["--sobol", "64", "--sd", "E40=3%"], "--sd: found 1, expected two or more"),
    (["--sobol", "64", "--mc", "10", "--sd", "E40=3%"], "--sobol: found it with --mc"),
    (["--sobol", "64"], "--sobol: found 64 without --sd"),
])
def test_bad_sobol_options(tmp_path, capsys, args, start):
    out = tmp_path / "o.xlsx"
    assert main(["sweep", str(TEMPLATE), *args, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"airgun-xl: error: {start}"), err
    assert not out.exists()


def test_without_salib_sobol_names_its_extra(tmp_path, capsys, monkeypatch):
    """Issue 24.10: SALib is an extra (it brings matplotlib, pandas and multiprocess); without
    it, --sobol is one line naming the extra, and nothing is written."""
    import sys

    for name in [m for m in sys.modules if m == "SALib" or m.startswith("SALib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "SALib", None)  # import SALib raises ImportError
    out = tmp_path / "s.xlsx"
    assert main(["sweep", str(TEMPLATE), "--sobol", "8", "--sd", "E40=3%", "--sd", "A28=2%",
                 "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pip install 'airgun-xl[sobol]'" in err
    assert not out.exists()
