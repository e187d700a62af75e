"""The archive as the view lists it: every entry's row, read once and kept while nothing changed.

An entry is written once and never rewritten (``archive verify`` finds one altered since), so
its row, read from its summary, provenance and inputs, is kept by the server for as long as the
index holds the same row for it. What is read afresh:

- the index's rows, when its :meth:`stamp` has changed (a new entry) or :data:`FRESH` seconds
  have passed;
- the verdicts, laws and lots' records, on the same terms (their folders' times are part of the
  stamp);
- a shot's page, every time: its entry checked whole as ``show`` checks it.

The first listing reads every entry (about 0.5 ms each); the server starts it in the background
as soon as it is built (:meth:`Listing.warm`), so the shots page is ready when the browser is.
"""
from __future__ import annotations

import dataclasses
import math
import os
import re
import threading
import time
from pathlib import Path
from typing import Any

#: How long a listing is kept before the index is read again even if its stamp is unchanged [s].
FRESH = 30.0

#: A crush law from the archive's library, as an entry's provenance names it.
_LIBRARY_LAW = re.compile(r"^fitted \(((.+)@(\d{1,9}))\)$")

#: The summary.json figures a scatter may draw: (key, words, unit, factor from SI).
FIGURES = (("peak_kg", "peak", "kG", 1.0), ("filtered_peak_kg", "filtered peak", "kG", 1.0),
           ("time_of_peak", "time of peak", "ms", 1e3),
           ("pulse_duration", "pulse duration", "ms", 1e3),
           ("max_crush", "maximum crush", "m", 1.0),
           ("final_length", "final mitigator length", "m", 1.0),
           ("obr_exit_velocity", "OBR exit velocity", "m/s", 1.0),
           ("mem_final_velocity", "MEM final velocity", "m/s", 1.0),
           ("warning_count", "warnings", "", 1.0))


def read_only(root: str | Path) -> Any:
    """The archive at ``root``, its index opened read-only: SQLite's ``mode=ro``, or every
    transaction on the server read-only."""
    from ..archive import Archive
    from ..archive.index import SqliteIndex

    found = Archive(root)
    if isinstance(found.index, SqliteIndex):
        found.index = SqliteIndex(found.root, read_only=True)
    else:
        found.index.read_only = True
    return found


@dataclasses.dataclass(frozen=True)
class Snapshot:
    """The archive as read at one moment.

    Attributes
    ----------
    index_rows : list of dict
        The index's rows as checked (:func:`airgun_xl.archive.index.checked_row`).
    entries : dict
        Each listed entry by its id.
    rows : list of dict
        One row an entry, in the index's order: its ``history`` row, with ``lot`` and ``law``
        (the library law it ran, if any), ``predicted`` (its predicted verdict's word),
        ``verdict`` (its shot's latest recorded verdict), ``inputs`` (cell -> number) and
        ``figures`` (key -> number, SI).
    bad : list of str
        The index's rows left out, each as its one-line message.
    lots : list of str
        The lots named by the entries' laws or by a chain.
    verdicts : dict
        Each shot's recorded verdicts (``list_verdicts``' rows), by the shot's archive name
        (:meth:`verdicts_of` gives an entry's own).
    """

    index_rows: list[dict[str, Any]]
    entries: dict[int, Any]
    rows: list[dict[str, Any]]
    bad: list[str]
    lots: list[str]
    verdicts: dict[str, list[dict[str, Any]]]

    def verdicts_of(self, entry: Any) -> list[dict[str, Any]]:
        """The verdicts recorded for ``entry``'s run: those of its very workbook (the same
        SHA-256 as the entry's input), and from records that kept no workbook's SHA-256 those
        of its shot's name, each marked ``by_name``. A verdict of another workbook of the
        same name (another version) is not this entry's."""
        digest = entry.row.get("input_sha256")
        return [{**v, "by_name": v["shot_sha256"] is None}
                for v in self.verdicts.get(entry.shot, [])
                if v["shot_sha256"] is None or v["shot_sha256"] == digest]

    def with_inputs(self, cell: str) -> None:
        """Make sure every row holds the input ``cell``, reading params.json where needed."""
        if cell in indexed_cells():
            return
        for r in self.rows:
            with_inputs(r, self.entries[r["id"]])


