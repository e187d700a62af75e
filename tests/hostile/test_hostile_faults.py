"""Faults during a fill: a full disk (a file-size limit), a failing archive, signals at random
moments. A fill is one transaction: workbook, sidecar and archive entry, all or none."""
import resource
import signal
import subprocess
import sys

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


#: A fill's stages into an existing archive, in order (airgun_xl.transaction.stages), and
#: whether a signal there finds the outputs committed (from the commit on, signals are held).
FILL_STAGES = (("entry-staged", False), ("publishing", False), ("entry-renamed", True),
               ("published", True))


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
@pytest.mark.parametrize("stage, committed", FILL_STAGES)
def test_a_signal_at_each_stage_leaves_all_or_nothing(tmp_path, signum, stage, committed):
    """A fill (workbook and archive entry, the history in it) gets the signal at each stage,
    the stage waited for (issue 43: the random moments of a fraction of a fill's time found
    no fill running on a busy machine): before the commit it ends with nothing of it left
    (exit 128+N), from the commit on complete (exit 0); no temp file, and the archive
    verifies clean."""
    from support import at_stage

    archive = tmp_path / "archive"
    assert main(["fill", str(SHOT), "-o", str(tmp_path / "warm.xlsx"), "--archive",
                 str(archive), "--only", "summary"]) == 0  # the archive exists
    out = tmp_path / "o.xlsx"
    code, err, reached = at_stage(tmp_path, ["fill", SHOT, "-o", out, "--archive", archive,
                                             "--sidecar", "always"], stage, signum)
    assert reached and "Traceback" not in err, err
    entries = len(Archive(archive).entries())
    if committed:  # the full history is in the entry (an archived fill writes no sidecar)
        assert code == 0 and out.exists() and entries == 2, err
        assert (archive / "shot_a" / "v0002" / "history.parquet").exists()
    else:
        assert code == 128 + signum, (code, err)
        assert not out.exists() and entries == 1
        assert not (tmp_path / "o.history.parquet").exists()
    assert _owned(tmp_path) == [], err
    assert Archive(archive).verify() == []


@pytest.mark.parametrize("stage, leaves", [("publishing", True), ("published", None)])
def test_a_killed_fill_leaves_at_most_temp_files_that_the_next_run_removes(tmp_path, stage,
                                                                         leaves):
    """SIGKILL at a stage (waited for, never a guessed time): while its outputs are staged,
    the fill leaves temps and no output; just past the commit point, both outputs. The next
    run's recovery removes what the killed one left, and workbook and sidecar are both there
    or neither is."""
    from support import at_stage

    out = tmp_path / "o.xlsx"
    code, _, reached = at_stage(tmp_path, ["fill", SHOT, "-o", out, "--force", "--sidecar",
                                           "always"], stage, signal.SIGKILL)
    assert reached and code == -signal.SIGKILL
    names = {p.name for p in tmp_path.iterdir()}
    if leaves:
        assert _owned(tmp_path)  # the temps of the staged outputs
    recover(tmp_path)  # what the next run does first
    assert _owned(tmp_path) == []
    pair = {"o.xlsx", "o.history.parquet"} & names
    assert pair == (set() if stage == "publishing" else {"o.xlsx", "o.history.parquet"})
    assert main(["fill", str(SHOT), "-o", str(out), "--force", "--only", "summary"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "stages") == ["o.xlsx"]


def test_convergence_writes_its_workbook_and_png_together(tmp_path):
    """The workbook (9.5 kB) fits a 30 kB file-size limit, the PNG (64 kB) does not: neither
    is left, since both are one publication."""
    proc = subprocess.run([sys.executable, "-m", "airgun_xl", "convergence", str(SHOT),
                           "--levels", "5us,2us,1us", "-o", str(tmp_path / "c.xlsx")],
                          capture_output=True, text=True, preexec_fn=_limited(30_000))
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and "cannot be written" in lines[-1], proc.stderr
    assert "Traceback" not in proc.stderr and sorted(tmp_path.iterdir()) == []
