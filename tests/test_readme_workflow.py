"""README's shell blocks (```sh), and those of the documents in docs/, pasted in order, line
by line, into a shell in a fresh copy of the clone, work as written: each command exits 0, or
the code its trailing '# exit N' comment states. The whole walk runs twice in the same copy
(a block runs again as it is), with HOME an empty folder that stays empty, and every file it
writes is one the clone's .gitignore knows (the blocks work in lab/): its first time is the
golden record's walk and its second a test of tests/test_golden_commands.py, in the same copy
(each walk takes a minute of a CI's thirty). The Python block runs as a script here.

Blocks that are not run, and why:
- README's two opening commands (a venv, pip install, the fill, the tests): `.ci/run` runs
  them verbatim, and tests/test_docs_count.py checks that it does;
- a block whose first line is a ``# needs:`` comment, which says what a test machine cannot
  give (root for apt-get, the lab's macro runner).
"""
import subprocess
import sys

from docs_walk import DOCUMENTS, ROOT, blocks, workspace


def test_the_documents_are_all_linked_from_the_readme():
    """Every document in docs/ is in DOCUMENTS (its blocks run) and linked from README."""
    readme = (ROOT / "README.md").read_text()
    docs = sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))
    assert docs == sorted(DOCUMENTS[1:])
    assert all(f"]({name})" in readme for name in docs)


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
