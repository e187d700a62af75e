"""The archive touches only what it owns, and reports damage instead of raising on it."""
import json
import shutil
import sqlite3

import builders as b
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from support import refused

from airgun_xl.archive import MARKER, SCRATCH, Archive, safe_name
from airgun_xl.cli import main

SHOT = b.TEMPLATE


def _home(tmp_path):
    """A folder like a home folder: its own .tmp with someone's files in it."""
    home = tmp_path / "home"
    (home / ".tmp" / "12345-notes").mkdir(parents=True)
    (home / ".tmp" / "12345-notes" / "draft.txt").write_text("keep me")
    (home / ".tmp" / "scratch.bin").write_bytes(b"\0" * 10)
    (home / "thesis.docx").write_text("keep me too")
    return home


def test_a_foreign_folder_is_never_written_or_cleaned(tmp_path, capsys):
    home = _home(tmp_path)
    out = tmp_path / "o.xlsx"
    refused(capsys, ["archive", "verify", home], tmp_path, naming=["not an airgun-xl archive"])
    refused(capsys, ["fill", SHOT, "-o", out, "--archive", home], tmp_path,
            naming=["not an airgun-xl archive"])
    refused(capsys, ["history", "--archive", home], tmp_path, naming=["not an airgun-xl archive"])
    refused(capsys, ["show", "x", "--archive", home], tmp_path, naming=["not an airgun-xl"])
    refused(capsys, ["compare", "a", "b", "--archive", home], tmp_path, naming=["not an"])
    assert not out.exists()  # refused before the run, so no workbook either


def test_a_missing_archive_is_not_created_by_reading_it(tmp_path, capsys):
    gone = tmp_path / "no" / "such" / "dir"
    for argv in (["archive", "verify", gone], ["history", "--archive", gone],
                 ["show", "x", "--archive", gone]):
        refused(capsys, argv, tmp_path, naming=["no such archive"])
    assert not (tmp_path / "no").exists()
    refused(capsys, ["fill", SHOT, "-o", tmp_path / "o.xlsx", "--archive", gone], tmp_path,
            naming=["does not exist"])


def test_an_empty_folder_becomes_an_archive(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["fill", str(SHOT), "-o", str(tmp_path / "o.xlsx"), "--only", "summary",
                 "--archive", str(empty)]) == 0
    assert json.loads((empty / MARKER).read_text())["tool"] == "airgun-xl"
    assert [e.ref for e in Archive(empty).entries()] == ["shot_a@1"]


@pytest.fixture
def archive(tmp_path):
    root = tmp_path / "archive"
    for k in range(2):
        assert main(["fill", str(SHOT), "-o", str(tmp_path / f"o{k}.xlsx"), "--only",
                     "summary", "--archive", str(root)]) == 0
    return root


def _fill_again(tmp_path, root):
    assert main(["fill", str(SHOT), "-o", str(tmp_path / "again.xlsx"), "--only", "summary",
                 "--archive", str(root)]) == 0


def test_a_copied_entry_folder_is_a_finding_not_a_crash(tmp_path, capsys, archive):
    shutil.copytree(archive / "shot_a" / "v0001", archive / "shot_a" / "v0001.bak")
    shutil.copytree(archive / "shot_a" / "v0002", archive / "shot_a" / "v0009")  # stray copy
    capsys.readouterr()
    assert main(["archive", "verify", str(archive)]) == 1
    out = capsys.readouterr().out
    assert "shot_a/v0001.bak: not an entry" in out
    assert "shot_a/v0009: not in the index (its manifest is missing, corrupt or names another" \
           in out
    _fill_again(tmp_path, archive)  # later fills still work, and take v0010
    assert max(e.version for e in Archive(archive).entries()) == 10


