"""A lot's chain in the archive (issue 45): each ``next`` keeps a proposal, the setting it
chose for the lot's next shot with the P(PASS) it predicted before the shot was fired, as
``.lots/<lot>/vNNNN.json`` (:mod:`.records`); the lot's law versions are the library's
(:mod:`.laws`), and the fired shots' verdicts :mod:`.verdicts`'.

A proposal names the shot it came from (its workbook's and recording's SHA-256, so a shot
recorded twice is counted once and a changed file is refused), the verdict of that shot, the
law version it made, and the workbook it wrote (its SHA-256: the shot fired from it is known
by its bytes). ``history --lot`` reads the chain back; what is read is untrusted.
"""
from pathlib import Path

from ..errors import ArchiveError
from ..transaction import display, signals_held
from .records import read_record, versions
from .store import Archive, safe_name
from .verdicts import StoredVerdict

LOTS = ".lots"


def _folder(root, lot):
    return Path(root) / LOTS / safe_name(lot)


def store_proposal(root, lot, record, version=None):
    """Keep ``record`` as the lot's next proposal (exactly ``version``, the one after the
    chain the caller read: :class:`~airgun_xl.archive.records.VersionTaken` if another call
    stored it first); return a :class:`~airgun_xl.archive.verdicts.StoredVerdict` (its
    ``take_back`` undoes it). The proposal is the commit point of ``next``: the law version
    it names is the lot's only once it is stored (:func:`committed`)."""
    with signals_held():
        archive = Archive(root, create=True)
        folder = _folder(root, lot)
        version = archive.keep(folder, record, "the proposal", version)
        stored = StoredVerdict(folder / f"v{version:04d}.json", archive)
    return stored


def proposals(root, lot):
    """The lot's proposals in order: ``[(version, record)]``.

    Raises
    ------
    ArchiveError
        A record that cannot be read (named): the chain is evidence, and a gap in it is not
        passed over.
    """
    out = []
    for version, path in versions(_folder(root, lot)):
        record = read_record(root, path, "proposal")
        if not isinstance(record, dict) or not isinstance(record.get("shots"), list):
            raise ArchiveError(f"{display(path)}: is not a proposal record, expected its "
                               "shots (see airgun-xl archive verify)")
        out.append((version, record))
    return out


def shot_keys(record, root, lot, version):
    """The (workbook, recording) SHA-256 pairs of a proposal's shots, each once.

    Raises
    ------
    ArchiveError
        A shot listed twice, or without its two SHA-256 (the record edited: a shot listed
        eight times counted as eight, and drew the gun's scatter from nothing).
    """
    shown = display(_folder(root, lot) / f"v{version:04d}.json")
    keys = []
    for s in record.get("shots") or []:
        key = (s.get("shot_sha256"), s.get("recording_sha256")) if isinstance(s, dict) \
            else (None, None)
        if not all(isinstance(k, str) and len(k) == 64 for k in key):
            raise ArchiveError(f"{shown}: lists a shot without its files' SHA-256, expected "
                               "each shot's workbook and recording (see airgun-xl archive "
                               "verify)")
        if key in keys:
            raise ArchiveError(f"{shown}: lists the shot {s.get('shot', '?')!s:.80} "
                               f"({s.get('recording', '?')!s:.80}) twice, expected each shot "
                               "once (see airgun-xl archive verify)")
        keys.append(key)
    return keys


def gun_launches(root, lot, gun):
    """The launch velocities fitted for the gun ``gun`` in the lot's latest proposal, when
    it names that gun (``next --gun``; a lot whose latest shot another gun fired is never
    read): ``[{"shot_sha256", "recording_sha256", "speed_m_s", "factor", "error"}]`` (the
    record's schema checked; an error null is NaN), or ``[]``.

    Raises
    ------
    ArchiveError
        A record that cannot be read, or whose launch velocities are not one for each of its
        shots (named).
    """
    found = versions(_folder(root, lot))
    if not found:
        return []
    version, path = found[-1]
    record = read_record(root, path, "proposal")
    if not isinstance(record, dict) or record.get("gun_name") != gun:
        return []
    keys = shot_keys(record, root, lot, version)
    launch = record.get("launch") or []
    pairs = [(e.get("shot_sha256"), e.get("recording_sha256")) if isinstance(e, dict) else e
             for e in launch]
    if len(pairs) != len(keys) or set(pairs) != set(keys):
        raise ArchiveError(f"{display(path)}: holds {len(launch)} launch velocities for its "
                           f"{len(keys)} shots, expected one for each shot (see airgun-xl "
                           "archive verify)")
    return [{**entry, "error": float("nan") if entry["error"] is None
             else entry["error"]} for entry in launch]


def committed(root, name, version, record):
    """Whether the law record ``record``, version ``version`` of ``name``, is part of the
    archive: a law ``next`` stored for its proposal N (``record["proposal"]``) is only once
    the lot's proposal N names it (a ``next`` killed between the two, or refused by another
    call's proposal, left it behind: never the lot's law); any other law is."""
    proposal = record.get("proposal") if isinstance(record, dict) else None
    if proposal is None:
        return True
    if not isinstance(proposal, int) or isinstance(proposal, bool) or proposal < 1:
        return False
    path = _folder(root, name) / f"v{proposal:04d}.json"
    if not path.exists():
        return False
    try:
        kept = read_record(root, path, "proposal")
    except ArchiveError:
        return False
    return isinstance(kept, dict) and kept.get("law") == f"{name}@{version}"


def lot_names(root):
    """The lots with a chain in the archive at ``root``."""
    base = Path(root) / LOTS
    if not base.is_dir() or base.is_symlink():
        return []
    return sorted(p.name for p in base.iterdir() if p.is_dir() and not p.is_symlink())
