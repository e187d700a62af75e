"""Every command's output is what it was before issue 44 moved the commands under ``app/``:
the documents' blocks and one line for each command they do not show, run in a fresh copy
of the clone, give the exit codes, terminal text and workbooks kept in
tests/golden/commands.json (how they are compared, and what is written as a name because it
differs from run to run of the same code: tests/golden_commands.py)."""
import difflib
import json

import pytest
from docs_walk import workspace
from golden_commands import GOLDEN, lines, walk


@pytest.fixture(scope="module")
def walked(tmp_path_factory):
    work, env = workspace(tmp_path_factory.mktemp("golden"))
    return walk(work, env)


def _kept():
    return json.loads(GOLDEN.read_text())


def test_the_golden_record_runs_the_lines_the_documents_and_commands_have_now():
    # a block added to a document, or a line to EXTRA, needs the record made again (and
    # the commit saying why): else a new example would be compared with nothing
    assert [(r["document"], r["line"]) for r in _kept()] == lines()


def test_every_line_gives_the_exit_code_text_and_files_it_gave_before(walked):
    kept = _kept()
    # a line may run more than once (history before and after a block): compared in order
    assert [r["line"] for r in walked] == [r["line"] for r in kept]
    problems = []
    for now, before in zip(walked, kept, strict=True):
        for key in ("code", "stdout", "stderr"):
            if now[key] != before[key]:
                diff = "\n".join(difflib.unified_diff(
                    str(before[key]).splitlines(), str(now[key]).splitlines(), "before", "now",
                    lineterm=""))
                problems.append(f"{now['line']}\n  {key} changed:\n{diff}")
        if now["files"] != before["files"]:
            changed = sorted(k for k in set(now["files"]) | set(before["files"])
                             if now["files"].get(k) != before["files"].get(k))
            problems.append(f"{now['line']}\n  files changed: {', '.join(changed)}")
    assert not problems, "\n\n".join(problems)


def test_the_record_holds_every_command_and_refusal(walked):
    # the record is not empty of what it is for: each command ran and wrote, and each
    # refusal is one line with exit 2
    codes = {r["line"]: r["code"] for r in walked}
    refusals = [r for r in walked if r["document"] == "golden" and r["code"] == 2]
    assert len(refusals) == 7
    assert all(len(r["stderr"].strip().splitlines()) == 1 for r in refusals)
    assert all(code == 0 for line, code in codes.items() if line.endswith("--help"))
    written = [k for r in walked for k in r["files"] if k.endswith(".xlsx")]
    assert len(written) >= 20
