"""Issue 36 (first part): an archive whose index is on a PostgreSQL server, its entries on the
lab's share. Every test runs against a real server started from its binaries
(tests/pg_server.py, the ``pg_server`` fixture); without them the tests skip, saying what to
install.

Covered here: ``archive init --index``, the marker (an identity, never an address), a password
in the address refused unrepeated, fill/history/show/verify unchanged on a server archive
(history equal to the SQLite archive's), 4 processes x 25 entries at once, two hosts sharing a
scratch folder, psycopg missing, a marker naming an archive the server does not hold,
``archive migrate``, and the faults (one line, exit 2, nothing published): the server
unreachable, the password wrong, the server stopped mid-campaign, a lock wait past its
timeout, the share turning read-only.
"""
import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import openpyxl
import pytest
from conftest import TEMPLATE

from airgun_xl.archive import MARKER, Archive
from airgun_xl.archive.index import SERVER_SCHEMA
from airgun_xl.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _init(tmp_path, capsys, name="shots"):
    """A server archive made as README's administrator makes it: by the schema's owner, for
    the engineers' role (issue 43); the engineers then use $AIRGUN_XL_INDEX."""
    root = tmp_path / name
    address = os.environ["AIRGUN_XL_INDEX"].replace("//lab@", "//lab_admin@")
    assert main(["archive", "init", str(root), "--index", address, "--writers", "lab"]) == 0
    out = capsys.readouterr().out
    assert "its index on 127.0.0.1:" in out and "/lab" in out
    return root


def _one_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    return err[0]


def test_init_makes_a_server_archive_whose_marker_names_its_identity_not_its_address(
        tmp_path, capsys, server_env):
    root = _init(tmp_path, capsys)
    marker = json.loads((root / MARKER).read_text())
    assert marker["index"] == "server" and len(marker["identity"]) == 32
    text = (root / MARKER).read_text()
    assert "127.0.0.1" not in text and str(server_env.port) not in text and "lab" not in text
    assert sorted(os.listdir(root)) == [MARKER]  # no index.sqlite: the rows are on the server
    import psycopg

    with psycopg.connect(server_env.admin.replace("dbname=postgres", "dbname=lab")) as conn:
        row = conn.execute(f"SELECT format FROM {SERVER_SCHEMA}.archives WHERE identity = %s",
                           (marker["identity"],)).fetchone()
    assert row == (1,)
    assert main(["archive", "init", str(root)]) == 2
    assert "is an archive already" in _one_line(capsys)


@pytest.mark.parametrize("where", ["option", "env"])
def test_a_password_in_the_address_is_refused_and_never_repeated(tmp_path, capsys,
                                                                 server_env, monkeypatch,
                                                                 where):
    address = f"postgresql://lab:hunter2secret@127.0.0.1:{server_env.port}/lab"
    argv = ["archive", "init", str(tmp_path / "shots")]
    if where == "option":
        argv += ["--index", address]
    else:
        monkeypatch.setenv("AIRGUN_XL_INDEX", address)
    assert main(argv) == 2
    line = _one_line(capsys)
    assert "found a password in the address" in line and "hunter2secret" not in line
    assert ("--index:" if where == "option" else "$AIRGUN_XL_INDEX:") in line
    assert not (tmp_path / "shots").exists()  # nothing made


