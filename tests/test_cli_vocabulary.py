"""Issue 35: the command line's help says what each command does today. Every argument of
every subcommand (nested ones included) has a help text, and design's and sweep's describe
their modes."""
import argparse

import pytest

from airgun_xl.cli.commands import build_parser
from airgun_xl.cli.vocabulary import VOCABULARY, Alias
from airgun_xl.specification import UNFILTERED, cfc_record


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
    assert err == ["airgun-xl: error: --sign: found '2', expected 1 or -1"]
    assert main(["accept", "shot.xlsx", "rec.csv", "--sign", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["airgun-xl: error: accept: argument --sign: found '2', expected 1 or -1"]


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
        wb = openpyxl.load_workbook(out, read_only=True)
        tables.append(list(wb["Sweep"].values))
        assert ("Seed of the draws", "1") in [r[:2] for r in wb["Spread"].values]
    assert tables[0] == tables[1] and len(tables[0]) == 9
    assert len({row[0] for row in tables[0][1:]}) == 8  # eight different draws of E40


def test_a_recording_is_named_recording_in_every_command():
    """accept, compare-measured and calibrate name their recording argument RECORDING."""
    for words in (("accept",), ("compare-measured",), ("calibrate",)):
        usage = SUBPARSERS[words].format_usage()
        assert "RECORDING" in usage and "MEASURED" not in usage, usage


def _spellings(action):
    longs = [o for o in action.option_strings if o.startswith("--")]
    return longs or ([action.metavar] if isinstance(action.metavar, str) else [action.dest])


@pytest.mark.parametrize("idea", sorted(VOCABULARY))
def test_every_parser_spells_each_idea_the_one_way_or_by_a_declared_alias(idea):
    """Walk every subcommand's parser: an argument stored where an idea is stored is spelt
    the idea's one way, or by one of its declared aliases (an option alias through the Alias
    action, which notes the new spelling), or is the positional subject of a command that the
    table names. The one spelling is used somewhere."""
    entry = VOCABULARY[idea]
    used = set()
    for words, parser in SUBPARSERS.items():
        for action in parser._actions:
            if action.dest not in entry.dests or isinstance(action, argparse._HelpAction):
                continue
            for spelt in _spellings(action):
                used.add(spelt)
                if spelt == entry.spelling:
                    continue
                if words[-1] in entry.subjects and not action.option_strings:
                    continue
                assert spelt in entry.aliases, (idea, words, spelt)
                if spelt.startswith("-"):
                    assert isinstance(action, Alias) and action.idea == idea, (words, spelt)
                else:  # a positional alias: its help says it is the old spelling
                    assert "old spelling of" in action.help, (words, spelt)
    assert entry.spelling in used


def test_an_option_spelt_one_way_means_one_idea():
    """No option string is the spelling of two ideas, and no alias is an idea's spelling."""
    spellings = [i.spelling for i in VOCABULARY.values()]
    aliases = [a for i in VOCABULARY.values() for a in i.aliases]
    assert len(set(spellings)) == len(spellings) and not set(spellings) & set(aliases)


def test_an_old_spelling_still_works_and_says_the_new_one(tmp_path, capsys):
    """--q stores Q where --srs-q does (srs, design), and history DIR finds the archive as
    --archive DIR does; each notes its new spelling once on stderr."""
    from conftest import TEMPLATE

    from airgun_xl.cli import main
    from airgun_xl.cli.messages import _LATER

    parser = SUBPARSERS[("srs",)]
    _LATER.clear()
    # srs stores it at its request's field, q (issue 61: its options are its request's)
    assert parser.parse_args(["s.xlsx", "--q", "25"]).q == 25.0
    assert parser.parse_args(["s.xlsx", "--srs-q", "25"]).q == 25.0
    # held until the command succeeds (issue 43.16: a refusal stays one line)
    assert "write --srs-q" not in capsys.readouterr().err
    assert any("write --srs-q" in n for n in _LATER)
    assert SUBPARSERS[("design",)].parse_args(["s.xlsx", "--q", "25"]).srs_q == "25"
    archive = tmp_path / "archive"
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--only", "summary",
                 "--archive", str(archive)]) == 0
    capsys.readouterr()
    assert main(["history", str(archive), "--json"]) == 0
    captured = capsys.readouterr()
    assert "history DIR is the old spelling of history --archive DIR" in captured.err
    old = captured.out
    assert main(["history", "--archive", str(archive), "--json"]) == 0
    captured = capsys.readouterr()
    assert captured.out == old and captured.err == ""
    assert main(["history", str(archive), "--archive", str(tmp_path)]) == 2
    assert "expected one archive" in capsys.readouterr().err


def test_convergence_takes_one_integrator_an_option_repeated(capsys):
    """convergence --integrator is one choice, as in every other command, given again for
    each integrator run side by side; the comma list is the old spelling, noted; a name not
    an integrator is one line naming the option."""
    from airgun_xl.errors import OptionError

    parser = SUBPARSERS[("convergence",)]
    assert parser.parse_args(["s.xlsx"]).integrators == ["legacy"]
    assert parser.parse_args(["s.xlsx", "--integrator", "newmark"]).integrators == ["newmark"]
    assert parser.parse_args(["s.xlsx", "--integrator", "newmark", "--integrator",
                              "legacy"]).integrators == ["newmark", "legacy"]
    assert capsys.readouterr().err == ""
    from airgun_xl.cli.messages import _LATER, say_later

    _LATER.clear()
    assert parser.parse_args(["s.xlsx", "--integrator", "legacy,newmark"]).integrators == [
        "legacy", "newmark"]
    assert capsys.readouterr().err == ""  # held until the command succeeds (issue 43.16)
    say_later()
    assert capsys.readouterr().err.strip() == (
        "airgun-xl: note: --integrator legacy,newmark is the old spelling of --integrator "
        "legacy --integrator newmark, kept until the next release: write --integrator legacy "
        "--integrator newmark")
    with pytest.raises(OptionError, match=r"^convergence: argument --integrator: found "
                                          r"'rk4', expected one of legacy, newmark$"):
        parser.parse_args(["s.xlsx", "--integrator", "rk4"])


