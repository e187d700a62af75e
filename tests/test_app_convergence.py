"""Issue 44: convergence as a function (airgun_xl.app.convergence.run) and as the Python API
(airgun_xl.convergence), driven without the CLI."""
import math

import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import OptionError

SHOT = airgun_xl.load(TEMPLATE)


def test_each_level_is_the_shot_run_at_that_step_and_the_step_recommended_follows():
    """Each level's peak is the shot run alone at that time step (the same kernel, bit for
    bit); each error is against the finest level; the step recommended is the coarsest
    whose error is within rtol."""
    outcome = airgun_xl.convergence(TEMPLATE, ["10us", "5us", "2us", "1us"],
                                    integrators=["legacy", "newmark"], rtol="1e-3")
    assert [lad.integrator for lad in outcome.ladders] == ["legacy", "newmark"]
    for lad in outcome.ladders:
        deltas = [lv.delta for lv in lad.levels]
        assert deltas == [1e-5, 5e-6, 2e-6, 1e-6]
        finest = lad.levels[-1].figures["peak_kg"]
        for lv in lad.levels:
            alone = SHOT.with_params(delta=lv.delta).run(integrator=lad.integrator, track=())
            assert lv.figures["peak_kg"] == alone.peak_kg
            assert lv.errors["peak_kg"] == pytest.approx(abs(lv.figures["peak_kg"] - finest)
                                                        / abs(finest), rel=1e-12)
        within = [lv.delta for lv in lad.levels[:-1] if lv.errors["peak_kg"] <= 1e-3]
        expected = max(within) if within else math.nan
        assert outcome.recommended[lad.integrator] == expected or (
            math.isnan(expected) and math.isnan(outcome.recommended[lad.integrator]))
    assert outcome.files == () and outcome.warnings == ()


def test_the_command_prints_the_functions_ladder(tmp_path, capsys):
    out = tmp_path / "c.xlsx"
    outcome = airgun_xl.convergence(TEMPLATE, "10us,5us", output=out)
    assert out in outcome.files and out.is_file()
    assert main(["convergence", str(TEMPLATE), "--levels", "10us,5us", "-o",
                 str(tmp_path / "d.xlsx")]) == 0
    printed = capsys.readouterr().out
    level = outcome.ladders[0].levels[0]
    assert f"{level.figures['peak_kg']:10.5f}" in printed


@pytest.mark.parametrize("given, said", [
    ({"levels": "10us"}, "levels: found '10us', expected at least two time steps"),
    ({"levels": "10us,5us", "rtol": "2"}, "rtol: found '2', expected a number between"),
    ({"levels": "10 furlongs,5us"}, "levels: found"),
    ({"levels": [1e-5, -5e-6]}, "levels: found [1e-05, -5e-06], expected positive time"),
    ({"integrators": ["legacy", "rk4"]}, "integrators: found 'rk4', expected one of "),
])
def test_bad_keywords_are_one_line_and_write_nothing(given, said, tmp_path):
    with pytest.raises(OptionError) as caught:
        airgun_xl.convergence(TEMPLATE, output=tmp_path / "c.xlsx", **given)
    assert str(caught.value).startswith(said) and "\n" not in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_the_command_line_names_the_flags(tmp_path, capsys):
    """The same refusals on the command line name the options: the request's field read by
    the same grammar, its keyword replaced by the flag (one line, exit 2, nothing written)."""
    for argv, said in ((["--levels", "10us"], "--levels: found '10us', expected at least"),
                       (["--levels", "10us,5us", "--rtol", "2"], "--rtol: found '2'")):
        assert main(["convergence", str(TEMPLATE), "-o", str(tmp_path / "c.xlsx"),
                     *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert said in err and "\n" not in err, err
    assert list(tmp_path.iterdir()) == []
