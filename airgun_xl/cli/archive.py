"""``history``, ``show``, ``compare``, ``archive init`` and ``archive verify``: make an
archive, and find archived shots again."""
import json
import sys

from ..archive import ENV, INDEX_ENV, Archive, archive_dir
from ..transaction import display
from ..untrusted_json import printable
from .run_options import ATOL_HELP, RTOL_HELP, add_force, tolerance
from .vocabulary import One


def add_parser(sub):
    where = f"DIR defaults to ${ENV}."
    h = sub.add_parser("history", help="list the runs stored in an archive, and its crush laws",
                       description=f"List archived runs with their key figures (peak, "
                                   f"filtered peak, pulse, crush, warnings, integrator, crush "
                                   f"law) and the archive's crush laws. {where}")
    h.add_argument("--archive", metavar="DIR", action=One, help="the archive folder")
    h.add_argument("dir", nargs="?", metavar="DIR",
                   help="old spelling of --archive DIR, kept one release")
    h.add_argument("--shot", metavar="NAME", help="only this shot's runs")
    h.add_argument("--since", metavar="DATE", help="only runs from this ISO date on, e.g. "
                                                   "2026-11-01")
    h.add_argument("--where", action="append", default=[], metavar="CELL=VALUE",
                   help="only runs whose input cell holds VALUE (to 1e-9 of it) or lies in "
                        "LO:HI, e.g. E40=2.703e7 or E40=2.6e7:2.8e7 (a honeycomb lot); may "
                        "be repeated")
    h.add_argument("-o", "--output", metavar="SHOTS.xlsx", action=One,
                   help="also write the table across the runs, with the peak against v0")
    add_force(h, "SHOTS.xlsx")
    h.add_argument("--json", action="store_true", help="print the list as JSON")
    h.set_defaults(run=run_history)
    s = sub.add_parser("show", help="print one archived run: inputs, figures, provenance",
                       description=f"Print one archived run. {where}")
    s.add_argument("entry", metavar="ENTRY", help="SHOT (its latest run), SHOT@VERSION or #ID")
    s.add_argument("--archive", metavar="DIR", action=One, help="the archive folder")
    s.add_argument("--json", action="store_true", help="print the run as JSON")
    s.set_defaults(run=run_show)
    c = sub.add_parser("compare", help="diff two archived runs: inputs, then every series",
                       description=f"Compare two archived runs: the parameter cells first, "
                                   f"then every series of their full histories. Exit 0 when "
                                   f"they agree, 1 when they differ. {where}")
    c.add_argument("entry1", metavar="ENTRY1", help="SHOT, SHOT@VERSION or #ID")
    c.add_argument("entry2", metavar="ENTRY2", help="SHOT, SHOT@VERSION or #ID")
    c.add_argument("--archive", metavar="DIR", action=One, help="the archive folder")
    c.add_argument("--rtol", default="1e-12", help=RTOL_HELP.replace("column", "series"))
    c.add_argument("--atol", default="0", help=ATOL_HELP)
    c.add_argument("--json", action="store_true", help="print the report as JSON, as diff does")
    c.add_argument("--report", metavar="REPORT.xlsx", action=One,
                   help="also write a workbook: the input cells that differ and the error table")
    add_force(c, "REPORT.xlsx")
    c.set_defaults(run=run_compare)
    a = sub.add_parser("archive", help="archive maintenance: init, migrate, verify",
                       description=f"init: make a new archive in a new or empty folder, its "
                                   f"index in the folder (SQLite, one machine) or, with "
                                   f"--index, on a PostgreSQL server (a lab's share written by "
                                   f"several hosts). migrate: move an archive's SQLite index to "
                                   f"such a server, writers kept out, every row verified "
                                   f"against its manifest, the SQLite index kept as a backup. "
                                   f"verify: finish what killed writers left, "
                                   f"re-hash every file of every entry, and list anything "
                                   f"missing, altered or out of place. Exit 0 clean, 1 with "
                                   f"problems. {where}")
    a.add_argument("action", choices=["init", "migrate", "verify"],
                   help="init: make a new archive; migrate: move an archive's SQLite index to "
                        "the --index server; verify: check one")
    a.add_argument("dir", nargs="?", metavar="DIR", help="the archive folder")
    a.add_argument("--index", metavar="postgresql://HOST/DB", action=One,
                   help=f"the PostgreSQL server of the archive's index (default "
                        f"${INDEX_ENV}, else libpq's PGHOST, PGSERVICE and service file); "
                        "never a password: ~/.pgpass or $PGPASSWORD hold it")
    a.add_argument("--writers", action="append", default=[], metavar="ROLE",
                   type=_role,
                   help="init and migrate on a server, run by the schema's owner: grant the "
                        "engineers' role what a writer needs and no more (read, add entries; "
                        "no update, delete or schema change); may be repeated")
    a.set_defaults(run=run_archive)


