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
from .run_options import SHOT_HELP, add_crush_law, add_force, add_output, add_run_options
from .spec_options import add_spec_options
from .vocabulary import Alias


def add_parser(sub):
    p = sub.add_parser("design", help="design a shot: to a target, to the middle of a "
                                      "specification, or most likely to pass it",
                       description="Design the shot and write it as a filled workbook, in one "
                                   "of three modes. With --target-peak (and --target-duration) "
                                   "or --target-srs: solve for the value of one parameter (two "
                                   "with a duration) that gives the target. Without a target, "
                                   "from a specification (the Specification sheet, a --profile "
                                   "or the options): the setting at the middle of the "
                                   "tolerances, whose smallest margin is largest. With "
                                   "--confidence P and the shot-to-shot scatter (--sd): the "
                                   "setting most likely to pass, its probability with a 95 % "
                                   "interval, and exit 3 when no setting reaches P.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    target = p.add_mutually_exclusive_group()
    target.add_argument("--target-peak", metavar="PEAK",
                        help="requested peak: 12kG, 11750g or 1.2e5m/s2")
    target.add_argument("--target-srs", metavar="REQ.csv",
                        help="required shock response spectrum (CSV: 'frequency [Hz],srs [g]'):"
                             " the least value whose SRS envelops it")
    p.add_argument("--q", dest="srs_q", metavar="Q", action=Alias, idea="SRS quality factor")
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
    add_spec_options(p)
    first = p.add_argument_group("first-shot success (with a specification, no --target-*)")
    first.add_argument("--confidence", type=float, metavar="P",
                       help="find the setting most likely to pass with the scatter of --sd, "
                            "and say whether it reaches P (0.95): exit 3 if none does")
    first.add_argument("--sd", action="append", metavar="CELL=SD",
                       help="a cell's shot-to-shot scatter: A28=1.5%% (the gun), E40=5%% (the "
                            "lot), E43=10%% (zeta); repeatable")
    first.add_argument("--shots", type=int, default=10_000, metavar="N",
                       help="Monte Carlo shots a setting (default 10,000)")
    first.add_argument("--seed", type=int, default=1, help="of the draws (default 1)")
    add_crush_law(p)
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
    from ..archive.laws import shot_with_law
    from ..studies.design import solve_peak, solve_peak_and_duration, variable

    if args.target_srs is not None:
        return run_srs(args)
    if args.target_peak is None:
        return run_spec(args)
    if args.confidence is not None:
        raise OptionError("--confidence: found with --target-peak, expected a design by the "
                          "specification (its fields, with no --target-*)")
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
    shot = shot_with_law(args.shot, args.crush_law, args.archive)
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
    from ..archive.laws import shot_with_law
    from ..readers.recording import read_spectrum
    from ..studies.design import solve_srs, variable

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
    q = _srs_q(args.srs_q)
    bounds = _range(args.range) if args.range else None
    frequencies, required = read_spectrum(args.target_srs, args.accel_unit)
    shot = shot_with_law(args.shot, args.crush_law, args.archive)
    started = time.perf_counter()
    design = solve_srs(shot.params, frequencies, required, var, q, args.integrator,
                       args.model, bounds)
    print(f"{var.cell}{'..A30' if var.cell == 'A28' else ''} = {design.values[0]:.6g} "
          f"{var.unit}")
    print(f"  its SRS (Q = {q:g}) envelops the {len(frequencies)} required levels with a "
          f"least margin of {design.margin:+.2%}, at {design.governing_hz:,.0f} Hz")
    print(f"  peak {design.peak_kg:.5f} kG, pulse {design.duration * 1e3:.4f} ms; "
          f"{design.evaluations} simulations in {time.perf_counter() - started:.2f} s")
    return _write_design(args, shot, design, (frequencies, required, q))


def _srs_q(text):
    """--srs-q with --target-srs: the SRS's quality factor (default 10) [-], read by the
    one grammar every command reads it with."""
    from ..specification import parse_q

    return 10.0 if text is None else parse_q(text, "--srs-q")


def run_spec(args):
    """Design by the specification: the middle of its tolerances, or with --confidence the
    setting most likely to pass on the first shot."""
    import math

    from ..archive.laws import shot_with_law
    from ..studies.design import Design, variable
    from ..studies.first_shot import solve_confidence, solve_middle
    from ..studies.sweep import parse_sds
    from .spec_options import resolve_spec

    names = args.vary or ["A28"]
    if len(names) != 1:
        raise OptionError("--vary: found two parameters, expected one for a design by the "
                          "specification")
    var = variable(names[0])
    bounds = _range(args.range) if args.range else None
    if args.confidence is not None and not 0 < args.confidence < 1:
        raise OptionError(f"--confidence: found {args.confidence!r}, expected a probability "
                          "between 0 and 1, such as 0.95")
    if args.confidence is not None and not 100 <= args.shots <= 10**6:
        raise OptionError(f"--shots: found {args.shots!r}, expected 100 to 1,000,000")
    sds = parse_sds(args.sd or [])
    if args.confidence is not None and not sds:
        raise OptionError("--confidence: found no --sd, expected the scatter to design "
                          "against (--sd A28=1.5%% --sd E40=5%%)".replace("%%", "%"))
    if args.confidence is None and sds:
        raise OptionError("--sd: found without --confidence, expected both")
    if not 0 <= args.seed < 2**128:
        raise OptionError(f"--seed: found {args.seed}, expected a whole number from 0 to "
                          "2**128 - 1")
    from ..transaction import check_output

    check_output(design_output(args), args.force, inputs=[args.shot])  # before the study
    shot = shot_with_law(args.shot, args.crush_law, args.archive)
    spec = resolve_spec(shot, args)
    if spec is None:
        raise OptionError("design: found no target and an empty specification, expected "
                          "--target-peak, --target-srs, or the specification's fields (the "
                          "Specification sheet, --profile, --peak 12kG:10%%...)".replace(
                              "%%", "%"))
    started = time.perf_counter()
    label = f"{var.cell}{'..A30' if var.cell == 'A28' else ''}"
    extra: list[str] = []  # warnings
    notes: list[str] = []  # the study's figures, for the Summary
    code = 0
    with cluster_runner(args) as runner:
        if args.confidence is None:
            middle = solve_middle(shot.params, spec, var, bounds, args.integrator, args.model,
                                  runner)
            value, evaluations = middle.value, middle.evaluations
            print(f"{label} = {value:.6g} {var.unit}: the prediction's smallest margin is "
                  f"{middle.margin:+.2%} of its nominal (the middle of the tolerances)")
            if middle.margin < 0:
                extra.append(f"design: no {var.label} in range makes the prediction pass; the "
                             f"best misses by {-middle.margin:.2%} of a nominal")
                code = 3
        else:
            c = solve_confidence(shot.params, spec, var, sds, args.shots, args.seed, bounds,
                                 args.integrator, args.model, runner)
            value, evaluations = c.best.setting, sum(r.shots for r in c.tried)
            lo, hi = c.best.interval
            worst = c.best.most_failing()
            print(f"{label} = {value:.6g} {var.unit}: P(PASS) = {c.best.probability:.4f} "
                  f"(95 % interval {lo:.4f}-{hi:.4f}, {c.shots:,} shots)")
            m_lo, m_hi = c.middle.interval
            print(f"  the middle design, {label} = {c.middle.setting:.6g} {var.unit}: "
                  f"P(PASS) = {c.middle.probability:.4f} ({m_lo:.4f}-{m_hi:.4f})")
            if worst is not None:
                print(f"  most likely to fail: {worst[0]} ({worst[1]:,} of {c.shots:,} shots)")
            scatter = ", ".join(args.sd)
            notes += [f"design --confidence {args.confidence:g}: P(PASS) = "
                      f"{c.best.probability:.4f} (95 % interval {lo:.4f}-{hi:.4f}) at {label} "
                      f"= {value:.6g} {var.unit}, over {c.shots:,} shots with {scatter}, "
                      f"seed {args.seed}; most likely to fail: "
                      f"{worst[0] if worst else 'none'}",
                      f"the middle design, {label} = {c.middle.setting:.6g} {var.unit}: "
                      f"P(PASS) = {c.middle.probability:.4f} ({m_lo:.4f}-{m_hi:.4f})"]
            extra += c.warnings
            if hi < args.confidence or c.best.probability < args.confidence:
                extra.append(f"design --confidence: no {var.label} in range reaches "
                             f"P(PASS) = {args.confidence:g}; the best found is "
                             f"{c.best.probability:.4f} at {value:.6g} {var.unit}")
                code = 3
    solved = var.apply(shot.params, value)
    design = Design([var], [value], solved, math.nan, math.nan, evaluations, extra)
    print(f"  {evaluations:,} simulations in {time.perf_counter() - started:.2f} s")
    if args.confidence is None:
        notes.append(f"design by the specification: {label} = {value:.6g} {var.unit}, the "
                     f"largest smallest margin ({middle.margin:+.2%} of a nominal)")
    written = _write_design(args, shot, design, spec=spec, notes=tuple(notes))
    return code or written


def design_output(args):
    """The designed shot's workbook: -o, or SHOT.design.xlsx beside the shot."""
    shot_path = Path(args.shot)
    return Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".design.xlsx")


def _write_design(args, shot, design, requirement=None, spec=None, notes=()):
    from ..pipeline import Options, fill_workbook
    from .messages import note, warn
    from .progress import Progress

    output = design_output(args)
    designed = with_cells(shot, design)  # its warnings go with the designed shot's figures
    designed = dataclasses.replace(designed, warnings=list(designed.warnings)
                                   + [w for w in design.warnings if w not in designed.warnings])
    outputs = from_sheet(shot.source.outputs_block)
    options = Options(args.integrator, "excel", args.model, False, args.force,
                      command=tuple(args.argv), srs_requirement=requirement, spec=spec,
                      study_notes=notes)
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
