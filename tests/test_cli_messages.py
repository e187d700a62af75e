"""Wording a new user meets: one prefix, counts in the singular, no 'nan' figures, a way out
named, and help for every archive command and argument."""
import re

import openpyxl
import pytest
from conftest import TEMPLATE

from airgun_xl.cli import main


def _variant(tmp_path, **cells):
    path = tmp_path / "shot.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    for address, value in cells.items():
        wb.worksheets[0][address] = value
    wb.save(path)
    return path


def test_a_usage_mistake_has_one_prefix(capsys):
    assert main(["fill"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "airgun-xl: error: fill: the following arguments are required: SHOT.xlsx"


def test_no_filtered_samples_is_said_in_words(tmp_path, capsys):
    shot = _variant(tmp_path, E34=10.0)  # one sample every 0.1 s: none in 6 ms
    assert main(["fill", str(shot), "--only", "summary"]) == 0
    out = capsys.readouterr().out
    assert "no filtered samples" in out and not re.search(r"\bnan\b", out)


def test_verify_counts_in_the_singular(tmp_path, capsys):
    archive = tmp_path / "a"
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--only", "summary",
                 "--archive", str(archive)]) == 0
    capsys.readouterr()
    assert main(["archive", "verify", str(archive)]) == 0
    assert capsys.readouterr().out.strip().startswith("1 entry, 0 problems in ")


def test_convergence_at_the_finest_level_says_what_to_do(tmp_path, capsys):
    shot = _variant(tmp_path, E2=5e-9, E6=1e-5)
    assert main(["convergence", str(shot)]) == 2
    err = capsys.readouterr().err
    assert "already at the finest default level (5 ns)" in err
    assert err.startswith("airgun-xl: error: --levels: ") and "e.g. 10ns,5ns,2ns" in err, err


@pytest.mark.parametrize("command,words", [
    ("history", ["the archive folder", "only this shot's runs", "ISO date", "as JSON"]),
    ("show", ["SHOT (its latest run)", "the archive folder"]),
    ("compare", ["Exit 0 when", "SHOT, SHOT@VERSION or #ID", "largest magnitude"]),
    ("archive", ["re-hash every", "verify: check one", "init: make a new archive",
                 "the archive folder", "never a password"]),
])
def test_archive_commands_have_help(capsys, command, words):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for word in words:
        assert word in text, word


def test_design_warns_once_about_extrapolation(tmp_path, capsys):
    """14 kG needs 255.9 m/s, past the crush-factor fit: said once, not by design and again by
    the fill of the designed shot."""
    assert main(["design", str(TEMPLATE), "--target-peak", "14kG", "-o",
                 str(tmp_path / "d.xlsx")]) == 0
    err = capsys.readouterr().err
    assert err.count("extrapolated") == 1 and "the bird meets the MEM at 255.9 m/s" in err


def test_the_rigid_model_names_no_modes(tmp_path, capsys):
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "r.xlsx"), "--model", "rigid",
                 "--only", "summary"]) == 0
    out = capsys.readouterr().out
    assert "(rigid)" in out and "dominant frequencies" not in out


def test_a_mitigator_of_no_length_is_one_line(tmp_path, capsys):
    shot = _variant(tmp_path, E16=0, E19=0)
    assert main(["fill", str(shot)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("airgun-xl: error: E16 (Length of Wedge Part): found 0 with E19")
    assert "E16 or E19 above 0" in err


def test_design_of_a_wedge_from_a_sheet_without_one_asks_for_a_range(tmp_path, capsys):
    shot = _variant(tmp_path, E16=0, E6=0.002)
    assert main(["design", str(shot), "--target-peak", "8kG", "--vary", "E16"]) == 2
    assert "--range: E16 is 0 on the sheet" in capsys.readouterr().err


def test_the_shared_run_options_have_one_help_text():
    """Issue 24.5: --integrator, --model and --force are declared once (cli/run_options.py):
    every subcommand that takes one has it with a help text, the same text everywhere."""
    import argparse

    from airgun_xl.cli.commands import build_parser

    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {}
    for name, sub in subparsers.choices.items():
        for action in sub._actions:
            for flag in ("--integrator", "--model"):
                if flag in action.option_strings and name != "convergence":  # repeatable
                    helps.setdefault(flag, set()).add(action.help)
            if "--force" in action.option_strings:
                assert action.help and action.help.startswith("overwrite "), name
    assert {flag: len(texts) for flag, texts in helps.items()} == {"--integrator": 1,
                                                                   "--model": 1}
    assert None not in helps["--integrator"] | helps["--model"]


def test_a_fractional_filter_step_is_said_once(tmp_path, capsys):
    """1/(E2*E34) = 333.3 rows: the check before the run and the run's filter say it in the
    same words, and the fill records it once (it said it twice before)."""
    import openpyxl
    from conftest import TEMPLATE

    shot = tmp_path / "fr.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    wb["Sheet1"]["E34"] = 6000
    wb.save(shot)
    assert main(["fill", str(shot), "-o", str(tmp_path / "o.xlsx")]) == 0
    err = capsys.readouterr().err
    assert err.count("is not a whole number of rows") == 1
    assert "E34 (Filter Frequency): 1/(E2*E34) = 333.333 is not a whole number" in err