def _role(text):
    """``--writers``: a PostgreSQL role name (a plain identifier)."""
    import argparse
    import re

    from ..archive.index import ROLE_NAME

    if not re.fullmatch(ROLE_NAME, str(text)):
        raise argparse.ArgumentTypeError(f"found {str(text)[:40]!r}, expected a role name: "
                                         "letters, digits and _, at most 63")
    return str(text)


def _count(n, one, many):
    return f"{n} {one if n == 1 else many}"


def _archive(given):
    root = archive_dir(given)
    return Archive(root)


def parse_where(text):
    """``E40=2.703e7`` -> ("E40", 2.703e7, 2.703e7); ``E40=2.6e7:2.8e7`` -> a range."""
    import math

    from ..cells import BY_ADDRESS
    from ..errors import OptionError

    cell, _, value = str(text).partition("=")
    cell = cell.strip().upper()
    try:
        first, _, second = value.partition(":")
        lo, hi = float(first), float(second) if second.strip() else float(first)
        ok = math.isfinite(lo) and math.isfinite(hi) and lo <= hi
    except ValueError:
        ok = False
    if cell not in BY_ADDRESS or not ok:
        raise OptionError(f"--where: found {text!r}, expected CELL=VALUE or CELL=LO:HI with "
                          "a parameter cell, e.g. E40=2.703e7 or A28=200:250")
    return cell, lo, hi


def _matches(params, where):
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


def history_rows(entries, where=()):
    """The campaign-table row of each entry (its summary.json figures and provenance) that
    ``where`` selects."""
    from ..errors import ArchiveError

    rows = []
    for e in entries:
        try:
            if where and not _matches(e.load("params.json"), where):
                continue
            s = e.load("summary.json")
            prov = e.load("provenance.json")
        except ArchiveError as exc:  # a listing flags a bad record, names it, and goes on
            rows.append(_unreadable_row(e, exc))
            continue
        law = prov.get("crush_law")
        warnings = s.get("warnings")
        rows.append({
            **dict(e.row), "ref": e.ref, "file": e.ref, "created": e.created, "v0": e.row["v0"],
            "peak_kg": s.get("peak_kg"), "filtered_peak_kg": s.get("filtered_peak_kg"),
            "time_of_peak": s.get("time_of_peak"), "pulse_duration": s.get("pulse_duration"),
            "max_crush": s.get("max_crush"), "final_length": s.get("final_length"),
            "warnings": [f"{w}" for w in warnings or []],
            "warning_count": len(warnings) if warnings is not None else None,
            "integrator": f"{prov.get('integrator')}/{prov.get('model')}",
            "crush_law": law["name"] if isinstance(law, dict) else "not recorded"})
    return rows


def _unreadable_row(e, exc):
    """An entry whose records cannot be read, as a row of the listing: no figures, and why."""
    figures = ("peak_kg", "filtered_peak_kg", "time_of_peak", "pulse_duration", "max_crush",
               "final_length", "warning_count")
    return {**dict(e.row), "ref": e.ref, "file": e.ref, "created": e.created,
            "v0": e.row["v0"], **{k: None for k in figures},
            "warnings": [f"unreadable: {exc}"], "integrator": "unreadable",
            "crush_law": f"unreadable: {exc}"}


def _cell(value, fmt, width):
    return f"{'n/a':>{width}}" if value is None else f"{value:>{width}{fmt}}"


