"""The archive's commands: ``history``, ``show``, ``compare`` and ``archive
init|migrate|verify``; and where a command's archive is (:func:`archive_root`).

Each is a typed function on a frozen request, returning a frozen outcome that holds the
records read (for ``--json``) and the lines the command prints. Whatever an entry's records
hold is untrusted: the lines are made printable by the CLI, a listing names a record it
cannot read and goes on, and ``show`` and ``compare`` refuse an entry ``verify`` would
report. Light at import (the standard library and the archive's store), as the CLI's
parser imports it.
"""
from __future__ import annotations

import dataclasses
import datetime
import math
import os
import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..archive import Archive, Entry, archive_dir
from ..archive.index import INDEX_ENV, ROLE_NAME
from ..archive.store import prestart_index
from ..cells import BY_ADDRESS
from ..errors import ArchiveError, OptionError
from ..transaction import check_output, display
from . import declared
from .diff import ATOL_HELP, DEFAULT_RTOL, RTOL_HELP, a_tolerance

if TYPE_CHECKING:
    from .diff import DiffReport

#: A listing's row: an entry's index row, its figures and its provenance (the campaign
#: table's columns).
Row = dict[str, Any]


def archive_root(given: str | None) -> str | None:
    """The archive a command was given (``--archive``), else ``$AIRGUN_XL_ARCHIVE``, else
    None."""
    root = archive_dir(given, required=False)
    return str(root) if root else None


def prestart(root: str | None) -> None:
    """Start a server index's agent now, so that psycopg loads while the command goes on."""
    prestart_index(root)


def is_role(text: str) -> bool:
    """Whether ``text`` is a PostgreSQL role name ``--writers`` takes (a plain identifier)."""
    return re.fullmatch(ROLE_NAME, str(text)) is not None


def _count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


# -- history -----------------------------------------------------------------------------

Where = tuple[str, float, float]


def parse_where(text: str, who: str = "where") -> Where:
    """``E40=2.703e7`` -> ("E40", 2.703e7, 2.703e7); ``E40=2.6e7:2.8e7`` -> a range; a
    refusal names ``who``."""
    cell, _, value = str(text).partition("=")
    cell = cell.strip().upper()
    lo = hi = math.nan
    try:
        first, _, second = value.partition(":")
        lo, hi = float(first), float(second) if second.strip() else float(first)
        ok = math.isfinite(lo) and math.isfinite(hi) and lo <= hi
    except ValueError:
        ok = False
    if cell not in BY_ADDRESS or not ok:
        raise OptionError(f"{who}: found {text!r}, expected CELL=VALUE or CELL=LO:HI with "
                          "a parameter cell, e.g. E40=2.703e7 or A28=200:250")
    return cell, lo, hi


def _matches(params: Iterable[dict[str, Any]], where: Sequence[Where]) -> bool:
    values = {p["cell"]: p["value"] for p in params}
    for cell, lo, hi in where:
        v = values.get(cell)
        if not isinstance(v, (int, float)):
            return False
        if lo == hi:
            if abs(v - lo) > 1e-9 * max(abs(lo), 1e-300):
                return False
        elif not lo <= v <= hi:
            return False
    return True


def history_rows(entries: Iterable[Entry], where: Sequence[Where] = ()) -> list[Row]:
    """The campaign-table row of each entry (its summary.json figures and provenance) that
    ``where`` selects."""
    rows = []
    folders: dict[Path, int] = {}
    for e in entries:
        misnamed = _misnamed(e, folders)
        if misnamed:  # a row of the index that names another entry's folder: flagged
            rows.append(_unreadable_row(e, ArchiveError(misnamed)))
            continue
        try:
            if where and not _matches(e.load("params.json"), where):
                continue
            s = e.load("summary.json")
            prov = e.load("provenance.json")
        except ArchiveError as exc:  # a listing flags a bad record, names it, and goes on
            rows.append(_unreadable_row(e, exc))
            continue
        rows.append(history_row(e, s, prov))
    return rows