@pytest.mark.parametrize("words", [("srs",), ("compare-measured",), ("calibrate",),
                                   ("accept",)], ids=" ".join)
def test_the_filter_is_cfc_n_or_none_in_every_command(words, capsys):
    """--cfc takes a J211 class or none (no filter: as if not given, but said), and anything
    else is one line naming the option."""
    parser = SUBPARSERS[words]
    positionals = ["s.xlsx"] if words == ("srs",) else ["s.xlsx", "r.csv"]
    given = parser.parse_args([*positionals, "--cfc", "none"])
    assert given.cfc is None and given.cfc_given
    assert parser.parse_args([*positionals, "--cfc", "600"]).cfc == 600
    assert parser.parse_args(positionals).cfc is None
    assert "--cfc N|none" in parser.format_usage()
    with pytest.raises(Exception, match="--cfc: found 'x', expected a J211 class"):
        parser.parse_args([*positionals, "--cfc", "x"])


def test_accept_cfc_none_judges_the_unfiltered_record_or_refuses_a_conflict(tmp_path, capsys):
    """accept --cfc none with its old spelling --record cfc1000 is refused in one line (the
    old spelling's note is held until a command succeeds: issue 43.16). --cfc none judges the
    unfiltered record; without --cfc (and no record on the sheet) the tool's default
    low-pass is judged, and said."""
    from conftest import TEMPLATE

    from airgun_xl.cli import main

    recording = TEMPLATE.parent / "shot_a_recording.csv"
    base = ["accept", str(TEMPLATE), str(recording), "--sign", "-1", "--peak", "9.5kG:10%",
            "-o", str(tmp_path / "a.xlsx")]
    assert main([*base, "--cfc", "none", "--record", "cfc1000"]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "airgun-xl: error: --record: found 1000, where --cfc gave it (none); expected the "
        "filter once (--cfc)"]
    import re

    peaks, judged = {}, {}
    for name, extra in (("none", ["--cfc", "none"]), ("absent", []),
                        ("1000", ["--cfc", "1000"]), ("record", ["--record", "cfc1000"])):
        assert main([*base, *extra, "--force"]) in (0, 3)
        out = capsys.readouterr().out
        peaks[name] = float(re.search(r"peak: ([\d.]+)(?: ± \S+)? kG", out)[1])  # with U
        judged[name] = re.search(r"record judged: (.*)", out)[1]
    assert judged["none"] == "unfiltered" and judged["absent"].startswith("the tool's default")
    assert judged["1000"] == judged["record"] == "CFC 1000 (SAE J211), both ways"
    # the unfiltered record keeps the ringing a low-pass takes off: its peak is the highest
    assert peaks["none"] > max(peaks["absent"], peaks["1000"])
    assert peaks["record"] == peaks["1000"]  # the old spelling, the same filter


@pytest.mark.parametrize("words", [("fill",), ("design",), ("accept",)], ids=" ".join)
def test_cfc_is_the_record_judged_in_every_command_that_judges(words):
    """fill, design and accept take the specification's record as --cfc N|none (the field is
    still 'record' on the sheet); --record is its old spelling, with a note."""
    from airgun_xl.cli.spec_options import options_spec

    parser = SUBPARSERS[words]
    positionals = ["s.xlsx", "r.csv"] if words == ("accept",) else ["s.xlsx"]
    spec = options_spec(parser.parse_args([*positionals, "--cfc", "600"]))
    assert spec.record == cfc_record(600) and spec.origin("record") == "options"
    assert options_spec(parser.parse_args([*positionals, "--cfc", "none"])).record == UNFILTERED
    assert options_spec(parser.parse_args(positionals)) is None
    with pytest.raises(Exception, match="--record: found 'cfc7', expected unfiltered or one "
                                        "of 60, 180, 600, 1000"):
        parser.parse_args([*positionals, "--record", "cfc7"])
    assert "--cfc N|none" in parser.format_usage()


@pytest.mark.parametrize("argv, said", [
    (["fill", "t.xlsx", "--forse"],
     "airgun-xl: error: fill: unrecognized arguments: --forse (did you mean --force?)\n"),
    (["accept", "s.xlsx", "r.csv", "--peek", "12kG"],
     "airgun-xl: error: accept: unrecognized arguments: --peek 12kG (did you mean --peak?)\n"),
    (["history", "--jsn"],
     "airgun-xl: error: history: unrecognized arguments: --jsn (did you mean --json?)\n"),
    # nothing near enough (difflib's ratio under 0.75): no guess
    (["design", "s.xlsx", "--colour", "red"],
     "airgun-xl: error: design: unrecognized arguments: --colour red\n"),
    (["--forse"], "airgun-xl: error: unrecognized arguments: --forse\n"),
])
def test_an_unknown_option_is_refused_by_its_command_with_the_nearest_one(argv, said, capsys,
                                                                         tmp_path,
                                                                         monkeypatch):
    """Issue 44: "unrecognized arguments" named no command and guessed nothing."""
    from airgun_xl.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.err == said and captured.out == ""
    assert list(tmp_path.iterdir()) == []
