"""Issue 12: design --target-srs finds the least v0 whose shock response spectrum envelops a
required one, as shock test specifications are written."""
import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.studies.shock import srs

SHOT = airgun_xl.load(TEMPLATE)
FREQUENCIES = np.array([200.0, 500.0, 1000.0, 2000.0, 4000.0])
G_PER_KG = 9800.0 / 9.80665  # the macro's kG in standard g


def _spec(path, frequencies, levels_g):
    lines = ["frequency [Hz],srs [g]"]
    lines += [f"{f!r},{a!r}" for f, a in zip(frequencies.tolist(), levels_g.tolist(), strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _srs_at(v0):
    r = SHOT.with_params(v31=v0, v32=v0, v33=v0).run(track=())
    a = r.accel_kg[np.isfinite(r.accel_kg)]
    return srs(a, SHOT.params.delta, FREQUENCIES)


def test_the_spectrum_of_a_known_shot_gives_back_its_speed(tmp_path, capsys):
    """The requirement is the SRS of shot A at 200 m/s: the least v0 that envelops it is 200
    m/s (the SRS grows with v0 at every frequency here), with a least margin of 0."""
    spec = _spec(tmp_path / "req.csv", FREQUENCIES, _srs_at(200.0) * G_PER_KG)  # kG -> g
    out = tmp_path / "d.xlsx"
    assert main(["design", str(TEMPLATE), "--target-srs", str(spec), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    v0 = float(text.split("A28..A30 = ")[1].split()[0])
    assert v0 == pytest.approx(200.0, abs=0.01)  # brentq to 1e-10; the CSV keeps 17 digits
    assert "least margin of +0.00%" in text
    # issue 18.10: a design said to envelop never has a negative margin ("-0.00%")
    from airgun_xl.studies.design import srs_margin, variable

    spectrum = np.array(FREQUENCIES), _srs_at(200.0)
    ws = openpyxl.load_workbook(out).worksheets[0]
    solved = variable("A28").apply(SHOT.params, ws["A28"].value)  # the design's own value
    assert srs_margin(solved, *spectrum, 10.0)[0] >= 0
    assert ws["A28"].value == pytest.approx(200.0, abs=0.01)
    assert (_srs_at(v0 + 0.05) >= _srs_at(200.0)).all()  # enveloped just above


def test_an_infeasible_spectrum_is_explained(tmp_path, capsys):
    spec = _spec(tmp_path / "req.csv", FREQUENCIES, _srs_at(200.0) * G_PER_KG * [1, 1, 1, 1, 20])
    assert main(["design", str(TEMPLATE), "--target-srs", str(spec), "-o",
                 str(tmp_path / "d.xlsx")]) == 2
    err = capsys.readouterr().err
    assert "the required SRS is out of reach for v0 in 10-260 m/s" in err
    assert "at 4,000 Hz (the governing frequency" in err and err.count("\n") == 1
    assert not (tmp_path / "d.xlsx").exists()


@pytest.mark.parametrize("body, message", [
    ("frequency [Hz],srs [g]\n200,10\n100,20\n", "row 3: frequency 100, expected positive "
                                                 "frequencies, increasing"),
    ("frequency [Hz],srs [g]\n200,-10\n", "row 2: level -10, expected a positive SRS level"),
    ("frequency [rpm],srs [g]\n200,10\n", "names no unit I know (rpm)"),
    ("frequency [Hz],srs [g]\n200,ten\n", "line 2 holds ['200', 'ten'], expected two numbers"),
])
def test_a_bad_specification_is_one_line(tmp_path, capsys, body, message):
    (tmp_path / "req.csv").write_text(body)
    assert main(["design", str(TEMPLATE), "--target-srs", str(tmp_path / "req.csv"), "-o",
                 str(tmp_path / "d.xlsx")]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "d.xlsx").exists()


def test_one_target_only(tmp_path, capsys):
    assert main(["design", str(TEMPLATE), "--target-srs", "r.csv", "--target-peak", "12kG"]) \
        == 2
    assert "not allowed with argument" in capsys.readouterr().err
    assert main(["design", str(TEMPLATE), "--target-srs", "r.csv", "--workers", "2"]) == 2
    assert "--workers: found with --target-srs" in capsys.readouterr().err


def test_the_spectrums_sheet_carries_the_runs_warnings(tmp_path, capsys):
    """Warnings travel with the figures: a designed shot that warns (E34 = 6,000 Hz makes
    1/(E2 E34) fractional) lists the warning on its SRS sheet too, not only on the Summary."""
    from conftest import template_with

    shot = template_with(tmp_path, E34=6000.0)
    spec = _spec(tmp_path / "req.csv", FREQUENCIES, _srs_at(200.0) * G_PER_KG * 0.9)
    out = tmp_path / "d.xlsx"
    assert main(["design", str(shot), "--target-srs", str(spec), "-o", str(out)]) == 0
    printed = [line.removeprefix("airgun-xl: warning: ")
               for line in capsys.readouterr().err.splitlines() if "E34" in line]
    texts = [c for r in openpyxl.load_workbook(out)["SRS"].iter_rows(values_only=True)
             for c in r if isinstance(c, str)]
    assert printed and all(w in texts for w in printed)
    assert any(t.startswith("Warnings (") for t in texts)