def _misnamed(e: Entry, folders: dict[Path, int]) -> str:
    """Why an index row cannot be listed as the entry it says (its folder is another
    entry's, or a folder an earlier row named), or ''; ``folders`` holds the rows seen."""
    named = (e.path.parent.name, int(e.path.name[1:]))
    folder = f"{named[0]}/{e.path.name}"
    if named != (e.shot, e.version):
        return (f"row #{e.id}: it says {e.ref}, but its folder {folder} is "
                f"{named[0]}@{named[1]}'s (see airgun-xl archive verify)")
    if e.path in folders:
        return (f"row #{e.id}: names the folder of row #{folders[e.path]} ({folder}): two "
                "rows on one folder (see airgun-xl archive verify)")
    folders[e.path] = e.id
    return ""


def history_row(e: Entry, s: dict[str, Any], prov: dict[str, Any]) -> Row:
    """An entry's campaign-table row from its summary.json (``s``) and provenance.json."""
    law = prov.get("crush_law")
    warnings = s.get("warnings")
    return {
        **dict(e.row), "ref": e.ref, "file": e.ref, "created": e.created, "v0": e.row["v0"],
        "peak_kg": s.get("peak_kg"), "filtered_peak_kg": s.get("filtered_peak_kg"),
        "time_of_peak": s.get("time_of_peak"), "pulse_duration": s.get("pulse_duration"),
        "max_crush": s.get("max_crush"), "final_length": s.get("final_length"),
        "warnings": [f"{w}" for w in warnings or []],
        "warning_count": len(warnings) if warnings is not None else None,
        "integrator": f"{prov.get('integrator')}/{prov.get('model')}",
        "crush_law": law["name"] if isinstance(law, dict) else "not recorded"}


def _unreadable_row(e: Entry, exc: Exception) -> Row:
    """An entry whose records cannot be read, as a row of the listing: no figures, and why."""
    figures = ("peak_kg", "filtered_peak_kg", "time_of_peak", "pulse_duration", "max_crush",
               "final_length", "warning_count")
    return {**dict(e.row), "ref": e.ref, "file": e.ref, "created": e.created,
            "v0": e.row["v0"], **{k: None for k in figures},
            "warnings": [f"unreadable: {exc}"], "integrator": "unreadable",
            "crush_law": f"unreadable: {exc}"}


def a_date_or_none(value: Any, who: str) -> str | None:
    """An ISO date (``"2026-11-01"``, or a time on it; a :class:`datetime.date` is its ISO
    text), or None."""
    if value is None:
        return None
    if isinstance(value, datetime.date):
        return value.isoformat()
    try:
        datetime.date.fromisoformat(str(value)[:10])
        ok = isinstance(value, str)
    except ValueError:
        ok = False
    if not ok:
        raise OptionError(f"{who}: found {value!r}, expected a date such as 2026-11-01")
    return str(value)


def some_wheres(value: Any, who: str) -> tuple[str, ...]:
    """Selections by input cell, ``CELL=VALUE`` or ``CELL=LO:HI`` each (a text, or a list of
    them), each checked (:func:`parse_where`)."""
    found = declared.texts(value, who)
    for text in found:
        parse_where(text, who)
    return found


@dataclasses.dataclass(frozen=True, kw_only=True)
class HistoryRequest(declared.Checked):
    """``history``: the archive's runs (``archive`` None: $AIRGUN_XL_ARCHIVE), filtered;
    ``output`` also writes their table. Declared once (:mod:`.declared`): the command's
    options and the API's keywords."""

    archive: str | None = declared.the_archive()
    shot: str | None = declared.option(None, "--shot", metavar="NAME",
                                       read=declared.a_text_or_none,
                                       help="only this shot's runs")
    since: str | None = declared.option(
        None, "--since", metavar="DATE", read=a_date_or_none,
        help="only runs from this ISO date on, e.g. 2026-11-01")
    where: tuple[str, ...] = declared.option(
        (), "--where", kind="repeated", metavar="CELL=VALUE", read=some_wheres,
        help="only runs whose input cell holds VALUE (to 1e-9 of it) or lies in LO:HI, e.g. "
             "E40=2.703e7 or E40=2.6e7:2.8e7 (a honeycomb lot); may be repeated")
    output: str | None = declared.option(
        None, "-o", "--output", metavar="SHOTS.xlsx", read=declared.a_folder_or_none,
        help="also write the table across the runs, with the peak against v0")
    force: bool = declared.force("SHOTS.xlsx")


