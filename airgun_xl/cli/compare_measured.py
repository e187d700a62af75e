"""``airgun-xl compare-measured SHOT.xlsx RECORDING``: the prediction against the test."""
from pathlib import Path

from .recording_options import RECORDING_HELP, add_recording_options
from .run_options import SHOT_HELP, add_crush_law, add_force, add_output, add_run_options


def add_parser(sub):
    p = sub.add_parser("compare-measured",
                       help="compare the shot's predicted pulse with a measured one (CSV, "
                            "xlsx, TDMS)",
                       description="Run the shot, read the measured pulse (a CSV of time and "
                                   "acceleration, units in the header: s/ms/us and g/kG/m/s^2), "
                                   "filter both alike (SAE J211), align them at the impact, "
                                   "and score the peak, its time, the pulse, the velocity "
                                   "change and their correlation.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("measured", metavar="RECORDING", help="the measured pulse: " + RECORDING_HELP)
    add_output(p, "scores and traces", "SHOT.measured.xlsx")
    add_force(p)
    add_recording_options(p)
    p.add_argument("--align", default="threshold", choices=("threshold", "xcorr"),
                   help="impact instant: where the zeroed pulse first holds 5%% of its peak "
                        "(or 5 sigma of its pre-trigger noise, if more) for 0.05 ms (default),"
                        " or the cross-correlation's best lag; each checks the other")
    add_run_options(p)
    add_crush_law(p)
    p.set_defaults(run=run)


def run(args):
    import dataclasses

    import numpy as np

    from ..archive.laws import shot_with_law
    from ..models import apply_model
    from ..readers.recording import input_file, read_trace
    from ..reports.measured import write_comparison
    from ..studies.check import after_run
    from ..studies.measured import ANTI_ALIAS_ORDER, compare
    from ..studies.shock import CFC_CLASSES, cfc_coefficients
    from ..transaction import check_output
    from .messages import warn

    if args.cfc is not None and args.cfc not in CFC_CLASSES:
        cfc_coefficients(args.cfc, 1.0)  # its one-line error, before the run
    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".measured.xlsx")
    check_output(output, args.force, inputs=[args.shot, input_file(args.measured)])
    trace = read_trace(args.measured, args.time_unit, args.accel_unit, args.sign,
                       args.channel)
    shot = shot_with_law(args.shot, args.crush_law, args.archive)
    result = dataclasses.replace(shot, params=apply_model(shot.params, args.model)).run(
        integrator=args.integrator, track=())
    finite = np.isfinite(result.accel_kg)
    other = "rigid" if args.model == "4-mass" else "4-mass"
    rigid = dataclasses.replace(shot, params=apply_model(shot.params, other)).run(
        integrator=args.integrator, track=())
    ok = np.isfinite(rigid.accel_kg)
    c = compare(result.history.time[finite], result.accel_kg[finite], trace, args.cfc,
                args.align, rigid=(rigid.history.time[ok], rigid.accel_kg[ok]),
                anti_alias=args.anti_alias)
    c.warnings[:0] = shot.warnings + [str(f) for f in after_run(result)]
    about = [("Shot", str(args.shot)), ("Measured", trace.name),
             ("Units read", f"time {trace.units[0]}, acceleration {trace.units[1]}"),
             ("Filter", f"CFC {args.cfc}" if args.cfc else "none"),
             ("Alignment", f"{args.align} (cross-checked against the other)"),
             ("Anti-alias model", "none" if c.anti_alias is None else
              f"{ANTI_ALIAS_ORDER}-pole Butterworth at {c.anti_alias:,.0f} Hz on the prediction"),
             ("Warnings", f"{len(c.warnings)} (below the scores)" if c.warnings else "none")]
    write_comparison(output, c, about, args.force, models=(args.model, other),
                     shot=Path(args.shot).name)
    print(f"wrote {output}: {trace.name} against {args.shot} ({len(c.time):,} samples, "
          f"aligned by {args.align}, shift {c.shift * 1e3:.4f} ms)")
    print(f"  peak {c.predicted.peak_kg:.4f} kG predicted, {c.measured.peak_kg:.4f} measured "
          f"({c.errors['peak_kg']:+.2%}); pulse {c.predicted.pulse_duration * 1e3:.4f} ms, "
          f"{c.measured.pulse_duration * 1e3:.4f} ({c.errors['pulse_duration']:+.2%})")
    print(f"  velocity change {c.predicted.delta_v:.3f} m/s, {c.measured.delta_v:.3f} "
          f"({c.errors['delta_v']:+.2%}); correlation r = {c.correlation:.4f}")
    r = c.iso
    if r is not None:
        print(f"  ISO/TS 18571 rating {r.overall:.3f} ({r.grade}): corridor {r.corridor:.3f}, "
              f"phase {r.phase:.3f}, magnitude {r.magnitude:.3f}, slope {r.slope:.3f}")
    print(f"  baseline: {c.baseline.words()}; impact at {c.level:.1%} of the peak; "
          "anti-alias model "
          + (f"{c.anti_alias:,.0f} Hz" if c.anti_alias else "none"))
    warn(c.warnings)
    return 0
