"""What every hostile test asserts: one line, exit 2, no traceback, nothing written or deleted;
and helpers to run the CLI in a child process and read its peak memory."""
import hashlib
import json
import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

from airgun_xl.cli import main
from airgun_xl.limits import READ_BUDGET_BYTES

#: A command reading any input under 50 MB stays under this resident size (issue 9).
MEMORY_CAP = READ_BUDGET_BYTES


def snapshot(*folders):
    """``{path: sha256}`` of every file under ``folders`` (symlinks by their target text)."""
    out = {}
    for folder in folders:
        for root, dirs, files in os.walk(folder):
            for name in dirs + files:
                p = Path(root) / name
                if p.is_symlink():
                    out[str(p)] = "link:" + os.readlink(p)
                elif p.is_file():
                    out[str(p)] = hashlib.sha256(p.read_bytes()).hexdigest()
                elif not p.is_dir():
                    out[str(p)] = "special"
    return out


def refused(capsys, argv, *folders, naming=()):
    """Run ``main(argv)`` in-process; assert the promise of a refusal and return its line.

    Exit 2, exactly one line on stderr that starts ``airgun-xl: error:`` and names each of
    ``naming``, no traceback, nothing on stdout, and no file under ``folders`` created,
    changed or removed.
    """
    before = snapshot(*folders)
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2, (code, out, err)
    assert len(lines) == 1 and lines[0].startswith("airgun-xl: error:"), err
    assert "Traceback" not in err and out == ""
    for word in naming:
        assert word in lines[0], (word, lines[0])
    assert snapshot(*folders) == before
    return lines[0]


#: The child reports VmHWM, the peak resident size of its own address space: ru_maxrss would
#: carry over the parent's peak through fork and exec on Linux.
CHILD = """
import json, sys
from airgun_xl.cli import main
code = main(sys.argv[2:])
with open("/proc/self/status") as fh:
    peak = next(int(line.split()[1]) for line in fh if line.startswith("VmHWM:"))
with open(sys.argv[1], "w") as fh:
    json.dump({"code": code, "peak_kb": peak}, fh)
sys.exit(code)
"""


def run_child(tmp_path, argv, timeout=300, **kwargs):
    """Run the CLI in a child process; return (exit code, stderr, peak RSS in bytes)."""
    report = tmp_path / f"child-{os.getpid()}-{len(list(tmp_path.iterdir()))}.json"
    proc = subprocess.run([sys.executable, "-c", CHILD, str(report), *map(str, argv)],
                          capture_output=True, text=True, timeout=timeout, **kwargs)
    rss = None
    if report.exists():
        rss = json.loads(report.read_text())["peak_kb"] * 1024
        report.unlink()
    return proc.returncode, proc.stderr, rss


def _xml_texts(path, pattern, wanted):
    """Every match of ``pattern`` in the workbook's XML members whose name has one of
    ``wanted`` in it."""
    found = []
    with zipfile.ZipFile(path) as zf:
        for name in zf.namelist():
            if name.endswith(".xml") and any(w in name for w in wanted):
                found += re.findall(pattern, zf.read(name).decode("utf-8"), re.S)
    return found


def formulas_in(path):
    """Every ``<f>`` formula text in a workbook's worksheets and every ``<c:f>`` in its charts."""
    return _xml_texts(path, r"<(?:c:)?f(?:\s[^>]*)?>(.*?)</(?:c:)?f>", ("worksheets/", "charts/"))


def strings_in(path):
    """Every text of a workbook's shared strings and inline strings."""
    return _xml_texts(path, r"<t(?:\s[^>]*)?>(.*?)</t>", ("sharedStrings", "worksheets/"))


def at_stage(tmp_path, argv, stage, signum, env=None, timeout=300):
    """Run ``airgun-xl argv`` in a child held at ``stage`` (airgun_xl.transaction.stages):
    wait until it reaches the stage (polling the file it writes there: a stage, never a
    guessed time), send it ``signum``, let it go on. Returns (exit code, stderr, whether the
    stage was reached)."""
    import signal as signals
    import time

    folder = tmp_path / "stages"
    folder.mkdir(exist_ok=True)
    for old in folder.iterdir():
        old.unlink()
    hold, reached = folder / f"{stage}.hold", folder / f"{stage}.reached"
    hold.touch()
    proc = subprocess.Popen([sys.executable, "-m", "airgun_xl", *map(str, argv)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, **(env or {}), "AIRGUN_XL_STAGES": str(folder)})
    deadline = time.monotonic() + timeout
    try:
        while not reached.exists() and proc.poll() is None:
            assert time.monotonic() < deadline, f"{stage} not reached in {timeout} s"
            time.sleep(0.002)  # a poll for the stage's file
        if reached.exists():
            os.kill(proc.pid, signum) if signum != signals.SIGKILL else proc.kill()
    finally:
        hold.unlink(missing_ok=True)
    _, err = proc.communicate(timeout=timeout)  # reads stderr to its end and closes it
    return proc.returncode, err, reached.exists()
