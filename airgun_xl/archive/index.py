"""The archive's index: one row an entry, on one of two back ends behind one interface.

- :class:`SqliteIndex`, the default: ``index.sqlite`` in the archive folder, WAL mode, for
  one machine (SQLite's WAL needs shared memory on one host, so it does not hold on a
  network share);
- :class:`ServerIndex`: tables on a PostgreSQL server (psycopg 3, the ``server`` extra), for
  a lab's share written by several hosts. The folder's marker names the archive's identity
  and that its index is on a server, never an address: the address comes from the user's
  side (:func:`server_address`), and the server must hold that identity.

A writer takes the archive's write lock with :meth:`write` (SQLite: ``BEGIN IMMEDIATE``; the
server: a row lock on the archive's own row, ``SELECT ... FOR UPDATE``) and gets a
:class:`Session`: the paths indexed, a shot's last version, the insert, the commit. Every SQL
statement takes its values as parameters, never as text pasted in.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import sqlite3
import time
from pathlib import Path
from typing import Any

from ..choices import INDEX_ENV
from ..errors import ArchiveError, OptionError
from ..transaction import display
from ..untrusted_json import printable
from .agent import Link, LinkError, agent, prestart

INDEX = "index.sqlite"

# INDEX_ENV (choices) gives a server archive's address (a libpq URL or ``key=value`` string,
# without a password); libpq's own variables and service file work too.
#: How long a writer waits for another's lock on the index [s].
LOCK_WAIT = 120

#: How long one statement may run on the server before it is cancelled [s].
STATEMENT_TIMEOUT = 60

#: The columns of an entry's row, after its id, in order.
COLUMNS = ("shot", "version", "path", "created", "input_sha256", "v0", "delta", "max_time",
           "sigmay", "rcone", "peak_kg", "integrator", "model", "engine")

SQLITE_SCHEMA = """
CREATE TABLE IF NOT EXISTS entries (
    id INTEGER PRIMARY KEY,
    shot TEXT NOT NULL,
    version INTEGER NOT NULL,
    path TEXT NOT NULL,
    created TEXT NOT NULL,
    input_sha256 TEXT,
    v0 REAL, delta REAL, max_time REAL, sigmay REAL, rcone REAL,
    peak_kg REAL, integrator TEXT, model TEXT, engine TEXT,
    UNIQUE (shot, version)
)"""

#: The server's schema: the role needs the rights of this schema only (README, "A shared
#: archive"). One schema holds any number of archives, each its own row in ``archives``; an
#: entry's id counts within its archive, as in SQLite (``#3`` is the same entry after a move).
SERVER_SCHEMA = "airgun_xl"
SERVER_TABLES = (
    f"CREATE SCHEMA IF NOT EXISTS {SERVER_SCHEMA}",
    f"""CREATE TABLE IF NOT EXISTS {SERVER_SCHEMA}.archives (
        identity TEXT PRIMARY KEY,
        created TEXT NOT NULL,
        format INTEGER NOT NULL)""",
    f"""CREATE TABLE IF NOT EXISTS {SERVER_SCHEMA}.entries (
        archive TEXT NOT NULL REFERENCES {SERVER_SCHEMA}.archives (identity),
        id BIGINT NOT NULL,
        shot TEXT NOT NULL,
        version INTEGER NOT NULL,
        path TEXT NOT NULL,
        created TEXT NOT NULL,
        input_sha256 TEXT,
        v0 DOUBLE PRECISION, delta DOUBLE PRECISION, max_time DOUBLE PRECISION,
        sigmay DOUBLE PRECISION, rcone DOUBLE PRECISION, peak_kg DOUBLE PRECISION,
        integrator TEXT, model TEXT, engine TEXT,
        PRIMARY KEY (archive, id),
        UNIQUE (archive, shot, version))""",
)


#: What the engineers' role needs, and all it gets (``archive init --writers ROLE``): the
#: schema, the archives read, the entries read and added. No UPDATE, DELETE or DDL: a writer
#: cannot rewrite history (the write lock is an advisory lock, which needs no right).
WRITER_GRANTS = (f"GRANT USAGE ON SCHEMA {SERVER_SCHEMA} TO {{role}}",
                 f"GRANT SELECT ON {SERVER_SCHEMA}.archives TO {{role}}",
                 f"GRANT SELECT, INSERT ON {SERVER_SCHEMA}.entries TO {{role}}")

#: A role name ``--writers`` takes: a plain PostgreSQL identifier.
ROLE_NAME = r"[A-Za-z_][A-Za-z0-9_]{0,62}"


class Session:
    """A write transaction on the index, holding the archive's write lock (from
    :meth:`SqliteIndex.write` or :meth:`ServerIndex.write`)."""

    def paths(self) -> set[str]:
        raise NotImplementedError

    def last_version(self, shot: str) -> int:
        raise NotImplementedError

    def insert(self, row: dict) -> bool:
        """Insert an entry's row; False when its (shot, version) is taken already."""
        raise NotImplementedError

    def commit(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        """Roll back what was not committed, and let the lock go."""
        raise NotImplementedError


def _filters(shot, mark):
    """The history's shot filter as SQL (`` AND shot = ?``) with its value as a parameter;
    ``mark`` is the driver's placeholder (``?`` or ``%s``). The date filter is applied to the
    rows read, as dates (:func:`since_filter`): compared as text, ``not-a-date`` sorts after
    every date."""
    return (f" AND shot = {mark}", [shot]) if shot else ("", [])


# -- the rows, read as untrusted ----------------------------------------------------------------

#: The longest text a column of a row may hold [characters] (a shot name is at most 100, a
#: path 110, a date 40, a hash 64): past it the row is refused, and the server sends no more
#: than this of it (``left()``), so a row of 280 MB costs no memory.
TEXT_CAP = 1000

#: The highest version an archive numbers (its folders are ``v0001`` ... ``v999999``).
MAX_VERSION = 999_999

#: What each column of a row must hold: "id" (a whole number), "version" (1 to MAX_VERSION),
#: "text", "date" (ISO 8601), "real" (a finite number); "?" where it may be empty (NULL).
ROW_TYPES = {"id": "id", "shot": "text", "version": "version", "path": "text",
             "created": "date", "input_sha256": "text?", "v0": "real?", "delta": "real?",
             "max_time": "real?", "sigmay": "real?", "rcone": "real?", "peak_kg": "real?",
             "integrator": "text?", "model": "text?", "engine": "text?"}


def _shown(value):
    """A value as a message quotes it: its repr, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:30]}... ({len(text):,} characters)"


def checked_row(raw, label):
    """A row of the index as untrusted data: each column of :data:`ROW_TYPES` converted to
    its type (from the value, or from text as the server sends it) and checked; the parsed
    creation date under ``_created``.

    Raises
    ------
    ArchiveError
        One line naming the row, the column, what it holds and what is expected.
    """
    import datetime
    import math

    out: dict[str, Any] = {}
    ident = raw.get("id")
    shown = ident if isinstance(ident, (int, str)) and len(str(ident)) < 25 else "?"
    name = f"{label}: row #{shown}"
    for column, declared in ROW_TYPES.items():
        value = raw.get(column)
        optional = declared.endswith("?")
        kind = declared.rstrip("?")
        if value is None:
            if optional:
                out[column] = None
                continue
            raise ArchiveError(f"{name}: {column}: found none (NULL), expected "
                               f"{_EXPECTED[kind]}")
        try:
            if kind in ("id", "version"):
                if isinstance(value, bool) or isinstance(value, float):
                    raise ValueError
                whole = int(value) if isinstance(value, int) else int(str(value), 10)
                low, high = (1, MAX_VERSION) if kind == "version" else (0, 2 ** 63 - 1)
                if not low <= whole <= high:
                    raise ValueError
                out[column] = whole
            elif kind == "real":
                if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                    raise ValueError
                number = float(value)
                if not math.isfinite(number):
                    raise ValueError
                out[column] = number
            else:
                if not isinstance(value, str) or len(value) > TEXT_CAP or not value:
                    raise ValueError
                if kind == "date":
                    stamp = datetime.datetime.fromisoformat(value)
                    if stamp.tzinfo is None:
                        stamp = stamp.replace(tzinfo=datetime.UTC)
                    out["_created"] = stamp
                out[column] = value
        except (ValueError, TypeError, OverflowError):
            raise ArchiveError(f"{name}: {column}: found {_shown(value)}, expected "
                               f"{_EXPECTED[kind]}") from None
    return out


_EXPECTED = {"id": "a whole number", "version": f"a whole number from 1 to {MAX_VERSION:,}",
             "text": f"text of 1 to {TEXT_CAP:,} characters",
             "date": "an ISO 8601 date, such as 2026-11-26T14:00:00+00:00",
             "real": "a finite number"}


def since_filter(rows, since):
    """The rows created on or after ``since`` (an ISO date or date and time; UTC unless it
    says), compared as dates."""
    if not since:
        return rows
    import datetime

    start = datetime.datetime.fromisoformat(str(since))
    if start.tzinfo is None:
        start = start.replace(tzinfo=datetime.UTC)
    return [r for r in rows if r["_created"] >= start]


def ordered(rows, order):
    """``rows`` sorted by the columns ``order`` names (``created, shot, version``), as their
    types compare (a version as a number, a date as a date), the id last."""
    names = [n.strip() for n in order.split(",")]
    found = sorted(rows, key=lambda r: tuple(r["_created"] if n == "created" else r[n]
                                             for n in names) + (r["id"],))
    return [{k: v for k, v in r.items() if k != "_created"} for r in found]


def checked_rows(raw_rows, label, bad=None):
    """:func:`checked_row` of each row; a bad row raises, or with ``bad`` (a list) is added
    to it, as its message, and left out."""
    out = []
    for raw in raw_rows:
        try:
            out.append(checked_row(raw, label))
        except ArchiveError as exc:
            if bad is None:
                raise
            bad.append(str(exc))
    return out


# -- SQLite ------------------------------------------------------------------------------------

def _prepare(conn):
    """WAL mode, full sync and the schema on a new connection. Two processes creating the index
    at once may see "database is locked" from the journal-mode switch, which SQLite does not
    retry through the busy timeout: it is retried here, up to :data:`LOCK_WAIT`."""
    deadline = time.monotonic() + LOCK_WAIT
    while True:
        try:
            if str(conn.execute("PRAGMA journal_mode").fetchone()[0]).lower() != "wal":
                conn.execute("PRAGMA journal_mode=WAL")
            conn.execute("PRAGMA synchronous=FULL")
            conn.execute(SQLITE_SCHEMA)
            return
        except sqlite3.OperationalError as exc:
            if "locked" not in str(exc) or time.monotonic() > deadline:
                raise
            time.sleep(0.02)


def is_sqlite_index(path):
    """Whether ``path`` is an SQLite file with this tool's ``entries`` table."""
    if not path.is_file():
        return False
    try:
        conn = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            row = conn.execute("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = "
                               "'entries'").fetchone()
        finally:
            conn.close()
    except sqlite3.Error:
        return False
    return row is not None


#: The columns as SQLite reads them: a number as it is, anything else as at most TEXT_CAP + 1
#: characters of text (a column may hold any type in SQLite, a blob of 280 MB included).
_SQLITE_COLUMNS = ", ".join(
    f"CASE WHEN typeof({c}) IN ('integer', 'real', 'null') THEN {c} ELSE "
    f"substr(CAST({c} AS TEXT), 1, {TEXT_CAP + 1}) END AS {c}" for c in ("id", *COLUMNS))


#: An index.sqlite larger than this [bytes] may hold a value too large to read whole: its
#: text and blob values are measured first (:func:`_oversized`). Below it, no value can cost
#: more memory than the file's size.
BIG_INDEX = 64 * 2 ** 20


def _oversized(conn, path):
    """``(rowid, column, bytes)`` of each text or blob value of ``entries`` longer than a
    column may be (4 bytes a character of :data:`TEXT_CAP`), measured without reading it
    (incremental blob I/O: its size only); none for an index under :data:`BIG_INDEX`."""
    try:
        if os.path.getsize(path) <= BIG_INDEX:
            return []
    except OSError:
        return []
    names = ("id", *COLUMNS)
    found = []
    kinds = conn.execute(f"SELECT rowid, {', '.join(f'typeof({c})' for c in names)} "
                         "FROM entries").fetchall()
    for row in kinds:
        rowid = row[0]
        for column, kind in zip(names, tuple(row)[1:], strict=True):
            if kind in ("text", "blob"):
                with conn.blobopen("entries", column, rowid, readonly=True) as blob:
                    size = len(blob)
                if size > 4 * (TEXT_CAP + 1):
                    found.append((rowid, column, size))
    return found


class _SqliteSession(Session):
    def __init__(self, conn, label):
        self.conn, self.label = conn, label

    def paths(self):
        return {r[0] for r in self.conn.execute(
            f"SELECT substr(CAST(path AS TEXT), 1, {TEXT_CAP + 1}) FROM entries")}

    def last_version(self, shot):
        rows = [dict(r) for r in self.conn.execute(
            f"SELECT {_SQLITE_COLUMNS} FROM entries WHERE shot = ?", (shot,))]
        return max((r["version"] for r in checked_rows(rows, self.label)), default=0)

    def insert(self, row):
        try:
            self.conn.execute(f"INSERT INTO entries ({', '.join(COLUMNS)}) VALUES "
                              f"({', '.join('?' * len(COLUMNS))})",
                              tuple(row.get(c) for c in COLUMNS))
        except sqlite3.IntegrityError:
            return False
        return True

    def all_rows(self):
        """Every row, checked, read under the write lock (archive migrate)."""
        self.conn.row_factory = sqlite3.Row
        return checked_rows([dict(r) for r in self.conn.execute(
            f"SELECT {_SQLITE_COLUMNS} FROM entries ORDER BY id")], self.label)

    def commit(self):
        try:
            self.conn.execute("COMMIT")
        except sqlite3.Error as exc:
            raise ArchiveError(f"{self.label}: the entry's row cannot be committed ({exc})") \
                from None

    def close(self):
        with contextlib.suppress(sqlite3.Error):
            if self.conn.in_transaction:
                self.conn.execute("ROLLBACK")
        self.conn.close()


class SqliteIndex:
    """The index as ``index.sqlite`` in the archive folder (the default: one machine)."""

    kind = "sqlite"

    def __init__(self, root, read_only=False):
        self.path = Path(root) / INDEX
        self.label = self.shown = display(self.path)
        self.read_only = read_only  # opened with SQLite's mode=ro: a reader that cannot write

    def exists(self):
        return self.path.exists()

    def _connect(self):
        try:
            if self.read_only:
                from urllib.parse import quote

                conn = sqlite3.connect(f"file:{quote(str(self.path.resolve()))}?mode=ro",
                                       uri=True, timeout=LOCK_WAIT, isolation_level=None)
                conn.row_factory = sqlite3.Row
                return conn
            conn = sqlite3.connect(self.path, timeout=LOCK_WAIT, isolation_level=None)
            conn.row_factory = sqlite3.Row
            _prepare(conn)
        except sqlite3.Error as exc:
            raise ArchiveError(f"{self.label}: cannot be used ({exc}), expected the archive's "
                               "SQLite index") from None
        return conn

    def write(self):
        """Begin a write transaction, holding the write lock: one writer at a time."""
        conn = self._connect()
        try:
            conn.execute("BEGIN IMMEDIATE")
        except sqlite3.Error as exc:
            conn.close()
            raise ArchiveError(f"{self.label}: cannot be used ({exc})") from None
        return _SqliteSession(conn, self.label)

    def rows(self, shot=None, since=None, order="created, shot, version", bad=None):
        """The entries' rows as dicts, checked (:func:`checked_row`), filtered by shot and
        creation date; a bad row raises, or with ``bad`` is listed there."""
        if not self.exists():
            return []
        conn = self._connect()
        try:
            where, args = _filters(shot, "?")
            oversized = _oversized(conn, self.path)
            for rowid, column, size in oversized:
                message = (f"{self.label}: row #{rowid}: {column}: found text of {size:,} "
                           f"bytes, expected {_EXPECTED['text']}")
                if bad is None:
                    raise ArchiveError(message)
                bad.append(message)
            skip = " AND rowid NOT IN (" + ", ".join(str(r) for r, _, _ in oversized) + ")" \
                if oversized else ""
            raw = [dict(r) for r in conn.execute(
                f"SELECT {_SQLITE_COLUMNS} FROM entries WHERE 1=1{where}{skip}", args)]
        except sqlite3.Error as exc:
            raise ArchiveError(f"{self.label}: cannot be read ({exc})") from None
        finally:
            conn.close()
        return ordered(since_filter(checked_rows(raw, self.label, bad), since), order)

    def stamp(self):
        """A token that changes when the entries do: each index file's size, modification
        time and inode (a commit writes the write-ahead log, a checkpoint the database). An
        empty log is no log: a reader's first open may create one, and it holds nothing the
        database does not."""
        out: list[tuple[int, int, int] | None] = []
        for name in (INDEX, f"{INDEX}-wal"):
            try:
                st = os.stat(self.path.with_name(name))
            except OSError:
                out.append(None)
                continue
            out.append((st.st_size, st.st_mtime_ns, st.st_ino) if st.st_size else None)
        return tuple(out)

    def problems(self):
        """What the index's own check finds (empty when sound)."""
        conn = self._connect()
        try:
            check = conn.execute("PRAGMA integrity_check").fetchone()[0]
        except sqlite3.Error as exc:
            return [f"{INDEX}: cannot be read ({exc})"]
        finally:
            conn.close()
        return [] if check == "ok" else [f"{INDEX}: {check}"]

    def count(self):
        """Entries indexed, counted under the write lock (no writer is committing)."""
        conn = sqlite3.connect(self.path, timeout=5, isolation_level=None)
        try:
            conn.execute("BEGIN IMMEDIATE")
            rows = conn.execute("SELECT COUNT(*) FROM entries").fetchone()[0]
            conn.execute("ROLLBACK")
        finally:
            conn.close()
        return int(rows)

    def files(self):
        """The index's own files in the archive folder."""
        return {INDEX, f"{INDEX}-wal", f"{INDEX}-shm", f"{INDEX}-journal"}

    def close(self):
        """Nothing to close: each use opens and closes its own connection."""

    def writer_gone(self, owner):
        """Whether a scratch folder's writer is gone: this host's process table says."""
        from ..transaction import owner_alive

        return not owner_alive(owner)

    def hold(self, owner):
        """Nothing to hold: this host's process table shows the writer's process."""
        return None


# -- PostgreSQL --------------------------------------------------------------------------------

#: What the archive says once a command, for the command to print as warnings (a role that
#: may rewrite history), and the servers already checked by this command.
NOTICES: list[str] = []
_CHECKED: set[str] = set()


def take_notices() -> list[str]:
    """The notices said since the last call, and a fresh start for the next command."""
    said = list(NOTICES)
    NOTICES.clear()
    _CHECKED.clear()
    return said


def session_options():
    """A connection's settings: how long a statement, a lock wait and an idle transaction
    may last."""
    return (f"-c statement_timeout={STATEMENT_TIMEOUT * 1000} "
            f"-c lock_timeout={LOCK_WAIT * 1000} -c idle_in_transaction_session_timeout="
            f"{(LOCK_WAIT + STATEMENT_TIMEOUT) * 1000}")


def preconnect():
    """Start the index's agent and connect it ahead of time, to the address a command without
    ``--index`` uses (``$AIRGUN_XL_INDEX`` or libpq's defaults): a fill then waits for neither
    psycopg's import nor the login. Nothing is checked here; the connection is used only by
    a :class:`ServerIndex` that asks for the same address, once that address is checked."""
    text = os.environ.get(INDEX_ENV)
    prestart("" if text is None else str(text).strip(), session_options())


def _link_error(exc, label, doing=""):
    """A :class:`~airgun_xl.archive.agent.LinkError` as the archive's one line."""
    if exc.kind == "missing":
        return ArchiveError("the archive's index is on a PostgreSQL server, and psycopg is not "
                            "installed; expected pip install 'airgun-xl[server]'")
    return ArchiveError(f"{label}: {doing}{exc.message}")


def server_address(given=None, where="--index"):
    """The server's address, checked: the given one, else ``$AIRGUN_XL_INDEX``, else libpq's
    own defaults (``PGHOST``, ``PGSERVICE`` and the service file). A password in it is
    refused, without repeating it: the command line is recorded in provenance and shown by
    ``ps``; it belongs in ``~/.pgpass`` or ``$PGPASSWORD``. libpq reads it, in the index's
    agent.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    text = given if given is not None else os.environ.get(INDEX_ENV)
    if text is None:
        return "", "libpq's defaults"
    source = where if given is not None else f"${INDEX_ENV}"
    text = str(text).strip()
    if not text.startswith(("postgresql://", "postgres://")) and "=" not in text:
        raise OptionError(f"{source}: found an address that is neither a postgresql:// URL "
                          "nor key=value pairs; expected postgresql://HOST[:PORT]/DATABASE")
    try:
        parts = agent().call("parse", address=text)
    except LinkError as exc:
        if exc.kind != "address":
            raise _link_error(exc, "the archive's index") from None
        raise OptionError(f"{source}: found an address libpq cannot read; expected "
                          "postgresql://HOST[:PORT]/DATABASE") from None
    secrets, unknown = parts.pop("secrets", []), parts.pop("unknown", [])
    parts.pop("password", None)
    if secrets:
        what = ("a password" if secrets[0] == "password" else
                f"the keyword {secrets[0]}, which carries a secret")
        raise OptionError(f"{source}: found {what} in the address (not repeated here); "
                          "expected none there, since the command line is recorded with every "
                          "entry and shown by ps: a password in ~/.pgpass or $PGPASSWORD, a "
                          "client key's pass phrase kept by the key's owner")
    if unknown:
        raise OptionError(f"{source}: found the keyword {printable(unknown[0])!r} in the "
                          "address, expected only libpq keywords that say where the server is, "
                          "who logs in and how the connection is secured (host, port, dbname, "
                          "user, sslmode, sslrootcert, service...; docs/security.md lists them)")
    return text, _shown_address(parts)


def _shown_address(parts):
    """An address as messages show it: host, port and database, never more."""
    host = parts.get("host") or parts.get("hostaddr") or "localhost"
    if str(host).startswith("/"):
        host = "socket"
    port = f":{parts['port']}" if parts.get("port") else ""
    return f"{host}{port}/{parts.get('dbname') or parts.get('service') or ''}"


def _owner_key(owner):
    """The advisory lock that a live writer holds for its owner token (64-bit)."""
    return int.from_bytes(hashlib.sha256(f"airgun-xl:{owner}".encode()).digest()[:8], "big",
                          signed=True)


#: The columns as the server sends them: each as at most TEXT_CAP + 1 characters of text,
#: whatever the table's column became (text, jsonb...), parsed and checked here.
_SERVER_COLUMNS = ", ".join(f"left(({c})::text, {TEXT_CAP + 1}) AS {c}"
                            for c in ("id", *COLUMNS))


class _ServerSession(Session):
    """A write transaction on the index's one connection (closing it rolls back what was not
    committed; the connection, and the writer's session lock, stay)."""

    def __init__(self, conn, identity, label, index):
        self.conn, self.identity, self.label, self.index = conn, identity, label, index

    def _run(self, sql, args=()):
        try:
            return self.conn.execute(sql, args)
        except LinkError as exc:
            raise _link_error(exc, self.label) from None

    def paths(self):
        return {r[0] for r in self._run(
            f"SELECT left(path::text, {TEXT_CAP + 1}) FROM {SERVER_SCHEMA}.entries WHERE "
            "archive = %s", (self.identity,))}

    def last_version(self, shot):
        rows = self._run(f"SELECT {_SERVER_COLUMNS} FROM {SERVER_SCHEMA}.entries WHERE "
                         "archive = %s AND shot = %s", (self.identity, shot)).dicts()
        return max((r["version"] for r in checked_rows(rows, self.label)), default=0)

    def insert(self, row):
        try:  # in a savepoint: a clash leaves the rest standing
            self.conn.execute(  # the next id of this archive, under its write lock
                f"INSERT INTO {SERVER_SCHEMA}.entries (archive, id, {', '.join(COLUMNS)}) "
                f"SELECT %s, COALESCE(MAX(id), 0) + 1, {', '.join(['%s'] * len(COLUMNS))} "
                f"FROM {SERVER_SCHEMA}.entries WHERE archive = %s",
                (self.identity, *(row.get(c) for c in COLUMNS), self.identity), savepoint=True)
        except LinkError as exc:
            if exc.kind == "unique":
                return False
            raise _link_error(exc, self.label) from None
        return True

    def commit(self):
        try:
            self.conn.commit()
        except LinkError as exc:
            raise _link_error(exc, self.label, "the entry's row cannot be committed: ") \
                from None

    def close(self):
        try:
            self.conn.rollback()
        except Exception:  # a broken connection: the next use makes a new one
            self.index.close()
        else:
            self.index._done()


class ServerIndex:
    """The index as tables on a PostgreSQL server (schema :data:`SERVER_SCHEMA`), reached
    through the index's agent (:mod:`airgun_xl.archive.agent`).

    Parameters
    ----------
    root : path
        The archive folder (its entries stay there, on the share).
    identity : str
        The archive's identity, from its marker: 32 hexadecimal digits.
    address : str, optional
        The server's address (checked by :func:`server_address`); None for
        ``$AIRGUN_XL_INDEX`` or libpq's defaults.
    """

    kind = "server"

    def __init__(self, root, identity, address=None, where="--index"):
        self.root = Path(root)
        self.identity = identity
        self.address, self.shown = server_address(address, where)
        self.label = f"the archive's index on {self.shown}"
        self._conn: Any = None  # one connection: the writer's lock, its writes, its reads
        self._held: Any = None  # (owner, the connection that holds its session lock)
        self.read_only = False  # set before first use: every transaction read-only (serve)

    def _connection(self):
        """The index's one connection, made (and the identity checked) on first use."""
        if self._conn is None or self._conn.closed or self._conn.broken:
            self._conn = self._connect()
        return self._conn

    def close(self):
        if self._conn is not None:
            with contextlib.suppress(Exception):
                self._conn.close()
            self._conn = None
        self._held = None

    def _done(self):
        """After a read or a write: keep the connection while it holds a writer's session
        lock (its scratch folder exists), else close it."""
        if self._held is None or self._held[1] is not self._conn:
            self.close()

    def _connect(self, check=True, fresh=False):
        try:
            options = session_options() + (" -c default_transaction_read_only=on"
                                           if self.read_only else "")
            conn = Link(self.address, options, fresh)
        except LinkError as exc:
            if exc.kind == "missing":
                raise _link_error(exc, self.label) from None
            if exc.kind == "login":
                raise ArchiveError(f"{self.label}: refused the login ({exc.message}); "
                                   "expected the role's password in ~/.pgpass or $PGPASSWORD, "
                                   "and a role the server knows") from None
            raise ArchiveError(f"{self.label}: cannot be reached ({exc.message}); expected a "
                               f"PostgreSQL server at ${INDEX_ENV}, --index or libpq's "
                               "defaults") from None
        if check:
            try:
                row = conn.execute(f"SELECT format FROM {SERVER_SCHEMA}.archives WHERE "
                                   "identity = %s", (self.identity,)).fetchone()
            except LinkError as exc:
                if exc.broken and not fresh:  # a login made ahead of time, lost since
                    conn.close()
                    return self._connect(check, fresh=True)
                if exc.kind != "undefined":  # the server went away, or refused the statement
                    conn.close()
                    raise ArchiveError(f"{self.label}: cannot be used ({exc.message})") \
                        from None
                row = None  # no archive was ever made here
            if row is None:
                conn.close()
                raise ArchiveError(f"{display(self.root)}: its marker names archive "
                                   f"{self.identity}, which {self.label} does not hold; "
                                   "expected the server the archive was made on (check "
                                   f"${INDEX_ENV})")
            try:
                self._check_role(conn)
                conn.rollback()
            except LinkError as exc:
                conn.close()
                raise ArchiveError(f"{self.label}: cannot be used ({exc.message})") from None
        return conn

    def _check_role(self, conn):
        """Whether this role could alter the schema or rewrite entries (it owns them, or
        holds CREATE on the schema, UPDATE, DELETE or TRUNCATE on the entries): said once a
        command (:data:`NOTICES`), since engineers should use a writer's role."""
        if self.label in _CHECKED:
            return
        _CHECKED.add(self.label)
        table = f"{SERVER_SCHEMA}.entries"
        row = conn.execute(
            "SELECT current_user, has_schema_privilege(%s, 'CREATE'), "
            "has_table_privilege(%s, 'UPDATE'), has_table_privilege(%s, 'DELETE'), "
            "has_table_privilege(%s, 'TRUNCATE')",
            (SERVER_SCHEMA, table, table, table)).fetchone()
        if row is not None and any(row[1:]):
            NOTICES.append(f"{self.label}: role {printable(row[0])!r} may alter the schema or "
                           "rewrite entries (it owns them, or holds CREATE, UPDATE, DELETE or "
                           "TRUNCATE there); expected the engineers' role to read and add only "
                           "(archive init --writers ROLE; README, 'A shared archive')")

    def create(self, rows=(), writers=()):
        """Make the schema (if the role may), this archive's row and ``rows`` (an index
        moved from SQLite, their ids kept apart), in one transaction; grant each of
        ``writers`` (role names) what a writer needs and no more (:data:`WRITER_GRANTS`)."""
        import datetime

        conn = self._connect(check=False)
        try:
            for sql in SERVER_TABLES:
                if sql.startswith("CREATE SCHEMA"):
                    exists = conn.execute("SELECT 1 FROM pg_namespace WHERE nspname = %s",
                                          (SERVER_SCHEMA,)).fetchone()
                    if exists:
                        continue
                conn.execute(sql)
            for role in writers:
                for grant in WRITER_GRANTS:
                    conn.execute(grant.format(role=f'"{role}"'))  # a checked name, quoted
            created = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
            conn.execute(f"INSERT INTO {SERVER_SCHEMA}.archives (identity, created, format) "
                         "VALUES (%s, %s, 1)", (self.identity, created))
            if rows:
                conn.executemany(
                    f"INSERT INTO {SERVER_SCHEMA}.entries (archive, id, {', '.join(COLUMNS)}) "
                    f"VALUES (%s, %s, {', '.join(['%s'] * len(COLUMNS))})",
                    [(self.identity, row["id"], *(row.get(c) for c in COLUMNS))
                     for row in rows])
            conn.commit()
        except LinkError as exc:
            if exc.kind == "missing":
                raise _link_error(exc, self.label) from None
            raise ArchiveError(f"{self.label}: cannot hold a new archive ({exc.message}); "
                               f"expected a role that owns schema {SERVER_SCHEMA} or may "
                               "create it (README, 'A shared archive')") from None
        finally:
            conn.close()

    def exists(self):
        return True

    def write(self):
        session = _ServerSession(self._connection(), self.identity, self.label, self)
        try:  # the write lock, one writer at a time: an advisory lock the transaction holds
            # (a row lock, SELECT ... FOR UPDATE, would need the writers' role to hold UPDATE)
            session._run("SELECT pg_advisory_xact_lock(%s)", (_owner_key(
                f"archive:{self.identity}"),))
        except BaseException:
            session.close()
            raise
        return session

    def rows(self, shot=None, since=None, order="created, shot, version", bad=None):
        """The entries' rows as dicts, checked (:func:`checked_row`), filtered by shot and
        creation date; a bad row raises, or with ``bad`` is listed there."""
        conn = self._connection()
        try:
            where, args = _filters(shot, "%s")
            found = conn.execute(
                f"SELECT {_SERVER_COLUMNS} FROM {SERVER_SCHEMA}.entries WHERE "
                f"archive = %s{where}", [self.identity, *args]).dicts()
            conn.rollback()  # no transaction left open between uses
            self._done()
        except LinkError as exc:
            self.close()
            raise ArchiveError(f"{self.label}: cannot be read ({exc.message})") from None
        return ordered(since_filter(checked_rows(found, self.label, bad), since), order)

    def stamp(self):
        """A token that changes when the entries do: their count and the last id (a writer's
        role can add entries, never change one: :data:`WRITER_GRANTS`)."""
        conn = self._connection()
        try:
            found = conn.execute(f"SELECT COUNT(*), MAX(id) FROM {SERVER_SCHEMA}.entries WHERE "
                                 "archive = %s", [self.identity]).fetchone()
            conn.rollback()
            self._done()
        except LinkError as exc:
            self.close()
            raise ArchiveError(f"{self.label}: cannot be read ({exc.message})") from None
        return tuple(str(v) for v in found) if found else ()

    def problems(self):
        return []  # the server keeps its own pages whole

    def count(self):
        return len(self.rows())

    def files(self):
        return set()

    def hold(self, owner):
        """Hold, on the index's connection and for as long as it lives, the session lock that
        says this writer's owner token is alive: another host asks the server, not its own
        process table (the server frees the lock when the session ends, the process dead)."""
        conn = self._connection()
        if self._held == (owner, conn):
            return
        try:
            conn.execute("SELECT pg_advisory_lock(%s)", (_owner_key(owner),))
            conn.commit()  # a session lock: it outlives the transaction
        except LinkError as exc:
            self.close()
            raise _link_error(exc, self.label) from None
        self._held = (owner, conn)

    def writer_gone(self, owner):
        """Whether a scratch folder's writer is gone: its advisory lock is free on the server
        (the server drops a session's locks when its process dies, on any host)."""
        from ..transaction import owner_alive
        from ..transaction.owners import host_tag, owner_host
        host = owner_host(owner)
        if host is None or host == host_tag():  # this host's process table says
            return not owner_alive(owner)
        conn = self._connection()  # within the writer's transaction: session locks ignore it
        key = _owner_key(owner)
        try:
            free = conn.execute("SELECT pg_try_advisory_lock(%s)", (key,)).fetchone()[0]
            if free:
                conn.execute("SELECT pg_advisory_unlock(%s)", (key,))
        except LinkError as exc:
            raise _link_error(exc, self.label) from None
        return bool(free)