def _history(root, capsys):
    assert main(["history", "--archive", str(root), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    keep = ("shot", "version", "peak_kg", "integrator", "model", "v0")
    return [{k: r.get(k) for k in keep} for r in rows]


def _local(root, monkeypatch):
    """An SQLite archive made at ``root`` with $AIRGUN_XL_INDEX unset for the moment (with it
    set, a command refuses to make a local index: issue 43.14)."""
    with monkeypatch.context() as m:
        m.delenv("AIRGUN_XL_INDEX")
        Archive(root, create=True)
    return root


def test_fill_history_show_and_verify_work_unchanged_and_agree_with_sqlite(tmp_path, capsys,
                                                                           server_env,
                                                                           monkeypatch):
    server = _init(tmp_path, capsys)
    local = _local(tmp_path / "local", monkeypatch)
    for root in (server, local):
        for k, extra in enumerate(([], ["--integrator", "newmark"])):
            out = tmp_path / f"o{k}.xlsx"
            assert main(["fill", str(TEMPLATE), "-o", str(out), "--force", "--archive",
                         str(root), "--only", "summary", *extra]) == 0
        capsys.readouterr()
    on_server, on_sqlite = _history(server, capsys), _history(local, capsys)
    assert on_server == on_sqlite and [r["version"] for r in on_server] == [1, 2]
    assert [r["integrator"].split("/")[0] for r in on_server] == ["legacy", "newmark"]
    for where in ("E40=2.703e7", "E40=1"):  # --where: the same rows on both back ends
        found = []
        for root in (server, local):
            assert main(["history", "--archive", str(root), "--where", where, "--json"]) == 0
            found.append([(r["shot"], r["version"]) for r in json.loads(capsys.readouterr().out)])
        assert found[0] == found[1] == ([("shot_a", 1), ("shot_a", 2)] if where != "E40=1"
                                        else [])
    assert main(["show", "shot_a@2", "--archive", str(server)]) == 0
    assert "newmark" in capsys.readouterr().out
    assert main(["archive", "verify", str(server)]) == 0
    assert "2 entries, 0 problems" in capsys.readouterr().out
    assert sorted(p.name for p in (server / "shot_a").iterdir()) == ["v0001", "v0002"]


WRITER = textwrap.dedent("""
    import sys
    from pathlib import Path
    from airgun_xl.archive import Archive

    root, k = Path(sys.argv[1]), int(sys.argv[2])
    note = root.parent / f"note{k}.txt"
    note.write_text(f"writer {k}")
    archive = Archive(root)
    for i in range(25):
        archive.add(f"s{i % 5}", {"note.txt": note}, {"summary.json": {"i": i, "k": k}},
                    {"v0": float(i)})
""")


def test_four_processes_of_25_entries_at_once_take_unique_versions(tmp_path, capsys,
                                                                   server_env):
    """4 processes x 25 entries into 5 shots at once: 100 entries, each shot's versions
    1..20 taken once, every entry whole; verify clean."""
    root = _init(tmp_path, capsys)
    procs = [subprocess.Popen([sys.executable, "-c", WRITER, str(root), str(k)],
                              stderr=subprocess.PIPE, text=True, cwd=ROOT) for k in range(4)]
    for proc in procs:
        _, err = proc.communicate(timeout=600)
        assert proc.returncode == 0, err
    entries = Archive(root).entries()
    assert len(entries) == 100
    for s in range(5):
        assert sorted(e.version for e in entries if e.shot == f"s{s}") == list(range(1, 21))
    assert Archive(root).verify() == []
    assert not any((root / ".airgun-xl-scratch").iterdir())


HOLDER = textwrap.dedent("""
    import sys
    from pathlib import Path
    from airgun_xl.archive.store import read_marker
    from airgun_xl.archive.index import ServerIndex

    root, owner = Path(sys.argv[1]), sys.argv[2]
    index = ServerIndex(root, read_marker(root)["identity"])
    index.hold(owner)  # as a writer on another host does while its scratch folder exists
    (root / ".airgun-xl-scratch" / f"{owner}-{'ab' * 16}").mkdir(parents=True)
    print("ready", flush=True)
    sys.stdin.read()  # until the test lets it go
""")


def test_two_hosts_on_one_share_never_remove_each_others_live_scratch_folder(
        tmp_path, capsys, server_env):
    """Host A's writer (another host's owner token) holds its scratch folder while this host
    recovers: the server says A is alive, so the folder stays; once A is gone (its session
    ends, as when its process dies), the next recovery removes it."""
    root = _init(tmp_path, capsys)
    owner = "4242.170000000025.hosta"
    folder = root / ".airgun-xl-scratch" / f"{owner}-{'ab' * 16}"
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(root), owner],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                              cwd=ROOT)
    assert holder.stdout.readline().strip() == "ready"
    try:
        assert Archive(root).verify() == [] and folder.is_dir()  # recovery ran: kept
        Archive(root).add("s", {}, {"summary.json": {}}, {})
        assert folder.is_dir()
    finally:
        holder.communicate("", timeout=60)
    assert Archive(root).verify() == [] and not folder.exists()  # its writer is gone


def test_on_an_sqlite_archive_another_hosts_scratch_folder_is_never_removed(tmp_path):
    """Without a server, nothing on this host can say that another host's writer is gone."""
    root = tmp_path / "local"
    Archive.init(root)
    folder = root / ".airgun-xl-scratch" / f"999999.12345.hosta-{'ab' * 16}"
    folder.mkdir(parents=True)
    mine = root / ".airgun-xl-scratch" / f"999999.12345-{'cd' * 16}"  # this host's, gone
    mine.mkdir()
    assert Archive(root).verify() == []
    assert folder.is_dir() and not mine.exists()


def test_without_psycopg_a_server_archive_is_one_line_naming_the_extra(tmp_path, capsys,
                                                                       server_env,
                                                                       monkeypatch):
    """psycopg is imported by the index's agent (airgun_xl/archive/agent.py): a psycopg that
    cannot be imported, first on the agent's path, is one that is not installed."""
    from airgun_xl.archive import agent

    root = _init(tmp_path, capsys)
    fake = tmp_path / "path" / "psycopg"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('as if not installed')\n")
    monkeypatch.setenv("PYTHONPATH", str(fake.parent))
    agent.stop()  # the next agent starts with that path
    out = tmp_path / "o.xlsx"
    try:
        assert main(["fill", str(TEMPLATE), "-o", str(out), "--archive", str(root)]) == 2
    finally:
        agent.stop()
    line = _one_line(capsys)
    assert "psycopg is not installed" in line and "airgun-xl[server]" in line
    assert not out.exists()


