"""``airgun-xl sweep SHOT.xlsx --vary A28=100:260:161``: many shots at once."""
import time
from pathlib import Path

from .. import limits
from ..errors import OptionError
from ..transaction import check_output
from .cluster_options import add_cluster_options, cluster_runner
from .run_options import SHOT_HELP, add_crush_law, add_force, add_output, add_run_options


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
    p.set_defaults(run=run)


def _progress_bar(total):
    """The one progress bar (cli/progress.py) on a terminal; nothing when stderr is not a TTY
    (logs, CI)."""
    from .progress import CountBar

    bar = CountBar(total)
    if not bar.enabled:
        return None, None
    return bar, bar.advance


def run(args):
    from ..archive.laws import shot_with_law
    from ..reports.sweep import write_sweep
    from ..studies.sensitivity import sobol
    from ..studies.sweep import grid, monte_carlo, parse_sds, parse_vary, spread

    shot = shot_with_law(args.shot, args.crush_law, args.archive)
    varies = [parse_vary(v) for v in args.vary]
    sds = parse_sds(args.sd)
    if args.mc is not None and args.sobol is not None:
        raise OptionError("--sobol: found it with --mc, expected one or the other")
    random = "--mc" if args.mc is not None else "--sobol" if args.sobol is not None else None
    if random is not None:
        text = args.mc if args.mc is not None else args.sobol
        try:
            n = int(text)
        except ValueError:
            n = 0
        if n < 2 or n > limits.MAX_SHOTS or not sds:
            raise OptionError(f"{random}: found {text!r}{'' if sds else ' without --sd'}, "
                              f"expected a number of shots from 2 to {limits.MAX_SHOTS:,}, "
                              "with --sd")
        if args.seed is not None and not 0 <= args.seed < 2**128:
            raise OptionError(f"--seed: found {args.seed}, expected a whole number from 0 "
                              "to 2**128 - 1")
        if varies:
            raise OptionError(f"--vary: found a grid with {random}, expected one or the other")
    elif not varies:
        raise OptionError("--vary: found none, expected CELL=LO:HI:N (or --mc N with --sd)")
    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".sweep.xlsx")
    check_output(output, args.force, inputs=[args.shot])
    total = n if args.mc is not None else n * (len(sds) + 2) if args.sobol is not None else 1
    for _, _, values in varies:
        total *= len(values)
    if total > limits.MAX_SHOTS:
        raise OptionError(f"--vary: found a grid of {total:,} shots, expected at most "
                          f"{limits.MAX_SHOTS:,} (fewer points per cell)")
    limits.check_memory(limits.sweep_bytes(total, shot.params.rows),
                        f"a sweep of {total:,} shots of {shot.params.rows:,} rows",
                        "fewer shots (--mc, or fewer points per --vary) or fewer rows")
    started = time.perf_counter()
    with cluster_runner(args) as runner:
        bar, progress = _progress_bar(total)
        try:
            sensitivity = None
            if args.mc is not None:
                result = monte_carlo(shot.params, sds, n, args.seed, args.integrator,
                                     args.model, progress, runner)
            elif args.sobol is not None:
                sensitivity = sobol(shot.params, sds, n, args.seed, args.integrator,
                                    args.model, progress, runner)
                result = sensitivity.shots
            else:
                result = grid(shot.params, varies, args.integrator, args.model, progress,
                              runner)
        finally:
            if bar is not None:
                bar.close()
    seconds = time.perf_counter() - started
    stats = spread(result.figures[:, 0])
    write_sweep(result, output, args.force, stats if args.mc is not None else None,
                sensitivity, shot=Path(args.shot).name,
                seed=None if result.kind == "grid" else args.seed)
    steps = total * (shot.params.rows - 2)
    print(f"wrote {output}: {total:,} shots in {seconds:.2f} s ({steps / seconds:.3g} "
          f"shot-steps/s); {int(result.diverged.sum())} diverged, "
          f"{int(result.invalid.sum())} invalid")
    if result.kind == "grid":  # every combination, not a distribution: its extremes
        import numpy as np

        peaks = result.figures[:, 0][np.isfinite(result.figures[:, 0])]
        if len(peaks):
            print(f"  peak from {peaks.min():.4f} to {peaks.max():.4f} kG over the grid")
    else:
        print(f"  peak {stats['mean']:.4f} kG mean, sd {stats['sd']:.4f}, 5-95% "
              f"{stats['p5']:.4f}-{stats['p95']:.4f} kG (seed {args.seed})")
    flagged, cells = result.flagged()
    if flagged:
        from .messages import warn

        warn([f"{flagged:,} of {total:,} shots have warnings, naming "
              + ", ".join(f"{cell} ({n:,} shots)" for cell, n in sorted(cells.items()))
              + f": see the Warnings column and sheet of {output}"])
    if sensitivity is not None:
        found = sensitivity.indices["peak_kg"]
        print("  Sobol indices of the peak: " + ", ".join(
            f"{cell} S1 {s1:.3f} ST {st:.3f}" for cell, s1, st in
            zip(sensitivity.cells, found["S1"], found["ST"], strict=True)))
    return 0
