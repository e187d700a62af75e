"""README's workflow block, pasted line by line into a shell in a temp folder, works as
written: each command exits 0, or the code its trailing '# exit N' comment states."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _workflow_block():
    text = (ROOT / "README.md").read_text()
    section = text.split("## The workflow", 1)[1]
    return re.search(r"```\n(.*?)```", section, re.S).group(1)


def test_the_workflow_block_runs_as_written(tmp_path):
    work = tmp_path / "work"
    (work / "legacy_reference").mkdir(parents=True)
    for name in ("shot_a_appendix_5us_input.xlsx", "shot_a_appendix_5us_legacy.xlsx"):
        shutil.copy(ROOT / "legacy_reference" / name, work / "legacy_reference" / name)
    shim = tmp_path / "bin"
    shim.mkdir()
    (shim / "airgun-xl").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m airgun_xl "$@"\n')
    (shim / "airgun-xl").chmod(0o755)
    env = dict(os.environ, HOME=str(tmp_path / "home"), PATH=f"{shim}:{os.environ['PATH']}")
    env.pop("AIRGUN_XL_ARCHIVE", None)
    (tmp_path / "home").mkdir()
    commands = [line for line in _workflow_block().splitlines()
                if line.strip() and not line.lstrip().startswith("#")]
    assert len(commands) >= 9
    for line in commands:
        expected = re.search(r"# exit (\d+)", line)
        done = subprocess.run(["bash", "-c", line], cwd=work, env=env, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == (int(expected.group(1)) if expected else 0), (line, done.stderr)
        assert "Traceback" not in done.stderr and "error:" not in done.stderr, (line, done.stderr)
    archive = tmp_path / "home" / "shots"
    assert sorted(p.name for p in (archive / "shot_17").iterdir()) == ["v0001", "v0002"]
    assert (work / "shot_17_diff.xlsx").exists()
