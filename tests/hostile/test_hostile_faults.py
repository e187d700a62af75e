"""Faults during a fill: a full disk (a file-size limit), a failing archive, signals at random
moments. A fill is one transaction: workbook, sidecar and archive entry, all or none."""
import os
import random
import resource
import signal
import subprocess
import sys
import time

import builders as b
import pytest
from support import refused

from airgun_xl.archive import Archive
from airgun_xl.cli import main
from airgun_xl.transaction import recover

SHOT = b.TEMPLATE


def _owned(folder):
    return sorted(p.name for p in folder.iterdir() if ".airgun-xl-" in p.name)


def _limited(limit):
    def preexec():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return preexec


@pytest.mark.parametrize("what,argv,limit", [
    # the workbook (0.6 MB with every output at --every 10) passes a 300 kB limit
    ("workbook", ["--every", "10"], 300_000),
    # the workbook (10 kB) fits, the sidecar (1.45 MB of Parquet) does not
    ("sidecar", ["--only", "summary", "--sidecar", "always"], 500_000),
])
def test_a_file_size_limit_leaves_nothing(tmp_path, what, argv, limit):
    """Like a full disk: ulimit -f makes the write fail (SIGXFSZ is ignored, so it is an
    EFBIG error); one line, exit 2, and neither the workbook nor the sidecar is left."""
    out = tmp_path / "o.xlsx"
    proc = subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(SHOT), "-o", str(out),
                           *argv], capture_output=True, text=True, preexec_fn=_limited(limit))
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "cannot be written" in lines[0] and "Traceback" not in proc.stderr
    assert (".history." in lines[0]) == (what == "sidecar")
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_failing_archive_leaves_no_workbook(tmp_path, capsys):
    """The archive's index is damaged: the entry cannot be committed, so the workbook is not
    published either (and the next fill into a sound archive works)."""
    archive = tmp_path / "archive"
    assert main(["fill", str(SHOT), "-o", str(tmp_path / "first.xlsx"), "--only", "summary",
                 "--archive", str(archive)]) == 0
    (archive / "index.sqlite").write_bytes(b"this is not an SQLite database" * 100)
    for extra in ("index.sqlite-wal", "index.sqlite-shm"):
        (archive / extra).unlink(missing_ok=True)
    out = tmp_path / "second.xlsx"
    refused(capsys, ["fill", SHOT, "-o", out, "--only", "summary", "--archive", archive],
            tmp_path / "first.xlsx", naming=["index.sqlite"])
    assert not out.exists() and _owned(tmp_path) == []


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_at_a_random_moment_leaves_all_or_nothing(tmp_path, signum):
    """Eight fills (workbook, sidecar and archive entry each) get the signal at a random
    moment: each ends either complete (exit 0) or with nothing of it left (exit 128+N),
    with no temp file, and the archive verifies clean."""
    archive = tmp_path / "archive"
    main(["fill", str(SHOT), "-o", str(tmp_path / "warm.xlsx"), "--archive", str(archive),
          "--only", "summary"])  # creates the archive; warms the bytecode
    def fill(out):
        return subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(SHOT), "-o",
                                 str(out), "--archive", str(archive), "--sidecar", "always"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)

    # the moments are fractions of a whole fill's time on this machine, not fixed sleeps: a
    # slower or busier machine stretches them alike
    began = time.perf_counter()
    assert fill(tmp_path / "timed.xlsx").wait(timeout=120) == 0
    whole = time.perf_counter() - began
    rng = random.Random(signum)
    stopped = 0
    for i in range(8):
        out = tmp_path / f"o{i}.xlsx"
        entries = len(Archive(archive).entries())
        proc = fill(out)
        time.sleep(whole * rng.uniform(0.1, 0.8))
        proc.send_signal(signum)
        code = proc.wait(timeout=120)
        err = proc.stderr.read()
        assert "Traceback" not in err, err
        now = len(Archive(archive).entries())
        if code == 0:
            assert out.exists() and now == entries + 1
        else:
            stopped += 1
            assert code == 128 + signum, (code, err)
            assert not out.exists() and now == entries
            assert not (tmp_path / f"o{i}.history.parquet").exists()
        assert _owned(tmp_path) == [], err
        assert Archive(archive).verify() == []
    assert stopped >= 3  # most signals land while the fill runs


def test_a_killed_fill_leaves_at_most_temp_files_that_the_next_run_removes(tmp_path):
    out = tmp_path / "o.xlsx"

    def fill():
        return subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(SHOT), "-o",
                                 str(out), "--force", "--sidecar", "always"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    # the kills land at fractions of a whole fill's time measured here, not at fixed sleeps:
    # a slower or busier machine stretches them alike (most in the writing, where temps exist)
    began = time.perf_counter()
    assert fill().wait(timeout=120) == 0
    whole = time.perf_counter() - began
    for stale in tmp_path.iterdir():
        stale.unlink()
    rng = random.Random(9)
    leftovers = 0
    for _ in range(8):
        proc = fill()
        time.sleep(whole * rng.uniform(0.3, 0.95))
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        names = {p.name for p in tmp_path.iterdir()}
        leftovers += bool(_owned(tmp_path))
        recover(tmp_path)  # what the next run does first
        assert _owned(tmp_path) == []
        pair = {"o.xlsx", "o.history.parquet"} & names
        assert pair in (set(), {"o.xlsx", "o.history.parquet"})  # both, or neither
    assert main(["fill", str(SHOT), "-o", str(out), "--force", "--only", "summary"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.xlsx"]
    assert leftovers >= 1  # some kills did leave temps behind for the recovery to remove


def test_convergence_writes_its_workbook_and_png_together(tmp_path):
    """The workbook (9.5 kB) fits a 30 kB file-size limit, the PNG (64 kB) does not: neither
    is left, since both are one publication."""
    proc = subprocess.run([sys.executable, "-m", "airgun_xl", "convergence", str(SHOT),
                           "--levels", "5us,2us,1us", "-o", str(tmp_path / "c.xlsx")],
                          capture_output=True, text=True, preexec_fn=_limited(30_000))
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and "cannot be written" in lines[-1], proc.stderr
    assert "Traceback" not in proc.stderr and sorted(tmp_path.iterdir()) == []
