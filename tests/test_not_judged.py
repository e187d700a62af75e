"""Issue 63: a third verdict, NOT JUDGED (exit 4). A criterion the record cannot show (not
measurable: a late trigger, a window past the record, a dropout) makes the verdict NOT
JUDGED, with the reason and what to change, never PASS and never FAIL; a measured failure of
another criterion still makes it FAIL, and so does a record that shows the figure outside
its limits all the same (a pulse that outlasts the record past its upper limit, a clipped
top). The prediction record counts such shots apart."""
import math
import shutil
import subprocess

import numpy as np
import pytest
from conftest import TEMPLATE

from airgun_xl.cli import main
from airgun_xl.specification import Specification
from airgun_xl.studies.acceptance import Criterion, Verdict

#: The long pulse: a 12 kG, 30 ms half-sine from 4 ms, recorded at 100 kHz for 20 ms (so
#: cut by the record's end at 0.995 of its peak), 0.01 kG of noise (seed 1).
RATE, START, LENGTH, SPAN = 100_000.0, 0.004, 0.030, 0.020


def _long_pulse(path):
    t = np.arange(int(round(SPAN * RATE))) / RATE
    a = np.where(t > START, 12.0 * np.sin(np.pi * np.clip((t - START) / LENGTH, 0, 1)), 0.0)
    a = a + np.random.default_rng(1).normal(0.0, 0.01, len(t))
    path.write_text("time [s],acceleration [kG]\n" + "".join(
        f"{x!r},{y!r}\n" for x, y in zip(t.tolist(), a.tolist(), strict=True)))
    return path


def _accept(capsys, *argv):
    capsys.readouterr()
    code = main(["accept", str(TEMPLATE), *map(str, argv), "--peak", "12kG:20%"])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_pulse_that_outlasts_the_record_past_its_limit_fails_else_is_not_judged(
        tmp_path, capsys):
    """Cut by the record's end 16 ms after its 10 % crossing, the pulse is at least that
    long (to a sample): against 5 ms ±10 % that is past the upper limit, FAIL (exit 3),
    the least length said; against 30 ms ±10 % (whose limits the 16 ms do not reach) the
    record cannot tell: NOT JUDGED (exit 4), the remedy said."""
    path = _long_pulse(tmp_path / "long.csv")
    out_file = tmp_path / "v.xlsx"
    code, out, err = _accept(capsys, path, "--duration", "5ms:10%", "-o", out_file)
    assert code == 3 and out.startswith("FAIL: "), out + err
    # the 10 % crossing of a half-sine lies asin(0.1)/pi of its length after its start
    least = (SPAN - 1 / RATE - START - math.asin(0.1) / math.pi * LENGTH) * 1e3
    said = err.split("shows it at least ")[1].split(" ms long")[0]
    assert float(said) == pytest.approx(least, abs=2e3 / RATE)  # the low-pass moves it a step
    assert "past its upper limit of 5.5 ms: judged FAIL" in err
    code, out, err = _accept(capsys, path, "--duration", "30ms:10%", "-o", out_file,
                             "--force")
    assert code == 4 and out.startswith("NOT JUDGED: "), out + err
    assert "NOT JUDGED  duration" in out and "PASS  peak" in out
    assert "duration: not measurable" in err and "a longer record" in err


def _criterion(name, passed, judged=True):
    return Criterion(name, math.nan if not judged else 1.0, "kG", 0.0, 2.0, 0.0, "%", passed,
                     judged=judged)


@pytest.mark.parametrize("criteria, word", [
    ([("peak", True, True), ("duration", True, True)], "PASS"),
    ([("peak", True, True), ("duration", False, False)], "NOT JUDGED"),
    ([("peak", False, True), ("duration", False, False)], "FAIL"),
    ([("peak", False, True), ("duration", True, True)], "FAIL"),
    ([("peak", False, False), ("duration", False, False)], "NOT JUDGED"),
])
def test_the_verdicts_word_is_fail_over_not_judged_over_pass(criteria, word):
    """A criterion judged and failed makes FAIL whatever the others; else one not judged
    makes NOT JUDGED; else PASS. ``passed`` is True for PASS alone."""
    v = Verdict([_criterion(*c) for c in criteria], Specification(), [])
    assert v.word == word
    assert v.passed == (word == "PASS")
    assert [c.word for c in v.criteria] == [
        "PASS" if p else "FAIL" if j else "NOT JUDGED" for _, p, j in criteria]


@pytest.mark.skipif(not shutil.which("pdftotext"), reason="needs poppler-utils (pdftotext)")
def test_the_report_of_a_record_that_cannot_show_a_criterion_says_not_judged(tmp_path,
                                                                             capsys):
    """accept --pdf on the long pulse against 30 ms: its report heads NOT JUDGED and the
    criterion's line says it, with the reason."""
    pytest.importorskip("matplotlib")
    path = _long_pulse(tmp_path / "long.csv")
    pdf = tmp_path / "r.pdf"
    code, _out, _err = _accept(capsys, path, "--duration", "30ms:10%", "-o",
                               tmp_path / "v.xlsx", "--pdf", pdf)
    assert code == 4
    text = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], capture_output=True,
                          text=True, check=True).stdout
    assert "Verdict: NOT JUDGED" in text
    assert "duration: not measurable" in text


def test_the_prediction_record_counts_a_shot_not_judged_apart():
    """Of four shots fired from proposals, one NOT JUDGED: the bands and the Brier score are
    of the three with an outcome, and the record says the fourth was left out."""
    from airgun_xl.app.next_shot import PredictionRecord
    from airgun_xl.studies.closed_loop import brier, outcomes, reliability

    shots = [{"predicted": 0.9, "verdict": "PASS"}, {"predicted": 0.8, "verdict": "FAIL"},
             {"predicted": 0.95, "verdict": "NOT JUDGED"}, {"predicted": 0.7, "verdict": "PASS"}]
    predicted, passed = outcomes(shots)
    assert predicted == [0.9, 0.8, 0.7] and passed == [True, False, True]
    score = brier(predicted, passed)
    assert score == pytest.approx((0.1 ** 2 + 0.8 ** 2 + 0.3 ** 2) / 3, rel=1e-12)
    record = PredictionRecord(tuple(shots), tuple(reliability(predicted, passed)), score, ())
    assert record.not_judged == 1 and sum(b.shots for b in record.bands) == 3
    assert "(1 NOT JUDGED, left out of the bands and the score)" in record.lines()[0]
