"""``airgun-xl calibrate SHOT.xlsx RECORDING [SHOT2.xlsx RECORDING2 ...]``: the model
fitted to the shots that were fired."""
from pathlib import Path

from ..errors import OptionError
from .recording_options import add_recording_options
from .run_options import add_force, add_integrator, add_json, add_output
from .vocabulary import One


def add_parser(sub):
    p = sub.add_parser("calibrate", help="fit the crush-factor law, E40 or zeta to measured "
                                         "shots; write a workbook fill can run",
                       description="Recover the crush-factor law from one or more measured "
                                   "shots by the report's iteration (force over static crush "
                                   "force against relative velocity, refit, rerun, until the "
                                   "law moves < 1 %), then a least-squares finish; and/or fit "
                                   "E40, E43 (zeta) or the law's scale by least squares. "
                                   "Writes the first shot's workbook with the fitted values "
                                   "and a Crush law sheet that fill runs.")
    p.add_argument("pairs", nargs="+", metavar="SHOT.xlsx RECORDING",
                   help="each shot's workbook followed by its measured pulse (a CSV, "
                        "trace.xlsx:Sheet1!A:B or a TDMS file)")
    add_output(p, "the calibrated workbook", "SHOT.calibrated.xlsx")
    add_force(p)
    p.add_argument("--law", action="store_true",
                   help="recover the crush-factor law (the default when --fit is not given)")
    p.add_argument("--fit", metavar="NAMES",
                   help="fit these by least squares, comma-separated: E40, E43, scale "
                        "(E40 and scale exclude each other)")
    p.add_argument("--objective", choices=("l2", "iso18571"), default="l2",
                   help="what the least squares minimise: the filtered pulses' difference "
                        "(default) or 1 - the ISO/TS 18571 rating")
    p.add_argument("--degree", type=int, default=6, help="of the law's polynomial (1-6, "
                                                          "default 6 as Eq. 8)")
    add_recording_options(p, "TDMS only: the channel of every measured file (default: the "
                             "first waveform channel)")
    add_integrator(p)
    p.add_argument("--archive", metavar="DIR", action=One,
                   help="with --name: keep the fitted law in this archive's library of crush "
                        "laws (default: $AIRGUN_XL_ARCHIVE when set), for fill --crush-law NAME")
    p.add_argument("--name", metavar="NAME",
                   help="the law's name in the archive, e.g. LOT-2026-07 (a honeycomb lot); "
                        "storing it again adds its next version")
    add_json(p, "the calibration")
    p.set_defaults(run=run)


#: The exit status of a calibration that was written but cannot be vouched for (a value at a
#: bound or not identified, a law not converged, a residual made worse): its warnings say why.
UNTRUSTED = 3


def _pairs(values):
    if len(values) % 2:
        raise OptionError(f"calibrate: found {len(values)} files, expected pairs of "
                          "SHOT.xlsx RECORDING")
    return tuple((values[i], values[i + 1]) for i in range(0, len(values), 2))


def request_of(args):
    """The :class:`~airgun_xl.app.calibrate.CalibrateRequest` the command line asks for
    (its default output beside the first shot)."""
    from ..app.calibrate import CalibrateRequest

    pairs = _pairs(args.pairs)
    first = Path(pairs[0][0])
    output = Path(args.output) if args.output else first.with_name(
        first.stem + ".calibrated.xlsx")
    return CalibrateRequest(pairs, args.law, args.fit, args.objective, args.degree, args.cfc,
                            args.sign, args.time_unit, args.accel_unit, args.channel,
                            args.anti_alias, args.integrator, output, args.force,
                            Path(args.archive) if args.archive else None, args.name,
                            tuple(args.argv))


def run(args):
    from ..app.calibrate import run as calibrate

    outcome = calibrate(request_of(args))
    if args.json:
        from .messages import warn

        print(outcome.to_json())
        warn(list(outcome.warnings))
        return 0 if outcome.trusted else UNTRUSTED
    cal, output, n = outcome.calibration, outcome.output, len(outcome.calibration.before)
    print(f"wrote {output}: calibrated on {n} shot{'s' * (n > 1)} "
          f"({cal.runs} runs, {cal.seconds:.2f} s)")
    _print_law(cal)
    for name, value in cal.fitted.items():
        print(f"  {name}: {cal.start[name]:.6g} -> {value:.6g} +/- {cal.errors[name]:.3g} "
              f"(1 standard error; 95 %: {value - 1.96 * cal.errors[name]:.6g} to "
              f"{value + 1.96 * cal.errors[name]:.6g})")
    for i, (before, after) in enumerate(zip(cal.before, cal.after, strict=True), start=1):
        print(f"  shot {i}: RMS error {before.rms:.2%} -> {after.rms:.2%}; ISO/TS 18571 "
              f"{before.iso:.3f} -> {after.iso:.3f}")
    for text in cal.notes:
        print(f"  note: {text}")
    if not outcome.trusted:
        from .messages import warn

        warn(list(outcome.warnings))
        print(f"  verdict: NOT TRUSTED ({len(cal.warnings)} warning"
              f"{'s' * (len(cal.warnings) > 1)}, also in {output}); exit {UNTRUSTED}")
        return UNTRUSTED
    print("  verdict: every fitted value identified, within its bounds, and every shot's "
          "residual improved")
    if outcome.stored is not None:
        root = outcome.archive_shown
        print(f"  stored the law as {outcome.stored} in {root} (fill --crush-law {args.name} "
              f"--archive {root})")
    return 0


def _print_law(cal):
    """The law recovered: its convergence, range and intervals at its nodes."""
    if cal.law_calibration is None:
        return
    lc = cal.law_calibration
    lo, hi = cal.params[0].crush_law.v_range
    print(f"  crush law: {'converged' if lc.converged else 'NOT converged'} in "
          f"{len(lc.iterations)} iterations (last change {lc.iterations[-1].change:.2%}), "
          f"then least squares; valid {lo:.1f} to {hi:.1f} m/s (the samples' span)")
    print("  crush law at its nodes, 95 % intervals (noise, baselines and alignment; not "
          "model error):")
    for node in cal.law_intervals:
        line = (f"    {node.velocity:6.1f} m/s: {node.value:.4f} ({node.low:.4f} to "
                f"{node.high:.4f}, +/- {node.half_width:.1%})")
        if node.weak:
            line += f" WEAKLY PINNED by {node.pinned_by() or 'no shot in particular'}"
            if node.suggested is not None:
                line += f"; a shot at about {node.suggested:.0f} m/s would pin it best"
        print(line)