class Listing:
    """The view's listing of ``archive`` (an open :class:`airgun_xl.archive.Archive`)."""

    def __init__(self, archive: Any) -> None:
        self.archive = archive
        self._lock = threading.Lock()
        self._snapshot: Snapshot | None = None
        self._stamp: Any = None
        self._taken = 0.0
        self._rows: dict[tuple[Any, ...], dict[str, Any]] = {}  # by the index row's key

    def warm(self) -> None:
        """Read the listing in a background thread (a failure is met again on first use)."""
        def run() -> None:
            try:
                self.snapshot()
            except Exception:  # noqa: BLE001, S110 - the request that needs it says why
                pass

        threading.Thread(target=run, name="airgun-xl-listing", daemon=True).start()

    def stamp(self) -> tuple[Any, ...]:
        """What changes when the archive's listing does: the index's stamp, and the times of
        the record folders (a verdict, a law or a proposal is a new file in its folder)."""
        root = Path(self.archive.root)
        folders: list[tuple[str, int | None]] = []
        for hidden in (".verdicts", ".laws", ".lots"):
            base = root / hidden
            try:
                folders.append((hidden, os.stat(base).st_mtime_ns))
                with os.scandir(base) as found:
                    folders += sorted((e.name, e.stat(follow_symlinks=False).st_mtime_ns)
                                      for e in found)
            except OSError:
                folders.append((hidden, None))
        return (self.archive.index.stamp(), tuple(folders))

    def snapshot(self) -> Snapshot:
        """The listing now: kept while :meth:`stamp` is unchanged, for at most :data:`FRESH`
        seconds."""
        with self._lock:
            stamp = self.stamp()
            if (self._snapshot is not None and stamp == self._stamp
                    and time.monotonic() - self._taken < FRESH):
                return self._snapshot
            self._snapshot = self._read()
            self._stamp, self._taken = stamp, time.monotonic()
            return self._snapshot

    def _read(self) -> Snapshot:
        from ..archive.lots import lot_names
        from ..archive.verdicts import list_verdicts

        bad: list[str] = []
        index_rows = self.archive.index.rows(bad=bad)
        verdicts: dict[str, list[dict[str, Any]]] = {}
        for v in list_verdicts(self.archive.root):
            verdicts.setdefault(str(v["folder"]), []).append(v)
        snapshot = Snapshot(index_rows, {}, [], bad, [], verdicts)
        entries, rows, kept = snapshot.entries, snapshot.rows, {}
        for r in index_rows:
            e = self.archive.entry_of(r)
            if e is None:
                bad.append(f"row #{r['id']}: its path {r['path']!r} is not SHOT/vNNNN, "
                           "expected an entry folder of the archive (left out)")
                continue
            key = (r["id"], r["shot"], r["version"], r["path"], r["created"])
            row = self._rows.get(key) or entry_row(e)
            kept[key] = row
            entries[e.id] = e
            stored = snapshot.verdicts_of(e)
            row["verdict"] = str(stored[-1]["verdict"]) if stored else None
            rows.append(row)
        self._rows = kept  # rows of entries gone from the index are dropped
        snapshot.lots.extend(sorted({r["lot"] for r in rows if r["lot"]}
                                    | set(lot_names(self.archive.root))))
        return snapshot


def indexed_cells() -> dict[str, str]:
    """The inputs the index holds: cell -> its column (the rest are read from params.json)."""
    from ..cells import address

    return {address(name): column for name, column in (
        ("v31", "v0"), ("delta", "delta"), ("max_time", "max_time"), ("sigmay", "sigmay"),
        ("rcone", "rcone"))}


def entry_row(e: Any) -> dict[str, Any]:
    """An entry's row (:class:`Snapshot`'s ``rows``) read from its records; an entry whose
    records cannot be read is a row that says so, with no figures. Its ``inputs`` are the
    index's (:func:`indexed_cells`) until :func:`with_inputs` reads the others."""
    from ..app.archive import history_row, history_rows
    from ..errors import ArchiveError

    indexed = {cell: e.row.get(column) for cell, column in indexed_cells().items()
               if _number(e.row.get(column)) is not None}
    try:
        summary = e.load("summary.json")
        provenance = e.load("provenance.json")
    except ArchiveError:  # the listing's own row for it, naming the damage
        return {**history_rows([e])[0], "lot": None, "law": None, "predicted": None,
                "inputs": indexed, "all_inputs": True, "figures": {}}
    row = history_row(e, summary, provenance)
    law = _LIBRARY_LAW.match(str(row["crush_law"]))
    verdict = summary.get("predicted_verdict")
    return {**row, "lot": law.group(2) if law else None, "law": law.group(1) if law else None,
            "predicted": str(verdict.get("verdict")) if isinstance(verdict, dict) else None,
            "inputs": indexed, "all_inputs": False,
            "figures": {k: row.get(k, summary.get(k)) for k, *_ in FIGURES
                        if _number(row.get(k, summary.get(k))) is not None}}


def with_inputs(row: dict[str, Any], entry: Any) -> None:
    """Read the rest of a row's inputs from its entry's params.json (once): a page that
    filters or draws by an input the index does not hold calls it. A params.json that cannot
    be read leaves the row with the index's inputs only."""
    from ..errors import ArchiveError

    if row["all_inputs"]:
        return
    try:
        params = entry.load("params.json")
    except ArchiveError:
        params = []
    row["inputs"] = {**{str(p.get("cell")): p["value"] for p in params
                        if isinstance(p, dict) and _number(p.get("value")) is not None},
                     **row["inputs"]}  # the index's own values stand
    row["all_inputs"] = True


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None
