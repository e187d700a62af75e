"""``airgun-xl sweep SHOT.xlsx --vary A28=100:260:161``: many shots at once."""
from pathlib import Path

from .cluster_options import add_cluster_options
from .run_options import SHOT_HELP, add_crush_law, add_force, add_json, add_output, add_run_options


def add_parser(sub):
    p = sub.add_parser("sweep", help="run a grid of shots, a Monte Carlo or Sobol indices over "
                                     "uncertain inputs",
                       description="Evaluate a grid of shots (--vary; several make a grid), a "
                                   "Monte Carlo (--mc N with --sd) or Sobol sensitivity indices "
                                   "(--sobol N with --sd) with the batch kernel, on this "
                                   "machine's cores or on a Dask cluster (--scheduler, "
                                   "--workers); write the headline figures per shot, the "
                                   "charts, and the spread or the indices.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("--vary", action="append", metavar="CELL=LO:HI:N", default=[],
                   help="a parameter cell and its values, e.g. A28=100:260:161")
    p.add_argument("--mc", metavar="N", help="Monte Carlo: this many shots")
    p.add_argument("--sd", action="append", metavar="CELL=SD[%]", default=[],
                   help="spread of an uncertain input, e.g. E40=3%% (Monte Carlo)")
    p.add_argument("--sobol", metavar="N",
                   help="Sobol indices of the peak, pulse and crush to the --sd inputs "
                        "(SALib): N (a power of 2) x (inputs + 2) shots")
    p.add_argument("--seed", type=int, default=1,
                   help="seed of the Monte Carlo's and Sobol's draws (default 1, so that a "
                        "run repeats; printed with the results)")
    add_run_options(p)
    add_output(p, "table and charts", "SHOT.sweep.xlsx")
    add_force(p)
    add_cluster_options(p)
    add_crush_law(p)
    add_json(p, "the shots' figures and the spread")
    p.set_defaults(run=run)


def request_of(args):
    """The :class:`~airgun_xl.app.sweep.SweepRequest` the command line asks for (its
    default output beside the shot)."""
    from ..app.sweep import SweepRequest

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".sweep.xlsx")
    return SweepRequest(shot_path, tuple(args.vary), args.mc, tuple(args.sd), args.sobol,
                        args.seed, args.integrator, args.model, output, args.force,
                        args.crush_law, Path(args.archive) if args.archive else None,
                        args.scheduler, args.workers, args.chunk)


def run(args):
    from ..app.sweep import lines
    from ..app.sweep import run as sweep
    from .messages import report
    from .progress import count_bar

    request = request_of(args)
    outcome = sweep(request, None if args.json else count_bar)
    return report(outcome, lines(request, outcome), args.json)