def run_history(args):
    from ..transaction import check_output

    if args.since:
        import datetime

        try:
            datetime.date.fromisoformat(args.since[:10])
        except ValueError:
            from ..errors import OptionError

            raise OptionError(f"--since: found {args.since!r}, expected a date such as "
                              "2026-11-01") from None
    where = [parse_where(w) for w in args.where]
    if args.output:
        check_output(args.output, args.force)  # before reading the entries
    archive = _archive(_history_archive(args))
    rows = history_rows(archive.entries(args.shot, args.since), where)
    from ..archive.laws import list_laws

    laws = list_laws(archive.root)
    from ..archive.verdicts import list_verdicts

    verdicts = list_verdicts(archive.root)
    if args.json:  # the index row of each entry, with its figures and its law
        print(json.dumps(rows, indent=1))
    else:
        print(f"{'entry':<24} {'created (UTC)':<26} {'v0 m/s':>8} {'peak kG':>9} "
              f"{'filt. kG':>9} {'pulse ms':>9} {'crush m':>8} {'warn':>4}  integrator, "
              "crush law")
        for r in rows:
            ms = {k: None if r[k] is None else r[k] * 1e3
                  for k in ("pulse_duration", "time_of_peak")}
            print(printable(
                f"{r['file']:<24} {r['created']:<26} {_cell(r['v0'], '.2f', 8)} "
                f"{_cell(r['peak_kg'], '.4f', 9)} {_cell(r['filtered_peak_kg'], '.4f', 9)} "
                f"{_cell(ms['pulse_duration'], '.4f', 9)} {_cell(r['max_crush'], '.4f', 8)} "
                f"{_cell(r['warning_count'], 'd', 4)}  {r['integrator']}, {r['crush_law']}"))
        print(f"{len(rows)} entr{'y' if len(rows) == 1 else 'ies'}"
              + (f" of {len(archive.entries(args.shot, args.since))} (--where)" if where
                 else ""))
        if laws:
            print("crush laws:")
            for law in laws:
                span = ("unreadable" if law["v_range"] is None else
                        f"{law['v_range'][0]:.4g} to {law['v_range'][1]:.4g} m/s")
                print(printable(f"  {law['ref']:<30} {span}, fitted on {law['shots']} shot"
                                f"{'s' * (law['shots'] != 1)}, {law['created']}"))
        if verdicts:
            print("verdicts (accept --archive):")
            for v in verdicts:
                print(printable(f"  {v['shot']}@{v['version']:<6} {v['verdict']:<5} "
                                f"{v['created']}  {v['recording']}"))
    if args.output:
        from ..reports.campaign import HISTORY_TABLE, write_campaign

        title = f"History of {display(archive.root)}: {len(rows)} runs"
        if where:
            title += " where " + ", ".join(w for w in args.where)
        write_campaign(args.output, rows, title, args.force, HISTORY_TABLE,
                       label=display(archive.root.name))
        print(f"wrote {args.output}: one row a run, the peak against v0", file=sys.stderr
              if args.json else sys.stdout)
    return 0


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


def shown_figure(key, value):
    """A summary.json figure in words with its unit: ``("Time of peak", "0.2885 ms")``,
    ``("Dominant frequencies", "5.333, 4.833 kHz")``, ``n/a`` where a value is missing; a key
    the table does not know (a record from another version) as it is written."""
    label, unit, factor, digits = FIGURE_UNITS.get(key, (key, "", 1.0, None))
    values = value if isinstance(value, list) else [value]
    if digits is None or not all(isinstance(v, (int, float)) or v is None for v in values):
        return label, str(value)
    text = ", ".join("n/a" if v is None else f"{v * factor:,.{digits}f}" for v in values)
    return label, f"{text} {unit}".rstrip() if values else "none"


def run_show(args):
    archive = _archive(args.archive)
    e = archive.checked(archive.get(args.entry))  # what verify would report is refused
    doc = {"entry": e.ref, "id": e.id, "path": str(e.path), "created": e.created,
           "params": e.load("params.json"), "summary": e.load("summary.json"),
           "provenance": e.load("provenance.json"), "files": e.manifest()["files"]}
    if args.json:
        print(json.dumps(doc, indent=1))
        return 0

    def say(text=""):  # what a record holds reaches the terminal as text, never as codes
        print(printable(text))

    say(f"{e.ref} (#{e.id}), created {e.created}, in {e.path}")
    say("inputs:")
    for p in doc["params"]:
        say(f"  {p['cell']:<4} {p['label']:<32} {p['value']!r:>22} {p['unit']}")
    say("figures:")
    summary = dict(doc["summary"])
    warnings = summary.pop("warnings", None)
    verdict = summary.pop("predicted_verdict", None)
    for k, v in summary.items():
        label, shown = shown_figure(k, v)
        say(f"  {label:<37} {shown}")
    if isinstance(verdict, dict):
        say(f"predicted verdict: {verdict.get('verdict')} (specification from "
              f"{verdict.get('specification')})")
        for c in verdict.get("criteria") or []:
            value = "not measured" if c["value"] is None else f"{c['value']:.6g} {c['unit']}"
            margin = "none" if c["margin"] is None else f"{c['margin']:+.2f} {c['margin_unit']}"
            say(f"  {c['name']:<24} {value}, margin {margin}, "
                  f"{'PASS' if c['passed'] else 'FAIL'}")
    if warnings is None:
        say("warnings: not recorded (an entry from before they were kept)")
    else:
        say(f"warnings: {len(warnings) or 'none'}")
        for text in warnings:
            say(f"  - {text}")
    prov = doc["provenance"]
    say(f"provenance: airgun-xl {prov['engine']}, {prov['integrator']} integrator, "
          f"{prov['model']} model, started {prov['started']}, {prov['run_seconds']:.2f} s")
    say(f"  input SHA-256 {prov['input_sha256']}")
    say(f"  command: {' '.join(prov['command'])}")
    say("files: " + ", ".join(doc["files"]))
    return 0