def test_a_marker_naming_an_archive_the_server_does_not_hold_is_refused(tmp_path, capsys,
                                                                        server_env):
    """A marker is a claim to check, never an address to dial: one naming an identity the
    server lacks is refused, and an address planted in it is not used."""
    root = _init(tmp_path, capsys)
    (root / MARKER).write_text(json.dumps({
        "format": 1, "index": "server", "identity": "f" * 32,
        "address": "postgresql://evil.example/steal"}))
    assert main(["history", "--archive", str(root)]) == 2
    line = _one_line(capsys)
    assert f"its marker names archive {'f' * 32}" in line and "evil" not in line
    (root / MARKER).write_text(json.dumps({"format": 1, "index": "server",
                                           "identity": "../../etc"}))
    assert main(["history", "--archive", str(root)]) == 2
    assert "identity" in _one_line(capsys)


@pytest.mark.parametrize("fault", ["refused", "password"])
def test_an_unreachable_server_or_a_wrong_password_is_one_line_and_publishes_nothing(
        tmp_path, capsys, server_env, monkeypatch, fault):
    root = _init(tmp_path, capsys)
    if fault == "refused":
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            closed = s.getsockname()[1]
        monkeypatch.setenv("AIRGUN_XL_INDEX", f"postgresql://lab@127.0.0.1:{closed}/lab")
    else:
        monkeypatch.setenv("PGPASSWORD", "not-the-password")
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(TEMPLATE), "-o", str(out), "--archive", str(root)]) == 2
    line = _one_line(capsys)
    assert "not-the-password" not in line
    if fault == "refused":
        assert "cannot be reached" in line
        assert "refused" in line or "connection failed" in line
    else:  # issue 43.16: a wrong password is a refused login, not a server out of reach
        assert "refused the login" in line and "password authentication failed" in line
        assert "cannot be reached" not in line
    assert not out.exists()
    assert sorted(os.listdir(root)) == [MARKER] or not any(
        (root / ".airgun-xl-scratch").iterdir())


def _history_rows(root, capsys):
    assert main(["history", "--archive", str(root), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_migrate_moves_the_index_and_history_reads_the_same(tmp_path, capsys, server_env,
                                                            monkeypatch):
    """An SQLite archive of three runs moved to the server: history is the same, ids
    included; the SQLite index is kept as a backup; the next fill goes to the server."""
    root = _local(tmp_path / "local", monkeypatch)
    for extra in ([], ["--integrator", "newmark"], ["--name", "other"]):
        assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--force",
                     "--archive", str(root), "--only", "summary", *extra]) == 0
    capsys.readouterr()
    before = _history_rows(root, capsys)
    owner = server_env.owner_address  # run by the administrator, for the engineers
    assert main(["archive", "migrate", str(root), "--index", owner, "--writers", "lab"]) == 0
    out = capsys.readouterr().out
    assert "(3 entries) to 127.0.0.1:" in out and "kept as .index.sqlite.moved-" in out
    assert _history_rows(root, capsys) == before
    marker = json.loads((root / MARKER).read_text())
    assert marker["index"] == "server" and not (root / "index.sqlite").exists()
    assert [p.name for p in root.iterdir() if p.name.startswith(".index.sqlite.moved-")]
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--force",
                 "--archive", str(root), "--only", "summary"]) == 0
    capsys.readouterr()
    after = _history_rows(root, capsys)
    assert len(after) == 4 and after[-1]["shot"] == "shot_a" and after[-1]["version"] == 3
    assert main(["archive", "verify", str(root)]) == 0
    assert "4 entries, 0 problems" in capsys.readouterr().out
    assert main(["archive", "migrate", str(root), "--index", owner]) == 2
    assert "its index is on a server already" in _one_line(capsys)


def test_migrate_refuses_a_row_that_does_not_match_its_manifest_and_moves_nothing(
        tmp_path, capsys, server_env, monkeypatch):
    root = _local(tmp_path / "local", monkeypatch)
    archive = Archive(root, create=True)
    note = tmp_path / "n.txt"
    note.write_text("x")
    archive.add("a", {"n.txt": note}, {}, {})
    archive.add("b", {"n.txt": note}, {}, {})
    (root / "b" / "v0001" / "n.txt").write_text("altered")
    marker = (root / MARKER).read_text()
    assert main(["archive", "migrate", str(root)]) == 2
    line = _one_line(capsys)
    assert "1 of 2 rows do not match their entry's manifest (the first: b@1)" in line
    assert (root / MARKER).read_text() == marker and (root / "index.sqlite").is_file()


