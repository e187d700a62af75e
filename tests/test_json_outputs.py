"""Issue 44: --json on every command a LIMS reads (accept's in tests/test_app_accept.py):
one JSON document on stdout, ASCII, its figures the function's outcome's, the exit status
and the stderr warnings as without it."""
import json

from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main

RECORDING = TEMPLATE.with_name("shot_a_recording.csv")


def _document(argv, capsys):
    code = main([*argv, "--json"])
    captured = capsys.readouterr()
    assert captured.out.isascii()
    return code, json.loads(captured.out), captured.err


def test_sweep_json_holds_each_shots_row(tmp_path, capsys):
    out = tmp_path / "s.xlsx"
    code, doc, err = _document(["sweep", str(TEMPLATE), "--vary", "A28=150:250:3", "-o",
                                str(out)], capsys)
    frame = airgun_xl.sweep(TEMPLATE, "A28=150:250:3").to_frame()
    assert code == 0 and doc["kind"] == "grid" and doc["shots"] == 3
    assert [r["peak_kg"] for r in doc["rows"]] == frame["peak_kg"].tolist()
    assert [r["A28"] for r in doc["rows"]] == [150.0, 200.0, 250.0]
    assert doc["rows"][2]["warnings"] and doc["files"] == [str(out)]
    assert doc["warnings"][0] in err  # said on stderr too


def test_srs_json_holds_the_spectrum(tmp_path, capsys):
    code, doc, _ = _document(["srs", str(TEMPLATE), "-o", str(tmp_path / "r.xlsx")], capsys)
    outcome = airgun_xl.srs(TEMPLATE)
    assert code == 0 and doc["levels_kG"] == outcome.levels.tolist()
    assert doc["frequencies_Hz"] == outcome.frequencies.tolist() and doc["q"] == 10.0
    assert doc["largest"] == {"level_kG": outcome.largest[0],
                              "frequency_Hz": outcome.largest[1]}


def test_compare_measured_json_holds_the_scores(tmp_path, capsys):
    code, doc, _ = _document(["compare-measured", str(TEMPLATE), str(RECORDING), "--sign",
                              "-1", "-o", str(tmp_path / "m.xlsx")], capsys)
    c = airgun_xl.compare_measured(TEMPLATE, RECORDING, sign=-1).comparison
    assert code == 0 and doc["errors"]["peak_kg"] == c.errors["peak_kg"]
    assert doc["predicted"]["peak_kg"] == c.predicted.peak_kg
    assert doc["iso18571"]["overall"] == c.iso.overall and doc["units_read"] == ["ms", "g"]


def test_design_json_says_whether_it_reached_p_and_exits_3_when_not(tmp_path, capsys):
    argv = ["design", str(TEMPLATE), "--peak", "12kG:10%", "--duration", "5ms:10%",
            "--confidence", "0.95", "--sd", "A28=1.5%", "--sd", "E40=5%", "--shots", "400",
            "-o", str(tmp_path / "d.xlsx")]
    code, doc, err = _document(argv, capsys)
    outcome = airgun_xl.design(TEMPLATE, peak="12kG:10%", duration="5ms:10%",
                               confidence=0.95, sd=["A28=1.5%", "E40=5%"], shots=400)
    assert code == 3 and doc["reached"] is False and doc["mode"] == "confidence"
    assert doc["values"] == {"A28": outcome.values["A28"]}
    best = doc["confidence"]["best"]
    assert best["probability"] == outcome.confidence.best.probability
    assert best["interval"] == list(outcome.confidence.best.interval)
    assert doc["summary"]["peak_kg"] > 0 and "design --confidence: no v0" in err


def test_calibrate_json_holds_the_fit_and_its_error(tmp_path, capsys):
    code, doc, _ = _document(["calibrate", str(TEMPLATE), str(RECORDING), "--sign", "-1",
                              "--fit", "E40", "--cfc", "1000", "-o",
                              str(tmp_path / "c.xlsx")], capsys)
    outcome = airgun_xl.calibrate(TEMPLATE, RECORDING, sign=-1, fit="E40", cfc=1000)
    assert code == 0 and doc["trusted"] is True and doc["law"] is None
    assert doc["fitted"] == outcome.fitted
    assert doc["standard_errors"]["E40"] == outcome.calibration.errors["E40"]
    assert doc["scores"][0]["after"]["rms"] == outcome.calibration.after[0].rms


def test_check_json_holds_the_critical_steps_and_exit_2_when_unstable(tmp_path, capsys):
    from conftest import template_with

    code, doc, _ = _document(["check", str(TEMPLATE)], capsys)
    outcome = airgun_xl.check(TEMPLATE)
    assert code == 0 and doc["stable"] is True
    assert doc["critical_time_step_s"] == outcome.critical.dt_crit
    assert doc["ratio"] == outcome.params.delta / outcome.critical.dt_crit
    coarse = template_with(tmp_path, E2=2 * outcome.critical.dt_crit)
    code, doc, _ = _document(["check", str(coarse)], capsys)
    assert code == 2 and doc["stable"] is False
    assert [f["level"] for f in doc["findings"]][:1] == ["error"]


def test_template_json_names_the_file(tmp_path, capsys):
    code, doc, _ = _document(["template", str(tmp_path / "t.xlsx")], capsys)
    assert code == 0 and doc == {"files": [str(tmp_path / "t.xlsx")]}
    assert airgun_xl.load(tmp_path / "t.xlsx").params == airgun_xl.load(TEMPLATE).params