@dataclasses.dataclass(frozen=True)
class HistoryOutcome:
    """The runs' rows, the archive's laws and verdicts, and the lines ``history`` prints."""

    archive: Path
    rows: tuple[Row, ...]
    total: int  # entries before --where
    laws: tuple[dict[str, Any], ...]
    verdicts: tuple[dict[str, Any], ...]
    files: tuple[Path, ...]
    lines: tuple[str, ...]
    wrote: str | None  # the line saying the table was written


def _cell(value: Any, fmt: str, width: int) -> str:
    return f"{'n/a':>{width}}" if value is None else f"{value:>{width}{fmt}}"


def history(request: HistoryRequest) -> HistoryOutcome:
    """List the archive's runs (``airgun-xl history``)."""
    where = [parse_where(w) for w in request.where]
    if request.output:
        check_output(request.output, request.force)  # before reading the entries
    archive = Archive(archive_dir(request.archive))
    entries = archive.entries(request.shot, request.since)
    rows = history_rows(entries, where)
    from ..archive.laws import list_laws
    from ..archive.verdicts import list_verdicts

    laws, verdicts = list_laws(archive.root), list_verdicts(archive.root)
    lines = _history_lines(rows, len(entries) if where else None, laws, verdicts)
    files: tuple[Path, ...] = ()
    wrote = None
    if request.output:
        from ..reports.campaign import HISTORY_TABLE, write_campaign

        title = f"History of {display(archive.root)}: {len(rows)} runs"
        if where:
            title += " where " + ", ".join(request.where)
        write_campaign(request.output, rows, title, request.force, HISTORY_TABLE,
                       label=display(archive.root.name))
        files, wrote = (Path(request.output),), \
            f"wrote {request.output}: one row a run, the peak against v0"
    return HistoryOutcome(archive.root, tuple(rows), len(entries), tuple(laws),
                          tuple(verdicts), files, tuple(lines), wrote)


def _history_lines(rows: list[Row], total: int | None, laws: list[dict[str, Any]],
                   verdicts: list[dict[str, Any]]) -> list[str]:
    """The listing: a line a run, the count (of ``total`` when filtered), the laws, the
    verdicts."""
    lines = [f"{'entry':<24} {'created (UTC)':<26} {'v0 m/s':>8} {'peak kG':>9} "
             f"{'filt. kG':>9} {'pulse ms':>9} {'crush m':>8} {'warn':>4}  integrator, "
             "crush law"]
    for r in rows:
        ms = {k: None if r[k] is None else r[k] * 1e3 for k in ("pulse_duration", "time_of_peak")}
        lines.append(
            f"{r['file']:<24} {r['created']:<26} {_cell(r['v0'], '.2f', 8)} "
            f"{_cell(r['peak_kg'], '.4f', 9)} {_cell(r['filtered_peak_kg'], '.4f', 9)} "
            f"{_cell(ms['pulse_duration'], '.4f', 9)} {_cell(r['max_crush'], '.4f', 8)} "
            f"{_cell(r['warning_count'], 'd', 4)}  {r['integrator']}, {r['crush_law']}")
    lines.append(f"{len(rows)} entr{'y' if len(rows) == 1 else 'ies'}"
                 + (f" of {total} (--where)" if total is not None else ""))
    if laws:
        from ..crush_law import speeds_text  # numpy: not on the parser's path

        lines.append("crush laws:")
        for law in laws:
            span = ("unreadable" if law["v_range"] is None else
                    f"holds at {speeds_text(law['v_range'])}")
            lines.append(f"  {law['ref']:<30} {span}, fitted on {law['shots']} shot"
                         f"{'s' * (law['shots'] != 1)}, {law['created']}")
    if verdicts:
        lines.append("verdicts (accept --archive):")
        lines += [f"  {v['shot']}@{v['version']:<6} {v['verdict']:<5} {v['created']}  "
                  f"{v['recording']}" for v in verdicts]
    return lines


