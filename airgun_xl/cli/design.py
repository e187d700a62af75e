"""``airgun-xl design SHOT.xlsx --target-peak 12kG``: solve for the pulse a client asks for."""
import dataclasses
import time
from pathlib import Path

from ..choices import DESIGN_VARIABLES
from ..errors import OptionError
from ..outputs import from_sheet
from ..units import parse_duration, parse_peak
from .cluster_options import add_cluster_options, cluster_runner
from .fill import print_summary
from .run_options import add_force, add_output, add_run_options


def add_parser(sub):
    p = sub.add_parser("design", help="find the v0 or geometry that gives a requested peak",
                       description="Solve for the value of one parameter (two with "
                                   "--target-duration) that gives the requested peak "
                                   "acceleration of the test item, and write the designed "
                                   "shot as a filled workbook.")
    p.add_argument("shot", metavar="SHOT.xlsx")
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument("--target-peak", metavar="PEAK",
                        help="requested peak: 12kG, 11750g or 1.2e5m/s2")
    target.add_argument("--target-srs", metavar="REQ.csv",
                        help="required shock response spectrum (CSV: 'frequency [Hz],srs [g]'):"
                             " the least value whose SRS envelops it")
    p.add_argument("--q", type=float, default=10.0,
                   help="the SRS's quality factor, with --target-srs (default 10)")
    p.add_argument("--accel-unit", help="the required SRS's unit, g, kG or m/s^2 (default: "
                                        "from its header)")
    p.add_argument("--target-duration", metavar="DURATION",
                   help="requested pulse duration (>= 10%% of peak): 5ms, 4500us; needs two "
                        "--vary")
    p.add_argument("--vary", action="append", metavar="CELL",
                   help=f"parameter to solve for: {', '.join(DESIGN_VARIABLES)} (A28: A28..A30 "
                        "together, the default)")
    p.add_argument("--range", metavar="LO:HI",
                   help="search range of the (first) varied parameter, in its unit")
    p.add_argument("--filtered", action="store_true", help="match the filtered peak")
    add_run_options(p)
    add_output(p, "designed shot, filled", "SHOT.design.xlsx")
    add_force(p)
    add_cluster_options(p)
    p.set_defaults(run=run)


def _range(text):
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except (ValueError, AttributeError):
        lo = hi = float("nan")
    if not lo < hi:
        raise OptionError(f"--range: found {text!r}, expected LO:HI with LO < HI")
    return lo, hi


def run(args):
    from ..shot import Shot
    from ..studies.design import solve_peak, solve_peak_and_duration, variable

    if args.target_srs is not None:
        return run_srs(args)
    target = parse_peak(args.target_peak)
    duration = parse_duration(args.target_duration) if args.target_duration else None
    names = args.vary or ["A28"]
    variables = [variable(n) for n in names]
    if duration is not None and len(variables) != 2:
        raise OptionError("--target-duration: found one --vary, expected two (the first meets "
                          "the peak, the second the duration)")
    if duration is None and len(variables) != 1:
        raise OptionError("--vary: found two parameters, expected one (or add "
                          "--target-duration)")
    bounds = _range(args.range) if args.range else None
    shot = Shot.from_workbook(args.shot)
    started = time.perf_counter()
    with cluster_runner(args) as runner:
        if duration is None:
            design = solve_peak(shot.params, target, variables[0], args.filtered,
                                args.integrator, args.model, bounds, runner=runner)
        else:
            design = solve_peak_and_duration(shot.params, target, duration, variables[0],
                                             variables[1], args.filtered, args.integrator,
                                             args.model, runner=runner)
    solve_seconds = time.perf_counter() - started
    for var, value in zip(design.variables, design.values, strict=True):
        print(f"{var.cell}{'..A30' if var.cell == 'A28' else ''} = {value:.6g} {var.unit}")
    print(f"  achieved peak {design.peak_kg:.5f} kG (target {target:.5f} kG), pulse "
          f"{design.duration * 1e3:.4f} ms"
          + (f" (target {duration * 1e3:.4f} ms)" if duration is not None else ""))
    print(f"  {design.evaluations} simulations in {solve_seconds:.2f} s")
    return _write_design(args, shot, design)


def run_srs(args):
    from ..shot import Shot
    from ..studies.design import solve_srs, variable
    from ..workbook.trace import read_spectrum

    for flag, value in (("--scheduler", args.scheduler), ("--workers", args.workers),
                        ("--chunk", args.chunk)):
        if value is not None:
            raise OptionError(f"{flag}: found with --target-srs, expected it only with "
                              "--target-peak (an SRS design runs on this machine)")
    if args.target_duration:
        raise OptionError("--target-duration: found with --target-srs, expected one target: "
                          "the spectrum, or a peak and a duration")
    names = args.vary or ["A28"]
    if len(names) != 1:
        raise OptionError("--vary: found two parameters, expected one with --target-srs")
    var = variable(names[0])
    if not args.q > 0.5:
        raise OptionError(f"--q: found {args.q!r}, expected a quality factor above 0.5")
    bounds = _range(args.range) if args.range else None
    frequencies, required = read_spectrum(args.target_srs, args.accel_unit)
    shot = Shot.from_workbook(args.shot)
    started = time.perf_counter()
    design = solve_srs(shot.params, frequencies, required, var, args.q, args.integrator,
                       args.model, bounds)
    print(f"{var.cell}{'..A30' if var.cell == 'A28' else ''} = {design.values[0]:.6g} "
          f"{var.unit}")
    print(f"  its SRS (Q = {args.q:g}) envelops the {len(frequencies)} required levels with a "
          f"least margin of {design.margin:+.2%}, at {design.governing_hz:,.0f} Hz")
    print(f"  peak {design.peak_kg:.5f} kG, pulse {design.duration * 1e3:.4f} ms; "
          f"{design.evaluations} simulations in {time.perf_counter() - started:.2f} s")
    return _write_design(args, shot, design, (frequencies, required, args.q))


def _write_design(args, shot, design, requirement=None):
    from ..pipeline import Options, fill_workbook
    from . import note, warn
    from .progress import Progress

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".design.xlsx")
    warn(design.warnings)
    designed = with_cells(shot, design)
    outputs = from_sheet(shot.source.outputs_block)
    options = Options(args.integrator, "excel", args.model, False, args.force,
                      command=tuple(args.argv), srs_requirement=requirement)
    progress = Progress.for_rows(designed.params.rows)
    try:
        filled = fill_workbook(designed, output, outputs, options, warn, None, note, progress)
    finally:
        progress.close()
    print_summary(output, filled)
    return 0


def with_cells(shot, design):
    """The shot with the solved values in their cells (as constants) and in its parameters."""
    from openpyxl.utils.cell import coordinate_to_tuple

    block = dict(shot.source.block)
    for var, value in zip(design.variables, design.values, strict=True):
        for address in var.cells:
            block[coordinate_to_tuple(address)] = (float(value), None)
    source = dataclasses.replace(shot.source, block=block)
    return dataclasses.replace(shot, params=design.params, source=source)
