"""The documents' shell blocks, and a fresh copy of the clone to run them in: shared by
tests/test_readme_workflow.py (each block runs as written) and tests/golden_commands.py (each
command's output kept from before issue 44's move)."""
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
             "docs/layout.md", "docs/dependencies.md", "docs/api.md")

#: The blocks not run: (document, first line).
NOT_RUN = [
    ("README.md", "python3 -m venv .venv && . .venv/bin/activate && pip install . && "
                  "airgun-xl fill templates/shot_a.xlsx"),
    ("README.md", '. .venv/bin/activate && pip install -e ".[test]" && python -m pytest '
                  '-n auto --dist loadfile'),
    ("README.md", '# needs: a lab\'s PostgreSQL server, and the extra: pip install '
                  '"airgun-xl[server]"'),
    ("docs/legacy.md", "# needs: root (apt-get) and the lab's macro runner, which is outside "
                       "this repository"),
]


def blocks(language):
    """(document, block) for every ```language block, in order."""
    return [(name, block) for name in DOCUMENTS
            for block in re.findall(rf"^```{language}\n(.*?)^```", (ROOT / name).read_text(),
                                    re.S | re.M)]


def runnable():
    """The shell blocks to run, after checking that the others are exactly NOT_RUN."""
    found = blocks("sh")
    readme_setup = [b for b in found if b[0] == "README.md"][:2]
    skipped = readme_setup + [b for b in found if b[1].startswith("# needs:")]
    assert [(name, block.splitlines()[0]) for name, block in skipped] == NOT_RUN
    return [b for b in found if b not in skipped]


def tracked():
    """The clone's tracked files (skips the test outside a git clone)."""
    done = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True)
    if done.returncode != 0 or not done.stdout:
        pytest.skip("not a git clone: the walk copies the clone's tracked files")
    return [name for name in done.stdout.decode().split("\0") if name]


def workspace(tmp_path):
    """A fresh copy of the clone (its tracked files, as they are in the working tree, in a
    new git repository so that `git status` sees what the blocks add), and an `airgun-xl` on
    PATH for this interpreter; HOME is an empty folder."""
    work = tmp_path / "clone"
    for name in tracked():
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


def walk_lines(work, env, found):
    """Run every command line of ``found`` blocks; return how many ran."""
    ran = 0
    for name, block in found:
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