# -- show --------------------------------------------------------------------------------

#: How ``show`` prints a figure of summary.json: its words (the Summary sheet's), unit,
#: factor from SI, digits after the point. ``--json`` gives the record's own keys, in SI.
FIGURE_UNITS = {
    "peak_kg": ("Peak acceleration (raw)", "kG", 1.0, 5),
    "time_of_peak": ("Time of peak", "ms", 1e3, 4),
    "filtered_peak_kg": ("Peak acceleration (filtered)", "kG", 1.0, 5),
    "time_of_filtered_peak": ("Time of filtered peak", "ms", 1e3, 4),
    "pulse_start": ("Pulse start", "ms", 1e3, 4), "pulse_end": ("Pulse end", "ms", 1e3, 4),
    "pulse_duration": ("Pulse duration", "ms", 1e3, 4),
    "max_crush": ("Maximum crush", "m", 1.0, 4),
    "final_length": ("Final mitigator length", "m", 1.0, 4),
    "final_m1": ("Final M1", "kg", 1.0, 4), "final_m31": ("Final m31", "kg", 1.0, 4),
    "obr_exit_velocity": ("OBR exit velocity", "m/s", 1.0, 3),
    "mem_final_velocity": ("MEM final velocity", "m/s", 1.0, 3),
    "natural_initial": ("Natural frequencies (initial masses)", "kHz", 1e-3, 3),
    "natural_final": ("Natural frequencies (final masses)", "kHz", 1e-3, 3),
    "dominant_frequencies_hz": ("Dominant frequencies", "kHz", 1e-3, 3),
    "rows": ("Rows", "", 1.0, 0),
}


def shown_figure(key: str, value: Any) -> tuple[str, str]:
    """A summary.json figure in words with its unit: ``("Time of peak", "0.2885 ms")``,
    ``("Dominant frequencies", "5.333, 4.833 kHz")``, ``n/a`` where a value is missing; a key
    the table does not know (a record from another version) as it is written."""
    label, unit, factor, digits = FIGURE_UNITS.get(key, (key, "", 1.0, None))
    values = value if isinstance(value, list) else [value]
    if digits is None or not all(isinstance(v, (int, float)) or v is None for v in values):
        return label, str(value)
    text = ", ".join("n/a" if v is None else f"{v * factor:,.{digits}f}" for v in values)
    return label, f"{text} {unit}".rstrip() if values else "none"


@dataclasses.dataclass(frozen=True)
class ShowOutcome:
    """One archived run: its records as read (``doc``, for ``--json``) and the lines
    ``show`` prints."""

    doc: dict[str, Any]
    lines: tuple[str, ...]


def an_entry(value: Any, who: str) -> str:
    """An archived run's name: ``SHOT``, ``SHOT@VERSION`` or ``#ID`` (found in the archive
    where it is read)."""
    if not isinstance(value, str) or not value.strip():
        found = "an empty name" if value == "" else repr(value)
        raise OptionError(f"{who}: found {found}, expected SHOT, SHOT@VERSION or #ID")
    return value


@dataclasses.dataclass(frozen=True, kw_only=True)
class ShowRequest(declared.Checked):
    """``show``: one archived run. Declared once (:mod:`.declared`): the command's options and
    the API's keywords."""

    entry: str = declared.positional("entry", metavar="ENTRY", read=an_entry,
                                     help="SHOT (its latest run), SHOT@VERSION or #ID")
    archive: str | None = declared.the_archive()


def show(request: ShowRequest) -> ShowOutcome:
    """One archived run (``airgun-xl show ENTRY``): SHOT, SHOT@VERSION or #ID."""
    return show_entry(Archive(archive_dir(request.archive)), request.entry)


