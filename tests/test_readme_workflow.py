"""README's shell blocks (```sh), and those of the documents in docs/, pasted in order, line
by line, into a shell in a fresh copy of the clone, work as written: each command exits 0, or
the code its trailing '# exit N' comment states. The whole walk runs twice in the same copy
(a block runs again as it is), with HOME an empty folder that stays empty, and every file it
writes is one the clone's .gitignore knows (the blocks work in lab/). The Python block runs as
a script there too.

Blocks that are not run, and why:
- README's two opening commands (a venv, pip install, the fill, the tests): `.ci/run` runs
  them verbatim, and tests/test_docs_count.py checks that it does;
- a block whose first line is a ``# needs:`` comment, which says what a test machine cannot
  give (root for apt-get, the lab's macro runner).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: README, then the documents it links, in the order their sections had in README (later
#: blocks use files that earlier ones made).
DOCUMENTS = ("README.md", "docs/cell-map.md", "docs/output.md", "docs/trust.md",
             "docs/studies.md", "docs/acceptance.md", "docs/legacy.md", "docs/security.md",
             "docs/speed.md",
             "docs/layout.md", "docs/dependencies.md")

#: The blocks not run: (document, first line).
NOT_RUN = [
    ("README.md", "python3 -m venv .venv && . .venv/bin/activate && pip install . && "
                  "airgun-xl fill templates/shot_a.xlsx"),
    ("README.md", '. .venv/bin/activate && pip install -e ".[test]" && python -m pytest'),
    ("README.md", '# needs: a lab\'s PostgreSQL server, and the extra: pip install '
                  '"airgun-xl[server]"'),
    ("docs/legacy.md", "# needs: root (apt-get) and the lab's macro runner, which is outside "
                       "this repository"),
]


def _blocks(language):
    """(document, block) for every ```language block, in order."""
    return [(name, block) for name in DOCUMENTS
            for block in re.findall(rf"^```{language}\n(.*?)^```", (ROOT / name).read_text(),
                                    re.S | re.M)]


def _runnable():
    """The shell blocks to run, after checking that the others are exactly NOT_RUN."""
    blocks = _blocks("sh")
    readme_setup = [b for b in blocks if b[0] == "README.md"][:2]
    skipped = readme_setup + [b for b in blocks if b[1].startswith("# needs:")]
    assert [(name, block.splitlines()[0]) for name, block in skipped] == NOT_RUN
    return [b for b in blocks if b not in skipped]


def test_the_documents_are_all_linked_from_the_readme():
    """Every document in docs/ is in DOCUMENTS (its blocks run) and linked from README."""
    readme = (ROOT / "README.md").read_text()
    docs = sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
    assert docs == sorted(DOCUMENTS[1:])
    assert all(f"]({name})" in readme for name in docs)


def _tracked():
    done = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True)
    if done.returncode != 0 or not done.stdout:
        pytest.skip("not a git clone: the walk copies the clone's tracked files")
    return [name for name in done.stdout.decode().split("\0") if name]


def _workspace(tmp_path):
    """A fresh copy of the clone (its tracked files, as they are in the working tree, in a
    new git repository so that `git status` sees what the blocks add), and an `airgun-xl` on
    PATH for this interpreter; HOME is an empty folder."""
    work = tmp_path / "clone"
    for name in _tracked():
        if (ROOT / name).is_file():
            (work / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, work / name)
    git = dict(os.environ, GIT_AUTHOR_NAME="t", GIT_AUTHOR_EMAIL="t@t", GIT_COMMITTER_NAME="t",
               GIT_COMMITTER_EMAIL="t@t")
    for argv in (["git", "init", "-q"], ["git", "add", "-A"]):
        subprocess.run(argv, cwd=work, env=git, check=True, capture_output=True)
    shim = tmp_path / "bin"
    shim.mkdir()
    (shim / "airgun-xl").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m airgun_xl "$@"\n')
    (shim / "airgun-xl").chmod(0o755)
    # PYTHONSAFEPATH: the package under test, not the copy's uncompiled one from the cwd
    env = dict(os.environ, HOME=str(tmp_path / "home"), PATH=f"{shim}:{os.environ['PATH']}",
               PYTHONSAFEPATH="1")
    env.pop("AIRGUN_XL_ARCHIVE", None)
    (tmp_path / "home").mkdir()
    return work, env


def _walk(work, env, blocks):
    """Run every command line of ``blocks``; return how many ran."""
    ran = 0
    for name, block in blocks:
        for line in block.splitlines():
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            expected = re.search(r"# exit (\d+)", line)
            done = subprocess.run(["bash", "-c", line], cwd=work, env=env, capture_output=True,
                                  text=True, timeout=300)
            assert done.returncode == (int(expected.group(1)) if expected else 0), \
                (name, line, done.stderr)
            assert "Traceback" not in done.stderr and "error:" not in done.stderr, \
                (name, line, done.stderr)
            ran += 1
    return ran


def test_every_shell_block_runs_as_written_twice_in_a_fresh_clone(tmp_path):
    work, env = _workspace(tmp_path)
    blocks = _runnable()
    first = _walk(work, env, blocks)
    assert first >= 30
    assert _walk(work, env, blocks) == first  # a block runs again as it is
    assert list((tmp_path / "home").iterdir()) == []  # nothing written into ~
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


def test_the_python_block_runs_as_a_script(tmp_path):
    work, env = _workspace(tmp_path)
    ((_, block),) = _blocks("python")
    (tmp_path / "readme.py").write_text(block + "print(result.peak_kg, result.time_of_peak)\n")
    done = subprocess.run([sys.executable, str(tmp_path / "readme.py")], cwd=work, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (work / "lab" / "run.xlsx").exists()
    peak, time_of_peak = map(float, done.stdout.split())
    # the block's comment: "11.99257..., 0.00028" (the appendix run at 5 us; 0.28 ms)
    assert f"{peak:.5f}" == "11.99257" and 0.00028 <= time_of_peak < 0.00029
