"""``history``, ``show``, ``compare``, ``archive init`` and ``archive verify``: make an
archive, and find archived shots again."""
import json
import sys

from ..choices import ARCHIVE_ENV as ENV
from ..untrusted_json import printable
from .declared import add_declared, flags_named, request_of
from .run_options import add_json

WHERE = f"DIR defaults to ${ENV}."


def add_parser(sub):
    _add_history(sub)
    _add_show(sub)
    _add_compare(sub)
    _add_archive(sub)


def _add_history(sub):
    from ..app.archive import HistoryRequest

    where = WHERE
    h = sub.add_parser("history", help="list the runs stored in an archive, and its crush laws",
                       description=f"List archived runs with their key figures (peak, "
                                   f"filtered peak, pulse, crush, warnings, integrator, crush "
                                   f"law) and the archive's crush laws. {where}")
    add_declared(h, HistoryRequest, only=("archive",))
    h.add_argument("dir", nargs="?", metavar="DIR",
                   help="old spelling of --archive DIR, kept one release")
    add_declared(h, HistoryRequest, only=("shot",))
    h.add_argument("--lot", metavar="NAME",
                   help="a lot's chain instead (airgun-xl next): each shot fired, its "
                        "verdict, the P(PASS) predicted for it, the law version, the next "
                        "setting")
    h.add_argument("--calibration", action="store_true",
                   help="the record of next's predictions instead: P(PASS) predicted before "
                        "each shot against its verdict, in bands, with the Brier score (-o "
                        "writes it with a reliability chart)")
    add_declared(h, HistoryRequest, only=("since", "where", "output", "force"))
    h.add_argument("--json", action="store_true", help="print the list as JSON")
    h.set_defaults(run=run_history)


def _add_show(sub):
    from ..app.archive import ShowRequest

    where = WHERE
    s = sub.add_parser("show", help="print one archived run: inputs, figures, provenance",
                       description=f"Print one archived run. {where}")
    add_declared(s, ShowRequest)
    s.add_argument("--json", action="store_true", help="print the run as JSON")
    s.set_defaults(run=run_show)


def _add_compare(sub):
    from ..app.archive import CompareRequest

    where = WHERE
    c = sub.add_parser("compare", help="diff two archived runs: inputs, then every series",
                       description=f"Compare two archived runs: the parameter cells first, "
                                   f"then every series of their full histories. Exit 0 when "
                                   f"they agree, 1 when they differ. {where}")
    add_declared(c, CompareRequest, skip=("report", "force"))
    c.add_argument("--json", action="store_true", help="print the report as JSON, as diff does")
    add_declared(c, CompareRequest, only=("report", "force"))
    c.set_defaults(run=run_compare)


def _add_archive(sub):
    from ..app.archive import ArchiveRequest

    where = WHERE
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
    add_declared(a, ArchiveRequest)
    add_json(a, "what was done (verify: every problem)")
    a.set_defaults(run=run_archive)


def _print(lines):
    for line in lines:  # what a record holds reaches the terminal as text, never as codes
        print(printable(line))


def run_history(args):
    from ..app.archive import HistoryRequest, history

    if args.lot is not None:
        return _run_chain(args)
    if args.calibration:
        from ..app.next_shot import prediction_record

        record = prediction_record(_history_archive(args), args.output, args.force)
        print(record.to_json() if args.json else "\n".join(record.lines()))
        return 0
    with flags_named(HistoryRequest):
        outcome = history(request_of(HistoryRequest, args, archive=_history_archive(args)))
    if args.json:  # the index row of each entry, with its figures and its law
        print(json.dumps(list(outcome.rows), indent=1))
    else:
        _print(outcome.lines)
    if outcome.wrote:
        print(outcome.wrote, file=sys.stderr if args.json else sys.stdout)
    return 0


def _run_chain(args):
    from ..app.next_shot import chain, chain_lines

    rows = chain(_history_archive(args), args.lot)
    print(json.dumps(rows, indent=1) if args.json else "\n".join(
        printable(line) for line in chain_lines(args.lot, rows)))
    return 0


def run_show(args):
    from ..app.archive import ShowRequest, show

    outcome = show(request_of(ShowRequest, args))
    if args.json:
        print(json.dumps(outcome.doc, indent=1))
    else:
        _print(outcome.lines)
    return 0


def run_compare(args):
    from ..app.archive import CompareRequest, compare

    outcome = compare(request_of(CompareRequest, args))
    if args.json:
        print(json.dumps(outcome.report.as_dict(), indent=1, default=str))
    else:
        print("\n".join(outcome.lines))
    return 0 if outcome.same else 1


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
    from ..app.archive import ArchiveRequest, maintain

    with flags_named(ArchiveRequest):
        outcome = maintain(request_of(ArchiveRequest, args))
    if args.json:
        print(outcome.to_json())
    else:
        _print(outcome.lines)
    return 1 if outcome.problems else 0
