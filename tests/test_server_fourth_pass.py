"""Issue 43 on a real PostgreSQL server (tests/pg_server.py): two roles, as README's
administrator makes them (``lab_admin`` owns the schema, ``lab`` the engineers' reads and adds
entries); rows typed and bounded whatever a column became; verify both ways; an address
checked by an allow-list. Each test is named after its finding (43.N)."""
import json
import os

import pytest
from conftest import TEMPLATE
from test_server_archive import _init, _one_line

from airgun_xl.archive import MARKER, Archive
from airgun_xl.archive.index import SERVER_SCHEMA
from airgun_xl.cli import main


def _fill(tmp_path, root, *extra, out="o.xlsx"):
    return main(["fill", str(TEMPLATE), "-o", str(tmp_path / out), "--force", "--only",
                 "summary", "--archive", str(root), *extra])


def _as(server, role):
    """A connection as ``role`` (its password is the tests' one)."""
    import psycopg
    from pg_server import PASSWORD

    return psycopg.connect(f"host=127.0.0.1 port={server.port} dbname=lab user={role} "
                           f"password={PASSWORD}", autocommit=True)


def _superuser(server):
    import psycopg

    return psycopg.connect(server.admin.replace("dbname=postgres", "dbname=lab"),
                           autocommit=True)


@pytest.fixture
def shots(tmp_path, capsys, server_env):
    """A server archive (made by the administrator for the engineers) of shot_a@1 and @2,
    filled by the engineers' role; returns (root, identity)."""
    root = _init(tmp_path, capsys)
    for _ in range(2):
        assert _fill(tmp_path, root) == 0
    capsys.readouterr()
    return root, json.loads((root / MARKER).read_text())["identity"]


# -- 43.3: an address by an allow-list ---------------------------------------------------------

@pytest.mark.parametrize("keyword, said", [
    ("sslpassword=hunter2secret", "the keyword sslpassword, which carries a secret"),
    ("password=hunter2secret", "a password"),
    ("options=-c%20statement_timeout%3D0", "the keyword 'options'"),
    ("replication=database", "the keyword 'replication'"),
])
def test_43_3_an_address_holding_a_secret_or_an_unknown_keyword_is_refused(
        tmp_path, capsys, server_env, monkeypatch, keyword, said):
    """sslpassword= was accepted (only password was refused): every secret keyword is
    refused without repeating it, and any keyword outside libpq's allow-list is named."""
    made = _init(tmp_path, capsys, "made")  # with the engineers' good address
    address = f"postgresql://lab@127.0.0.1:{server_env.port}/lab?{keyword}"
    monkeypatch.setenv("AIRGUN_XL_INDEX", address)
    for argv in (["archive", "init", str(tmp_path / "new"), "--index", address],
                 ["history", "--archive", str(made)]):
        assert main(argv) == 2
        line = _one_line(capsys)
        assert said in line and "hunter2secret" not in line, line
    assert not (tmp_path / "new").exists()


# -- 43.4: two roles ----------------------------------------------------------------------------

def test_43_4_the_engineers_role_cannot_rewrite_history(shots, server_env):
    """The engineers' role reads and adds entries, and nothing more: ALTER TABLE, UPDATE,
    DELETE, TRUNCATE and DROP are refused by the server (the single role lab owned the
    schema, so any engineer could)."""
    import psycopg

    root, identity = shots
    with _as(server_env, "lab") as conn:
        assert conn.execute(f"SELECT count(*) FROM {SERVER_SCHEMA}.entries WHERE archive = %s",
                            (identity,)).fetchone() == (2,)
        for statement in (f"ALTER TABLE {SERVER_SCHEMA}.entries DROP CONSTRAINT entries_pkey",
                          f"UPDATE {SERVER_SCHEMA}.entries SET version = 9",
                          f"DELETE FROM {SERVER_SCHEMA}.entries",
                          f"TRUNCATE {SERVER_SCHEMA}.entries",
                          f"DROP TABLE {SERVER_SCHEMA}.entries",
                          f"CREATE TABLE {SERVER_SCHEMA}.planted (x int)",
                          f"INSERT INTO {SERVER_SCHEMA}.archives VALUES ('x', 'x', 1)"):
            with pytest.raises(psycopg.errors.InsufficientPrivilege):
                conn.execute(statement)


