"""docs/api.md's walk-through runs as written (issue 44): its python blocks, in order, as one
script in a fresh copy of the clone; every ``print(...)`` whose comment starts with ``->``
prints what follows it."""
import re
import subprocess
import sys

from docs_walk import ROOT, workspace

API = ROOT / "docs" / "api.md"
_EXPECTED = re.compile(r"^\s*print\(.*#\s*->\s*(.*)$")


def _blocks():
    return re.findall(r"^```python\n(.*?)^```", API.read_text(), re.S | re.M)


def test_the_walk_through_runs_and_prints_what_its_comments_say(tmp_path):
    work, env = workspace(tmp_path)
    script = "".join(_blocks())
    expected = [m[1].strip() for line in script.splitlines() if (m := _EXPECTED.match(line))]
    assert len(expected) >= 6  # the walk-through's checked figures are there to be checked
    (tmp_path / "api.py").write_text(script)
    done = subprocess.run([sys.executable, str(tmp_path / "api.py")], cwd=work, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    printed = done.stdout.splitlines()
    # the unchecked prints (the criteria's lines) sit between the checked ones: each
    # expected line is printed, in order
    at = 0
    for line in expected:
        assert line in printed[at:], f"{line!r} not printed after line {at}: {printed}"
        at = printed.index(line, at) + 1
    assert (work / "lab" / "api_verdict.xlsx").is_file()
