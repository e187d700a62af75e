"""Issue 44: ruff (its rules: pyproject.toml's [tool.ruff]) runs in the tests, and so in CI,
over the package, the tests and the benchmarks: it had caught what slipped into commits
(an unsorted import, a zip without strict=) only when someone ran it."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _ruff(*argv, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", *argv],
                          cwd=cwd, capture_output=True, text=True, timeout=300)


def test_ruff_passes_on_the_whole_tree():
    done = _ruff(".")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "All checks passed!" in done.stdout


def test_ruff_catches_what_the_rules_name(tmp_path):
    # the check can fail: the project's rules find an unsorted import and a zip with no
    # strict= in a file given to it
    script = tmp_path / "bad.py"
    script.write_text("import sys\nimport os\n\nprint(list(zip(os.sep, sys.argv)))\n")
    done = _ruff("--config", str(ROOT / "pyproject.toml"), str(script), cwd=tmp_path)
    assert done.returncode == 1
    assert "I001" in done.stdout and "B905" in done.stdout, done.stdout
