"""Versioned JSON records in the archive's hidden folders (crush laws, verdicts): each record
is ``vNNNN.json`` of its folder, written to a temp file and linked to its name, which fails if
another writer took that version first (it then takes the next). So two writers can store at
once and none is ever half-written."""
import json
import os
import re
import uuid
from pathlib import Path

from ..errors import ArchiveError
from ..transaction import display
from ..transaction.stages import stage

_VERSION = re.compile(r"^v(\d{4,})\.json$")


def versions(folder):
    """``[(version, path)]`` of a record folder, oldest first: every name of a version, a
    FIFO, a folder or a link in its place included, so that its reader names what is there
    (and a writer never waits on a version something else holds)."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in folder.iterdir() if (m := _VERSION.match(p.name))]
    return sorted(found)


def all_versions(base):
    """``(folder, version, path)`` of every record under ``base`` (one of the archive's hidden
    folders: ``.laws``, ``.verdicts``), folders by name, versions in order."""
    base = Path(base)
    if not base.is_dir():
        return
    for folder in sorted(p for p in base.iterdir() if p.is_dir() and not p.is_symlink()):
        for version, path in versions(folder):
            yield folder, version, path


def link_below(root, path):
    """The first part of ``path`` below ``root`` that is a link (a symbolic link, or a
    Windows junction), and where it leads: ``(part, target)``; None when there is none.
    ``root`` itself is the folder the user named, trusted as named."""
    root, path = Path(root), Path(path)
    try:
        relative = path.relative_to(root)
    except ValueError:
        return path, "outside the archive"
    part = root
    for name in relative.parts:
        part = part / name
        junction = getattr(os.path, "isjunction", None)  # Python 3.12 and later
        if part.is_symlink() or (junction is not None and junction(part)):
            try:
                target = os.readlink(part)
            except OSError:
                target = "somewhere unreadable"
            return part, str(target)
    return None


def inside(root, path, what):
    """Refuse ``path`` unless it, resolved (every link followed), lies inside the archive at
    ``root`` and no part of it below ``root`` is a link: a planted ``.verdicts``,
    ``.laws/NAME``, shot or entry folder link must not carry a write (or a read) out of the
    archive.

    The check is a resolved-path one: a link swapped in between it and the use is the race a
    writer closes with the directory descriptors of :mod:`airgun_xl.archive.store` where the
    platform has them (``os.supports_dir_fd``).

    Raises
    ------
    ArchiveError
    """
    root, path = Path(root), Path(path)
    try:
        relative = path.relative_to(root)
    except ValueError:
        relative = None
    found = link_below(root, path) if relative is not None else None
    if found is not None:
        part, target = found
        raise ArchiveError(f"{display(part)}: is a link to {display(target)}, expected "
                           f"{what} inside the archive {display(root)} (a link could lead "
                           "out of it; not followed)")
    real_root = root.resolve()
    real = path.resolve()
    if relative is None or not (real == real_root or real_root in real.parents):
        raise ArchiveError(f"{display(path)}: lies outside the archive {display(root)}, "
                           f"expected {what} inside it")


def read_record(root, path, kind):
    """A record of the archive at ``root`` (a law, a verdict), checked to lie inside it and
    read by the bounded reader (:func:`airgun_xl.untrusted_json.read_json`)."""
    from ..untrusted_json import read_json

    inside(root, path, f"the {kind}")
    return read_json(path, kind, display(path), ArchiveError)


class VersionTaken(ArchiveError):
    """The version a writer had to store was taken by another writer first."""


def store_record(folder, record, what, root=None, version=None):
    """Write ``record`` as the next version in ``folder`` (created, inside the archive at
    ``root``: :func:`inside`), or as exactly ``version``; return the version.

    Raises
    ------
    VersionTaken
        ``version`` was given and another writer holds it (the caller read a state that
        has changed since).
    ArchiveError
        Naming the folder and ``what`` could not be written, or lies outside the archive.
    """
    folder = Path(folder)
    if root is not None:
        inside(root, folder, what)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ArchiveError(f"{display(folder)}: cannot be created ({exc.strerror})") from None
    if root is not None:  # made now: a link swapped in meanwhile is caught here
        inside(root, folder, what)
    tmp = folder / f".{uuid.uuid4().hex}.tmp"
    try:
        with open(tmp, "x", encoding="utf-8") as fh:
            json.dump(record, fh, indent=1)
            fh.flush()
            os.fsync(fh.fileno())
        if version is not None:  # this version or none: a compare and swap
            try:
                os.link(tmp, folder / f"v{version:04d}.json")
            except FileExistsError:
                raise VersionTaken(f"{display(folder / f'v{version:04d}.json')}: was "
                                   f"stored by another writer while this one ran, expected "
                                   f"{what} to follow the version it was made from") from None
        else:
            for _ in range(1000):  # a version another writer took first: the next one
                found = versions(folder)
                version = (found[-1][0] if found else 0) + 1
                try:
                    os.link(tmp, folder / f"v{version:04d}.json")
                    break
                except FileExistsError:
                    continue
            else:
                raise ArchiveError(f"{display(folder)}: no free version, expected fewer "
                                   "writers")
        stage("record-stored")
    except OSError as exc:
        raise ArchiveError(f"{display(folder)}: {what} cannot be written "
                           f"({exc.strerror or exc})") from None
    finally:
        tmp.unlink(missing_ok=True)
    return version
