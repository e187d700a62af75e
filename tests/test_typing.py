"""Issue 11: the public API's type hints hold (mypy, configured in pyproject.toml)."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_passes_on_the_whole_package():
    """Issue 24.6: ``mypy`` (its files: the whole package, pyproject.toml) is clean, the
    public API's modules with every function annotated."""
    done = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    count = sum(1 for _ in (ROOT / "airgun_xl").rglob("*.py"))
    assert f"Success: no issues found in {count} source files" in done.stdout


def test_mypy_catches_a_wrong_call(tmp_path):
    """The check can fail: a script passing a number as the workbook path is an error."""
    script = tmp_path / "use.py"
    script.write_text("import airgun_xl\n"
                      "shot = airgun_xl.load(42)\n"
                      "peak: float = shot.run(track=()).peak_kg\n")
    done = subprocess.run([sys.executable, "-m", "mypy", "--follow-imports=silent",
                           "--ignore-missing-imports", str(script)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 1 and 'Argument 1 to "load" has incompatible type "int"' in \
        done.stdout, done.stdout


def test_mypy_checks_the_commands_keywords(tmp_path):
    """Issue 44: the functions' keywords are typed, the specification's fields too (one
    TypedDict, SpecKeywords): a number for a field given as text, or a misspelt field, is
    an error before the script runs."""
    script = tmp_path / "use.py"
    script.write_text("import airgun_xl\n"
                      "v = airgun_xl.accept('s.xlsx', 'r.csv', peak=12)\n"
                      "d = airgun_xl.design('s.xlsx', peek='12kG:10%')\n"
                      "ok: bool = airgun_xl.accept('s.xlsx', 'r.csv', peak='12kG').passed\n")
    done = subprocess.run([sys.executable, "-m", "mypy", "--follow-imports=silent",
                           "--ignore-missing-imports", str(script)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 1, done.stdout
    assert 'Argument "peak" to "accept" has incompatible type "int"' in done.stdout
    assert 'Unexpected keyword argument "peek" for "design"' in done.stdout
    assert done.stdout.count("error:") == 2, done.stdout
