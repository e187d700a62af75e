"""README's shell blocks (```sh), and those of the documents in docs/, pasted in order, line
by line, into a shell in one temp folder, work as written: each command exits 0, or the code
its trailing '# exit N' comment states. The Python block runs as a script there too.

Four commands are left out, each for a reason the test cannot reproduce: README's two set-up
lines (a venv, `pip install` and the tests themselves: `.ci/run` runs them verbatim), `apt-get`
(root and the network) and `../shared/legacy/run-legacy-macro` (the lab's LibreOffice runner,
outside this repository; its output is replaced by a copy of a legacy case).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

NOT_RUN = ("python3 -m venv .venv && ", ". .venv/bin/activate && ", "apt-get ",
           "../shared/legacy/run-legacy-macro")


#: README, then the documents it links, in the order their sections had in README (later
#: blocks use files that earlier ones made).
DOCUMENTS = ("README.md", "docs/cell-map.md", "docs/output.md", "docs/trust.md",
             "docs/studies.md", "docs/acceptance.md", "docs/legacy.md", "docs/security.md",
             "docs/speed.md",
             "docs/layout.md", "docs/dependencies.md")


def _blocks(language):
    text = "\n".join((ROOT / name).read_text() for name in DOCUMENTS)
    return re.findall(rf"^```{language}\n(.*?)^```", text, re.S | re.M)


def test_the_documents_are_all_linked_from_the_readme():
    """Every document in docs/ is in DOCUMENTS (its blocks run) and linked from README."""
    readme = (ROOT / "README.md").read_text()
    docs = sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
    assert docs == sorted(DOCUMENTS[1:])
    assert all(f"]({name})" in readme for name in docs)


def _workspace(tmp_path):
    """A folder like a clone: templates/ and legacy_reference/, shot.xlsx from the template,
    and an `airgun-xl` on PATH for this interpreter; HOME is a fresh folder."""
    work = tmp_path / "work"
    # only the committed templates: README's own set-up writes templates/shot_a.out.xlsx in
    # the clone before the tests run, and the blocks here must make theirs afresh
    shutil.copytree(ROOT / "templates", work / "templates",
                    ignore=shutil.ignore_patterns("*.out.xlsx", "*.history.*"))
    (work / "legacy_reference").mkdir()
    for name in ("shot_a_appendix_5us_input.xlsx", "shot_a_appendix_5us_legacy.xlsx"):
        shutil.copy(ROOT / "legacy_reference" / name, work / "legacy_reference" / name)
    shutil.copy(ROOT / "templates" / "shot_a.xlsx", work / "shot.xlsx")
    shim = tmp_path / "bin"
    shim.mkdir()
    (shim / "airgun-xl").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m airgun_xl "$@"\n')
    (shim / "airgun-xl").chmod(0o755)
    env = dict(os.environ, HOME=str(tmp_path / "home"), PATH=f"{shim}:{os.environ['PATH']}")
    env.pop("AIRGUN_XL_ARCHIVE", None)
    (tmp_path / "home").mkdir()
    return work, env


def test_every_shell_block_runs_as_written(tmp_path):
    work, env = _workspace(tmp_path)
    commands = [line for block in _blocks("sh") for line in block.splitlines()
                if line.strip() and not line.lstrip().startswith("#")]
    skipped = [line for line in commands if line.startswith(NOT_RUN)]
    assert len(skipped) == 4, skipped  # exactly the documented four
    ran = 0
    for line in commands:
        if line.startswith(NOT_RUN):
            if "run-legacy-macro" in line:  # what the runner would have written
                shutil.copy(ROOT / "legacy_reference" / "shot_a_appendix_5us_legacy.xlsx",
                            work / line.split()[2])
            continue
        expected = re.search(r"# exit (\d+)", line)
        done = subprocess.run(["bash", "-c", line], cwd=work, env=env, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == (int(expected.group(1)) if expected else 0), (line, done.stderr)
        assert "Traceback" not in done.stderr and "error:" not in done.stderr, (line, done.stderr)
        ran += 1
    assert ran == len(commands) - len(skipped) >= 20
    archive = tmp_path / "home" / "shots"
    assert sorted(p.name for p in (archive / "shot_17").iterdir()) == ["v0001", "v0002"]
    for name in ("shot_17_diff.xlsx", "shot.out.xlsx",
                 "run7.xlsx", "my_shot.xlsx", "my_shot_new.xlsx", "tenth.xlsx", "grid.xlsx",
                 "mc.xlsx"):
        assert (work / name).exists(), name


def test_the_python_block_runs_as_a_script(tmp_path):
    work, env = _workspace(tmp_path)
    (block,) = _blocks("python")
    (work / "readme.py").write_text(block + "print(result.peak_kg, result.time_of_peak)\n")
    done = subprocess.run([sys.executable, "readme.py"], cwd=work, env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (work / "run.xlsx").exists()
    peak, time_of_peak = map(float, done.stdout.split())
    # the block's comment: "11.99257..., 0.00028" (the appendix run at 5 us; 0.28 ms)
    assert f"{peak:.5f}" == "11.99257" and 0.00028 <= time_of_peak < 0.00029
