"""``airgun-xl fill SHOT.xlsx [-o OUT.xlsx] [--force] [...]``: run a shot into a new workbook."""
import dataclasses
import time
from pathlib import Path

from ..archive import ENV, archive_dir
from ..choices import HOSTS, INTEGRATORS, MODELS, SIDECAR_MODES, UNLOADINGS
from ..outputs import GROUPS, from_sheet
from ..transaction import display


def add_parser(sub):
    p = sub.add_parser("fill", help="run the shot in a workbook and write a new filled workbook",
                       description="Read the report's parameter cells from SHOT, run ArtSim, and "
                                   "write the macro's result columns, a summary and charts into "
                                   "a new workbook. SHOT itself is never modified. The "
                                   "workbook's Outputs sheet, if any, picks the outputs; the "
                                   "flags below override it.")
    p.add_argument("shot", metavar="SHOT.xlsx", help="workbook in the report's layout")
    p.add_argument("-o", "--output", metavar="OUT.xlsx",
                   help="output workbook (default: SHOT.out.xlsx beside SHOT)")
    p.add_argument("--force", action="store_true", help="overwrite OUT.xlsx if it exists")
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
    p.add_argument("--integrator", choices=sorted(INTEGRATORS), default="legacy",
                   help="legacy: ArtSim's scheme (the default); newmark: average-acceleration "
                        "Newmark, unconditionally stable for the OBR chain")
    p.add_argument("--allow-unstable", action="store_true",
                   help="run even when the time step is above the critical step (a diverging "
                        "run still stops)")
    p.add_argument("--model", choices=MODELS, default="4-mass",
                   help="4-mass: ArtSim (default); rigid: the previous rigid-body model")
    p.add_argument("--crush-law", choices=("workbook", "legacy"), default="workbook",
                   help="workbook: the law the workbook's Crush law sheet names (a calibrated "
                        "workbook's fitted law), else the macro's (default); legacy: the "
                        "macro's polynomial, Eq. (8), whatever the workbook says")
    p.add_argument("--unloading", choices=UNLOADINGS, default="macro",
                   help="macro: the macro's unloading force, quirk included (default); "
                        "continuous: each unloading starts from the force before it (no jump "
                        "at a second unloading)")
    p.add_argument("--compare-models", action="store_true",
                   help="also run the other model; both curves in the acceleration chart and "
                        "both peaks in the Summary")
    p.add_argument("--archive", metavar="DIR",
                   help=f"also store the run as a new entry of this archive (default: "
                        f"${ENV} when set)")
    p.add_argument("--name", help="shot name in the archive (default: the cell beside a 'Shot' "
                                  "label in the sheet, else SHOT's file name)")
    p.add_argument("--reproducible", action="store_true",
                   help="leave run times out of the Summary, so equal inputs give equal bytes")
    p.set_defaults(run=run)


def default_output(shot_path):
    shot_path = Path(shot_path)
    return shot_path.with_name(shot_path.stem + ".out.xlsx")


def _ms(seconds):
    return f"{seconds * 1e3:.4f} ms"


def print_summary(output, filled):
    from ..engine.summary import PULSE_FRACTION
    from ..workbook.sheets import variant_name

    result, s, stride, sidecar = filled.result, filled.summary, filled.stride, filled.sidecar
    lines = [f"wrote {output}: {result.rows:,} rows"
             + (f", 1 in {stride} on the sheets" if stride > 1 else "")
             + f"; {result.params.model.split(' (')[0]} model"
             + (" (rigid)" if result.model == "rigid" else "")
             + f", {result.integrator} integrator"
             + ("" if result.params.crush_law.is_legacy else
                ", the workbook's fitted crush law (Crush law sheet)")]
    if s is not None:
        filtered = ("no filtered samples" if s.filtered_peak_kg != s.filtered_peak_kg else
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
    print("\n".join(lines))


def run(args):
    from ..archive.entry import now, shot_name
    from ..pipeline import ArchiveRequest, Options, fill_workbook
    from ..shot import Shot
    from . import note, warn
    from .progress import Progress

    started = time.perf_counter()
    output = Path(args.output) if args.output else default_output(args.shot)
    # --crush-law legacy runs the macro's law whatever the sheet says: the sheet is not read
    shot = Shot.from_workbook(args.shot, read_law=args.crush_law != "legacy")
    if args.unloading != "macro":
        shot = shot.with_params(unloading=args.unloading)
    outputs = from_sheet(shot.source.outputs_block).with_flags(
        args.only, args.no_charts, args.every, args.max_sheet_rows, args.sidecar)
    options = Options(args.integrator, args.host, args.model, args.compare_models, args.force,
                      args.allow_unstable, args.reproducible, command=tuple(args.argv))
    root = archive_dir(args.archive, required=False)
    if root is not None:
        outputs = dataclasses.replace(outputs, sidecar="never")  # the entry holds the history
        options.track_all = True
        options.archive = ArchiveRequest(root, shot_name(shot, args.name), now())
    progress = Progress.for_rows(shot.params.rows)
    try:
        filled = fill_workbook(shot, output, outputs, options, warn, started, note, progress)
    finally:
        progress.close()
    print_summary(output, filled)
    if filled.entry is not None:
        print(f"  archived as {filled.entry.ref} in {display(root)}")
    return 0
