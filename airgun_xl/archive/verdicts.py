"""Verdicts in the archive: each ``accept --archive DIR`` keeps its verdict (every criterion
with its value, limits and margin, the tolerances used, the warnings, the recording, the
report and the command) as ``.verdicts/<shot>/vNNNN.json`` (:mod:`.records`). ``history``
lists them."""
import dataclasses
import datetime
import hashlib
from pathlib import Path

from ..errors import ArchiveError
from ..transaction import display
from .entry import shot_name
from .records import all_versions, read_record
from .store import Archive, safe_name

VERDICTS = ".verdicts"


def _plain(value):
    if isinstance(value, float) and value != value:
        return None
    if isinstance(value, float) and abs(value) == float("inf"):
        return None
    return value


def verdict_record(verdict, shot, recording, report, command=()):
    """The JSON record of a verdict."""
    data = Path(str(recording).partition(":")[0])
    try:
        digest = hashlib.sha256(data.read_bytes()).hexdigest() if data.is_file() else None
    except OSError:
        digest = None
    return {"shot": shot_name(shot), "verdict": verdict.word,
            "criteria": [{k: _plain(v) for k, v in dataclasses.asdict(c).items()}
                         for c in verdict.criteria],
            "tolerances": verdict.tolerances(), "definitions": verdict.definitions,
            "specification": verdict.spec.source, "notes": list(verdict.spec.notes),
            "warnings": list(verdict.warnings), "recording": str(recording),
            "recording_read": dict(verdict.quality.block(
                verdict.spec.duration.nominal if verdict.spec.duration else None))
            if verdict.quality is not None else None,
            "recording_sha256": digest, "report": str(report),
            "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "command": list(command)}


def store_verdict(root, shot, verdict, recording, report, command=()):
    """Keep the verdict in the archive at ``root`` (made if new); return a
    :class:`StoredVerdict`, which :meth:`StoredVerdict.take_back` undoes. Call it with signals
    held (:func:`~airgun_xl.transaction.signals_held`) and assign its result inside that
    section: a signal then arrives once the record and the archive are whole, and the
    caller takes them back."""
    record = verdict_record(verdict, shot, recording, report, command)
    archive = Archive(root, create=True)
    folder = Path(root) / VERDICTS / safe_name(shot_name(shot))
    version = archive.keep(folder, record, "the verdict")  # a failure takes the archive back
    return StoredVerdict(folder / f"v{version:04d}.json", archive)


@dataclasses.dataclass
class StoredVerdict:
    path: Path
    archive: Archive

    def take_back(self):
        """Remove the record, the folders it made that are left empty, and the archive
        folder itself if this command created it and nothing else is in it."""
        self.path.unlink(missing_ok=True)
        for folder in (self.path.parent, self.path.parent.parent):
            try:
                folder.rmdir()  # only if empty: another verdict stays
            except OSError:
                break
        self.archive.remove_if_unused()


def list_verdicts(root):
    """Every stored verdict: ``[{"shot", "version", "verdict", "created", "recording"}]``."""
    out: list[dict] = []
    for folder, version, path in all_versions(Path(root) / VERDICTS):
        try:
            record = read_record(root, path, "verdict")
            out.append({"shot": record["shot"], "version": version,
                        "verdict": record["verdict"], "created": record.get("created", ""),
                        "recording": record.get("recording", "")})
        except ArchiveError as exc:  # listed and named, not fatal (as a law)
            out.append({"shot": folder.name, "version": version, "verdict": "?",
                        "created": f"unreadable: {exc}", "recording": display(path)})
    return out