def run_compare(args):
    rtol, atol = tolerance("--rtol", args.rtol), tolerance("--atol", args.atol)
    if args.report:
        from ..transaction import check_output

        check_output(args.report, args.force)
    archive = _archive(args.archive)
    a, b = (archive.checked(archive.get(ref)) for ref in (args.entry1, args.entry2))
    pa = {p["cell"]: p for p in a.load("params.json")}
    pb = {p["cell"]: p for p in b.load("params.json")}
    differing = [(c, pa[c]["label"], pa[c]["value"], pb[c]["value"]) for c in pa
                 if pa[c]["value"] != pb[c]["value"]]
    from ..app.diff import diff_histories, format_report

    report = diff_histories(a.ref, _history(a), b.ref, _history(b), rtol, atol)
    report.inputs = differing  # the entries' parameter cells, compared above
    if args.report:
        from ..reports.diff_report import write_diff_report

        write_diff_report(report, args.report, args.force)
    if args.json:
        print(json.dumps(report.as_dict(), indent=1, default=str))
        return 0 if report.same else 1
    print(f"{a.ref} vs {b.ref}")
    if differing:
        print(f"inputs differ (so the numbers may differ for that reason), {a.ref} vs "
              f"{b.ref}:")
    for cell, label, x, y in differing:
        print(f"  {cell} {label}: {x!r} vs {y!r}")
    if not differing:
        print(f"inputs: the {len(pa)} parameter cells agree")
    print(format_report(report))
    return 0 if report.same else 1


def _history(entry):
    """The entry's full time history, column -> array."""
    import pandas as pd

    from ..errors import ArchiveError

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


def _history_archive(args):
    """history's archive: --archive, or the old positional DIR (noted)."""
    if args.dir is None:
        return args.archive
    from .messages import later
    from .vocabulary import old_spelling_note

    if args.archive is not None and args.archive != args.dir:
        from ..errors import OptionError

        raise OptionError(f"--archive: found {args.archive!r} and the folder {args.dir!r}, "
                          "expected one archive")
    later([old_spelling_note("history DIR", "history --archive DIR")])
    return args.dir


def run_archive(args):
    if args.action == "init":
        return run_init(args)
    if args.action == "migrate":
        return run_migrate(args)
    return run_verify(args)


def run_migrate(args):
    """Move an archive's SQLite index to a server, writers kept out, every row verified."""
    archive = Archive(archive_dir(args.dir))
    before = len(archive.entries())
    backup = archive.migrate(args.index, args.writers)
    print(f"moved the index of {display(archive.root)} ({_count(before, 'entry', 'entries')}) "
          f"to {archive.index.shown}; the SQLite index is kept as {backup.name}")
    return 0


def run_init(args):
    """Make a new archive: its index in the folder, or on a server with --index."""
    import os

    root = archive_dir(args.dir)
    server = args.index is not None or bool(os.environ.get(INDEX_ENV))
    if args.writers and not server:
        from ..errors import OptionError

        raise OptionError("--writers: found roles for an archive whose index is in its folder, "
                          f"expected --index or ${INDEX_ENV} (a server's roles)")
    archive = Archive.init(root, args.index, server=server, writers=args.writers)
    where = (f"its index on {archive.index.shown}" if archive.index.kind == "server"
             else "its index in the folder")
    print(f"made the archive {display(archive.root)}, {where}")
    return 0


def run_verify(args):
    archive = Archive(archive_dir(args.dir), index=args.index, check=False)
    problems = archive.verify()
    entries = archive.entries(bad=[])
    for p in problems:
        print(printable(f"problem: {p}"))
    print(f"{_count(len(entries), 'entry', 'entries')}, "
          f"{_count(len(problems), 'problem', 'problems')} in {display(archive.root)}")
    return 0 if not problems else 1
