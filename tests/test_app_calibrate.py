"""Issue 44: calibrate as a function (airgun_xl.app.calibrate.run) and as the Python API
(airgun_xl.calibrate), driven without the CLI.

The "measured" pulse is the model's own under a known E40 (5 % above shot A's), sampled
every 10 us with 1 % white noise and a 2 % recorder-mount ringing at 8 kHz
(studies.calibrate.synthetic_measurement, seed 3), written to CSV with every digit;
tests/test_calibrate.py holds such fits within 1 % (the noise and the ringing)."""
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.app.calibrate import CalibrateRequest, run
from airgun_xl.cli import main
from airgun_xl.errors import OptionError
from airgun_xl.studies.calibrate import calibrate, synthetic_measurement

SHOT = airgun_xl.load(TEMPLATE).params


@pytest.fixture
def measured(tmp_path):
    trace = synthetic_measurement(SHOT.replace(sigmay=SHOT.sigmay * 1.05), seed=3,
                                  ringing=0.02)
    path = tmp_path / "m.csv"
    path.write_text("time [s],acceleration [kG]\n" + "\n".join(
        f"{t!r},{a!r}" for t, a in zip(trace.time.tolist(), trace.accel_kg.tolist(),
                                       strict=True)) + "\n")
    return path


def test_the_api_fits_e40_as_the_study_does(measured):
    outcome = airgun_xl.calibrate(TEMPLATE, measured, fit="E40", cfc=1000)
    assert outcome.trusted and outcome.warnings == () and outcome.files == ()
    assert outcome.fitted["E40"] == pytest.approx(SHOT.sigmay * 1.05, rel=0.01)
    # the function is the study on the same inputs: the same value, bit for bit
    from airgun_xl.readers.recording import read_trace

    direct = calibrate([SHOT], [read_trace(str(measured))], law=False, fit=["E40"], cfc=1000)
    assert outcome.fitted == direct.fitted
    before, after = outcome.calibration.before[0], outcome.calibration.after[0]
    assert after.rms < before.rms


def test_a_trusted_law_is_kept_by_name_and_fill_runs_it(measured, tmp_path, capsys):
    archive = tmp_path / "archive"
    outcome = run(CalibrateRequest(((str(TEMPLATE), str(measured)),), fit="scale", cfc=1000,
                                   output=tmp_path / "cal.xlsx", archive=archive,
                                   name="LOT-1"))
    assert outcome.trusted and outcome.stored == "LOT-1@1"
    assert outcome.files == (tmp_path / "cal.xlsx",) and (tmp_path / "cal.xlsx").is_file()
    assert main(["fill", str(TEMPLATE), "--crush-law", "LOT-1", "--archive", str(archive),
                 "-o", str(tmp_path / "f.xlsx")]) == 0
    assert "the archive's crush law LOT-1@1" in capsys.readouterr().out


@pytest.mark.parametrize("given, said", [
    ({"fit": "E40,scale"}, "--fit: found both E40 and scale"),
    ({"fit": "E40", "degree": 9}, "--degree: found 9, expected 1 to 6"),
    ({"fit": "E40", "cfc": 42}, "--cfc: found '42'"),
    ({"fit": "E40", "name": "LOT"}, "--name: found with --fit of no law"),
    ({"fit": "scale", "name": "../x", "archive": "a"}, "--name: found '../x'"),
])
def test_bad_keywords_are_one_line_naming_the_option_and_write_nothing(given, said, measured,
                                                                      tmp_path):
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(OptionError) as caught:
        airgun_xl.calibrate(TEMPLATE, measured, output=tmp_path / "c.xlsx", **given)
    assert str(caught.value).startswith(said) and "\n" not in str(caught.value)
    assert sorted(tmp_path.rglob("*")) == before


def test_files_come_in_pairs(measured):
    with pytest.raises(OptionError, match="calibrate: found 3 files, expected pairs"):
        airgun_xl.calibrate(TEMPLATE, measured, TEMPLATE)
