"""All-or-nothing output: a command's files are all published, or none is.

A :class:`Publication` stages each output as a temp file beside its final name
(``.NAME.<owner>-<hex>.airgun-xl-tmp``), written while the command works. :meth:`commit` then,
holding an exclusive lock on the output folder and with SIGINT, SIGTERM and SIGHUP held back
(:func:`signals_held`; from the commit on they stay held, so a late signal cannot make a
finished command look failed):

1. recovers what a killed publisher left in that folder (below);
2. writes a journal (``.NAME.<owner>-<hex>.airgun-xl-journal``) naming every temp, final
   name, backup and the temps' inodes;
3. publishes each file: without ``force`` by ``link(2)``, which fails when the name exists, so
   of two commands writing one output exactly one wins; with ``force`` the old file (or
   symlink, never its target) is first renamed to a backup;
4. commits a participant, such as an archive entry, whose marker file then names this
   publication;
5. deletes the journal (the commit point, when there is no participant), then the temps and
   backups.

Any failure before the commit point rolls back: published names that still hold our inode are
removed and backups renamed back. A process killed with SIGKILL leaves temps, backups or a
journal whose owner is gone; the next publisher in the folder rolls such a journal back, or
forward when its participant's marker shows the participant committed, and removes the rest.
Only names that match these patterns, of owners that are gone, are ever touched.
"""
import contextlib
import errno
import json
import os
import re
import secrets
from pathlib import Path

from ..errors import OutputError
from .checks import display, same_folder
from .locks import folder_lock, fsync
from .owners import OWNER_PATTERN, owner_alive, owner_token
from .signals import SIGNALS, Interrupted, signals_held
from .stages import stage

SUFFIX = "airgun-xl"
_OWNED = re.compile(r"^\.(?P<name>.+)\.(?P<owner>" + OWNER_PATTERN + r")-(?P<hex>[0-9a-f]{16})"
                    r"\.airgun-xl-(?P<kind>tmp|bak|journal)$")


