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
