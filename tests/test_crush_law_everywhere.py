"""Issue 44: ``--crush-law NAME[@N]`` (a law of the archive's library) on every command that
runs a shot, through one loader (archive/laws.py, shot_with_law), not fill's only.

The law stored is the macro's polynomial scaled by 1.2 (a stronger honeycomb lot) over
100-300 m/s, so a command that runs it must say other figures than with the workbook's law;
design's v0 is checked against the design solved in Python with the same law."""
import re

import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.archive.laws import store_law
from airgun_xl.cli import main
from airgun_xl.crush_law import LEGACY_COEFFICIENTS, CrushLaw
from airgun_xl.studies.design import VARIABLES, solve_peak

RECORDING = TEMPLATE.with_name("shot_a_recording.csv")
STRONGER = CrushLaw(tuple(1.2 * c for c in LEGACY_COEFFICIENTS), (100.0, 300.0), "fitted")

COMMANDS = {
    "design": ["design", str(TEMPLATE), "--target-peak", "8kG"],
    "sweep": ["sweep", str(TEMPLATE), "--vary", "A28=200:240:2"],
    "srs": ["srs", str(TEMPLATE)],
    "compare-measured": ["compare-measured", str(TEMPLATE), str(RECORDING), "--sign", "-1"],
    "convergence": ["convergence", str(TEMPLATE), "--levels", "10us,5us"],
    "accept": ["accept", str(TEMPLATE), str(RECORDING), "--sign", "-1", "--peak",
               "9.5kG:10%"],
}


@pytest.fixture
def library(tmp_path):
    root = tmp_path / "archive"
    store_law(root, "LOT", STRONGER, [], [])
    return root


def _said(argv, capsys):
    code = main(argv)
    captured = capsys.readouterr()
    # measured times and the folder aside: what the run computed
    text = re.sub(r"\d+(\.\d+)? s\b|\d[\d.e+-]* shot-steps/s", "<time>", captured.out)
    out = str(argv[argv.index("-o") + 1]).removesuffix(".xlsx")  # and its .png
    return code, text.replace(out, "<out>"), captured.err


@pytest.mark.parametrize("command", sorted(set(COMMANDS) - {"accept"}))
def test_every_command_runs_a_library_law_by_name(command, library, tmp_path, capsys):
    argv = COMMANDS[command]
    code, default, _ = _said([*argv, "-o", str(tmp_path / "default.xlsx")], capsys)
    assert code in (0, 3)
    code, lot, err = _said([*argv, "-o", str(tmp_path / "lot.xlsx"), "--crush-law", "LOT",
                            "--archive", str(library)], capsys)
    assert code in (0, 3) and "Traceback" not in err
    assert lot != default  # the law ran: the figures are not the workbook law's
    # and only the figures: the same lines, some of their numbers different
    assert len(lot.splitlines()) == len(default.splitlines())


def test_design_with_a_library_law_solves_what_python_solves_with_that_law(library, tmp_path,
                                                                          capsys):
    params = airgun_xl.load(TEMPLATE).params.replace(crush_law=STRONGER)
    expected = solve_peak(params, 8.0, VARIABLES["A28"]).values[0]
    assert main(["design", str(TEMPLATE), "--target-peak", "8kG", "-o",
                 str(tmp_path / "d.xlsx"), "--crush-law", "LOT@1", "--archive",
                 str(library)]) == 0
    printed = capsys.readouterr().out
    assert f"A28..A30 = {expected:.6g} m/s" in printed, printed


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_library_law_without_its_archive_is_one_line_and_writes_nothing(command, tmp_path,
                                                                         capsys, monkeypatch):
    monkeypatch.delenv("AIRGUN_XL_ARCHIVE", raising=False)
    out = tmp_path / "out.xlsx"
    assert main([*COMMANDS[command], "-o", str(out), "--crush-law", "LOT-9"]) == 2
    err = capsys.readouterr().err
    assert err == ("airgun-xl: error: --crush-law: found 'LOT-9' without --archive, expected "
                   "workbook, legacy, or a law name with the archive that holds it\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_law_not_in_the_library_is_refused_naming_what_is(command, library, tmp_path,
                                                            capsys):
    out = tmp_path / "out.xlsx"
    assert main([*COMMANDS[command], "-o", str(out), "--crush-law", "LOT@2", "--archive",
                 str(library)]) == 2
    err = capsys.readouterr().err
    assert "--crush-law: found 'LOT@2', expected workbook, legacy or a law in" in err
    assert "there: LOT@1" in err and err.count("\n") == 1
    assert not out.exists()


def test_accept_takes_the_law_for_its_prediction_and_judges_the_recording_alike(library,
                                                                              tmp_path,
                                                                              monkeypatch):
    """accept runs the shot's prediction only to tell a probable unit error in the
    recording: with the law by name (from the CLI or the API) the verdict is the
    recording's, the same as with the workbook's law, and is archived in the law's archive."""
    monkeypatch.delenv("AIRGUN_XL_ARCHIVE", raising=False)
    default = airgun_xl.accept(TEMPLATE, RECORDING, sign=-1, peak="9.5kG:10%")
    lot = airgun_xl.accept(TEMPLATE, RECORDING, sign=-1, peak="9.5kG:10%", crush_law="LOT",
                           archive=library, output=tmp_path / "v.xlsx")
    assert [(c.name, c.value, c.passed) for c in lot.criteria] == [
        (c.name, c.value, c.passed) for c in default.criteria]
    assert lot.archived is not None and lot.archived.is_relative_to(library)
    with pytest.raises(airgun_xl.OptionError, match="found 'LOT' without --archive"):
        airgun_xl.accept(TEMPLATE, RECORDING, sign=-1, peak="9.5kG:10%", crush_law="LOT")