def test_43_4_a_writer_with_the_owners_rights_is_warned_once(tmp_path, capsys, shots,
                                                            server_env, monkeypatch):
    """Filled with the owner's role: one warning, once a command, naming the role; the
    engineers' role gets none."""
    root, _ = shots
    monkeypatch.setenv("AIRGUN_XL_INDEX", server_env.owner_address)
    assert _fill(tmp_path, root) == 0
    err = capsys.readouterr().err
    assert err.count("may alter the schema or rewrite entries") == 1
    assert "role 'lab_admin'" in err and "--writers ROLE" in err
    monkeypatch.setenv("AIRGUN_XL_INDEX", server_env.address)
    assert _fill(tmp_path, root) == 0
    assert "may alter the schema" not in capsys.readouterr().err


# -- 43.5 to 43.8: the server's rows typed and bounded ------------------------------------------

def _loosened(server):
    """The entries table with its constraints dropped and its columns' types changed, as a
    role with the owner's rights could leave it."""
    with _superuser(server) as conn:
        table = f"{SERVER_SCHEMA}.entries"
        conn.execute(f"ALTER TABLE {table} DROP CONSTRAINT IF EXISTS "
                     "entries_archive_shot_version_key")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN created DROP NOT NULL")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN version TYPE text")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN v0 TYPE jsonb USING to_jsonb(v0)")
    return table


@pytest.fixture
def loose(server_env):
    """The loosened table for one test, the server's own back after it (the next tests
    make archives in the same schema)."""
    table = _loosened(server_env)
    yield table
    with _superuser(server_env) as conn:
        conn.execute(f"DELETE FROM {table} WHERE version !~ '^[0-9]+$' OR created IS NULL "
                     "OR length(path) > 1000 OR jsonb_typeof(v0) <> 'number'")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN created SET NOT NULL")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN version TYPE integer USING "
                     "version::integer")
        conn.execute(f"ALTER TABLE {table} ALTER COLUMN v0 TYPE double precision USING "
                     "(v0 #>> '{}')::double precision")


@pytest.mark.parametrize("change, expected", [
    ("created = NULL", "created: found none (NULL), expected an ISO 8601 date"),
    ("version = 'abc'", "version: found 'abc', expected a whole number from 1 to 999,999"),
    ("v0 = '{\"a\": 1}'", "v0: found '{\"a\": 1}', expected a finite number"),
    ("created = 'not-a-date'", "created: found 'not-a-date', expected an ISO 8601 date"),
])
def test_43_5_a_null_or_wrongly_typed_column_on_the_server_is_one_line(
        tmp_path, capsys, shots, server_env, loose, change, expected):
    """A NULL or wrongly typed column (created NULL, version text, v0 jsonb) ended history
    and fill in a traceback: each command now says it in one line naming the row; verify
    lists it."""
    root, identity = shots
    with _superuser(server_env) as conn:
        conn.execute(f"UPDATE {loose} SET {change} WHERE archive = %s AND id = 2",
                     (identity,))
    for argv in (["history", "--archive", str(root)],
                 ["history", "--archive", str(root), "--since", "2000-01-01"],
                 ["show", "shot_a@1", "--archive", str(root)]):
        assert main(argv) == 2
        line = _one_line(capsys)
        assert "row #2:" in line and expected in line, line
    assert _fill(tmp_path, root) == 2
    assert "row #2:" in _one_line(capsys)
    assert main(["archive", "verify", str(root)]) == 1
    assert f"row #2: {expected}" in capsys.readouterr().out


def test_43_6_verify_checks_the_servers_rows_against_the_folders_both_ways(
        tmp_path, capsys, shots, server_env, loose):
    """A row whose (shot, version) contradicts its folder's manifest, two rows on one folder,
    one version twice: verify named none of them ("0 problems"); show of the contradicting
    row printed another entry's inputs, and is refused now."""
    root, identity = shots
    columns = ("shot, version, path, created, input_sha256, v0, delta, max_time, sigmay, "
               "rcone, peak_kg, integrator, model, engine")
    with _superuser(server_env) as conn:
        conn.execute(f"UPDATE {loose} SET version = '3' WHERE archive = %s AND id = 1",
                     (identity,))
        conn.execute(f"INSERT INTO {loose} (archive, id, {columns}) SELECT archive, 3, shot, "
                     "'4', path, created, input_sha256, v0, delta, max_time, sigmay, rcone, "
                     f"peak_kg, integrator, model, engine FROM {loose} WHERE archive = %s AND "
                     "id = 2", (identity,))
        conn.execute(f"INSERT INTO {loose} (archive, id, {columns}) SELECT archive, 4, shot, "
                     "'2', 'shot_a/v0009', created, input_sha256, v0, delta, max_time, sigmay,"
                     f" rcone, peak_kg, integrator, model, engine FROM {loose} WHERE archive "
                     "= %s AND id = 2", (identity,))
    assert main(["archive", "verify", str(root)]) == 1
    out = capsys.readouterr().out
    assert "row #1: it says shot_a@3, but its folder shot_a/v0001 holds shot_a@1" in out
    assert "row #3: names the folder of row #2 (shot_a/v0002): two rows on one folder" in out
    assert "row #4: shot_a@2 is row #2's version too" in out
    assert main(["show", "shot_a@3", "--archive", str(root)]) == 2
    assert "row #1: it says shot_a@3" in _one_line(capsys)


