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


def store_proposal(root, lot, record):
    """Keep ``record`` as the lot's next proposal; return a
    :class:`~airgun_xl.archive.verdicts.StoredVerdict` (its ``take_back`` undoes it)."""
    with signals_held():
        archive = Archive(root, create=True)
        folder = _folder(root, lot)
        version = archive.keep(folder, record, "the proposal")
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


def gun_launches(root, lot, gun):
    """The launch velocities fitted for the gun ``gun`` in the lot's latest proposal naming
    it (``next --gun``): ``[{"shot_sha256", "recording_sha256", "speed_m_s", "factor",
    "error"}]`` (the record's schema checked; an error null is NaN), or ``[]``.

    Raises
    ------
    ArchiveError
        A record that cannot be read (named).
    """
    for _version, path in reversed(versions(_folder(root, lot))):
        record = read_record(root, path, "proposal")
        if isinstance(record, dict) and record.get("gun_name") == gun:
            return [{**entry, "error": float("nan") if entry["error"] is None
                     else entry["error"]} for entry in record.get("launch") or []]
    return []


def lot_names(root):
    """The lots with a chain in the archive at ``root``."""
    base = Path(root) / LOTS
    if not base.is_dir() or base.is_symlink():
        return []
    return sorted(p.name for p in base.iterdir() if p.is_dir() and not p.is_symlink())