def test_a_writer_that_waited_on_the_lock_through_a_migrate_stops_and_publishes_nothing(
        tmp_path, server_env, monkeypatch):
    """Writers are kept out: one that held its scratch folder and waited for the SQLite lock
    while the index moved finds the marker changed, stops in one line, and leaves nothing."""
    from airgun_xl.errors import ArchiveError

    root = _local(tmp_path / "local", monkeypatch)
    archive = Archive(root, create=True)
    archive.add("a", {}, {"summary.json": {}}, {})
    pending = archive.prepare("a", {}, {"summary.json": {"late": True}}, {})
    Archive(root).migrate(server_env.owner_address, ["lab"])
    with pytest.raises(ArchiveError, match="its index was moved to a server while this "
                                           "writer waited"):
        try:
            pending.prepare()
        finally:
            pending.release()
    assert not any((root / ".airgun-xl-scratch").iterdir())
    assert [e.ref for e in Archive(root).entries()] == ["a@1"]


def _server_rows(server, root):
    """Entries the server holds for the archive at ``root`` (read as the superuser)."""
    import psycopg

    identity = json.loads((root / MARKER).read_text())["identity"]
    with psycopg.connect(server.admin.replace("dbname=postgres", "dbname=lab")) as conn:
        return conn.execute(f"SELECT shot, version FROM {SERVER_SCHEMA}.entries WHERE "
                            "archive = %s ORDER BY shot, version", (identity,)).fetchall()


def test_the_server_stopped_mid_campaign_names_the_shots_not_archived_and_a_rerun_ends_it(
        tmp_path, capsys, server_env):
    """pg_ctl stop -m immediate while a campaign archives: the shots it could not archive are
    named, each in one line, with exit 2, and their workbooks are not published; once the
    server is back, a second run fills and archives only those: no duplicate, no loss."""
    import time

    from conftest import template_with

    root = _init(tmp_path, capsys)
    day = tmp_path / "day"
    day.mkdir()
    for k in range(8):
        template_with(day, A28=150.0 + 5 * k, A29=150.0 + 5 * k,
                      A30=150.0 + 5 * k).rename(day / f"s{k}.xlsx")
    proc = subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(day), "--jobs", "2",
                             "--archive", str(root), "--only", "summary"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    deadline = time.monotonic() + 120
    try:
        while not _server_rows(server_env, root):  # polled: the first shot archived
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.01)
        server_env.stop("immediate")
        out, err = proc.communicate(timeout=300)
    finally:
        server_env.start()
    assert proc.returncode == 2, (out, err)
    assert "Traceback" not in err
    failed = sorted(set(re.findall(r"^airgun-xl: error: .*/(s\d)\.xlsx: the archive's index "
                                   r"on 127\.0\.0\.1:\d+/lab: ", err, re.M)))
    published = sorted(p.name for p in day.glob("s?.out.xlsx"))
    archived = sorted(shot for shot, _ in _server_rows(server_env, root))
    assert failed and len(published) + len(failed) == 8, (out, err)
    assert [n.replace(".out.xlsx", "") for n in published] == archived  # published = archived
    proc2 = subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(day), "--jobs", "2",
                            "--archive", str(root), "--only", "summary"],
                           capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc2.returncode == 0, proc2.stderr
    rows = _server_rows(server_env, root)
    assert sorted(shot for shot, _ in rows) == [f"s{k}" for k in range(8)]  # once each
    assert all(version == 1 for _, version in rows)
    assert Archive(root).verify() == []


def test_a_statement_that_times_out_is_one_line_and_publishes_nothing(tmp_path, capsys,
                                                                       server_env,
                                                                       monkeypatch):
    """Another session holds the entries table: the writer's wait ends at the lock timeout
    (1 s here, 120 s as shipped) in one line, exit 2; no workbook, no row, no scratch."""
    import psycopg

    from airgun_xl.archive import index

    root = _init(tmp_path, capsys)
    monkeypatch.setattr(index, "LOCK_WAIT", 1)
    monkeypatch.setattr(index, "STATEMENT_TIMEOUT", 1)
    out = tmp_path / "o.xlsx"
    with psycopg.connect(server_env.admin.replace("dbname=postgres", "dbname=lab")) as conn:
        conn.execute(f"LOCK TABLE {SERVER_SCHEMA}.entries IN ACCESS EXCLUSIVE MODE")
        code = main(["fill", str(TEMPLATE), "-o", str(out), "--archive", str(root),
                     "--only", "summary"])
        line = _one_line(capsys)
        conn.rollback()
    assert code == 2 and "timeout" in line, line
    assert not out.exists() and _server_rows(server_env, root) == []
    assert not any((root / ".airgun-xl-scratch").iterdir())


