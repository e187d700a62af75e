"""Issue 18.2: implausible inputs and the sheet's quiet cells are named, on the terminal and in
the Summary, instead of giving figures with no flag."""
import json

import openpyxl
import pytest
from conftest import REFERENCE, TEMPLATE, template_with

import airgun_xl
from airgun_xl.cells import CELLS
from airgun_xl.cli import main
from airgun_xl.studies.check import plausibility


def _shot(tmp_path, **cells):
    return template_with(tmp_path, **cells)


def _fill(tmp_path, capsys, **cells):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(_shot(tmp_path, **cells)), "-o", str(out), "--only",
                 "summary"]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines()
                if line.startswith("airgun-xl: warning: ")]
    ws = openpyxl.load_workbook(out, read_only=True)["Summary"]
    summary = {r[0]: r[1] for r in ws.iter_rows(values_only=True) if r and r[0]}
    return warnings, summary


def test_the_template_is_plausible_everywhere():
    assert plausibility(airgun_xl.load(TEMPLATE).params) == []


def test_every_legacy_case_is_plausible_but_the_random_and_extreme_ones():
    """The report's cases sit inside every range (so a range is not a false alarm there)."""
    for name in ("shot_a_appendix_5us", "shot_a_published_5us", "low_velocity_60",
                 "moving_mem_unequal_v", "tiny_wedge", "wedge_only_15"):
        p = airgun_xl.load(REFERENCE / f"{name}_input.xlsx").params
        assert plausibility(p) == [], name


def test_yield_stress_in_psi_is_named_and_so_is_the_negative_length(tmp_path, capsys):
    """E40 = 3920 (shot A's 27.03 MPa typed in psi): the mitigator is crushed past its length
    and the Summary shows a negative final length; E40's magnitude, the crush past the end and
    the negative length are each a warning naming its cell, on the terminal and the Summary."""
    warnings, summary = _fill(tmp_path, capsys, E40=3920)
    text = "\n".join(warnings)
    assert "E40 (Yield Stress): 3920 Pa is below the" in text
    assert "E19 (Length of Cylindrical Part): the mitigator is crushed by" in text
    assert "is negative, which no real mitigator reaches" in text
    assert summary["Final mitigator length"] < 0
    assert summary[f"Warnings ({len(warnings)})"] is None  # the heading row, then each warning
    ws_text = [k for k in summary if isinstance(k, str)]
    for line in warnings:
        assert line.removeprefix("airgun-xl: warning: ") in ws_text
    # the figures those warnings doubt are flagged where they are shown
    ws = openpyxl.load_workbook(tmp_path / "o.xlsx")["Summary"]
    notes = {r[0].value: (r[3].value or "", r[1].fill.fgColor.rgb) for r in ws.iter_rows()
             if r[0].value}
    for label, cells in (("Final mitigator length", "E40, E19"), ("Maximum crush", "E40, E19"),
                         ("Peak acceleration (raw)", "E40;")):  # E19 doubts the crush only
        assert notes[label][0].startswith(f"DOUBTED: see the warnings on {cells}"), label
        assert notes[label][1].endswith("FFC7CE")
    assert not notes["OBR chain natural frequency 1 (initial masses)"][0].startswith("DOUBTED")


@pytest.mark.parametrize("cell", [c for c in CELLS if c.plausible], ids=lambda c: c.address)
def test_each_range_names_its_cell(cell):
    """Every cell with a range warns, naming itself alone, for a value 1000 times below its
    lower end (or the cell's smallest accepted non-zero value, its floor)."""
    p = airgun_xl.load(TEMPLATE).params
    value = getattr(p, cell.name)
    sign = -1.0 if value < 0 else 1.0
    low = sign * max(cell.plausible[0] / 1e3, cell.floor or 0.0)
    if cell.address == "E6":
        p = p.replace(delta=low / 10)  # E2 no longer than E6
    found = plausibility(p.replace(**{cell.name: low}))
    assert [f.cell for f in found] == [cell.address]
    assert "below the" in found[0].message


def test_k1_is_said_to_be_unused_when_it_holds_a_value(tmp_path, capsys):
    """The macro never reads A6 (K1): any value there gives the same run (A6 = -2e12 equals
    the template, column for column), and fill says so; the template leaves it blank and
    says why on the sheet."""
    plain = airgun_xl.load(TEMPLATE)
    assert plain.warnings == [] and plain.source.block.get((6, 1), (None, None))[0] is None
    assert "K1 (A6) is not used" in plain.source.block[(7, 1)][0]
    odd = airgun_xl.load(_shot(tmp_path, A6=-2e12))
    assert odd.params == plain.params
    assert any(w.startswith("A6 (K1): holds -2000000000000, which the macro never reads")
               for w in odd.warnings)


def test_blank_test_item_runs_three_masses_where_the_macro_stops(tmp_path, capsys):
    """D2 and C6 blank: the macro stops with "Division by zero" (the runner's output); fill
    runs the 3-mass model and says so, naming D2."""
    case = json.loads((REFERENCE / "reduced_model_cases.json").read_text())[
        "no_test_item_blank"]
    legacy = openpyxl.load_workbook(REFERENCE / case["legacy_output"], read_only=True)
    assert legacy.worksheets[0]["AZ1"].value == case["macro_error"]
    legacy.close()
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "D2 (M33): D2 and C6 are blank: airgun-xl runs the 3-mass model, where the macro " \
           "itself stops with 'Division by zero'" in err
