"""``airgun-xl fill SHOT.xlsx [-o OUT.xlsx] [--force] [...]``: run a shot into a new workbook."""
import math
from pathlib import Path

from ..archive import ENV, archive_dir
from ..archive.store import prestart_index
from ..choices import HOSTS, SIDECAR_MODES, UNLOADINGS
from ..outputs import GROUPS
from ..transaction import display
from .run_options import add_crush_law, add_force, add_integrator, add_model
from .spec_options import add_spec_options
from .vocabulary import One


def add_parser(sub):
    p = sub.add_parser("fill", help="run the shot in a workbook and write a new filled workbook",
                       description="Read the report's parameter cells from SHOT, run ArtSim, and "
                                   "write the macro's result columns, a summary and charts into "
                                   "a new workbook. SHOT itself is never modified. The "
                                   "workbook's Outputs sheet, if any, picks the outputs; the "
                                   "flags below override it.")
    p.add_argument("shots", nargs="+", metavar="SHOT.xlsx",
                   help="workbook in the report's layout; several, or a folder (its .xlsx "
                        "shots), fill a campaign")
    p.add_argument("-o", "--output", metavar="OUT.xlsx", action=One,
                   help="output workbook (default: SHOT.out.xlsx beside SHOT; one shot only)")
    add_force(p)
    p.add_argument("--jobs", metavar="N",
                   help="worker processes for a campaign (default: the cores this process "
                        "may use)")
    p.add_argument("--summary", metavar="DAY.xlsx",
                   help="also write the campaign's table: one row a shot, the peak against "
                        "v0, every warning")
    p.add_argument("--host", choices=HOSTS, default="excel",
                   help="whose Offset rounding the filtered column reproduces when 1/(E2*E34) "
                        "is fractional (default: excel)")
    p.add_argument("--only", metavar="GROUPS",
                   help=f"write only these comma-separated outputs: {', '.join(GROUPS)}")
    p.add_argument("--no-charts", action="store_true", help="leave out the Charts sheet")
    p.add_argument("--every", metavar="N", help="write every N-th time row to the sheets")
    p.add_argument("--max-sheet-rows", metavar="N",
                   help="most time rows on a sheet before every N-th row is written")
    p.add_argument("--sidecar", choices=SIDECAR_MODES,
                   help="full time history beside the output: auto (when rows are left out), "
                        "always or never")
    add_integrator(p)
    p.add_argument("--allow-unstable", action="store_true",
                   help="run even when the time step is above the critical step (a diverging "
                        "run still stops)")
    add_model(p)
    add_crush_law(p, archive=False)  # fill's --archive is its own (below)
    p.add_argument("--unloading", choices=UNLOADINGS, default="macro",
                   help="macro: the macro's unloading force, quirk included (default); "
                        "continuous: each unloading starts from the force before it (no jump "
                        "at a second unloading)")
    p.add_argument("--compare-models", action="store_true",
                   help="also run the other model; both curves in the acceleration chart and "
                        "both peaks in the Summary")
    p.add_argument("--archive", metavar="DIR", action=One,
                   help=f"also store the run as a new entry of this archive (default: "
                        f"${ENV} when set)")
    p.add_argument("--name", help="shot name in the archive (default: the cell beside a 'Shot' "
                                  "label in the sheet, else SHOT's file name)")
    p.add_argument("--reproducible", action="store_true",
                   help="leave run times out of the Summary, so equal inputs give equal bytes")
    add_spec_options(p)
    p.set_defaults(run=run)


def _ms(seconds):
    return f"{seconds * 1e3:.4f} ms"