@pytest.mark.parametrize("stage", ["scratch", "rename"])
def test_a_share_that_turns_read_only_is_one_line_and_publishes_nothing(
        tmp_path, capsys, server_env, monkeypatch, stage):
    """EROFS, injected (root ignores permissions): when the scratch folder is made, or when
    the entry is renamed into place. One line, exit 2; no workbook, no row."""
    import errno

    root = _init(tmp_path, capsys)
    real = os.mkdir if stage == "scratch" else os.rename

    def read_only(src, *args, **kwargs):
        # the entry's rename is made between folder descriptors (src_dir_fd: the scratch)
        if ".airgun-xl-scratch" in str(src) or kwargs.get("src_dir_fd") is not None:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(src))
        return real(src, *args, **kwargs)

    monkeypatch.setattr(os, "mkdir" if stage == "scratch" else "rename", read_only)
    out = tmp_path / "o.xlsx"
    code = main(["fill", str(TEMPLATE), "-o", str(out), "--archive", str(root),
                 "--only", "summary"])
    line = _one_line(capsys)
    assert code == 2 and "Read-only file system" in line, line
    assert not out.exists() and _server_rows(server_env, root) == []


KILLED_AT = textwrap.dedent("""
    import os, signal, sys
    from pathlib import Path
    from airgun_xl.archive import Archive, index, store

    root, stage = Path(sys.argv[1]), sys.argv[2]

    def die(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGKILL)

    def after(original):
        def wrapped(*args, **kwargs):
            result = original(*args, **kwargs)
            die()
            return result
        return wrapped

    if stage == "scratch":  # files written and synced, nothing asked of the server
        store.PendingEntry.prepare = die
    elif stage == "locked":  # the write lock held on the server, the version chosen
        store.Archive._next_version = after(store.Archive._next_version)
    elif stage == "renamed":  # the folder in place, its row not inserted
        index._ServerSession.insert = die
    elif stage == "inserted":  # the row inserted, not committed
        index._ServerSession.commit = die
    elif stage == "committed":  # the row committed, the scratch lock still held
        store.PendingEntry.commit = after(store.PendingEntry.commit)
    Archive(root).add("s", {}, {"summary.json": {"stage": float(sys.argv[3])}}, {"v0": 1.0})
""")

STAGES = ("scratch", "locked", "renamed", "inserted", "committed")


@pytest.mark.parametrize("stage, kept", [("scratch", False), ("locked", False),
                                         ("renamed", True), ("inserted", True),
                                         ("committed", True)])
def test_a_sigkill_at_each_stage_of_a_publication_leaves_nothing_the_next_writer_cannot_recover(
        tmp_path, capsys, server_env, stage, kept):
    """The writer SIGKILLed at each stage: the server rolls back its transaction and frees its
    locks when the session ends; the next writer removes the dead writer's scratch folder (the
    server says it is gone) and adopts a folder renamed into place from its manifest. The
    entry is whole or absent, and the next entry takes the next version."""
    root = _init(tmp_path, capsys)
    Archive(root).add("s", {}, {"summary.json": {"first": True}}, {})
    proc = subprocess.run([sys.executable, "-c", KILLED_AT, str(root), stage,
                           str(STAGES.index(stage))], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == -9, proc.stderr
    Archive(root).add("s", {}, {"summary.json": {"after": True}}, {})
    assert Archive(root).verify() == []
    versions = [e.version for e in Archive(root).entries("s")]
    assert versions == ([1, 2, 3] if kept else [1, 2])
    assert not any((root / ".airgun-xl-scratch").iterdir())
    if kept:
        assert Archive(root).get("s@2").load("summary.json") == {
            "stage": float(STAGES.index(stage))}


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


def _nested(inner):
    """Lists and objects of ``inner`` (a named function: hypothesis reads a lambda's source
    to check that it recurses, and misreads one split over lines)."""
    return st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner,
                                                         max_size=3)


MARKER_VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-5, 5), st.text(max_size=40),
              st.sampled_from(["server", "sqlite", "f" * 32, "0" * 31, "postgresql://x/y"])),
    _nested, max_leaves=8)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(marker=st.dictionaries(st.sampled_from(["format", "tool", "index", "identity",
                                               "address", "host"]), MARKER_VALUES,
                              max_size=5))
def test_any_random_marker_is_a_checked_claim_or_one_line(tmp_path_factory, marker):
    """The marker is untrusted: random content is read as an archive of one kind or the other
    (a server one only with a well-formed identity), or refused in one line naming the file;
    it is never an address to dial (nothing here connects: there is no server)."""
    from airgun_xl.archive.store import read_marker
    from airgun_xl.errors import ArchiveError

    root = tmp_path_factory.mktemp("m")
    (root / MARKER).write_text(json.dumps(marker))
    try:
        read = read_marker(root)
    except ArchiveError as exc:
        line = str(exc)
        assert "\n" not in line and line.startswith(str(root / MARKER)), line
        return
    assert read["format"] == 1 and read["index"] in ("sqlite", "server")
    if read["index"] == "server":
        assert len(read["identity"]) == 32 and set(read["identity"]) <= set("0123456789abcdef")


