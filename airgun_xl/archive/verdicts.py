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


#: Spans of the record a verdict keeps for a drawing (each keeps its smallest and largest
#: sample): at most twice this many points, about 100 kB of JSON.
TRACE_SPANS = 2000


def _short(value):
    """A number to 6 significant digits for a drawing; None (a gap) where not finite."""
    value = float(value)
    return float(f"{value:.6g}") if value == value and abs(value) != float("inf") else None


def judged_trace(verdict, spans=TRACE_SPANS):
    """The record a verdict judged, kept for a drawing (``serve``'s shot page): a min/max
    envelope (the record cut into ``spans`` spans of time, each keeping its smallest and
    largest sample, in time order, so no peak is lost to the thinning), time [ms] and
    acceleration [kG], with the corridor's limits at those times where one was judged (None
    outside its window) and the ideal pulse's start [ms]; None when the verdict holds no
    record."""
    import numpy as np

    if verdict.record is None:
        return None
    time, kg = (np.asarray(a, dtype=float) for a in verdict.record)
    if len(time) > 2 * spans:
        edges = np.linspace(0, len(time), spans + 1).astype(int)
        keep = []
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            part = kg[lo:hi]
            if not len(part) or not np.isfinite(part).any():
                continue
            low, high = lo + int(np.nanargmin(part)), lo + int(np.nanargmax(part))
            keep += sorted({low, high})
        index = np.array(keep, dtype=int)
    else:
        index = np.arange(len(time))
    t, a = time[index], kg[index]
    trace = {"time_ms": [_short(x * 1e3) for x in t], "kg": [_short(x) for x in a],
             "upper_kg": None, "lower_kg": None,
             "onset_ms": None if verdict.onset is None else _short(verdict.onset * 1e3),
             "samples": int(len(time)),
             "thinned": "whole" if len(index) == len(time) else
             f"the smallest and largest sample of each of {spans:,} spans"}
    spec = verdict.spec
    if spec.corridor is not None and verdict.onset is not None and verdict.window:
        from ..studies.acceptance import corridor_limits

        upper, lower = corridor_limits(spec, t - verdict.onset)
        inside = (t >= verdict.window[0]) & (t <= verdict.window[1])
        trace["upper_kg"] = [_short(u) if k else None for u, k in zip(upper, inside,
                                                                         strict=True)]
        trace["lower_kg"] = [_short(v) if k else None for v, k in zip(lower, inside,
                                                                         strict=True)]
    return trace


def verdict_record(verdict, shot, recording, report, command=(), lot=None):
    """The JSON record of a verdict (``lot``: the lot its shot belongs to, ``next``'s)."""
    data = Path(str(recording).partition(":")[0])
    try:
        digest = hashlib.sha256(data.read_bytes()).hexdigest() if data.is_file() else None
    except OSError:
        digest = None
    return {"shot": shot_name(shot),
            "shot_sha256": shot.source.sha256 if shot.source is not None else None,
            "verdict": verdict.word,
            "criteria": [{k: _plain(v) for k, v in dataclasses.asdict(c).items()}
                         for c in verdict.criteria],
            "tolerances": verdict.tolerances(), "definitions": verdict.definitions,
            "specification": verdict.spec.source, "notes": list(verdict.spec.notes),
            "warnings": list(verdict.warnings), "recording": str(recording),
            "recording_read": dict(verdict.quality.block(
                verdict.spec.duration.nominal if verdict.spec.duration else None))
            if verdict.quality is not None else None,
            "recording_sha256": digest, "report": str(report),
            "trace": judged_trace(verdict),
            "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "command": list(command), "test": dict(verdict.test),
            **({"lot": str(lot)} if lot is not None else {})}


def store_verdict(root, shot, verdict, recording, report, command=(), lot=None):
    """Keep the verdict in the archive at ``root`` (made if new; with ``lot``, in a folder of
    the lot's, ``LOT.SHOT``); return a
    :class:`StoredVerdict`, which :meth:`StoredVerdict.take_back` undoes. Call it with signals
    held (:func:`~airgun_xl.transaction.signals_held`) and assign its result inside that
    section: a signal then arrives once the record and the archive are whole, and the
    caller takes them back."""
    record = verdict_record(verdict, shot, recording, report, command, lot)
    archive = Archive(root, create=True)
    # a lot's shots are the lot's: the same file name in two lots is two shots
    name = shot_name(shot) if lot is None else f"{lot}.{shot_name(shot)}"
    folder = Path(root) / VERDICTS / safe_name(name)
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
    """Every stored verdict: ``[{"shot", "version", "verdict", "created", "recording",
    "shot_sha256", "folder", "lot"}]`` (``shot_sha256``: the judged workbook's, None in a
    record from before it was kept; ``folder``: the record's folder, its shot's archive
    name, ``LOT.SHOT`` for a lot's; ``lot``: None for a verdict of no lot's)."""
    out: list[dict] = []
    for folder, version, path in all_versions(Path(root) / VERDICTS):
        try:
            record = read_record(root, path, "verdict")
            digest = record.get("shot_sha256")
            out.append({"shot": record["shot"], "version": version,
                        "verdict": record["verdict"], "created": record.get("created", ""),
                        "recording": record.get("recording", ""),
                        "shot_sha256": digest if isinstance(digest, str) else None,
                        "folder": folder.name,
                        "lot": record["lot"] if isinstance(record.get("lot"), str) else None})
        except ArchiveError as exc:  # listed and named, not fatal (as a law)
            out.append({"shot": folder.name, "version": version, "verdict": "?",
                        "created": f"unreadable: {exc}", "recording": display(path),
                        "shot_sha256": None, "folder": folder.name, "lot": None})
    return out
