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
import re
import subprocess
import sys

from docs_walk import DOCUMENTS, ROOT, blocks, runnable, workspace


def test_the_documents_are_all_linked_from_the_readme():
    """Every document in docs/ is in DOCUMENTS (its blocks run) and linked from README."""
    readme = (ROOT / "README.md").read_text()
    docs = sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
    assert docs == sorted(DOCUMENTS[1:])
    assert all(f"]({name})" in readme for name in docs)


def _walk(work, env, found):
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


def test_every_shell_block_runs_as_written_twice_in_a_fresh_clone(tmp_path):
    work, env = workspace(tmp_path)
    found = runnable()
    first = _walk(work, env, found)
    assert first >= 30
    assert _walk(work, env, found) == first  # a block runs again as it is
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
    work, env = workspace(tmp_path)
    ((_, block),) = [b for b in blocks("python") if b[0] == "README.md"]  # api.md's: its own
    (tmp_path / "readme.py").write_text(block + "print(result.peak_kg, result.time_of_peak)\n")
    done = subprocess.run([sys.executable, str(tmp_path / "readme.py")], cwd=work, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (work / "lab" / "run.xlsx").exists()
    peak, time_of_peak = map(float, done.stdout.split())
    # the block's comment: "11.99257..., 0.00028" (the appendix run at 5 us; 0.28 ms)
    assert f"{peak:.5f}" == "11.99257" and 0.00028 <= time_of_peak < 0.00029
