"""Issue 44: --quiet on every command: nothing on stdout but --json's document, no notice
and no progress bar; the warnings, the errors, the exit status and the files are the same."""
import json

import pytest
from conftest import TEMPLATE, template_with

from airgun_xl.cli import main
from airgun_xl.cli.commands import build_parser

RECORDING = TEMPLATE.with_name("shot_a_recording.csv")


def test_every_command_takes_quiet():
    import argparse

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert all("--quiet" in p.format_help() for p in sub.choices.values())


@pytest.mark.parametrize("argv", [
    ["fill", str(TEMPLATE)],
    ["sweep", str(TEMPLATE), "--vary", "A28=150:250:3"],
    ["accept", str(TEMPLATE), str(RECORDING), "--sign", "-1", "--peak", "12kG:10%"],
    ["check", "{stiff}"],
])
def test_quiet_says_only_the_warnings_and_keeps_the_exit_status(argv, tmp_path, capsys):
    stiff = template_with(tmp_path, E2=1e-4)  # unstable: check exits 2 and says why
    argv = [a.replace("{stiff}", str(stiff)) for a in argv]
    out = ["-o", str(tmp_path / "loud.xlsx")] if argv[0] != "check" else []
    loud = main([*argv, *out])
    said = capsys.readouterr()
    out = ["-o", str(tmp_path / "quiet.xlsx")] if argv[0] != "check" else []
    quiet = main([*argv, *out, "--quiet"])
    hushed = capsys.readouterr()
    assert quiet == loud and said.out != "" and hushed.out == ""
    assert hushed.err == said.err.replace("loud.xlsx", "quiet.xlsx")
    if argv[0] != "check":
        assert (tmp_path / "quiet.xlsx").is_file()


def test_quiet_with_json_prints_the_document(tmp_path, capsys):
    assert main(["srs", str(TEMPLATE), "-o", str(tmp_path / "s.xlsx"), "--json",
                 "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["q"] == 10.0
