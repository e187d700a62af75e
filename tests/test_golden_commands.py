"""Every command's output is what it was before issue 44 moved the commands under ``app/``:
the documents' blocks and one line for each command they do not show, run in a fresh copy
of the clone, give the exit codes, terminal text and workbooks kept in
tests/golden/commands.json (how they are compared, and what is written as a name because it
differs from run to run of the same code: tests/golden_commands.py).

The walk is also the first of README's workflow test (tests/test_readme_workflow.py): every
document's line exits 0 or as its '# exit N' comment says, and the documents' blocks run
again as they are in the same copy, with HOME left empty and nothing tracked changed."""
import difflib
import json
import re
import subprocess

import pytest
from docs_walk import runnable, walk_lines, workspace
from golden_commands import GOLDEN, lines, walk


@pytest.fixture(scope="module")
def golden_walk(tmp_path_factory):
    """(the copy of the clone, its environment, the walk's records, its folder, what ~
    held after the documents' lines)."""
    folder = tmp_path_factory.mktemp("golden")
    work, env = workspace(folder)
    home = []  # what ~ holds once the documents' lines have run (EXTRA's --pdf lines then
    # let matplotlib keep its font cache there)
    records = walk(work, env, lambda: home.extend(sorted((folder / "home").rglob("*"))))
    return work, env, records, folder, home


@pytest.fixture(scope="module")
def walked(golden_walk):
    return golden_walk[2]


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


def test_every_shell_block_runs_as_written_twice_in_a_fresh_clone(golden_walk):
    """The documents' lines of the golden walk exit as their comments say; the blocks run
    again as they are in the same copy; nothing is written into ~ and no tracked file
    changes (every file written is one .gitignore knows: lab/)."""
    work, env, records, folder, home = golden_walk
    assert home == []  # the documents' lines wrote nothing into ~
    extra = sorted((folder / "home").rglob("*"))
    documents = [r for r in records if r["document"] != "golden"]
    assert len(documents) >= 30
    for r in documents:
        expected = re.search(r"# exit (\d+)", r["line"])
        assert r["code"] == (int(expected.group(1)) if expected else 0), (r["line"], r["stderr"])
        assert "Traceback" not in r["stderr"] and "error:" not in r["stderr"], r["line"]
    assert walk_lines(work, env, runnable()) == len(documents)  # a block runs again as it is
    assert sorted((folder / "home").rglob("*")) == extra  # nor did they the second time
    status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"],
                            cwd=work, capture_output=True, text=True, check=True).stdout
    changed = [line for line in status.splitlines() if not line.startswith("A  ")]
    assert changed == []  # no tracked file changed; every file written is ignored (lab/)
    lab = work / "lab"
    # two walks, two fills a walk: four versions of shot_17 in the archive
    assert sorted(p.name for p in (lab / "shots" / "shot_17").iterdir()) == [
        "v0001", "v0002", "v0003", "v0004"]
    for name in ("shot_17_diff.xlsx", "shot.out.xlsx", "run7.xlsx", "judged.xlsx",
                 "day_summary.xlsx", "shot_02_lot.xlsx", "tenth.xlsx", "grid.xlsx", "mc.xlsx",
                 "sobol.xlsx", "shot_srs.xlsx"):
        assert (lab / name).exists(), name