def print_summary(output, filled):
    from ..engine.summary import PULSE_FRACTION
    from ..xlsx.sheets import variant_name

    result, s, stride, sidecar = filled.result, filled.summary, filled.stride, filled.sidecar
    lines = [f"wrote {output}: {result.rows:,} rows"
             + (f", 1 in {stride} on the sheets" if stride > 1 else "")
             + f"; {result.params.model.split(' (')[0]} model"
             + (" (rigid)" if result.model == "rigid" else "")
             + f", {result.integrator} integrator"
             + ("" if result.params.crush_law.is_legacy else
                f", the archive's crush law {result.params.crush_law.source}"
                if result.params.crush_law.source else
                ", the workbook's fitted crush law (Crush law sheet)")]
    if s is not None:
        filtered = ("no filtered samples" if math.isnan(s.filtered_peak_kg) else
                    f"filtered {s.filtered_peak_kg:.5f} kG at "
                    f"{_ms(s.time_of_filtered_peak)}")
        lines.append(f"  peak {s.peak_kg:.5f} kG at {_ms(s.time_of_peak)}; {filtered}")
        lines.append(f"  pulse {_ms(s.pulse_duration)} (>= {PULSE_FRACTION:.0%} of peak), "
                     f"max crush {s.max_crush:.4f} m, final length {s.final_length:.4f} m")
        if s.spectrum.peaks and result.model != "rigid":  # one body: no modes to name
            lines.append("  dominant frequencies "
                         + ", ".join(f"{f / 1e3:.2f}" for f in s.spectrum.peaks) + " kHz")
    else:
        lines.append(f"  peak {result.peak_kg:.5f} kG at {_ms(result.time_of_peak)}")
    if filled.compared is not None:
        c = filled.compared
        lines.append(f"  {variant_name(c)}: peak {c.peak_kg:.5f} kG at {_ms(c.time_of_peak)}")
    if sidecar is not None:
        lines.append(f"  full history in {sidecar}")
    v = filled.verdict
    if v is not None:
        from ..xlsx.sheets import flagged_figures

        doubted = flagged_figures(filled.warnings).get("Peak acceleration (raw)")
        lines.append(f"  specification ({v.spec.source or 'options'}), predicted: {v.word}"
                     + (f" (DOUBTED: see the warnings on {', '.join(doubted)})" if doubted
                        else "") + ": "
                     + "; ".join(f"{c.name} {c.value:.5g} {c.unit} {c.margin:+.2f} "
                                 f"{c.margin_unit} {'PASS' if c.passed else 'FAIL'}"
                                 for c in v.criteria))
        lines += [f"    {line}" for line in v.sources()]
        lines += [f"    note: {line}" for line in v.spec.notes]  # a profile's caveats
    from ..untrusted_json import printable

    print("\n".join(printable(line) for line in lines))  # a file's text, never control codes


def settings_of(args):
    """The :class:`~airgun_xl.campaign.FillSettings` the command line asks for."""
    from ..app.specifying import SpecFields, options_spec
    from ..campaign import FillSettings
    from ..specification import load_profile

    return FillSettings(
        args.output, args.force, args.host, args.only, args.no_charts, args.every,
        args.max_sheet_rows, args.sidecar, args.integrator, args.allow_unstable, args.model,
        args.crush_law, args.unloading, args.compare_models,
        str(archive_dir(args.archive, required=False) or "") or None, args.name,
        args.reproducible, tuple(args.argv),
        load_profile(args.profile) if args.profile else None,  # once, before any shot
        options_spec(SpecFields.of(args)))


def run(args):
    prestart_index(archive_dir(args.archive, required=False))  # psycopg loads meanwhile
    settings = settings_of(args)
    if len(args.shots) == 1 and not Path(args.shots[0]).is_dir() and not args.summary:
        return run_one(args.shots[0], settings)
    from .campaign import run_batch

    return run_batch(args, settings)


def run_one(path, settings):
    """One shot, as fill always did: its warnings and notes on the terminal, a progress bar,
    its figures printed."""
    from ..campaign import fill_one
    from .messages import note, warn
    from .progress import Progress

    output, filled, root = fill_one(path, settings, warn, note, Progress.for_rows)
    print_summary(output, filled)
    if filled.entry is not None:
        print(f"  archived as {filled.entry.ref} in {display(root)}")
    return 0