@settings(max_examples=400, deadline=None, derandomize=True)
@given(marker=st.one_of(MARKER_VALUES, st.dictionaries(
    st.sampled_from(["format", "tool", "index", "identity", "x"]),
    st.one_of(MARKER_VALUES, st.sampled_from([1, 1.0, True, 2, "1", "a" * 32, "a" * 32 + "\n",
                                              "A" * 32])), max_size=5)))
def test_the_markers_short_check_agrees_with_its_json_schema(marker):
    """The marker is checked without jsonschema (its import costs every archive command
    50 ms): the short check accepts and refuses exactly what the schema does."""
    from airgun_xl.errors import ArchiveError
    from airgun_xl.untrusted_json import check, check_marker

    def verdict(checker):
        try:
            checker(marker, "marker", "m", ArchiveError)
        except ArchiveError as exc:
            assert "\n" not in str(exc) and str(exc).startswith("m: ")
            return False
        return True

    assert verdict(check_marker) == verdict(check)


def _files_hold(folder, secret):
    """The files under ``folder`` (a workbook's zipped parts opened) that hold ``secret``."""
    import zipfile

    found = []
    for path in sorted(p for p in Path(folder).rglob("*") if p.is_file()):
        parts = [path.read_bytes()]
        if zipfile.is_zipfile(path):
            with zipfile.ZipFile(path) as z:
                parts = [z.read(n) for n in z.namelist()]
        if any(secret.encode() in part for part in parts):
            found.append(path)
    return found


def test_every_archive_command_works_unchanged_and_the_password_is_never_written(
        tmp_path, capsys, server_env):
    """calibrate --name, fill --crush-law NAME, a campaign, accept, history --where and -o,
    show, compare and verify on a server archive, as on an SQLite one; the password (in
    $PGPASSWORD, as a lab's shell has it) appears in no message, --json, workbook,
    provenance or any other file the commands wrote."""
    import pg_server
    from conftest import write_trace_csv

    import airgun_xl
    from airgun_xl.studies.calibrate import synthetic_measurement
    from airgun_xl.studies.recorder import Recorder

    root = _init(tmp_path, capsys)
    work = tmp_path / "work"
    work.mkdir()
    p = airgun_xl.load(TEMPLATE).params
    measured = write_trace_csv(work / "m.csv", synthetic_measurement(
        p.replace(sigmay=p.sigmay * 1.05), seed=5))
    said = []

    def run(*argv, code=0):
        assert main([*map(str, argv)]) == code, argv
        said.append(capsys.readouterr())
        return said[-1].out

    out = run("calibrate", TEMPLATE, measured, "--cfc", "1000", "-o", work / "cal.xlsx",
              "--archive", root, "--name", "LOT-36")
    assert "stored the law as LOT-36@1" in out
    run("fill", TEMPLATE, "--crush-law", "LOT-36", "--archive", root, "-o",
        work / "by_law.xlsx", "--name", "shot", "--only", "summary")
    day = work / "day"
    day.mkdir()
    for k in range(2):
        (day / f"d{k}.xlsx").write_bytes(TEMPLATE.read_bytes())
    run("fill", day, "--jobs", "2", "--archive", root, "--only", "summary")
    run("fill", TEMPLATE, "--archive", root, "-o", work / "again.xlsx", "--name", "shot",
        "--only", "summary", "--integrator", "newmark")
    recording = work / "rec.csv"
    Recorder(rate=50_000.0).csv(Recorder(rate=50_000.0).record(
        airgun_xl.load(TEMPLATE).run(track=()), seed=5), recording)
    out = run("accept", TEMPLATE, recording, "--sign", "-1", "--cfc", "1000", "--peak",
              "9.5kG:10%", "-o", work / "v.xlsx", "--archive", root)
    assert "PASS: " in out
    assert len(list((root / ".verdicts").rglob("v*.json"))) == 1

    listed = json.loads(run("history", "--archive", root, "--json"))
    assert sorted((r["shot"], r["version"]) for r in listed) == [
        ("d0", 1), ("d1", 1), ("shot", 1), ("shot", 2)]
    where = json.loads(run("history", "--archive", root, "--where", "E40=2.703e7", "--json"))
    assert sorted(r["shot"] for r in where) == ["d0", "d1", "shot", "shot"]
    out = run("history", "--archive", root)
    assert "LOT-36@1" in out and "verdicts (accept --archive):" in out
    run("history", "--archive", root, "-o", work / "shots.xlsx")
    rows = list(openpyxl.load_workbook(work / "shots.xlsx").worksheets[0].values)
    assert sorted(r[0] for r in rows[3:7]) == ["d0@1", "d1@1", "shot@1", "shot@2"]
    provenance = Archive(root).get("shot@1").load("provenance.json")
    assert provenance["crush_law"]["name"] == "fitted (LOT-36@1)"
    assert "newmark" in run("show", "shot@2", "--archive", root)
    compared = json.loads(run("compare", "shot@1", "shot@2", "--archive", root, "--json",
                              code=1))
    assert compared["same"] is False  # another law and another integrator
    assert json.loads(run("compare", "d0", "d1", "--archive", root, "--json"))["same"] is True
    assert "4 entries, 0 problems" in run("archive", "verify", root)

    secret = pg_server.PASSWORD
    assert not [s for s in said if secret in s.out or secret in s.err]
    assert _files_hold(root, secret) == [] and _files_hold(work, secret) == []


