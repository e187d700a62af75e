"""The publication protocol of airgun_xl.transaction, step by step, and the memory estimate.

The end-to-end tests (tests/hostile) kill and signal real fills; these set up each state a
killed publisher can leave and check what the next publisher's recovery makes of it.
"""
import json
import os
import re
import sys

import pytest
from conftest import TEMPLATE

from airgun_xl import limits
from airgun_xl.cli import main
from airgun_xl.errors import OutputError, ResourceError
from airgun_xl.transaction import Publication, owner_alive, owner_token, recover

DEAD = "999999.12345"  # no such process


def _dead_publication(folder, finals, committed=None, marker_token="t"):
    """What a publisher killed after publishing ``finals`` leaves: temps (linked to the
    finals), backups of the old files, and its journal."""
    token = f"{DEAD}-{'ab' * 8}"
    files = []
    for name in finals:
        final = folder / name
        temp = folder / f".{name}.{token}.airgun-xl-tmp"
        if final.exists():
            os.rename(final, folder / f".{name}.{token}.airgun-xl-bak")
        temp.write_text(f"new {name}")
        os.link(temp, final)
        st = os.stat(temp)
        files.append({"final": name, "inode": [st.st_dev, st.st_ino]})
    record = {"token": token, "files": files, "removals": []}
    if committed is not None:
        marker = folder / "manifest.json"
        marker.write_text(json.dumps({"txn": token if committed else "another"}))
        record["marker"] = {"path": str(marker), "token": token}
    (folder / f".{finals[0]}.{token}.airgun-xl-journal").write_text(json.dumps(record))
    return token


def _names(folder):
    return sorted(p.name for p in folder.iterdir())


def test_an_uncommitted_journal_is_rolled_back(tmp_path):
    (tmp_path / "o.xlsx").write_text("old workbook")
    _dead_publication(tmp_path, ["o.xlsx", "o.history.parquet"])
    recover(tmp_path)
    assert _names(tmp_path) == ["o.xlsx"]
    assert (tmp_path / "o.xlsx").read_text() == "old workbook"  # the backup is back


def test_a_journal_whose_participant_committed_is_rolled_forward(tmp_path):
    (tmp_path / "o.xlsx").write_text("old workbook")
    _dead_publication(tmp_path, ["o.xlsx", "o.history.parquet"], committed=True)
    recover(tmp_path)
    assert _names(tmp_path) == ["manifest.json", "o.history.parquet", "o.xlsx"]
    assert (tmp_path / "o.xlsx").read_text() == "new o.xlsx"


def test_a_marker_naming_another_publication_is_not_a_commit(tmp_path):
    _dead_publication(tmp_path, ["o.xlsx"], committed=False)
    recover(tmp_path)
    assert _names(tmp_path) == ["manifest.json"]


def test_a_planted_journal_cannot_reach_outside_its_folder(tmp_path):
    """A journal naming ../victim is not acted on; the victim, with the very inode the
    journal names, stays."""
    folder = tmp_path / "out"
    folder.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    st = os.stat(victim)
    token = f"{DEAD}-{'cd' * 8}"
    record = {"token": token, "files": [{"final": "../victim.txt",
                                         "inode": [st.st_dev, st.st_ino]}], "removals": []}
    (folder / f".o.xlsx.{token}.airgun-xl-journal").write_text(json.dumps(record))
    recover(folder)
    assert victim.read_text() == "keep" and _names(folder) == []


def test_a_live_publishers_files_are_left_alone(tmp_path):
    token = f"{owner_token()}-{'ef' * 8}"
    temp = tmp_path / f".o.xlsx.{token}.airgun-xl-tmp"
    temp.write_text("mine, in progress")
    foreign = tmp_path / ".o.xlsx.notours.airgun-xl-tmp"
    foreign.write_text("someone else's")
    recover(tmp_path)
    assert temp.exists() and foreign.exists()


def test_a_reused_pid_does_not_look_like_the_owner():
    pid, started, host = owner_token().split(".")
    assert owner_alive(f"{pid}.{started}.{host}") and owner_alive(f"{pid}.{started}")
    assert not owner_alive(f"{pid}.{int(started) + 1}.{host}")  # same pid, another process
    assert not owner_alive(DEAD)


def test_an_owner_names_its_host_and_another_hosts_owner_is_never_taken_for_dead():
    """Issue 36: two hosts on one share. A token names its host; a process of another host
    cannot be seen from this one, so it is taken to be alive (its files are never removed
    here); a token of before the host was named is this host's."""
    from airgun_xl.transaction import owners

    token = owner_token()
    assert re.fullmatch(owners.OWNER_PATTERN, token) and token.endswith("." + owners.host_tag())
    assert owners.host_tag("LAB-Cell.2") == "labcell2" and owners.host_tag("42") == "h42"
    assert owners.host_tag("x" * 40) == "x" * 32 and owners.host_tag("") == "h"
    assert owner_alive(f"{DEAD}.otherhost")  # another host's: alive as far as this one knows
    assert not owner_alive(f"{DEAD}.{owners.host_tag()}")  # this host's, gone
    # a file name reads one way: the owner with its host, not the host taken for a start time
    name = f".out.xlsx.{DEAD}.h42-{'ab' * 8}.airgun-xl-tmp"
    from airgun_xl.transaction.publication import _OWNED

    match = _OWNED.match(name)
    assert match and match["owner"] == f"{DEAD}.h42" and match["name"] == "out.xlsx"


