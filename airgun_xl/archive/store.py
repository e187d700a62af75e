"""The archive's store: folders, index, entries, and their transactions.

Layout of an archive folder::

    .airgun-xl-archive      marker: this folder is an archive (JSON: the format version; for
                            an index on a server, its identity, never its address)
    index.sqlite            one row an entry (SQLite, WAL mode; no server), or the same rows
                            on a PostgreSQL server (:mod:`.index`)
    <shot>/v0001/           an entry: input, output.xlsx, params.json, history.parquet,
                            summary.json, provenance.json, manifest.json (SHA-256 of each)
    .airgun-xl-scratch/<owner>-<hex>/   an entry being written

The tool only ever writes into a folder it created, an empty one, or one that holds the marker
or an index of its own; a non-empty foreign folder is refused. It removes nothing but its own
scratch folders, by their exact name pattern, once their owner process is gone.

An entry is either fully there or not at all: its files are written and synced in a scratch
folder, then, holding the index's write lock, the folder is renamed into place (an atomic
rename: the commit point) and its row inserted in the same transaction. A process killed at any
point leaves either a scratch folder (removed by the next writer) or a complete folder whose row
was not committed (indexed by the next writer from its manifest). Two processes writing at once
queue on the lock and never take the same version. A fill publishes its workbook and the entry
together (:class:`PendingEntry` joins its :class:`airgun_xl.transaction.Publication`).

``verify`` reports, rather than raises on, whatever it finds: a copied entry folder, a corrupt
manifest, a missing or altered file, a row that points outside the archive.
"""
import contextlib
import datetime
import errno
import hashlib
import json
import os
import re
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..choices import ARCHIVE_ENV
from ..errors import ArchiveError, OptionError
from ..transaction import display, fsync, owner_token
from ..transaction.owners import OWNER_PATTERN
from ..transaction.stages import stage
from .index import INDEX, INDEX_ENV, MAX_VERSION, ServerIndex, SqliteIndex, is_sqlite_index
from .records import inside, link_below, store_record

ENV = ARCHIVE_ENV
MARKER = ".airgun-xl-archive"
SCRATCH = ".airgun-xl-scratch"
MANIFEST = "manifest.json"
FORMAT = 1
_SCRATCH_NAME = re.compile(r"^(?P<owner>" + OWNER_PATTERN + r")-[0-9a-f]{32}$")

#: A marker being written (:func:`_write_marker`): a new archive's folder holding only
#: these is still empty to a fill that comes to it at the same moment.
_MARKER_TEMP = re.compile(r"^\." + re.escape(MARKER) + r"\." + OWNER_PATTERN + r"\.tmp$")


def _write_marker(root, marker):
    """Write ``marker`` as ``root``'s marker, whole or not at all: written and synced under
    a name of its own, then linked to the marker's name, which fails if it exists (two
    fills making one archive at once: one marker, and no fill ever reads half of one).
    Returns whether this call made it. Where the file system has no hard links, the
    rename that takes its place is exclusive on Windows; on POSIX it may replace a marker
    made the same moment, which says the same (a new archive's index is the folder's)."""
    root = Path(root)
    temp = root / f".{MARKER}.{owner_token()}.tmp"
    try:
        with open(temp, "x") as fh:
            json.dump(marker, fh)
            fh.flush()
            os.fsync(fh.fileno())
        try:
            os.link(temp, root / MARKER)
        except FileExistsError:
            return False
        except OSError as exc:
            if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EMLINK):
                raise
            if (root / MARKER).exists():
                return False
            try:
                os.rename(temp, root / MARKER)  # exclusive on Windows
            except FileExistsError:
                return False
        fsync(root, directory=True)
        return True
    finally:
        temp.unlink(missing_ok=True)
_ENTRY_NAME = re.compile(r"^v(\d{4,})$")
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
    if text.lower().startswith(INDEX):  # index.sqlite, -wal, -shm are the index's own files
        text = f"shot_{text}"[:100]
    return text or "shot"


def sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@dataclass
class Entry:
    id: int
    shot: str
    version: int
    path: Path
    created: str
    row: dict
    root: Path | None = None  # the archive's folder: nothing below it is read through a link

    @property
    def ref(self):
        return f"{self.shot}@{self.version}"

    def contained(self):
        """Refuse an entry whose shot folder, entry folder or files are reached through a
        link (it could lead out of the archive): one line naming the link and its target.

        Raises
        ------
        ArchiveError
        """
        if self.root is None:
            return
        found = link_below(self.root, self.path)
        if found is not None:
            part, target = found
            raise ArchiveError(f"{self.ref}: {display(part)} is a link to {display(target)}, "
                               "expected the entry's own folder inside the archive (not "
                               "followed; see airgun-xl archive verify)")

    def manifest(self):
        return self.load(MANIFEST)

    def load(self, name):
        """A JSON file of the entry.

        Raises
        ------
        ArchiveError
            When it is missing or not valid JSON (``archive verify`` lists such damage).
        """
        from ..untrusted_json import read_json

        self.contained()
        path = self.path / name
        if not os.path.lexists(path):
            raise ArchiveError(f"{self.ref}: {name} is missing from {display(self.path)}, "
                               "expected a whole entry (see airgun-xl archive verify)")
        if path.is_symlink():
            raise ArchiveError(f"{self.ref}: {name} is a link, expected the entry's own file "
                               "(see airgun-xl archive verify)")
        return read_json(path, RECORD_KINDS.get(name, "summary"), f"{self.ref}: {name}",
                         ArchiveError)


def _entry_version(folder):
    """The version of an entry folder name (``v0003`` -> 3), else None."""
    m = _ENTRY_NAME.match(folder.name)
    return int(m.group(1)) if m else None


#: The kind (:data:`airgun_xl.untrusted_json.SCHEMAS`) of each JSON file of an entry.
RECORD_KINDS = {"params.json": "params", "summary.json": "summary",
                "provenance.json": "provenance", MANIFEST: "manifest"}