def test_a_hostile_row_on_the_server_is_reported_never_followed(tmp_path, capsys,
                                                                  server_env):
    """A row planted on the server (by a role that may write the schema) whose path leads out
    of the folder and whose shot is a formula: history shows it as text, show and compare
    refuse it in one line, verify reports it, and nothing outside the archive is read or
    written."""
    import psycopg

    root = _init(tmp_path, capsys)
    Archive(root).add("s", {}, {"summary.json": {}}, {"v0": 1.0})
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "v0001").mkdir()
    identity = json.loads((root / MARKER).read_text())["identity"]
    with psycopg.connect(server_env.admin.replace("dbname=postgres", "dbname=lab")) as conn:
        conn.execute(f"INSERT INTO {SERVER_SCHEMA}.entries (archive, id, shot, version, path, "
                     "created) VALUES (%s, 7, %s, 1, %s, '2026-01-01')",
                     (identity, '=HYPERLINK("http://x","y")', "../outside/v0001"))
    before = sorted(os.listdir(outside))
    assert main(["history", "--archive", str(root), "-o", str(tmp_path / "h.xlsx")]) == 0
    capsys.readouterr()
    cells = [c for r in openpyxl.load_workbook(tmp_path / "h.xlsx").worksheets[0].iter_rows()
             for c in r if isinstance(c.value, str) and "HYPERLINK" in c.value]
    assert all(c.data_type == "s" for c in cells)  # text, never a live formula
    assert main(["show", "#7", "--archive", str(root)]) == 2
    assert "no such entry" in _one_line(capsys)
    assert main(["archive", "verify", str(root)]) == 1
    out = capsys.readouterr().out
    assert "row #7: its path '../outside/v0001' is not an entry folder" in out
    assert sorted(os.listdir(outside)) == before and not any((outside / "v0001").iterdir())


def test_a_fill_leaves_psycopg_to_the_index_agent_which_ends_with_it(tmp_path, capsys,
                                                                     server_env):
    """The fill process never imports psycopg (its 0.1 s of import runs in the index's agent,
    beside the fill: benchmarks/bench_archive.py); the agent ends when its parent ends, even
    by SIGKILL, and the server then frees the parent's locks (the next writer goes on)."""
    import signal
    import time

    root = _init(tmp_path, capsys)
    code = textwrap.dedent(f"""
        import os, sys
        from airgun_xl.cli import main
        from airgun_xl.archive import agent
        assert main(["fill", {str(TEMPLATE)!r}, "-o", {str(tmp_path / 'o.xlsx')!r},
                     "--only", "summary", "--archive", {str(root)!r}]) == 0
        assert "psycopg" not in sys.modules, "the fill imported psycopg"
        from airgun_xl.archive import Archive
        pending = Archive({str(root)!r}).prepare("held", {{}}, {{"summary.json": {{}}}}, {{}})
        print(agent.agent().proc.pid, flush=True)
        os.kill(os.getpid(), 9)  # the writer dies holding its scratch folder's session lock
    """)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    helper = int(proc.stdout.split()[-1])
    deadline = time.monotonic() + 30
    while _running(helper):  # it reads the end of its input, and ends (polled)
        assert time.monotonic() < deadline, "the agent outlived its parent"
        time.sleep(0.01)
    Archive(root).add("next", {}, {"summary.json": {}}, {})
    assert Archive(root).verify() == []
    assert sorted(e.ref for e in Archive(root).entries()) == ["next@1", "shot_a@1"]
    assert not any((root / ".airgun-xl-scratch").iterdir())


def _running(pid):
    import psutil

    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def test_the_agent_lost_mid_publication_is_one_line_and_the_next_writer_goes_on(
        tmp_path, capsys, server_env):
    """The index's agent killed between an entry's scratch folder and its commit: the commit
    is one ArchiveError naming the index, nothing is published, and the next entry (a new
    agent) takes version 1."""
    from airgun_xl.archive import agent
    from airgun_xl.errors import ArchiveError

    root = _init(tmp_path, capsys)
    pending = Archive(root).prepare("s", {}, {"summary.json": {}}, {})
    agent.agent().proc.kill()
    with pytest.raises(ArchiveError) as caught:
        pending.commit_alone()
    line = str(caught.value)
    assert "\n" not in line and "helper process stopped" in line, line
    assert "the archive's index on 127.0.0.1:" in line
    assert Archive(root).entries() == [] and not (root / "s").exists()
    assert Archive(root).add("s", {}, {"summary.json": {}}, {}).version == 1
    assert Archive(root).verify() == []