def test_a_corrupt_manifest_and_a_missing_file_are_findings(tmp_path, capsys, archive):
    (archive / "shot_a" / "v0001" / "manifest.json").write_text("{not json")
    (archive / "shot_a" / "v0002" / "params.json").unlink()
    capsys.readouterr()
    assert main(["archive", "verify", str(archive)]) == 1
    out = capsys.readouterr().out
    assert "shot_a@1: manifest.json is missing, corrupt or names another entry" in out
    assert "shot_a@2: missing params.json" in out
    refused(capsys, ["show", "shot_a@2", "--archive", archive], archive,
            naming=["shot_a@2: missing params.json", "archive verify"])
    _fill_again(tmp_path, archive)
    assert len(Archive(archive).entries()) == 3


def test_an_index_row_pointing_outside_is_a_finding(tmp_path, capsys, archive):
    conn = sqlite3.connect(archive / "index.sqlite")
    conn.execute("UPDATE entries SET path = '../../etc' WHERE version = 1")
    conn.commit()
    conn.close()
    capsys.readouterr()
    assert main(["archive", "verify", str(archive)]) == 1
    out = capsys.readouterr().out
    assert "its path '../../etc' is not an entry folder" in out
    refused(capsys, ["show", "shot_a@1", "--archive", archive], archive, naming=["no such entry"])


def test_only_its_own_dead_scratch_folders_are_removed(tmp_path, archive):
    scratch = archive / SCRATCH
    scratch.mkdir(exist_ok=True)
    dead = scratch / f"999999.1-{'a' * 32}"
    dead.mkdir()
    (dead / "output.xlsx").write_bytes(b"half")
    foreign = scratch / "notes"
    foreign.mkdir()
    assert main(["archive", "verify", str(archive)]) == 0
    assert not dead.exists() and foreign.exists()


def test_empty_and_odd_entry_names(tmp_path, capsys, archive):
    refused(capsys, ["show", "", "--archive", archive], archive, naming=["empty name"])
    refused(capsys, ["show", "../../etc/passwd", "--archive", archive], archive,
            naming=["no such entry"])


@settings(max_examples=30, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=st.text(min_size=0, max_size=300))
@example(name="-:")  # a name that starts with '-'
@example(name="")  # no name: the file's
@example(name="../../etc/passwd")
def test_any_shot_name_stays_inside_the_archive(tmp_path, name):
    """Whatever --name holds, the entry is one folder down inside DIR, named safely."""
    safe = safe_name(name)
    assert safe and safe == safe_name(safe) and "/" not in safe and not safe.startswith(".")
    assert len(safe) <= 100 and not safe.lower().startswith("index.sqlite")
    root = tmp_path / "names"
    argv = ["fill", str(SHOT), "-o", str(tmp_path / "o.xlsx"), "--force", "--only", "summary",
            "--archive", str(root), f"--name={name}"]  # '=': a name may start with '-'
    assert main(argv) == 0
    expected = safe if name else "shot_a"  # no name: the input file's
    entry = max(Archive(root).entries(shot=expected), key=lambda e: e.version)
    assert entry.path.parent.parent == root and entry.shot == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == ["names", "o.xlsx"]


def test_a_refused_run_does_not_create_its_archive(tmp_path, capsys):
    """The shot is refused after reading (its time step is unstable): no archive folder."""
    stiff = tmp_path / "stiff.xlsx"
    import openpyxl

    wb = openpyxl.load_workbook(SHOT)
    wb.worksheets[0]["C6"] = -5e11  # the stiff case of README at 5 us
    wb.worksheets[0]["E2"] = 5e-6
    wb.save(stiff)
    refused(capsys, ["fill", stiff, "--archive", tmp_path / "new_archive"], tmp_path,
            naming=["unstable"])
    assert not (tmp_path / "new_archive").exists()


def test_a_symlinked_shot_folder_is_reported_not_followed(tmp_path, capsys, archive):
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "v0001").mkdir(parents=True)
    (archive / "linked").symlink_to(elsewhere)
    capsys.readouterr()
    assert main(["archive", "verify", str(archive)]) == 1
    out = capsys.readouterr().out
    assert f"linked: a symbolic link to {elsewhere}, not a shot folder (not followed)" in out
    assert sorted(p.name for p in elsewhere.iterdir()) == ["v0001"]
