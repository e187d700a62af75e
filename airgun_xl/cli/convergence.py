"""``airgun-xl convergence SHOT.xlsx``: error against time step and run time."""
import math
from pathlib import Path

from .run_options import (
    SHOT_HELP,
    add_crush_law,
    add_force,
    add_integrator,
    add_json,
    add_output,
)


def add_parser(sub):
    p = sub.add_parser("convergence", help="run a shot over a ladder of time steps",
                       description="Run the shot at each time step of a ladder, report each "
                                   "figure's error against the finest level (with Richardson "
                                   "extrapolation and the observed order), recommend the "
                                   "coarsest time step that meets --rtol on the peak, and "
                                   "write a workbook and a PNG of error against run time.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("--levels", help="comma-separated time steps, e.g. 5us,2us,1us,500ns "
                                    "(default: the sheet's E2, then 1-2-5 steps down to 5ns)")
    add_integrator(p, repeated=True)
    p.add_argument("--rtol", default="1e-3", help="tolerance on the peak (default 0.1%%)")
    add_output(p, "workbook; the PNG goes beside it", "SHOT.convergence.xlsx")
    add_force(p)
    add_crush_law(p)
    add_json(p, "the ladders")
    p.set_defaults(run=run)


def run(args):
    from ..app.convergence import ConvergenceRequest
    from ..app.convergence import run as convergence
    from .messages import warn

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".convergence.xlsx")
    outcome = convergence(ConvergenceRequest(
        shot_path, args.levels, tuple(args.integrator), args.rtol, output, args.force,
        args.crush_law, Path(args.archive) if args.archive else None))
    warn(list(outcome.warnings))
    if args.json:
        print(outcome.to_json())
        return 0
    print_table(outcome.ladders)
    print(f"wrote {output} and {outcome.png}" if outcome.png else f"wrote {output}")
    return 0


def print_table(ladders):
    for lad in ladders:
        print(f"{lad.integrator} integrator:")
        print(f"  {'dt':>9} {'rows':>10} {'kernel s':>9} {'total s':>8} {'peak kG':>10} "
              f"{'rel.err':>9} {'order':>6} {'crush m':>8} {'rel.err':>9}")
        for lv in lad.levels:
            order = lv.order.get("peak_kg")
            print(f"  {lv.delta:9.3g} {lv.rows:10,} {lv.kernel_seconds:9.4f} "
                  f"{lv.total_seconds:8.3f} {lv.figures['peak_kg']:10.5f} "
                  f"{lv.errors['peak_kg']:9.2e} {'' if order is None else f'{order:6.2f}':>6} "
                  f"{lv.figures['max_crush']:8.5f} {lv.errors['max_crush']:9.2e}")
        extrapolated = lad.richardson["peak_kg"]
        finest = lad.levels[-1].figures["peak_kg"]
        print(f"  Richardson: peak {extrapolated:.5f} kG (finest level off by "
              f"{abs(finest - extrapolated) / abs(extrapolated):.1e})")
        rec = lad.recommended
        print(f"  coarsest dt with peak within {lad.rtol:.1%} of the finest: "
              + (f"{rec:.3g} s" if not math.isnan(rec) else "none of the coarser levels"))

