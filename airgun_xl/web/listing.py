"""The archive as the view lists it: every entry's row, read once and kept while nothing changed.

An entry is written once and never rewritten (``archive verify`` finds one altered since), so
its row, read from its summary, provenance and inputs, is kept by the server for as long as the
index holds the same row for it. What is read afresh:

- the index's rows, when its :meth:`stamp` has changed (a new entry) or :data:`FRESH` seconds
  have passed;
- the verdicts, laws and lots' records, on the same terms (their folders' times are part of the
  stamp);
- a shot's page, every time: its entry checked whole as ``show`` checks it.

The first listing reads every entry's summary and provenance (about 0.5 ms each), then every
entry's inputs; the server does both in the background from its start, between requests
(:meth:`Listing.warm`), and a page that needs what is still being read says how far the read
is (503, and a reload each second) instead of waiting.
"""
from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import re
import threading
import time
from collections.abc import Iterator
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


def _now() -> str:
    import datetime

    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")


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
    taken: str = ""  # when it was read: UTC, to the second

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
        self._lock = threading.Lock()  # one reader of the listing at a time
        self._index = threading.Lock()  # the index's connection is one: one user at a time
        self._snapshot: Snapshot | None = None
        self._stamp: Any = None
        self._taken = 0.0
        self._rows: dict[tuple[Any, ...], dict[str, Any]] = {}  # by the index row's key
        #: While a listing is read: (entries read, entries in all); None otherwise.
        self.progress: tuple[int, int] | None = None
        #: While :meth:`warm` reads the inputs the index does not hold: (entries read, in
        #: all); None otherwise.
        self.inputs_progress: tuple[int, int] | None = None
        self._in_flight = 0  # requests being answered: the background read waits for them
        self._counted = threading.Lock()
        self._idle = threading.Event()
        self._idle.set()

    @contextlib.contextmanager
    def request(self) -> Iterator[None]:
        """Around a request's work: while any is answered, the background read of
        :meth:`warm` waits between entries, so a page asked meanwhile has the machine."""
        with self._counted:
            self._in_flight += 1
            self._idle.clear()
        try:
            yield
        finally:
            with self._counted:
                self._in_flight -= 1
                if not self._in_flight:
                    self._idle.set()

    def warm(self) -> None:
        """Read the listing in a background thread, holding the listing's lock from now on
        (a page asked meanwhile says how far the read is), after importing what a shot's page
        reads its history with; a failure is met again on first use."""
        self._lock.acquire()

        def run() -> None:
            snapshot = None
            try:
                import pandas  # noqa: F401 - a shot's page reads its history with them: the
                import pyarrow.parquet  # noqa: F401 - first one need not wait for the imports

                snapshot = self._refresh(background=True)
                self.inputs_progress = (0, len(snapshot.rows))  # before a page can ask
            except Exception:  # noqa: BLE001, S110 - the request that needs it says why
                pass
            finally:
                self.progress = None
                self._lock.release()
            if snapshot is not None:
                self._all_inputs(snapshot)

        threading.Thread(target=run, name="airgun-xl-listing", daemon=True).start()

    def _all_inputs(self, snapshot: Snapshot) -> None:
        """Read every row's inputs the index does not hold, between requests
        (:attr:`inputs_progress` says how far); a page that needs one meanwhile says so."""
        try:
            for k, row in enumerate(snapshot.rows):
                self.inputs_progress = (k, len(snapshot.rows))
                self._idle.wait()
                with_inputs(row, snapshot.entries[row["id"]])
        finally:
            self.inputs_progress = None

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
        with self._index:
            return (self.archive.index.stamp(), tuple(folders))

    def snapshot(self, wait: bool = True) -> Snapshot | None:
        """The listing now: kept while :meth:`stamp` is unchanged, for at most :data:`FRESH`
        seconds. Without ``wait``, while another reads it: the one before (its ``taken`` says
        when), or None before the first (:attr:`progress` says how far)."""
        if not self._lock.acquire(blocking=wait):
            return self._snapshot
        try:
            return self._refresh()
        finally:
            self.progress = None
            self._lock.release()

    def _refresh(self, background: bool = False) -> Snapshot:
        """The listing, read again if :meth:`stamp` changed or it is :data:`FRESH` seconds
        old; the caller holds the lock. ``background``: read between requests only
        (:meth:`request`)."""
        stamp = self.stamp()
        if (self._snapshot is not None and stamp == self._stamp
                and time.monotonic() - self._taken < FRESH):
            return self._snapshot
        self._snapshot = self._read(background)
        self._stamp, self._taken = stamp, time.monotonic()
        return self._snapshot

    def one(self, ident: int) -> Snapshot:
        """A listing of the entry ``ident`` alone (no entry's records read): the index's rows,
        the entry, and the verdicts, for a shot's page while the whole listing is read."""
        from ..archive.verdicts import list_verdicts

        with self._index:
            index_rows = self.archive.index.rows(bad=[])
        found = [e for e in (self.archive.entry_of(r) for r in index_rows if r["id"] == ident)
                 if e is not None]
        verdicts: dict[str, list[dict[str, Any]]] = {}
        for v in list_verdicts(self.archive.root):
            verdicts.setdefault(_verdict_key(v), []).append(v)
        return Snapshot(index_rows, {e.id: e for e in found}, [], [], [], verdicts, _now())

    def _read(self, background: bool = False) -> Snapshot:
        from ..archive.lots import lot_names
        from ..archive.verdicts import list_verdicts

        bad: list[str] = []
        with self._index:
            index_rows = self.archive.index.rows(bad=bad)
        self.progress = (0, len(index_rows))
        verdicts: dict[str, list[dict[str, Any]]] = {}
        for v in list_verdicts(self.archive.root):
            verdicts.setdefault(_verdict_key(v), []).append(v)
        snapshot = Snapshot(index_rows, {}, [], bad, [], verdicts, _now())
        entries, rows, kept = snapshot.entries, snapshot.rows, {}
        for k, r in enumerate(index_rows):
            self.progress = (k, len(index_rows))
            if background:
                self._idle.wait()
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


def _verdict_key(verdict: dict[str, Any]) -> str:
    """The shot's archive name a verdict is listed under: its folder, or for a lot's verdict
    (kept in ``LOT.SHOT``) its shot's own name (its workbook's SHA-256 then tells the lot's
    shot from another lot's of the same name)."""
    from ..archive.store import safe_name

    return str(verdict["folder"]) if verdict.get("lot") is None else safe_name(
        str(verdict["shot"]))