def show_entry(found: Archive, entry: str | Entry,
               rows: list[dict[str, Any]] | None = None) -> ShowOutcome:
    """One run of an archive already open (``serve`` holds one, its index read-only): an
    entry named as ``show`` takes it, or one already found; ``rows``, the index's rows when
    the caller has just read them."""
    # what verify would report is refused
    e = found.checked(found.get(entry) if isinstance(entry, str) else entry, rows)
    doc = {"entry": e.ref, "id": e.id, "path": str(e.path), "created": e.created,
           "params": e.load("params.json"), "summary": e.load("summary.json"),
           "provenance": e.load("provenance.json"), "files": e.manifest()["files"]}
    lines = [f"{e.ref} (#{e.id}), created {e.created}, in {e.path}", "inputs:"]
    lines += [f"  {p['cell']:<4} {p['label']:<32} {p['value']!r:>22} {p['unit']}"
              for p in doc["params"]]
    lines.append("figures:")
    summary = dict(doc["summary"])
    warnings = summary.pop("warnings", None)
    verdict = summary.pop("predicted_verdict", None)
    lines += ["  {:<37} {}".format(*shown_figure(k, v)) for k, v in summary.items()]
    if isinstance(verdict, dict):
        lines += _verdict_lines(verdict)
    if warnings is None:
        lines.append("warnings: not recorded (an entry from before they were kept)")
    else:
        lines.append(f"warnings: {len(warnings) or 'none'}")
        lines += [f"  - {text}" for text in warnings]
    prov = doc["provenance"]
    lines += [f"provenance: airgun-xl {prov['engine']}, {prov['integrator']} integrator, "
              f"{prov['model']} model, started {prov['started']}, {prov['run_seconds']:.2f} s",
              f"  input SHA-256 {prov['input_sha256']}",
              f"  command: {' '.join(prov['command'])}",
              "files: " + ", ".join(doc["files"])]
    return ShowOutcome(doc, tuple(lines))


def _verdict_lines(verdict: dict[str, Any]) -> list[str]:
    """An entry's predicted verdict, a line a criterion."""
    lines = [f"predicted verdict: {verdict.get('verdict')} (specification from "
             f"{verdict.get('specification')})"]
    for c in verdict.get("criteria") or []:
        value = "not measured" if c["value"] is None else f"{c['value']:.6g} {c['unit']}"
        margin = "none" if c["margin"] is None else f"{c['margin']:+.2f} {c['margin_unit']}"
        word = "PASS" if c["passed"] else "NOT JUDGED" if c.get("judged") is False else "FAIL"
        lines.append(f"  {c['name']:<24} {value}, margin {margin}, {word}")
    return lines


# -- compare -----------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True, kw_only=True)
class CompareRequest(declared.Checked):
    """``compare``: two archived runs, inputs first, then every series of their histories,
    each within ``rtol`` [-] of the series' largest magnitude (or ``atol``). Declared once
    (:mod:`.declared`): the command's options and the API's keywords."""

    entry1: str = declared.positional("entry1", metavar="ENTRY1", read=an_entry,
                                      help="SHOT, SHOT@VERSION or #ID")
    entry2: str = declared.positional("entry2", metavar="ENTRY2", read=an_entry,
                                      help="SHOT, SHOT@VERSION or #ID")
    archive: str | None = declared.the_archive()
    rtol: float = declared.option(DEFAULT_RTOL, "--rtol", read=a_tolerance,
                                  help=RTOL_HELP.replace("column", "series"))
    atol: float = declared.option(0.0, "--atol", help=ATOL_HELP, read=a_tolerance)
    report: str | None = declared.option(
        None, "--report", metavar="REPORT.xlsx", read=declared.a_folder_or_none,
        help="also write a workbook: the input cells that differ and the error table")
    force: bool = declared.force("REPORT.xlsx")


@dataclasses.dataclass(frozen=True)
class CompareOutcome:
    """The comparison (``report``), whether the runs agree, and the lines printed."""

    report: DiffReport
    same: bool
    files: tuple[Path, ...]
    lines: tuple[str, ...]


