"""Issue 45: the proposal's setting is one the gun (and the ``--vary`` knob) can be set to.

``next --step A28=0.5`` rounds the best setting found to the gun's grid: of the settable
neighbours of the best (the multiple of the step below and the one above, each knob), the one
with the highest P(PASS) on the final round's draws. The best found between them is kept
(``unrounded``) and said wherever the setting is: the terminal, ``--json``, the next
workbook's Summary and the proposal.
"""
import json

import pytest
from conftest import TEMPLATE
from test_closed_loop import GUN, SHOTS, SPEC, fire

import airgun_xl
from airgun_xl.app.next_shot import NextRequest, lines
from airgun_xl.app.specifying import keyword_fields, resolve
from airgun_xl.archive.lots import proposals
from airgun_xl.errors import OptionError
from airgun_xl.studies.design import variable
from airgun_xl.studies.first_shot import (
    centred,
    draws,
    pass_probability,
    settable,
    solve_confidence,
)
from airgun_xl.studies.sweep import parse_sds

RANGE = (10.0, 260.0)  # [m/s] A28's search range (studies.design.VARIABLES)


def test_the_settable_neighbours_of_a_setting():
    """The multiples of the step below and above, as written (12 significant digits: 0.1's
    multiples read 244.1, not 244.10000000000002), within the range; a setting already on
    the grid is among them; a pair's knob without a step keeps its value."""
    assert settable(244.17, (0.5,), [RANGE]) == [244.0, 244.5]
    assert settable(244.17, (0.1,), [RANGE]) == [244.1, 244.2]
    assert settable(244.0, (0.5,), [RANGE]) == [244.0, 244.5]
    assert settable(259.9, (7.0,), [RANGE]) == [259.0]  # 266 is past the range
    assert settable((244.17, 0.0331), (0.5, None), [RANGE, (0.01, 0.1)]) == [
        (244.0, 0.0331), (244.5, 0.0331)]
    assert settable((244.17, 0.0331), (1.0, 0.002), [RANGE, (0.01, 0.1)]) == [
        (244.0, 0.032), (244.0, 0.034), (245.0, 0.032), (245.0, 0.034)]
    with pytest.raises(OptionError, match="--step: found a step of 300"):
        settable(12.0, (300.0,), [RANGE])


def test_the_best_settable_is_the_neighbour_most_likely_to_pass_on_the_same_draws():
    """Shot A, the gun's 1.5 %, 400 draws: with a step of 0.5 m/s the best found is the one
    found without steps (the same seeds: ``unrounded``); the setting chosen is one of its two
    settable neighbours, and its P(PASS) the higher of the two, each recomputed here on the
    final round's draws (seed + 1) by pass_probability, exactly; among them the one
    centred() proposes (within the best's error, nearest the middle)."""
    shot = airgun_xl.load(TEMPLATE)
    spec = resolve(shot, keyword_fields("test", SPEC))
    sds = parse_sds(GUN)
    v0 = variable("A28")
    free = solve_confidence(shot.params, spec, v0, sds, SHOTS, seed=1, keep_middle=False)
    stepped = solve_confidence(shot.params, spec, v0, sds, SHOTS, seed=1, keep_middle=False,
                               steps=(0.5,))
    assert stepped.unrounded == free.best and free.unrounded is None
    near = settable(free.best.setting, (0.5,), [RANGE])
    assert len(near) == 2 and free.best.setting not in near
    assert stepped.best.setting in near and (stepped.best.setting * 2).is_integer()
    drawn = draws(shot.params, sds, SHOTS, 2)
    again = {x: pass_probability(shot.params, spec, sds, SHOTS, 2, v0, x, drawn=drawn)
             for x in near}
    assert stepped.best.passes == again[stepped.best.setting].passes
    # the one centred() picks: within the best's Wilson bound, nearest the middle (issue 60)
    assert stepped.best.setting == centred(list(again.values()), spec).setting


def test_next_sets_the_gun_to_its_step_and_says_what_it_rounded(tmp_path):
    """A lot's first shot through next with --step A28=0.5: the next workbook's A28 is a
    multiple of 0.5 m/s within a step of the best found; the terminal, --json, the Summary
    and the proposal say the step and the best found between the steps with its P(PASS)."""
    shot = tmp_path / "shot1.xlsx"
    shot.write_bytes(TEMPLATE.read_bytes())
    fire(shot, tmp_path / "rec1.csv", seed=3)
    out = airgun_xl.next_shot(shot, tmp_path / "rec1.csv", archive=tmp_path / "arch",
                              lot="LOT-R", new_lot=True, sd=GUN, shots=SHOTS,
                              step="A28=0.5", **SPEC)
    assert (out.setting * 2).is_integer() and out.unrounded is not None
    assert abs(out.setting - out.unrounded.setting) < 0.5
    assert airgun_xl.load(out.output).params.v31 == out.setting
    said = (f"set to the knobs' steps (A28=0.5): the best between them, A28 = "
            f"{out.unrounded.setting:.6g} m/s, had P(PASS) = {out.unrounded.probability:.4f} "
            "on the same draws")
    request = NextRequest(shot, str(tmp_path / "rec1.csv"), tmp_path / "arch", "LOT-R",
                          step=("A28=0.5",))
    assert f"  {said}" in lines(request, out)
    assert json.loads(out.to_json())["next"]["unrounded"] == {
        "A28_m_s": out.unrounded.setting, "p_pass": out.unrounded.probability}
    record = proposals(tmp_path / "arch", "LOT-R")[-1][1]
    assert record["setting_A28"] == out.setting and record["step"] == ["A28=0.5"]
    assert record["unrounded"]["A28_m_s"] == out.unrounded.setting
    import openpyxl

    book = openpyxl.load_workbook(out.output, read_only=True)
    text = [str(c) for row in book["Summary"].iter_rows(values_only=True) for c in row if c]
    assert any(said in t for t in text)


def test_a_pair_is_set_on_both_knobs_grids():
    """--vary E13 with --step A28=0.5 and --step E13=0.001 (1 mm of the radius): the four
    settable neighbours of the best pair found are each run on the same draws, and the pair
    chosen is the one most likely to pass among them (shot A, 200 draws, the duration to
    10 %: the velocity alone cannot meet it on a stronger lot, so the radius moves)."""
    shot = airgun_xl.load(TEMPLATE)
    spec = resolve(shot, keyword_fields("test", {"peak": "8.5kG:5%",
                                                  "duration": "4.5ms:10%"}))
    found = solve_confidence(shot.params, spec, variable("A28"), parse_sds(GUN), 200, 1,
                             keep_middle=False, second=variable("E13"), steps=(0.5, 0.001))
    at = (found.unrounded.setting, found.unrounded.second)
    near = settable(at, (0.5, 0.001), [RANGE, variable("E13").bounds(shot.params)])
    assert len(near) == 4 and at not in near
    grid = found.tried[-4:]
    assert [(r.setting, r.second) for r in grid] == near
    assert (found.best.setting, found.best.second) in near
    chosen = centred(grid, spec)  # within the best's Wilson bound, nearest the middle
    assert (found.best.setting, found.best.second) == (chosen.setting, chosen.second)
    top = max(grid, key=lambda r: r.probability)
    assert found.best.probability >= top.interval[0]
