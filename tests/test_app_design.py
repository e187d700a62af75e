"""Issue 44: design as a function (airgun_xl.app.design.run) and as the Python API
(airgun_xl.design), in its three modes, driven without the CLI."""
import openpyxl
import pytest
from conftest import TEMPLATE
from scipy.stats import binomtest

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import OptionError
from airgun_xl.studies.design import VARIABLES, solve_peak

SHOT = airgun_xl.load(TEMPLATE)


def test_a_target_peak_is_the_solvers_value_and_the_designed_shot_meets_it():
    """The function's v0 is solve_peak's, bit for bit (the same solver on the same shot);
    the designed shot, run alone, peaks at 8 kG to 1e-6 kG (brentq stops at 1e-12 m/s on a
    peak that moves about 0.06 kG per m/s there)."""
    outcome = airgun_xl.design(TEMPLATE, target_peak="8kG")
    expected = solve_peak(SHOT.params, 8.0, VARIABLES["A28"]).values[0]
    assert outcome.values == {"A28": expected} and outcome.mode == "target"
    run = outcome.designed.run()
    assert run.peak_kg == pytest.approx(8.0, abs=1e-6)
    assert outcome.designed.params.v31 == outcome.designed.params.v32 == expected
    assert outcome.lines[0] == f"A28..A30 = {expected:.6g} m/s"
    assert outcome.reached and outcome.files == () and outcome.filled is None


def test_the_designed_workbook_holds_the_solved_value_in_its_cells(tmp_path, capsys):
    out = tmp_path / "d.xlsx"
    outcome = airgun_xl.design(TEMPLATE, target_peak="8kG", output=out)
    assert outcome.files == (out,) and out.is_file()
    book = openpyxl.load_workbook(out, read_only=True)
    sheet = book.worksheets[0]
    assert [sheet[c].value for c in ("A28", "A29", "A30")] == [outcome.values["A28"]] * 3
    book.close()
    # the command prints what the function says, then the fill's summary
    assert main(["design", str(TEMPLATE), "--target-peak", "8kG", "-o",
                 str(tmp_path / "c.xlsx")]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[:2] == list(outcome.lines[:2])


def test_first_shot_success_says_its_probability_and_whether_it_reached_it():
    """P(PASS) is the share of passing shots, its interval Wilson's at 95 % on them (scipy's
    binomtest, an implementation of its own: to 1e-12, rounding); the
    same seed gives the same draws; not reaching P is said, as the CLI's exit 3."""
    given = dict(peak="12kG:10%", duration="5ms:10%", confidence=0.95,
                 sd=["A28=1.5%", "E40=5%"], shots=400, seed=3)
    outcome = airgun_xl.design(TEMPLATE, **given)
    again = airgun_xl.design(TEMPLATE, **given)
    best = outcome.confidence.best
    assert outcome.mode == "confidence" and again.values == outcome.values
    assert best.probability == again.confidence.best.probability
    assert best.probability == pytest.approx(best.passes / best.shots, rel=1e-12)
    wilson = binomtest(best.passes, best.shots).proportion_ci(0.95, method="wilson")
    assert best.interval == pytest.approx((wilson.low, wilson.high), rel=1e-12)
    assert not outcome.reached  # shot A's peak is too sensitive to the lot for +-10 %
    assert outcome.warnings[-1].startswith("design --confidence: no v0 in range reaches "
                                           "P(PASS) = 0.95; the best found is ")


@pytest.mark.parametrize("given, said", [
    ({"peak": "12kG:10%", "confidence": 0.95}, "--confidence: found no --sd"),
    ({"peak": "12kG:10%", "sd": "A28=1.5%"}, "--sd: found without --confidence"),
    ({"peak": "12kG:10%", "vary": ["A28", "E40"]}, "--vary: found two parameters"),
    ({"target_peak": "8kG", "confidence": 0.9}, "--confidence: found with --target-peak"),
    ({"target_peak": "8 furlongs"}, "--target-peak: found"),
    ({}, "design: found no target and an empty specification"),
])
def test_bad_keywords_are_one_line_naming_the_option_and_write_nothing(given, said, tmp_path):
    with pytest.raises(OptionError) as caught:
        airgun_xl.design(TEMPLATE, output=tmp_path / "d.xlsx", **given)
    assert str(caught.value).startswith(said) and "\n" not in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_first_shot_success_tells_its_progress_shot_by_shot():
    """design --confidence ran silent for 20-30 s: the study now tells its progress as its
    Monte Carlo shots end (the CLI draws a bar on a terminal), counted against the most
    shots it can run, and closes it."""
    from airgun_xl.app.design import DesignRequest, run
    from airgun_xl.app.specifying import SpecFields

    class Recorder:
        def __init__(self, total):
            self.total, self.done, self.closed = total, 0, False

        def advance(self, k):
            self.done += k

        def close(self):
            self.closed = True

    made = []

    def progress_for(total):
        made.append(Recorder(total))
        return made[-1]

    request = DesignRequest(TEMPLATE, spec=SpecFields(peak="12kG:10%", duration="5ms:10%"),
                            confidence=0.95, sd=("A28=1.5%", "E40=5%"), shots=400)
    outcome = run(request, shots_progress_for=progress_for)
    (bar,) = made
    assert bar.closed and 0 < bar.done <= bar.total
    assert bar.done == sum(r.shots for r in outcome.confidence.tried)
