"""Issue 35: the command line's help says what each command does today. Every argument of
every subcommand (nested ones included) has a help text, and design's and sweep's describe
their modes."""
import argparse

import pytest

from airgun_xl.cli.commands import build_parser


def _subparsers(parser, prefix=()):
    """(command words, parser) of every subcommand, nested ones included."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*prefix, name), sub
                yield from _subparsers(sub, (*prefix, name))


SUBPARSERS = dict(_subparsers(build_parser()))


def test_the_walk_finds_every_subcommand():
    assert {" ".join(k) for k in SUBPARSERS} >= {
        "fill", "diff", "archive", "history", "show", "compare", "check",
        "convergence", "design", "sweep", "srs", "compare-measured", "calibrate", "accept",
        "template"}


@pytest.mark.parametrize("words", sorted(SUBPARSERS), ids=" ".join)
def test_every_argument_has_a_help_text(words):
    missing = [action.option_strings or action.dest for action in SUBPARSERS[words]._actions
               if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
               and (not action.help or action.help == argparse.SUPPRESS)]
    assert missing == []


def test_design_describes_its_three_modes():
    text = SUBPARSERS[("design",)].format_help()
    assert "--target-peak" in text and "middle of the tolerances" in " ".join(text.split())
    assert "most likely to pass" in " ".join(text.split())


def test_sweep_describes_sobol_and_not_a_fixed_core_count():
    text = " ".join(SUBPARSERS[("sweep",)].format_help().split())
    assert "Sobol" in text and "both cores" not in text


def test_sign_is_written_1_or_minus_1(capsys):
    """--sign shows and takes 1 or -1 (+1 and -1.0 read the same); anything else is one line
    naming the option and what it expects."""
    from airgun_xl.cli.recording_options import sign_value

    assert [sign_value(t) for t in ("1", "+1", "-1", "-1.0")] == [1.0, 1.0, -1.0, -1.0]
    assert "--sign 1|-1" in SUBPARSERS[("accept",)].format_usage()
    from airgun_xl.cli import main

    assert main(["compare-measured", "shot.xlsx", "rec.csv", "--sign", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["airgun-xl: error: compare-measured: argument --sign: found '2', expected 1 "
                   "or -1"]


def test_a_monte_carlo_without_seed_repeats_and_prints_its_seed(tmp_path, capsys):
    """sweep's default seed is 1: two runs without --seed draw the same shots, and the seed
    is printed with the spread."""
    import openpyxl
    from conftest import TEMPLATE

    from airgun_xl.cli import main

    tables = []
    for k in range(2):
        out = tmp_path / f"mc{k}.xlsx"
        assert main(["sweep", str(TEMPLATE), "--mc", "8", "--sd", "E40=3%", "-o", str(out)]) == 0
        assert "(seed 1)" in capsys.readouterr().out
        tables.append(list(openpyxl.load_workbook(out, read_only=True)["Sweep"].values))
    assert tables[0] == tables[1] and len(tables[0]) == 9
    assert len({row[0] for row in tables[0][1:]}) == 8  # eight different draws of E40


def test_a_recording_is_named_recording_in_every_command():
    """accept, compare-measured and calibrate name their recording argument RECORDING."""
    for words in (("accept",), ("compare-measured",), ("calibrate",)):
        usage = SUBPARSERS[words].format_usage()
        assert "RECORDING" in usage and "MEASURED" not in usage, usage