def test_an_interrupt_between_request_and_reply_ends_the_agent_and_the_next_starts_anew(
        tmp_path, capsys, server_env, monkeypatch):
    """Ctrl-C while the agent works: its reply would answer the next request, so the agent is
    ended (the server rolls its session back); the next use starts another."""
    from airgun_xl.archive import agent

    root = _init(tmp_path, capsys)
    helper = agent.agent()

    def interrupted(self):
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(agent.Agent, "_read", interrupted)
        with pytest.raises(KeyboardInterrupt):
            Archive(root).entries()
    assert not helper.running and agent.agent() is not helper
    assert Archive(root).add("s", {}, {"summary.json": {}}, {}).version == 1
    assert [e.ref for e in Archive(root).entries()] == ["s@1"]


def test_a_login_made_ahead_of_time_and_lost_since_is_made_again(tmp_path, capsys,
                                                                server_env):
    """fill logs in ahead of time (index.preconnect); a server restarted meanwhile has closed
    that session: the archive logs in again, and the entry is stored."""
    from airgun_xl.archive import agent, index

    root = _init(tmp_path, capsys)
    agent.stop()
    index.preconnect()
    agent.agent().call("parse", address=server_env.address)  # the login ahead is made
    assert len(agent.agent().early) == 1
    server_env.stop("fast")
    server_env.start()
    assert Archive(root).add("s", {}, {"summary.json": {}}, {}).version == 1
    assert Archive(root).verify() == []


def test_the_address_and_password_from_libpqs_service_and_password_files(tmp_path, capsys,
                                                                         server_env,
                                                                         monkeypatch):
    """No $AIRGUN_XL_INDEX and no $PGPASSWORD: libpq's service file names the server
    ($PGSERVICE) and its password file holds the password; init, fill and history work, and
    the marker names neither."""
    services = tmp_path / "pg_service.conf"
    services.write_text(f"[lab]\nhost=127.0.0.1\nport={server_env.port}\ndbname=lab\n"
                        f"user=lab\n[lab_admin]\nhost=127.0.0.1\nport={server_env.port}\n"
                        "dbname=lab\nuser=lab_admin\n")
    passwords = tmp_path / "pgpass"
    import pg_server

    passwords.write_text(f"127.0.0.1:{server_env.port}:lab:lab:{pg_server.PASSWORD}\n"
                         f"127.0.0.1:{server_env.port}:lab:lab_admin:{pg_server.PASSWORD}\n")
    passwords.chmod(0o600)
    monkeypatch.delenv("AIRGUN_XL_INDEX")
    monkeypatch.delenv("PGPASSWORD")
    monkeypatch.setenv("PGSERVICEFILE", str(services))
    monkeypatch.setenv("PGSERVICE", "lab")
    monkeypatch.setenv("PGPASSFILE", str(passwords))
    root = tmp_path / "shots"
    assert main(["archive", "init", str(root), "--index", "service=lab_admin", "--writers",
                 "lab"]) == 0  # the administrator's service
    assert "its index on localhost/lab" in capsys.readouterr().out
    assert "lab" not in json.loads((root / MARKER).read_text()).values()
    assert main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--archive",
                 str(root), "--only", "summary"]) == 0
    capsys.readouterr()
    assert [r["shot"] for r in _history(root, capsys)] == ["shot_a"]


def test_an_agent_that_cannot_start_or_answers_nonsense_is_one_line(tmp_path, capsys,
                                                                    server_env, monkeypatch):
    """No Python to start the agent with: one line, exit 2. An agent whose reply is not JSON
    (a stray print): the agent is ended and the call fails as a LinkError, never a
    traceback."""
    from airgun_xl.archive import agent

    root = _init(tmp_path, capsys)
    agent.stop()
    with monkeypatch.context() as m:
        m.setattr(agent.sys, "executable", str(tmp_path / "no-python"))
        assert main(["history", "--archive", str(root)]) == 2
    line = _one_line(capsys)
    assert "the index's helper process cannot be started" in line, line
    for nonsense in ("not json", '{"x": 1}', "[1]"):
        helper = agent.agent()
        helper.stop(kill=True)
        helper.proc = subprocess.Popen(
            [sys.executable, "-c", f"import sys\nfor line in sys.stdin: print({nonsense!r}, "
                                   "flush=True)"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        with pytest.raises(agent.LinkError) as caught:
            helper.call("parse", address=server_env.address)
        assert caught.value.kind == "lost" and not helper.running
    assert main(["history", "--archive", str(root)]) == 0  # a new agent