def test_43_7_a_280_mb_text_in_one_row_is_one_line_in_bounded_memory(tmp_path, shots,
                                                                     server_env):
    """280 MB in one row's path: history refuses it in one line and peaks under 300 MB (it
    peaked at 1.1 GB): the server sends 1,001 characters of it."""
    from hostile.support import run_child

    root, identity = shots
    with _superuser(server_env) as conn:
        conn.execute(f"UPDATE {SERVER_SCHEMA}.entries SET path = repeat('x', %s) WHERE "
                     "archive = %s AND id = 2", (280 * 2 ** 20, identity))
    try:
        code, err, rss = run_child(tmp_path, ["history", "--archive", root],
                                   env={**os.environ})
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1, err
        assert "row #2: path: found 'xxxxxxxx" in lines[0] and "1,000 characters" in lines[0]
        assert rss is None or rss < 300 * 2 ** 20, rss
    finally:
        with _superuser(server_env) as conn:
            conn.execute(f"DELETE FROM {SERVER_SCHEMA}.entries WHERE archive = %s AND id = 2",
                         (identity,))


def test_43_8_a_version_at_the_integer_limit_stops_that_shot_only(tmp_path, capsys, shots,
                                                                 server_env):
    root, identity = shots
    with _superuser(server_env) as conn:
        conn.execute(f"UPDATE {SERVER_SCHEMA}.entries SET version = 2147483647 WHERE "
                     "archive = %s AND id = 2", (identity,))
    assert _fill(tmp_path, root) == 2
    assert "version: found '2147483647'" in _one_line(capsys)
    assert _fill(tmp_path, root, "--name", "other") == 0


def test_43_8_a_server_archives_marker_edited_to_say_sqlite_is_refused(tmp_path, capsys,
                                                                      shots):
    """The marker of a server archive edited to say sqlite: a fill made a new SQLite index
    without a word; now it is refused (entries on disk and no index.sqlite), and verify says
    why."""
    root, _ = shots
    marker = json.loads((root / MARKER).read_text())
    (root / MARKER).write_text(json.dumps({"format": marker["format"], "tool": "airgun-xl",
                                           "index": "sqlite"}))
    assert _fill(tmp_path, root, out="new.xlsx") == 2
    line = _one_line(capsys)
    assert "says the index is index.sqlite, which is missing, while 2 entries" in line
    assert not (root / "index.sqlite").exists() and not (tmp_path / "new.xlsx").exists()
    assert main(["archive", "verify", str(root)]) == 1
    assert "which is missing, while 2 entries are on disk" in capsys.readouterr().out


# -- 43.14: a new archive, with the server named -----------------------------------------------

def test_43_14_init_dials_the_server_and_fill_of_a_new_folder_is_refused(tmp_path, capsys,
                                                                        server_env):
    """With $AIRGUN_XL_INDEX set, archive init NEW makes its index on that server; fill
    --archive NEW2 (never made) made a local SQLite index silently, and is refused now."""
    root = _init(tmp_path, capsys, "made")
    assert json.loads((root / MARKER).read_text())["index"] == "server"
    assert _fill(tmp_path, tmp_path / "never_made") == 2
    line = _one_line(capsys)
    assert "a new archive, while $AIRGUN_XL_INDEX names a server" in line
    assert "archive init" in line and not (tmp_path / "never_made").exists()
    assert _fill(tmp_path, root) == 0
    assert [e.ref for e in Archive(root).entries()] == ["shot_a@1"]