def compare(request: CompareRequest) -> CompareOutcome:
    """Compare two archived runs (``airgun-xl compare``)."""
    if request.report:
        check_output(request.report, request.force)
    archive = Archive(archive_dir(request.archive))
    a, b = (archive.checked(archive.get(ref)) for ref in (request.entry1, request.entry2))
    pa = {p["cell"]: p for p in a.load("params.json")}
    pb = {p["cell"]: p for p in b.load("params.json")}
    differing = [(c, pa[c]["label"], pa[c]["value"], pb[c]["value"]) for c in pa
                 if pa[c]["value"] != pb[c]["value"]]
    from .diff import diff_histories, format_report

    report = diff_histories(a.ref, _history(a), b.ref, _history(b), request.rtol, request.atol)
    report.inputs = differing  # the entries' parameter cells, compared above
    files: tuple[Path, ...] = ()
    if request.report:
        from ..reports.diff_report import write_diff_report

        write_diff_report(report, request.report, request.force)
        files = (Path(request.report),)
    lines = [f"{a.ref} vs {b.ref}"]
    if differing:
        lines.append(f"inputs differ (so the numbers may differ for that reason), {a.ref} vs "
                     f"{b.ref}:")
    lines += [f"  {cell} {label}: {x!r} vs {y!r}" for cell, label, x, y in differing]
    if not differing:
        lines.append(f"inputs: the {len(pa)} parameter cells agree")
    lines.append(format_report(report))
    return CompareOutcome(report, bool(report.same), files, tuple(lines))


def predicted_pulse(entry: Entry) -> tuple[Any, Any]:
    """An entry's predicted pulse: its time [s] and the bird's acceleration [kG]."""
    columns = _history(entry)
    missing = [c for c in ("time", "accel_kg") if c not in columns]
    if missing:
        raise ArchiveError(f"{entry.ref}: its history has no {', '.join(missing)} column, "
                           "expected the run's time and acceleration (see airgun-xl archive "
                           "verify)")
    return columns["time"], columns["accel_kg"]


def _history(entry: Entry) -> dict[str, Any]:
    """The entry's full time history, column -> array."""
    import pandas as pd

    path = next((p for p in (entry.path / "history.parquet", entry.path / "history.csv")
                 if p.exists()), None)
    if path is None:
        raise ArchiveError(f"{entry.ref}: its history is missing, expected history.parquet or "
                           "history.csv (see airgun-xl archive verify)")
    try:
        frame = pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow and pandas raise their own types
        raise ArchiveError(f"{entry.ref}: {path.name} cannot be read ({type(exc).__name__}), "
                           "expected an intact entry (see airgun-xl archive verify)") from None
    frame.columns = [c.split(" [")[0] for c in frame.columns]
    return {c: frame[c].to_numpy() for c in frame.columns}


# -- archive init | migrate | verify -----------------------------------------------------


@dataclasses.dataclass(frozen=True)
class MaintenanceOutcome:
    """What ``archive init|migrate|verify`` did: the lines printed and, for verify, the
    problems found (exit 1 when there are any)."""

    lines: tuple[str, ...]
    problems: tuple[str, ...] = ()
    archive: str = ""  # the folder, as shown
    entries: int | None = None  # verify: the entries checked

    def to_json(self) -> str:
        """``archive ... --json``: the archive, what was done, and verify's problems."""
        from .documents import dumps

        return dumps({"archive": self.archive, "entries": self.entries,
                      "problems": self.problems, "lines": self.lines})


def some_roles(value: Any, who: str) -> tuple[str, ...]:
    """PostgreSQL role names (a text, or a list of them): plain identifiers
    (:func:`is_role`)."""
    found = declared.texts(value, who)
    for text in found:
        if not is_role(text):
            raise OptionError(f"{who}: found {text[:40]!r}, expected a role name: letters, "
                              "digits and _, at most 63")
    return found


#: What ``archive`` does.
ACTIONS = ("init", "migrate", "verify")


