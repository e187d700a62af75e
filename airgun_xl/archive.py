"""An archive of shots: every run kept with its inputs, outputs and provenance.

Layout of an archive folder::

    index.sqlite            one row an entry (SQLite, WAL mode; no server)
    <shot>/v0001/           an entry: input, output.xlsx, params.json, history.parquet,
                            summary.json, provenance.json, manifest.json (SHA-256 of each)
    .tmp/<pid>-<uuid>/      an entry being written

An entry is either fully there or not at all: its files are written and synced in a private
folder under ``.tmp``, then, holding the index's write lock, the folder is renamed into place
(an atomic rename) and its row inserted in the same transaction. A process killed at any point
leaves either a ``.tmp`` folder (removed by the next writer, once its process is gone) or a
complete folder whose row was not committed (indexed by the next writer from its manifest).
Two processes writing at once queue on the lock and never take the same version.
"""
import datetime
import hashlib
import json
import os
import re
import shutil
import sqlite3
import uuid
from dataclasses import dataclass
from pathlib import Path

from .errors import AirgunXlError, OptionError

ENV = "AIRGUN_XL_ARCHIVE"
INDEX = "index.sqlite"
TMP = ".tmp"
MANIFEST = "manifest.json"
SCHEMA = """
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


class ArchiveError(AirgunXlError):
    """The archive cannot be used or does not hold what was asked for."""


def archive_dir(given=None, required=True):
    """The archive folder: the given one, else $AIRGUN_XL_ARCHIVE."""
    path = given or os.environ.get(ENV)
    if not path:
        if required:
            raise OptionError(f"DIR: found none, expected an archive folder or ${ENV}")
        return None
    return Path(path)


def safe_name(name):
    """A shot name that cannot leave the archive: letters, digits, '.', '_' and '-' only,
    no leading dots, at most 100 characters (``../../x`` -> ``x``)."""
    text = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._-")
    text = re.sub(r"\.{2,}", ".", text)[:100]
    return text or "shot"


def sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _fsync_dir(path):
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@dataclass
class Entry:
    id: int
    shot: str
    version: int
    path: Path
    created: str
    row: dict

    @property
    def ref(self):
        return f"{self.shot}@{self.version}"

    def manifest(self):
        return json.loads((self.path / MANIFEST).read_text())

    def load(self, name):
        return json.loads((self.path / name).read_text())


class Archive:
    """An archive folder (created on first use)."""

    def __init__(self, root):
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise ArchiveError(f"{self.root}: is not a folder, expected an archive folder")

    # -- the index ------------------------------------------------------------------------
    def _connect(self):
        self.root.mkdir(parents=True, exist_ok=True)
        conn = sqlite3.connect(self.root / INDEX, timeout=120, isolation_level=None)
        conn.row_factory = sqlite3.Row
        conn.execute("PRAGMA journal_mode=WAL")
        conn.execute("PRAGMA synchronous=FULL")
        conn.execute(SCHEMA)
        return conn

    def _insert(self, conn, manifest, path):
        meta = manifest["index"]
        conn.execute(
            "INSERT INTO entries (shot, version, path, created, input_sha256, v0, delta, "
            "max_time, sigmay, rcone, peak_kg, integrator, model, engine) VALUES "
            "(?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
            (meta["shot"], meta["version"], str(path.relative_to(self.root)), meta["created"],
             meta.get("input_sha256"), meta.get("v0"), meta.get("delta"), meta.get("max_time"),
             meta.get("sigmay"), meta.get("rcone"), meta.get("peak_kg"),
             meta.get("integrator"), meta.get("model"), meta.get("engine")))

    def _recover(self, conn):
        """Under the write lock: index complete entries whose row was lost to a kill, and
        remove the private folders of writers that are gone."""
        known = {r["path"] for r in conn.execute("SELECT path FROM entries")}
        for manifest_path in self.root.glob(f"*/v*/{MANIFEST}"):
            folder = manifest_path.parent
            rel = str(folder.relative_to(self.root))
            if rel not in known and self._complete(folder):
                self._insert(conn, json.loads(manifest_path.read_text()), folder)
        tmp = self.root / TMP
        for folder in tmp.glob("*") if tmp.is_dir() else ():
            pid = folder.name.split("-", 1)[0]
            if not pid.isdigit() or not _alive(int(pid)):
                shutil.rmtree(folder, ignore_errors=True)

    def _complete(self, folder):
        try:
            manifest = json.loads((folder / MANIFEST).read_text())
        except (OSError, ValueError):
            return False
        return all((folder / name).is_file() and sha256(folder / name) == digest
                   for name, digest in manifest["files"].items())

    # -- writing --------------------------------------------------------------------------
    def add(self, shot, files, documents, index, generated=None):
        """Store one entry.

        Parameters
        ----------
        shot : str
            Shot name (sanitized here).
        files : dict
            Entry file name -> source path, copied.
        documents : dict
            Entry file name -> JSON-able object, written as JSON.
        index : dict
            Columns of the index row (v0, delta, peak_kg, ...).
        generated : dict, optional
            Entry file name -> function that writes that file at the path it is given.

        Returns
        -------
        Entry
        """
        shot = safe_name(shot)
        tmp_root = self.root / TMP
        tmp_root.mkdir(parents=True, exist_ok=True)
        work = tmp_root / f"{os.getpid()}-{uuid.uuid4().hex}"
        work.mkdir()
        try:
            for name, source in files.items():
                shutil.copyfile(source, work / name)
            for name, doc in documents.items():
                (work / name).write_text(json.dumps(doc, indent=1, default=str))
            for name, write in (generated or {}).items():
                write(work / name)
            digests = {p.name: sha256(p) for p in sorted(work.iterdir())}
            created = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
            manifest = {"files": digests, "index": dict(index, shot=shot, created=created)}
            for p in work.iterdir():
                with open(p, "rb") as fh:
                    os.fsync(fh.fileno())
            conn = self._connect()
            try:
                conn.execute("BEGIN IMMEDIATE")  # the write lock: one writer at a time
                self._recover(conn)
                version = self._next_version(conn, shot)
                manifest["index"]["version"] = version
                (work / MANIFEST).write_text(json.dumps(manifest, indent=1, default=str))
                with open(work / MANIFEST, "rb") as fh:
                    os.fsync(fh.fileno())
                _fsync_dir(work)
                final = self.root / shot / f"v{version:04d}"
                final.parent.mkdir(exist_ok=True)
                os.rename(work, final)  # the entry appears whole
                _fsync_dir(final.parent)
                self._insert(conn, manifest, final)
                conn.execute("COMMIT")
            except BaseException:
                if conn.in_transaction:
                    conn.execute("ROLLBACK")
                raise
            finally:
                conn.close()
        finally:
            if work.exists():
                shutil.rmtree(work, ignore_errors=True)
        return self.get(f"{shot}@{version}")

    def _next_version(self, conn, shot):
        row = conn.execute("SELECT MAX(version) FROM entries WHERE shot = ?", (shot,)).fetchone()
        on_disk = [int(p.name[1:]) for p in (self.root / shot).glob("v*")
                   if p.name[1:].isdigit()] if (self.root / shot).is_dir() else []
        return max([row[0] or 0] + on_disk) + 1

    # -- reading --------------------------------------------------------------------------
    def entries(self, shot=None, since=None):
        if not (self.root / INDEX).exists():
            return []
        conn = self._connect()
        try:
            sql, args = "SELECT * FROM entries WHERE 1=1", []
            if shot:
                sql += " AND shot = ?"
                args.append(safe_name(shot))
            if since:
                sql += " AND created >= ?"
                args.append(since)
            rows = conn.execute(sql + " ORDER BY created, shot, version", args).fetchall()
        finally:
            conn.close()
        return [self._entry(r) for r in rows]

    def _entry(self, r):
        return Entry(r["id"], r["shot"], r["version"], self.root / r["path"], r["created"],
                     dict(r))

    def get(self, ref):
        """An entry by ``shot@version``, ``shot`` (its latest version), ``shot/v0003`` or
        ``#id``."""
        ref = str(ref).strip()
        candidates = self.entries()
        by_id = re.fullmatch(r"#?(\d+)", ref)
        if by_id:
            found = [e for e in candidates if e.id == int(by_id.group(1))]
        else:
            match = re.fullmatch(r"(.+?)(?:@(\d+)|/v(\d+))?", ref)
            name, version = match.group(1), match.group(2) or match.group(3)
            found = [e for e in candidates if e.shot == safe_name(name)
                     and (version is None or e.version == int(version))]
            found = found[-1:]
        if not found:
            raise ArchiveError(f"{ref}: no such entry in {self.root}, expected SHOT, "
                               "SHOT@VERSION or #ID (see airgun-xl history)")
        return found[0]

    def verify(self):
        """Re-hash every file of every entry; return the problems found (empty when clean).

        Recovery runs first, under the write lock, as any writer's would.
        """
        problems = []
        conn = self._connect()
        try:
            conn.execute("BEGIN IMMEDIATE")
            self._recover(conn)
            conn.execute("COMMIT")
            check = conn.execute("PRAGMA integrity_check").fetchone()[0]
            if check != "ok":
                problems.append(f"{INDEX}: {check}")
        finally:
            conn.close()
        indexed = set()
        for e in self.entries():
            indexed.add(e.path)
            if not (e.path / MANIFEST).is_file():
                problems.append(f"{e.ref}: missing {e.path}")
                continue
            for name, digest in e.manifest()["files"].items():
                f = e.path / name
                if not f.is_file():
                    problems.append(f"{e.ref}: missing {name}")
                elif sha256(f) != digest:
                    problems.append(f"{e.ref}: {name} altered (SHA-256 differs)")
        for folder in self.root.glob("*/v*"):
            if folder.is_dir() and folder not in indexed:
                problems.append(f"{folder.relative_to(self.root)}: not in the index")
        return problems


def _alive(pid):
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