def _read_manifest(folder):
    """An entry folder's manifest, or None when missing, corrupt or not for this folder."""
    from ..untrusted_json import read_json

    try:
        if (folder / MANIFEST).is_symlink():
            return None
        manifest = read_json(folder / MANIFEST, "manifest", str(folder / MANIFEST),
                             ArchiveError)
        index = manifest["index"]
        files = manifest["files"]
        ok = (index["shot"] == folder.parent.name and index["version"] == _entry_version(folder)
              and isinstance(files, dict)
              and all(isinstance(n, str) and n == os.path.basename(n) and n not in ("", ".", "..")
                      and isinstance(d, str) for n, d in files.items()))
    except (ArchiveError, OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return manifest if ok else None


def read_marker(root):
    """An archive folder's marker: {"format", "index" ("sqlite" or "server"), "identity"};
    read as untrusted (a hostile marker is refused in one line, never dialled)."""
    from ..untrusted_json import read_json

    marker = read_json(Path(root) / MARKER, "marker", display(Path(root) / MARKER),
                       ArchiveError)
    marker.setdefault("index", "sqlite")
    if marker["index"] == "server" and "identity" not in marker:
        raise ArchiveError(f"{display(Path(root) / MARKER)}: identity: found none, expected "
                           "the archive's identity (32 hexadecimal digits) for an index on a "
                           "server")
    return marker


def prestart_index(root):
    """Start the index's agent now when ``root`` is an archive whose index is on a server
    (:func:`airgun_xl.archive.agent.prestart`), so that psycopg loads on the other core
    while the command goes on; anything else does nothing here (it is checked where the
    archive is opened)."""
    if root is None or not (Path(root) / MARKER).is_file():
        return
    with contextlib.suppress(ArchiveError):
        if read_marker(root)["index"] == "server":
            from .index import preconnect

            preconnect()


class Archive:
    """An archive folder.

    Parameters
    ----------
    root : path
    create : bool
        Create the folder (its parent must exist), or adopt an empty one, for writing. Without
        it, ``root`` must already be an archive.
    dry_run : bool
        With ``create``: check that it could, and change nothing.
    index : str, optional
        For an archive whose index is on a server: its address (else ``$AIRGUN_XL_INDEX`` or
        libpq's defaults; never the marker's say).
    check : bool
        Refuse a marker that contradicts where the index is (:meth:`marker_problems`);
        ``archive verify`` opens without, to report it.
    initialising : bool
        :meth:`init`'s own probe: with ``$AIRGUN_XL_INDEX`` set, any other command refuses
        to make a new archive (its index would be local).

    Raises
    ------
    ArchiveError
        When ``root`` is missing (without ``create``), not a folder, or a folder that holds
        other files and is not an archive.
    """

    def __init__(self, root, create=False, dry_run=False, index=None, check=True,
                 initialising=False):
        self.root = Path(root)
        self.index: SqliteIndex | ServerIndex = SqliteIndex(self.root)
        self.created_here = False  # this object made the folder (undone if nothing commits)
        shown = display(self.root)
        if create and not initialising and os.environ.get(INDEX_ENV) and not (
                (self.root / MARKER).is_file() or (self.root / INDEX).exists()):
            raise ArchiveError(f"{shown}: a new archive, while ${INDEX_ENV} names a server for "
                               "archives' indexes; expected airgun-xl archive init "
                               f"{shown} first, which makes its index there (never a local "
                               "index, which a share cannot serve)")
        if dry_run and not self.root.exists():  # what create would do, without doing it
            if not self.root.parent.is_dir():
                raise ArchiveError(f"{shown}: its folder {display(self.root.parent)} does not "
                                   "exist, expected an existing folder for the archive")
            return
        if not self.root.exists():
            if not create:
                raise ArchiveError(f"{shown}: no such archive, expected a folder written by "
                                   "airgun-xl fill --archive")
            try:
                os.mkdir(self.root)
                self.created_here = True
            except FileExistsError:
                pass  # another fill created it a moment ago: it is checked below as any other
            except FileNotFoundError:
                raise ArchiveError(f"{shown}: its folder {display(self.root.parent)} does not "
                                   "exist, expected an existing folder for the archive") from None
            except OSError as exc:
                raise ArchiveError(f"{shown}: cannot be created ({exc.strerror})") from None
        if not self.root.is_dir():
            raise ArchiveError(f"{shown}: is not a folder, expected an archive folder")
        marked = (self.root / MARKER).is_file() or is_sqlite_index(self.root / INDEX)
        if not marked:
            try:
                with os.scandir(self.root) as found:  # a marker being written: still empty
                    empty = not any(not _MARKER_TEMP.match(f.name) for f in found)
            except OSError as exc:
                raise ArchiveError(f"{shown}: cannot be read ({exc.strerror})") from None
            # a fill that created the folder a moment ago may have marked it since we looked
            marked = (self.root / MARKER).is_file() or is_sqlite_index(self.root / INDEX)
            if not (create and empty) and not marked:
                raise ArchiveError(
                    f"{shown}: is not an airgun-xl archive (no {MARKER} or {INDEX}), expected "
                    + ("an archive, an empty folder or a new folder name" if create
                       else "a folder written by airgun-xl fill --archive"))
        if create and not dry_run and not (self.root / MARKER).is_file():
            try:
                made = _write_marker(self.root, {"format": FORMAT, "tool": "airgun-xl"})
            except OSError as exc:
                if self.created_here:  # the folder this made, left as it was: none
                    with contextlib.suppress(OSError):
                        os.rmdir(self.root)
                raise ArchiveError(f"{shown}: cannot be written ({exc.strerror})") from None
            if made:
                stage("archive-made")
        if not (self.root / MARKER).is_file():
            return
        if dry_run:  # a server archive's agent starts while the run goes on
            prestart_index(self.root)
            return
        marker = read_marker(self.root)
        if marker["index"] == "server":
            self.index = ServerIndex(self.root, marker["identity"], index)
        elif check and (found := self.marker_problems()):  # verify (check False) reports it
            raise ArchiveError(f"{shown}: {found[0]} (see airgun-xl archive verify)")

    @classmethod
    def init(cls, root, index=None, server=None, writers=()):
        """Make a new archive at ``root`` (a new or empty folder): its index in the folder, or
        with ``server`` (default: when ``index`` is given) on a PostgreSQL server at ``index``
        (an address, :func:`~airgun_xl.archive.index.server_address`; None for
        ``$AIRGUN_XL_INDEX`` or libpq's defaults), the marker naming its identity, and the
        ``writers`` roles granted what a writer needs; return it.

        Raises
        ------
        airgun_xl.errors.ArchiveError
            When ``root`` is an archive already, or a folder that holds other files.
        """
        root = Path(root)
        shown = display(root)
        if (root / MARKER).exists() or (root / INDEX).exists():
            raise ArchiveError(f"{shown}: is an archive already, expected a new or empty "
                               "folder (airgun-xl archive migrate moves an index to a server)")
        on_server = server if server is not None else index is not None
        server = None
        if on_server:  # the address checked, and the server reached, before the folder is made
            server = ServerIndex(root, uuid.uuid4().hex, index)
        probe = cls(root, create=True, dry_run=True, initialising=True)
        del probe
        if root.exists() and next(iter(os.listdir(root)), None) is not None:
            raise ArchiveError(f"{shown}: is not empty, expected a new or empty folder")
        if server is not None:
            server.create(writers=writers)
        made = not root.exists()
        try:
            os.makedirs(root, exist_ok=True)
            marker = {"format": FORMAT, "tool": "airgun-xl"}
            if server is not None:
                marker.update(index="server", identity=server.identity)
            if not _write_marker(root, marker):
                raise FileExistsError(errno.EEXIST, "made by another command meanwhile")
        except OSError as exc:
            if made:
                shutil.rmtree(root, ignore_errors=True)
            raise ArchiveError(f"{shown}: cannot be written ({exc.strerror})") from None
        return cls(root, index=index)  # the server it was made on, as given

    def migrate(self, index=None, writers=()):
        """Move this archive's SQLite index to a PostgreSQL server at ``index`` (else
        ``$AIRGUN_XL_INDEX`` or libpq's defaults); return the backup the SQLite index was
        renamed to.

        Writers are kept out throughout: the SQLite write lock is held from the first read
        to the new marker, and a writer that waited on it finds the marker changed and stops
        (:meth:`PendingEntry.prepare`). Every row is verified against its entry's manifest
        first (any mismatch refuses the move, changing nothing); the rows reach the server in
        one transaction; the marker then names the server's archive, and only then is the
        SQLite index renamed, kept as a backup.

        Raises
        ------
        airgun_xl.errors.ArchiveError
        """
        if self.index.kind != "sqlite":
            raise ArchiveError(f"{display(self.root)}: its index is on a server already, "
                               "expected an archive whose index is index.sqlite")
        if not self.index.exists():
            raise ArchiveError(f"{display(self.root)}: has no {INDEX} to move, expected an "
                               "archive written by airgun-xl fill --archive")
        server = ServerIndex(self.root, uuid.uuid4().hex, index)  # checked before the lock
        session = self.index.write()
        try:
            self._recover(session)
            rows = session.all_rows()
            wrong = [r for r in rows if not self._matches_manifest(r)]
            if wrong:
                r = wrong[0]
                raise ArchiveError(f"{display(self.root)}: {len(wrong)} of {len(rows)} rows do "
                                   f"not match their entry's manifest (the first: "
                                   f"{r['shot']}@{r['version']}); expected a clean archive "
                                   "(see airgun-xl archive verify); nothing was moved")
            server.create(rows, writers)
            marker = {"format": FORMAT, "tool": "airgun-xl", "index": "server",
                      "identity": server.identity}
            temp = self.root / f".{MARKER}.{owner_token()}.tmp"
            try:
                with open(temp, "w") as fh:
                    json.dump(marker, fh)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.replace(temp, self.root / MARKER)  # from here on, writers use the server
            finally:
                temp.unlink(missing_ok=True)
            fsync(self.root, directory=True)
        finally:
            session.close()
        stamp = datetime.datetime.now(datetime.UTC).strftime("%Y%m%dT%H%M%SZ")
        backup = self.root / f".{INDEX}.moved-{stamp}"
        for suffix in ("", "-wal", "-shm"):
            with contextlib.suppress(FileNotFoundError):
                os.rename(self.root / f"{INDEX}{suffix}", self.root / f"{backup.name}{suffix}")
        self.index = server
        return backup

    def _moved(self):
        """Whether the marker now says the index is on a server (a migrate finished while
        this writer waited on the SQLite lock)."""
        try:
            return read_marker(self.root)["index"] == "server"
        except ArchiveError:
            return False

    def _matches_manifest(self, row):
        """Whether an index row is its entry's: the folder is ``<shot>/vNNNN``, its manifest
        names this shot and version, and every file hashes as listed."""
        entry = self.entry_of(row)
        if entry is None or not entry.path.is_dir():
            return False
        manifest = _read_manifest(entry.path)
        return (manifest is not None and manifest["index"]["shot"] == row["shot"]
                and manifest["index"]["version"] == row["version"]
                and self._complete(entry.path, manifest))

    def keep(self, folder, record, what, version=None):
        """Store ``record`` as the next version in ``folder`` (one of the archive's record
        folders: a law's, a verdict's; :func:`~airgun_xl.archive.records.store_record}), or
        as exactly ``version``; return the version. A failure takes back the folders this
        made and the archive itself if this object created it and nothing else is in it."""
        folder = Path(folder)
        made = [f for f in (folder.parent, folder) if not f.exists()]
        try:
            return store_record(folder, record, what, self.root, version)
        except BaseException:
            for f in reversed(made):
                with contextlib.suppress(OSError):
                    f.rmdir()  # only if empty
            self.remove_if_unused()
            raise

    def remove_if_unused(self):
        """Undo the creation of a new archive whose first entry was never committed (a failed
        or interrupted fill): remove its empty index, marker and empty scratch folder, then
        the folder, and stop at anything else in it (another writer's work). Only for a
        folder this object created."""
        if not self.created_here:
            return
        if self.index.kind != "sqlite":
            return  # a server archive is made by archive init, and kept
        index_files = self.index.files()
        with contextlib.suppress(Exception):  # OSError, or the index's own error
            if set(os.listdir(self.root)) - {MARKER, SCRATCH} - index_files:
                return
            if self.index.exists() and self.index.count():
                return
            if (self.root / SCRATCH).exists():
                os.rmdir(self.root / SCRATCH)  # fails if another writer works in it
            for name in sorted(index_files):
                (self.root / name).unlink(missing_ok=True)
            if set(os.listdir(self.root)) - {MARKER}:
                return
            (self.root / MARKER).unlink(missing_ok=True)
            os.rmdir(self.root)

    # -- the index ------------------------------------------------------------------------
    @staticmethod
    def _row(manifest, path, root):
        meta = manifest["index"]
        return dict(meta, path=path.relative_to(root).as_posix())

    def _entry_folders(self):
        """``(folder, version)`` of every folder shaped like an entry, ``<shot>/vNNNN``."""
        for shot in sorted(self.root.iterdir()):
            if shot.name.startswith(".") or not shot.is_dir() or shot.is_symlink():
                continue
            for folder in sorted(shot.iterdir()):
                version = _entry_version(folder)
                if version is not None and folder.is_dir() and not folder.is_symlink():
                    yield folder, version

    def _recover(self, session):
        """Under the write lock: index complete entries whose row was lost to a kill, and
        remove the scratch folders of writers that are gone (only those: another host's only
        when a server index says so)."""
        known = session.paths()
        for folder, _ in self._entry_folders():
            rel = folder.relative_to(self.root).as_posix()
            if rel in known:
                continue
            manifest = _read_manifest(folder)
            if manifest is not None and self._complete(folder, manifest):
                session.insert(self._row(manifest, folder, self.root))  # a clash: verify says
        scratch = self.root / SCRATCH
        for folder in scratch.iterdir() if scratch.is_dir() else ():
            m = _SCRATCH_NAME.match(folder.name)
            if m and folder.is_dir() and not folder.is_symlink() and self.index.writer_gone(
                    m["owner"]):
                shutil.rmtree(folder, ignore_errors=True)

    def _complete(self, folder, manifest):
        return all((folder / name).is_file() and sha256(folder / name) == digest
                   for name, digest in manifest["files"].items())

    # -- writing --------------------------------------------------------------------------
    def prepare(self, shot, files, documents, index, generated=None):
        """Write an entry's files into a scratch folder; return the :class:`PendingEntry`
        that commits it (alone with :meth:`PendingEntry.commit_alone`, or inside a
        :class:`airgun_xl.transaction.Publication`).

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
        """
        shot = safe_name(shot)
        scratch = self.root / SCRATCH
        self.index.hold(owner_token())  # a server archive: this writer is alive, on any host
        try:
            scratch.mkdir(exist_ok=True)
            work = scratch / f"{owner_token()}-{uuid.uuid4().hex}"
            work.mkdir()
            inside(self.root, work, "the scratch folder")  # a planted link: nothing written
        except OSError as exc:
            self.index.close()  # no scratch folder to vouch for
            raise ArchiveError(f"{display(scratch)}: cannot be written ({exc.strerror})") from None
        except ArchiveError:
            self.index.close()
            raise
        pending = PendingEntry(self, shot, work)
        try:
            for name, source in files.items():
                shutil.copyfile(source, work / name)
            for name, doc in documents.items():
                (work / name).write_text(json.dumps(doc, indent=1, default=str))
            for name, write in (generated or {}).items():
                write(work / name)
            digests = {p.name: sha256(p) for p in sorted(work.iterdir())}
            for p in work.iterdir():
                with open(p, "rb") as fh:
                    os.fsync(fh.fileno())
            stage("entry-staged")
        except BaseException as exc:
            pending.release()
            if isinstance(exc, OSError):
                raise ArchiveError(f"{display(self.root)}: the entry cannot be written "
                                   f"({exc.strerror or exc})") from None
            raise
        created = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
        pending.manifest = {"files": digests, "index": dict(index, shot=shot, created=created)}
        return pending

    def add(self, shot, files, documents, index, generated=None):
        """Store one entry on its own (see :meth:`prepare`); return the :class:`Entry`."""
        return self.prepare(shot, files, documents, index, generated).commit_alone()

    def _next_version(self, session, shot):
        folder = self.root / shot
        on_disk = [v for v in (_entry_version(p) for p in folder.iterdir()) if v is not None] \
            if folder.is_dir() and not folder.is_symlink() else []
        last = max([session.last_version(shot)] + on_disk)
        if last >= MAX_VERSION:  # this shot only: the others go on
            raise ArchiveError(f"{display(self.root)}: shot {shot}: its last version is "
                               f"{last:,}, expected fewer than {MAX_VERSION:,} (the most an "
                               "archive numbers; see airgun-xl archive verify)")
        return last + 1

    # -- reading --------------------------------------------------------------------------
    def entries(self, shot=None, since=None, bad=None):
        rows = self.index.rows(safe_name(shot) if shot else None, since, bad=bad)
        return [e for e in (self.entry_of(r) for r in rows) if e is not None]

    def entry_of(self, r):
        """An Entry from an index row; None for a row whose path is not ``<shot>/vNNNN``."""
        path = str(r["path"])
        parts = path.split("/")
        if len(parts) != 2 or parts[0] != safe_name(parts[0]) or not _ENTRY_NAME.match(parts[1]):
            return None
        return Entry(r["id"], r["shot"], r["version"], self.root / parts[0] / parts[1],
                     r["created"], dict(r), self.root)

    def get(self, ref):
        """An entry by ``shot@version``, ``shot`` (its latest version), ``shot/v0003`` or
        ``#id``."""
        ref = str(ref).strip()
        if not ref:
            raise ArchiveError("ENTRY: found an empty name, expected SHOT, SHOT@VERSION or #ID "
                               "(see airgun-xl history)")
        candidates = self.entries()
        by_id = re.fullmatch(r"#?(\d+)", ref)
        if by_id:
            found = [e for e in candidates if e.id == int(by_id.group(1))]
        else:
            match = re.fullmatch(r"(.+?)(?:@(\d+)|/v(\d+))?", ref)
            assert match is not None  # any non-empty text matches
            name, version = match.group(1), match.group(2) or match.group(3)
            found = [e for e in candidates if e.shot == safe_name(name)
                     and (version is None or e.version == int(version))]
            found = found[-1:]
        if not found:
            raise ArchiveError(f"{ref}: no such entry in {display(self.root)}, expected SHOT, "
                               "SHOT@VERSION or #ID (see airgun-xl history)")
        return found[0]

    def entry_problems(self, entry, hash_files=True):
        """What is wrong with an indexed entry, in words (empty when it is whole): a link on
        its way (and where it leads), its folder missing, its manifest missing, corrupt or
        naming another shot or version than its row, a file missing, a link or altered (with
        ``hash_files``)."""
        found = link_below(self.root, entry.path)
        if found is not None:
            part, target = found
            return [f"{entry.ref}: {part.relative_to(self.root).as_posix()} is a link to "
                    f"{display(target)} (not followed)"]
        if not entry.path.is_dir():
            return [f"{entry.ref}: missing {entry.path.relative_to(self.root).as_posix()}"]
        manifest = _read_manifest(entry.path)
        if manifest is None:
            return [f"{entry.ref}: {MANIFEST} is missing, corrupt or names another entry"]
        named = (manifest["index"]["shot"], manifest["index"]["version"])
        if named != (entry.shot, entry.version):
            return [f"row #{entry.id}: it says {entry.ref}, but its folder "
                    f"{entry.path.relative_to(self.root).as_posix()} holds "
                    f"{named[0]}@{named[1]}"]
        problems = []
        for name, digest in manifest["files"].items():
            f = entry.path / name
            if f.is_symlink():
                problems.append(f"{entry.ref}: {name} is a link to {display(os.readlink(f))} "
                                "(not followed)")
            elif not f.is_file():
                problems.append(f"{entry.ref}: missing {name}")
            elif hash_files and sha256(f) != digest:
                problems.append(f"{entry.ref}: {name} altered (SHA-256 differs)")
        return problems

    def checked(self, entry, rows=None):
        """``entry``, refused in one line when ``verify`` would report it: a show or a
        compare reads only whole entries of the archive's own. ``rows``: the index's rows,
        when the caller has just read them (else they are read).

        Raises
        ------
        ArchiveError
        """
        problems = self.entry_problems(entry)
        twins = [r for r in (self.index.rows() if rows is None else rows)
                 if r["id"] != entry.id and (
            r["path"] == entry.row.get("path") or (r["shot"], r["version"]) == (
                entry.shot, entry.version))]
        if twins:
            problems.append(f"{entry.ref}: row #{twins[0]['id']} names the same entry "
                            "(two rows on one folder, or one version twice)")
        if problems:
            raise ArchiveError(f"{problems[0]}; expected a whole entry of the archive's own "
                               "(see airgun-xl archive verify)")
        return entry

    def marker_problems(self):
        """Where the marker and the index disagree: a marker that says the index is
        ``index.sqlite`` while there is none and entries are on disk, or a backup of an
        index moved to a server beside it."""
        if self.index.kind != "sqlite" or self.index.exists():
            return []
        moved = sorted(p.name for p in self.root.glob(f".{INDEX}.moved-*"))
        folders = sum(1 for _ in self._entry_folders())
        if moved:
            return [f"{MARKER}: says the index is {INDEX}, which is missing, and {moved[0]} "
                    "holds an index moved to a server (the marker was changed?); expected "
                    "the marker archive migrate wrote"]
        if folders:
            return [f"{MARKER}: says the index is {INDEX}, which is missing, while {folders} "
                    "entries are on disk; expected the archive's index"]
        return []

    def verify(self):
        """Re-hash every file of every entry; check the index against the folders both ways;
        return the problems found (empty when clean).

        Recovery runs first, under the write lock, as any writer's would. Damage is reported,
        never raised: a bad row (a column of the wrong type, NULL, too long), a row whose
        path is not an entry, whose folder is reached through a link or names another shot or
        version, two rows on one folder or one version twice, a copied or stray entry folder,
        a link (and where it leads), a corrupt manifest, a missing or altered file, a marker
        that contradicts where the index is.
        """
        problems = list(self.marker_problems())
        if not problems:
            try:
                session = self.index.write()
                try:
                    self._recover(session)
                    session.commit()
                finally:
                    session.close()
                problems += self.index.problems()
            except ArchiveError as exc:
                problems.append(str(exc))
        bad: list[str] = []
        try:
            rows = self.index.rows(order="shot, version", bad=bad)
        except ArchiveError as exc:
            problems.append(str(exc))
            rows = []
        problems += bad
        indexed = set()
        by_path: dict[Path, int] = {}
        by_version: dict[tuple[str, int], int] = {}
        for r in rows:
            e = self.entry_of(r)
            if e is None:
                problems.append(f"row #{r['id']}: its path {r['path']!r} is not an entry folder")
                continue
            if e.path in by_path:
                problems.append(f"row #{r['id']}: names the folder of row #{by_path[e.path]} "
                                f"({r['path']}): two rows on one folder")
                continue
            if (e.shot, e.version) in by_version:
                problems.append(f"row #{r['id']}: {e.ref} is row #"
                                f"{by_version[(e.shot, e.version)]}'s version too")
            by_path[e.path] = r["id"]
            by_version.setdefault((e.shot, e.version), r["id"])
            indexed.add(e.path)
            problems += self.entry_problems(e)
        for folder, _ in self._entry_folders():
            if folder not in indexed:
                why = ("its manifest is missing, corrupt or names another entry"
                       if _read_manifest(folder) is None else "incomplete or clashing")
                problems.append(f"{folder.relative_to(self.root).as_posix()}: not in the index "
                                f"({why})")
        for shot in sorted(self.root.iterdir()):
            if shot.name.startswith(".") or not (shot.is_dir() or shot.is_symlink()):
                continue
            if shot.is_symlink():
                problems.append(f"{shot.name}: a symbolic link to {display(os.readlink(shot))}, "
                                "not a shot folder (not followed)")
                continue
            for folder in sorted(shot.iterdir()):
                if folder.is_symlink():
                    problems.append(f"{folder.relative_to(self.root).as_posix()}: a symbolic "
                                    f"link to {display(os.readlink(folder))}, not an entry "
                                    "(not followed)")
                elif _entry_version(folder) is None:
                    problems.append(f"{folder.relative_to(self.root).as_posix()}: not an entry "
                                    "(a copied or stray file?)")
        return problems


#: Opening a folder without following a link where the platform can (POSIX); elsewhere the
#: resolved-path check of :func:`~airgun_xl.archive.records.inside` stands alone.
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_DIRECTORY", 0)
_BY_DESCRIPTOR = (os.rename in os.supports_dir_fd and os.mkdir in os.supports_dir_fd
                  and os.open in os.supports_dir_fd and _NOFOLLOW != 0)


def _rename_inside(root, work, final):
    """Rename the scratch folder ``work`` to the entry folder ``final`` (``root/shot/vNNNN``,
    its shot folder made if new) without following a link below ``root``: each folder is
    opened by descriptor, relative to the one above it, refusing a link (``O_NOFOLLOW``), and
    the rename is made between those descriptors (renameat), so a link swapped in after the
    check cannot take the entry out of the archive. Where the platform has no such calls
    (Windows), the folders are checked by resolved path just before the rename: a link
    swapped in between the two is the race that remains there.

    Raises
    ------
    ArchiveError
        For a link below ``root``.
    OSError
    """
    root, work, final = Path(root), Path(work), Path(final)
    shot = final.parent.name
    if not _BY_DESCRIPTOR:
        inside(root, work, "the entry being written")
        with contextlib.suppress(FileExistsError):
            os.mkdir(final.parent)
        inside(root, final, "the entry")
        os.rename(work, final)
        return
    opened: list[int] = []

    def descend(name):  # a folder of the archive's top, opened without following a link
        try:
            opened.append(os.open(name, os.O_RDONLY | _NOFOLLOW, dir_fd=opened[0]))
        except OSError as exc:
            if exc.errno in (errno.ELOOP, errno.ENOTDIR):
                inside(root, root / name, "the entry's folder")  # names the link
            raise
        return opened[-1]

    try:
        opened.append(os.open(root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0)))
        with contextlib.suppress(FileExistsError):
            os.mkdir(shot, dir_fd=opened[0])
        shot_fd = descend(shot)
        scratch_fd = descend(SCRATCH)
        os.rename(work.name, final.name, src_dir_fd=scratch_fd, dst_dir_fd=shot_fd)
    finally:
        for fd in opened:
            os.close(fd)