def test_without_force_the_second_publication_of_a_name_fails_whole(tmp_path):
    out = tmp_path / "o.xlsx"
    with Publication() as first:
        first.stage(out).write_text("first")
        second = Publication()
        second.stage(out).write_text("second")
        second.stage(tmp_path / "o.history.csv").write_text("second's sidecar")
        first.commit()
    with pytest.raises(OutputError, match="already exists"), second:
        second.commit()
    assert _names(tmp_path) == ["o.xlsx"] and out.read_text() == "first"


def test_a_failing_participant_rolls_the_files_back(tmp_path):
    (tmp_path / "o.xlsx").write_text("old")

    class Failing:
        released = False

        def prepare(self, token):
            return tmp_path / "marker.json"

        def commit(self):
            raise OSError("disk full")

        def release(self):
            Failing.released = True

    # the participant's OSError is the command's one-line OutputError (23.15)
    with pytest.raises(OutputError, match="cannot be published"), \
            Publication(force=True) as pub:
        pub.stage(tmp_path / "o.xlsx").write_text("new")
        pub.join(Failing())
        pub.commit()
    assert _names(tmp_path) == ["o.xlsx"] and (tmp_path / "o.xlsx").read_text() == "old"
    assert Failing.released


# -- memory --------------------------------------------------------------------------------------
def test_a_run_past_the_memory_budget_is_refused_before_it_starts(tmp_path, capsys,
                                                                    monkeypatch):
    monkeypatch.setenv(limits.MEMORY_ENV, "150MB")
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("airgun-xl: error: a run of 12,002 rows") and "0.15 GB available" in err
    assert "a larger E2" in err and list(tmp_path.iterdir()) == []
    assert main(["sweep", str(TEMPLATE), "--mc", "2000000", "--sd", "E40=3%"]) == 2
    assert "a sweep of 2,000,000 shots" in capsys.readouterr().err
    monkeypatch.setenv(limits.MEMORY_ENV, "lots")
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx")]) == 2
    assert "$AIRGUN_XL_MEMORY: found 'lots'" in capsys.readouterr().err


def test_the_estimate_is_above_the_measured_peak(tmp_path):
    """A 1.2 M-row fill with every output, in a child: its own peak resident size (VmHWM) is
    below the estimate, which is what lets a refusal come before the run."""
    import openpyxl

    shot = tmp_path / "long.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    wb.worksheets[0]["E2"] = 5e-9
    wb.save(shot)
    sys.path.insert(0, str(TEMPLATE.parents[1] / "tests" / "hostile"))
    from support import run_child

    code, err, peak = run_child(tmp_path, ["fill", shot, "-o", tmp_path / "o.xlsx",
                                           "--allow-unstable"], timeout=600)
    assert code == 0, err
    rows = 1_200_002
    assert peak < limits.fill_bytes(rows, 8)
    assert peak > 0.5 * limits.fill_bytes(rows, 8)  # and not wildly above it either


def test_parse_bytes_and_the_budget(monkeypatch):
    assert limits.parse_bytes("2GB") == 2 * 2**30
    assert limits.parse_bytes("500 MB") == 500 * 2**20
    assert limits.parse_bytes("1.5e9") == 1_500_000_000
    assert limits.parse_bytes("-1") is None and limits.parse_bytes("x") is None
    monkeypatch.setenv(limits.MEMORY_ENV, "1GB")
    limits.check_memory(2**30, "a run", "less")  # exactly the budget: allowed
    with pytest.raises(ResourceError, match="needs about 1.00 GB, more than the 1.00 GB"):
        limits.check_memory(2**30 + 1, "a run", "less")


def test_owner_liveness_asks_psutil_not_os_kill(monkeypatch):
    """Issue 24.4: liveness is psutil's (pid_exists and the start time) on every platform; it
    never calls os.kill, which on Windows sends CTRL_C_EVENT instead of testing for the pid.
    The logic, with the platform's answers mocked: a gone pid, a reused pid (another start
    time) and the owner itself."""
    import os as os_module

    import psutil

    from airgun_xl.transaction import owners

    def no_kill(*args):
        raise AssertionError("os.kill called")

    monkeypatch.setattr(os_module, "kill", no_kill)

    class FakeProcess:
        def __init__(self, pid):
            if pid not in started:
                raise psutil.NoSuchProcess(pid)
            self.pid = pid

        def create_time(self):
            return started[self.pid]

    started = {4242: 1700000000.25}
    monkeypatch.setattr(psutil, "Process", FakeProcess)
    monkeypatch.setattr(psutil, "pid_exists", lambda pid: pid in started)
    assert owners.owner_alive("4242.170000000025")  # the owner, same start time
    assert not owners.owner_alive("4242.170000000024")  # pid reused by a later process
    assert not owners.owner_alive("4343.170000000025")  # gone
    assert not owners.owner_alive("not-a-pid.1") and not owners.owner_alive("0.1")
    assert owners.owner_alive("4242.0")  # no start time known: the pid's existence decides
