"""``airgun-xl fill SHOT.xlsx [-o OUT.xlsx] [--force]``: run a shot into a new workbook."""
from pathlib import Path

from ..engine.filtered import HOSTS
from ..shot import Shot
from ..workbook.atomic import check_output


def add_parser(sub):
    p = sub.add_parser("fill", help="run the shot in a workbook and write a new filled workbook",
                       description="Read the report's parameter cells from SHOT, run ArtSim, and "
                                   "write the macro's result columns into a new workbook. SHOT "
                                   "itself is never modified.")
    p.add_argument("shot", metavar="SHOT.xlsx", help="workbook in the report's layout")
    p.add_argument("-o", "--output", metavar="OUT.xlsx",
                   help="output workbook (default: SHOT.out.xlsx beside SHOT)")
    p.add_argument("--force", action="store_true", help="overwrite OUT.xlsx if it exists")
    p.add_argument("--host", choices=HOSTS, default="excel",
                   help="whose Offset rounding the filtered column reproduces when 1/(E2*E34) "
                        "is fractional (default: excel)")
    p.set_defaults(run=run)


def default_output(shot_path):
    shot_path = Path(shot_path)
    return shot_path.with_name(shot_path.stem + ".out.xlsx")


def run(args):
    from . import warn

    output = Path(args.output) if args.output else default_output(args.shot)
    shot = Shot.from_workbook(args.shot)
    check_output(output, args.force, inputs=[args.shot])  # before the run, not after
    warn(shot.warnings)
    result = shot.run(host=args.host)
    warn(result.warnings[len(shot.warnings):])
    warn(result.write(output, force=args.force))
    print(f"wrote {output}: {result.rows:,} rows, peak {result.peak_kg:.5f} kG at "
          f"{result.time_of_peak * 1e3:.4f} ms")
    return 0