@dataclasses.dataclass(frozen=True, kw_only=True)
class ArchiveRequest(declared.Checked):
    """``archive init|migrate|verify``: on ``folder`` (None: $AIRGUN_XL_ARCHIVE), its index
    on the server ``index`` (None: $AIRGUN_XL_INDEX, else the folder's SQLite), the roles
    ``writers`` granted a writer's rights. Declared once (:mod:`.declared`)."""

    action: str = declared.positional(
        "action", choices=ACTIONS, read=declared.one_of(ACTIONS),
        help="init: make a new archive; migrate: move an archive's SQLite index to the "
             "--index server; verify: check one")
    folder: str | None = declared.optional_positional(
        "folder", metavar="DIR", read=declared.a_folder_or_none, help="the archive folder")
    index: str | None = declared.option(
        None, "--index", metavar="postgresql://HOST/DB", read=declared.a_text_or_none,
        help=f"the PostgreSQL server of the archive's index (default ${INDEX_ENV}, else "
             "libpq's PGHOST, PGSERVICE and service file); never a password: ~/.pgpass or "
             "$PGPASSWORD hold it")
    writers: tuple[str, ...] = declared.option(
        (), "--writers", kind="repeated", metavar="ROLE", read=some_roles,
        help="init and migrate on a server, run by the schema's owner: grant the engineers' "
             "role what a writer needs and no more (read, add entries; no update, delete or "
             "schema change); may be repeated")


def maintain(request: ArchiveRequest) -> MaintenanceOutcome:
    """Do what ``request`` asks: :func:`init`, :func:`migrate` or :func:`verify`."""
    if request.action == "init":
        return init(request.folder, request.index, request.writers)
    if request.action == "migrate":
        return migrate(request.folder, request.index, request.writers)
    if request.writers:
        raise declared.refusal("{0}: found roles with verify, expected them with init or "
                               "migrate", "writers")
    return verify(request.folder, request.index)


def init(folder: str | None, index: str | None = None,
         writers: Sequence[str] = ()) -> MaintenanceOutcome:
    """Make a new archive: its index in the folder, or on a server with ``index`` (or
    ``$AIRGUN_XL_INDEX``)."""
    root = archive_dir(folder)
    server = index is not None or bool(os.environ.get(INDEX_ENV))
    if writers and not server:
        raise declared.refusal("{0}: found roles for an archive whose index is in its "
                               "folder, expected {1} or ${env} (a server's roles)", "writers",
                               "index", env=INDEX_ENV)
    archive = Archive.init(root, index, server=server, writers=list(writers))
    where = (f"its index on {archive.index.shown}" if archive.index.kind == "server"
             else "its index in the folder")
    return MaintenanceOutcome((f"made the archive {display(archive.root)}, {where}",),
                              archive=display(archive.root))


def migrate(folder: str | None, index: str | None,
            writers: Sequence[str] = ()) -> MaintenanceOutcome:
    """Move an archive's SQLite index to a server, writers kept out, every row verified."""
    archive = Archive(archive_dir(folder))
    before = len(archive.entries())
    backup = archive.migrate(index, list(writers))
    return MaintenanceOutcome((
        f"moved the index of {display(archive.root)} ({_count(before, 'entry', 'entries')}) "
        f"to {archive.index.shown}; the SQLite index is kept as {backup.name}",),
        archive=display(archive.root), entries=before)


def verify(folder: str | None, index: str | None = None) -> MaintenanceOutcome:
    """Finish what killed writers left, re-hash every file of every entry, and list what is
    missing, altered or out of place."""
    archive = Archive(archive_dir(folder), index=index, check=False)
    problems = [str(p) for p in archive.verify()]
    entries = archive.entries(bad=[])
    lines = [f"problem: {p}" for p in problems]
    lines.append(f"{_count(len(entries), 'entry', 'entries')}, "
                 f"{_count(len(problems), 'problem', 'problems')} in {display(archive.root)}")
    return MaintenanceOutcome(tuple(lines), tuple(problems), display(archive.root),
                              len(entries))