class PendingEntry:
    """An entry written to scratch, waiting to be committed.

    As a participant of a :class:`airgun_xl.transaction.Publication`: :meth:`prepare` takes
    the index's write lock and picks the version, :meth:`commit` renames the folder into place
    and commits the row, :meth:`release` drops the lock and the scratch folder.
    """

    def __init__(self, archive, shot, work):
        self.archive, self.shot, self.work = archive, shot, work
        self.manifest: Any = None  # the entry's manifest, set by Archive.prepare
        self.conn: Any = None  # the index connection holding the write lock, from prepare
        self.final: Any = None  # the entry's folder, from prepare
        self.entry: Entry | None = None  # once committed

    def prepare(self, txn=None):
        """Lock the index, recover, pick the version; return the path of the manifest that
        names ``txn`` once the entry is committed."""
        self.conn = self.archive.index.write()  # the write lock: one writer at a time
        if self.archive.index.kind == "sqlite" and self.archive._moved():
            raise ArchiveError(f"{display(self.archive.root)}: its index was moved to a server "
                               "while this writer waited (archive migrate); expected the same "
                               "command run again")
        self.archive._recover(self.conn)
        version = self.archive._next_version(self.conn, self.shot)
        self.manifest["index"]["version"] = version
        if txn is not None:
            self.manifest["txn"] = txn
        with open(self.work / MANIFEST, "w") as fh:
            json.dump(self.manifest, fh, indent=1, default=str)
            fh.flush()
            os.fsync(fh.fileno())
        fsync(self.work, directory=True)
        self.final = self.archive.root / self.shot / f"v{version:04d}"
        return (self.final / MANIFEST).resolve()

    def commit(self):
        """Rename the entry into place and commit its row (under the lock from prepare)."""
        try:
            _rename_inside(self.archive.root, self.work, self.final)  # the commit point
        except OSError as exc:
            raise ArchiveError(f"{display(self.final)}: cannot be written "
                               f"({exc.strerror})") from None
        try:
            stage("entry-renamed")
            fsync(self.final.parent, directory=True)
            if not self.conn.insert(self.archive._row(self.manifest, self.final,
                                                      self.archive.root)):
                raise ArchiveError(f"{display(self.final)}: its version was taken by another "
                                   "writer, expected the write lock to keep it")
            self.conn.commit()
        except BaseException:
            with contextlib.suppress(OSError):
                os.rename(self.final, self.work)  # not committed after all
            raise
        self.conn.close()
        self.conn = None
        self.archive.index.close()  # no scratch folder left to vouch for
        self.entry = Entry(0, self.shot, self.manifest["index"]["version"], self.final,
                           self.manifest["index"]["created"], {})

    def release(self):
        """Give up: roll back the index transaction and remove the scratch folder."""
        if self.conn is not None:
            self.conn.close()
            self.conn = None
        if self.work.exists():
            shutil.rmtree(self.work, ignore_errors=True)
        self.archive.index.close()

    def commit_alone(self):
        """Commit without a publication; return the :class:`Entry`."""
        try:
            self.prepare()
            self.commit()
        finally:
            self.release()
        return self.archive.get(f"{self.shot}@{self.manifest['index']['version']}")
