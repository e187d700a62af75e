"""``airgun-xl calibrate SHOT.xlsx RECORDING [SHOT2.xlsx RECORDING2 ...]``: the model
fitted to the shots that were fired."""
import math
from pathlib import Path

from ..errors import OptionError
from .recording_options import add_recording_options
from .run_options import add_force, add_integrator, add_output
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
    p.set_defaults(run=run)


#: The exit status of a calibration that was written but cannot be vouched for (a value at a
#: bound or not identified, a law not converged, a residual made worse): its warnings say why.
UNTRUSTED = 3


def _pairs(values):
    if len(values) % 2:
        raise OptionError(f"calibrate: found {len(values)} files, expected pairs of "
                          "SHOT.xlsx RECORDING")
    return [(values[i], values[i + 1]) for i in range(0, len(values), 2)]


def run(args):
    from ..readers.recording import input_file, read_trace
    from ..reports.calibration import write_calibration
    from ..shot import Shot
    from ..studies.calibrate import calibrate, check_fit
    from ..studies.shock import CFC_CLASSES, cfc_coefficients
    from ..transaction import check_output

    files = _pairs(args.pairs)
    if args.cfc is not None and args.cfc not in CFC_CLASSES:
        cfc_coefficients(args.cfc, 1.0)  # its one-line error, before any run
    if not 1 <= args.degree <= 6:
        raise OptionError(f"--degree: found {args.degree}, expected 1 to 6 (Eq. 8 is of "
                          "degree 6)")
    names = [n.strip() for n in (args.fit or "").split(",") if n.strip()]
    if args.fit is not None:
        names = check_fit(names, args.objective)
    law = args.law or not names
    root = _law_library(args, law or "scale" in names)
    first = Path(files[0][0])
    output = Path(args.output) if args.output else first.with_name(
        first.stem + ".calibrated.xlsx")
    check_output(output, args.force,
                 inputs=[input_file(f) for pair in files for f in pair])
    shots = [Shot.from_workbook(s) for s, _ in files]
    traces = [read_trace(m, args.time_unit, args.accel_unit, args.sign, args.channel)
              for _, m in files]
    cal = calibrate([s.params for s in shots], traces, law=law, fit=names, cfc=args.cfc,
                    degree=args.degree, objective=args.objective,
                    integrator=args.integrator, anti_alias=args.anti_alias)
    cal.warnings[:0] = [w for s in shots for w in s.warnings]
    write_calibration(output, shots[0], cal, files, args, args.force)
    print(f"wrote {output}: calibrated on {len(files)} shot{'s' * (len(files) > 1)} "
          f"({cal.runs} runs, {cal.seconds:.2f} s)")
    if cal.law_calibration is not None:
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
    for name, value in cal.fitted.items():
        print(f"  {name}: {cal.start[name]:.6g} -> {value:.6g} +/- {cal.errors[name]:.3g} "
              f"(1 standard error; 95 %: {value - 1.96 * cal.errors[name]:.6g} to "
              f"{value + 1.96 * cal.errors[name]:.6g})")
    for i, (before, after) in enumerate(zip(cal.before, cal.after, strict=True), start=1):
        print(f"  shot {i}: RMS error {before.rms:.2%} -> {after.rms:.2%}; ISO/TS 18571 "
              f"{before.iso:.3f} -> {after.iso:.3f}")
    for text in cal.notes:
        print(f"  note: {text}")
    if cal.warnings:
        from .messages import warn

        warn(cal.warnings)
        print(f"  verdict: NOT TRUSTED ({len(cal.warnings)} warning"
              f"{'s' * (len(cal.warnings) > 1)}, also in {output}); exit {UNTRUSTED}")
        return UNTRUSTED
    print("  verdict: every fitted value identified, within its bounds, and every shot's "
          "residual improved")
    if root is not None:
        from ..archive.laws import store_law
        from ..transaction import display

        shots_record = [{"workbook": display(w), "recording": display(m), "v0": p.v31}
                        for (w, m), p in zip(files, cal.params, strict=True)]
        scores = [{"rms_before": b.rms, "rms_after": a.rms, "iso_before": _plain(b.iso),
                   "iso_after": _plain(a.iso)}
                  for b, a in zip(cal.before, cal.after, strict=True)]
        ref = store_law(root, args.name, cal.params[0].crush_law, shots_record, scores,
                        [display(a) for a in args.argv])
        print(f"  stored the law as {ref} in {display(root)} (fill --crush-law {args.name} "
              f"--archive {display(root)})")
    return 0


def _plain(value):
    return None if math.isnan(value) else value  # NaN (too short a pulse): null


def _law_library(args, fits_a_law):
    """The archive the law goes to (``--name``), checked before any run; None without it."""
    from ..archive import Archive, archive_dir, safe_name

    if args.name is None:
        if args.archive is not None:
            raise OptionError("--archive: found without --name, expected --name NAME for the "
                              "law's name in the archive's library")
        return None
    if not fits_a_law:
        raise OptionError("--name: found with --fit of no law, expected a law to keep (the "
                          "default, --law, or --fit scale)")
    if not args.name or safe_name(args.name) != args.name or args.name.lower() in (
            "workbook", "legacy"):
        raise OptionError(f"--name: found {args.name!r}, expected a law name of letters, "
                          "digits, '-', '_' and '.' (such as LOT-2026-07), not workbook or "
                          "legacy")
    root = archive_dir(args.archive)
    Archive(root, create=True, dry_run=True)  # a foreign folder is refused now
    return root