class Publication:
    """Files staged and published together; see the module docstring.

    Parameters
    ----------
    force : bool
        Replace existing outputs (kept as backups until the commit).
    force_word : str
        How messages name ``force``: ``--force`` for the CLI, ``force=True`` for the API.
    """

    def __init__(self, force=False, force_word="--force"):
        self.force = force
        self.force_word = force_word
        self.token = f"{owner_token()}-{secrets.token_hex(8)}"
        self.files = []  # (temp, final)
        self.removals = []  # finals to remove at the commit (a stale sidecar, with force)
        self.participant = None
        self.committed = False

    def _name(self, final, kind):
        return _owned(final.parent, final.name, self.token, kind)

    def _exists_error(self, final):
        return OutputError(f"{display(final)}: already exists (another command wrote it first), "
                           f"expected a new file name or {self.force_word}")

    def stage(self, final):
        """A new empty temp file for ``final``, to be written by the caller."""
        final = Path(final)
        if self.files and not same_folder(final, self.files[0][1]):
            raise ValueError("a publication's files share one folder")  # for_file first
        if self.files:  # one folder by one path: the journal names its files in it
            final = self.files[0][1].parent / final.name
        temp = self._name(final, "tmp")
        try:
            os.close(os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
        except OSError as exc:
            raise OutputError(f"{display(final)}: cannot be written ({exc.strerror})") from None
        self.files.append((temp, final))
        return temp

    def remove(self, final):
        """Remove ``final`` at the commit, if it exists (restored on a rollback)."""
        self.removals.append(Path(final))

    def join(self, participant):
        """Commit ``participant`` with the files. It has ``prepare(token)``, which locks and
        returns the path of a JSON file whose ``txn`` will be ``token`` once committed,
        ``commit()`` and ``release()``; see :class:`airgun_xl.archive.PendingEntry`."""
        self.participant = participant

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if not self.committed:
            self.abort()
        return False

    def abort(self):
        """Drop every temp file and the participant's scratch work."""
        for temp, _ in self.files:
            with contextlib.suppress(OSError):
                os.unlink(temp)
        if self.participant is not None:
            self.participant.release()

    def commit(self):
        """Publish every staged file and commit the participant, or none of it.

        Raises
        ------
        OutputError
            When an output exists (created meanwhile by another command, or without force) or
            cannot be published; nothing is left changed.
        """
        if not self.files:
            raise ValueError("nothing staged")
        try:
            self._commit()
        except OSError as exc:  # a full disk while the journal is written (23.15): one line
            raise OutputError(f"{display(self.files[0][1])}: cannot be published "
                              f"({exc.strerror or exc}); nothing was changed") from None

    def _commit(self):
        folder = self.files[0][1].parent
        for temp, _ in self.files:
            fsync(temp)
        stage("publishing")
        with folder_lock(folder), signals_held():
            if SIGNALS["pending"] is not None:  # swallowed earlier: stop before publishing
                signum, SIGNALS["pending"] = SIGNALS["pending"], None
                raise Interrupted(signum)
            recover(folder)
            record = self._record()
            journal = self._name(self.files[0][1], "journal")
            try:
                if self.participant is not None:
                    marker = self.participant.prepare(self.token)
                    record["marker"] = {"path": str(marker), "token": self.token}
                with open(journal, "x") as fh:
                    json.dump(record, fh)
                    fh.flush()
                    os.fsync(fh.fileno())
                fsync(folder, directory=True)
                for temp, final in self.files:
                    self._publish(temp, final)
                for final in self.removals:
                    if os.path.lexists(final):
                        os.rename(final, self._name(final, "bak"))
                if self.participant is not None:
                    self.participant.commit()
            except BaseException:
                _roll_back(folder, record)
                with contextlib.suppress(OSError):
                    os.unlink(journal)
                if self.participant is not None:
                    self.participant.release()
                raise
            os.unlink(journal)  # the commit point
            fsync(folder, directory=True)
            self.committed = True
            stage("published")
            _clean(folder, record)
            SIGNALS["held"] += 1  # done: a signal from now on no longer stops the command
            SIGNALS["committed"] = True

    def _record(self):
        files = []
        for temp, final in self.files:
            st = os.stat(temp)
            files.append({"final": final.name, "inode": [st.st_dev, st.st_ino]})
        return {"token": self.token, "files": files,
                "removals": [f.name for f in self.removals]}

    def _publish(self, temp, final):
        if os.path.lexists(final):
            if not self.force:
                raise self._exists_error(final)
            os.rename(final, self._name(final, "bak"))  # a symlink itself, never its target
        try:
            os.link(temp, final)  # fails if the name exists: exactly one writer wins
        except FileExistsError:
            raise self._exists_error(final) from None
        except OSError as exc:
            if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EMLINK):
                raise OutputError(f"{display(final)}: cannot be written "
                                  f"({exc.strerror})") from None
            # no hard links here (e.g. FAT): claim the name, then move the temp onto it
            try:
                os.close(os.open(final, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
            except FileExistsError:
                raise self._exists_error(final) from None
            os.replace(temp, final)


def _owned(folder, final, token, kind):
    """The name of a publication's temp, backup or journal beside ``final`` (see _OWNED)."""
    return folder / f".{final}.{token}.{SUFFIX}-{kind}"


def _names(folder, record, final, kind):
    return _owned(folder, final, record["token"], kind)


def _roll_back(folder, record):
    """Undo a publication: our inodes leave the final names, backups come back."""
    for f in reversed(record["files"]):
        final = folder / f["final"]
        with contextlib.suppress(OSError):
            st = os.lstat(final)
            if [st.st_dev, st.st_ino] == f["inode"]:
                os.unlink(final)
        backup = _names(folder, record, f["final"], "bak")
        if os.path.lexists(backup) and not os.path.lexists(final):
            with contextlib.suppress(OSError):
                os.rename(backup, final)
        with contextlib.suppress(OSError):
            os.unlink(_names(folder, record, f["final"], "tmp"))
    for name in record["removals"]:
        backup = _names(folder, record, name, "bak")
        if os.path.lexists(backup) and not os.path.lexists(folder / name):
            with contextlib.suppress(OSError):
                os.rename(backup, folder / name)


def _clean(folder, record):
    """After the commit: the temps (now extra links) and the backups go."""
    for name in [f["final"] for f in record["files"]] + record["removals"]:
        for kind in ("tmp", "bak"):
            with contextlib.suppress(OSError):
                os.unlink(_names(folder, record, name, kind))


def _committed(record):
    marker = record.get("marker")
    if not marker:
        return False
    try:
        with open(marker["path"]) as fh:
            return json.load(fh).get("txn") == marker["token"]
    except (OSError, ValueError, AttributeError):
        return False


def _valid(record, token):
    names = [f.get("final") for f in record.get("files", [])] + record.get("removals", [])
    return record.get("token") == token and all(
        isinstance(n, str) and n and "/" not in n and n not in (".", "..") for n in names)


def recover(folder):
    """Finish what killed publishers left in ``folder``: roll their journals back (or forward
    when their participant committed), then remove their temps and backups."""
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    matches = [(e, _OWNED.match(e.name)) for e in entries]
    owned = [(e, m) for e, m in matches if m is not None and not owner_alive(m["owner"])]
    for entry, m in owned:
        if m["kind"] != "journal":
            continue
        token = f"{m['owner']}-{m['hex']}"
        try:
            with open(entry.path) as fh:
                record = json.load(fh)
        except (OSError, ValueError):
            record = None
        if isinstance(record, dict) and _valid(record, token):
            if _committed(record):
                _clean(Path(folder), record)
            else:
                _roll_back(Path(folder), record)
        with contextlib.suppress(OSError):
            os.unlink(entry.path)
    for entry, m in owned:
        if m["kind"] in ("tmp", "bak"):
            with contextlib.suppress(OSError):
                if entry.is_file(follow_symlinks=False) or entry.is_symlink():
                    os.unlink(entry.path)


def for_file(pub, final, force=False, force_word="--force"):
    """The publication ``final`` is staged in: ``pub`` when ``final`` shares its folder (the
    two published together), else a new one for ``final``'s folder, to be committed after
    ``pub`` by :func:`commit_after` (each file whole; a failure between them is said)."""
    if not pub.files or same_folder(final, pub.files[0][1]):
        return pub
    return Publication(force, force_word)


def commit_after(pub, later):
    """Commit ``later`` (from :func:`for_file`) once ``pub`` is committed; when it cannot be
    published, the error says that ``pub``'s files were."""
    if later is pub:
        return
    with later:
        try:
            later.commit()
        except OutputError as exc:
            written = ", ".join(display(final) for _temp, final in pub.files)
            raise OutputError(f"{exc}; {written} was written") from None


@contextlib.contextmanager
def atomic_path(path, force=False, force_word="--force"):
    """Yield a temp path for ``path``; publish it on success (see :class:`Publication`)."""
    with Publication(force, force_word) as pub:
        temp = pub.stage(path)
        yield temp
        pub.commit()
