"""``airgun-xl accept SHOT.xlsx RECORDING``: did the fired shot meet its specification?

Exit 0 on PASS, 3 on FAIL (:data:`FAIL_EXIT`), 2 for bad input."""
from pathlib import Path

from .recording_options import RECORDING_HELP, add_recording_options
from .run_options import SHOT_HELP, add_force, add_output
from .spec_options import RECORD_HELP, add_spec_options
from .vocabulary import One

#: The exit status of a shot that fails its specification (2 stays for bad input).
FAIL_EXIT = 3


def add_parser(sub):
    p = sub.add_parser("accept", help="judge a recording against the shot's specification: "
                                      "PASS or FAIL, criterion by criterion",
                       description="Read the recording (as compare-measured does), judge it "
                                   "against the specification (the shot's Specification "
                                   "sheet, a --profile, the options): peak, duration, velocity"
                                   " change, the corridor round the ideal pulse and the SRS; "
                                   "write the verdict workbook. Exit 0 on PASS, 3 on FAIL.")
    p.add_argument("shot", metavar="SHOT.xlsx", help=SHOT_HELP)
    p.add_argument("recording", metavar="RECORDING", help="the recorded pulse: " + RECORDING_HELP)
    add_output(p, "verdict workbook", "SHOT.accept.xlsx")
    add_force(p)
    add_recording_options(p, anti_alias=False, cfc_help=(
        RECORD_HELP + ", over the sheet's and the profile's (refused where the filter is "
        "unstable, below 4.155 x the class in samples a second; a warning below J211's 10 x)"))
    add_spec_options(p, cfc=False)
    p.add_argument("--archive", metavar="DIR", action=One,
                   help="record the verdict in the archive (the verdict file of the shot's "
                        "next entry)")
    p.set_defaults(run=run)


def run(args):

    from ..errors import OptionError
    from ..readers.recording import input_file, read_trace
    from ..shot import Shot
    from ..studies.acceptance import expectations, judge_record
    from ..studies.measured import prepare
    from ..transaction import check_output
    from .messages import warn
    from .spec_options import resolve_spec

    shot_path = Path(args.shot)
    output = Path(args.output) if args.output else shot_path.with_name(
        shot_path.stem + ".accept.xlsx")
    check_output(output, args.force, inputs=[args.shot, input_file(args.recording)])
    if args.archive:  # a folder that is not an archive: refused before any work
        from ..archive import Archive

        Archive(args.archive, create=True, dry_run=True)
    shot = Shot.from_workbook(args.shot)
    spec = resolve_spec(shot, args)
    if spec is None:
        raise OptionError(f"{args.shot}: its Specification sheet is empty and no option gives"
                          " a criterion; expected --peak, --duration, --velocity-change, --srs"
                          " or --profile")
    cfc = spec.judged.cfc  # --cfc is the specification's record field, over the sheet's
    trace = read_trace(args.recording, args.time_unit, args.accel_unit, args.sign,
                       args.channel)
    from ..studies.shock import check_cfc

    filtering = check_cfc(cfc, trace.dt) if cfc else []
    expected, notes = expectations(shot, spec)
    # zeroed and its quality read; the record judged is made below
    rec = prepare(trace, None, anti_alias="none", flat_top=spec.shape == "trapezoid",
                  expected=expected,
                  nominal_duration=spec.duration.nominal if spec.duration else None)
    verdict = judge_record(rec.trace.time, rec.corrected, spec, trace.name,
                           noise=rec.base.noise,
                           warnings=shot.warnings + filtering + rec.warnings,
                           quality=rec.quality)
    verdict.definitions += notes
    assert verdict.record is not None
    time, kg = verdict.record
    pulse, spectra = report_data(time, kg, spec, verdict)
    about = [("Shot", str(args.shot)), ("Recording", trace.name),
             ("Units read", f"time {trace.units[0]}, acceleration {trace.units[1]}"),
             ("Record judged", verdict.definitions[0].removeprefix("record judged: ")),
             ("Baseline", rec.base.words()), ("Verdict", verdict.word)]
    from ..reports.acceptance import write_acceptance

    # the verdict's record first, taken back if the workbook is not published: a failure or
    # a signal leaves neither (the archive, if this made it, included)
    from ..transaction import signals_held

    stored = None
    try:
        if args.archive:
            with signals_held():  # a signal comes once the record is whole, and assigned
                stored = record_verdict(args, shot, verdict, output)
        write_acceptance(output, verdict, about, pulse, spectra, args.force,
                         shot=Path(args.shot).name)
    except BaseException:
        if stored is not None:
            stored.take_back()
        raise
    if stored is not None:
        print(f"  archived the verdict as {stored.path}")
    print_verdict(verdict, f"{trace.name} against {args.shot}")
    print(f"  wrote {output}")
    eq = spectra["equivalent"]
    print(f"  equivalent half-sine (its SRS envelops the record's): {eq[0]:.4f} kG, "
          f"{eq[1] * 1e3:.4f} ms; pseudo-velocity up to {max(spectra['pv']):.3f} m/s")
    warn(verdict.warnings)
    return 0 if verdict.passed else FAIL_EXIT


def print_verdict(verdict, what):
    """The verdict, a line a criterion, with the tolerances used; what files gave (a
    profile's notes, names) reaches the terminal as text, never as control codes."""
    from ..untrusted_json import printable

    n = len(verdict.warnings)
    print(printable(f"{verdict.word}: {what}" + (
        f" (with {n} warning{'s' * (n != 1)}: read them before relying on it)" if n else "")))
    from ..studies.acceptance import limits_text

    for c in verdict.criteria:
        limits = limits_text(c)
        margin = f"{c.margin:+.2f} {c.margin_unit}"
        print(printable(f"  {'PASS' if c.passed else 'FAIL'}  {c.name}: {c.value:.5g} "
                        f"{c.unit} (limits {limits}; margin {margin})"
                        + (f"; {c.detail}" if c.detail else "")))
    for line in verdict.definitions:
        print(printable(f"  {line}"))
    for line in verdict.spec.notes:  # a profile's caveats, with every verdict judged by it
        print(printable(f"  note: {line}"))


def report_data(time, kg, spec, verdict):
    """The pulse with its corridor, and the spectra, for the verdict workbook."""
    import numpy as np

    from ..studies.acceptance import corridor_limits, equivalent_half_sine, ideal, pseudo_velocity
    from ..studies.shock import decimated_for, default_frequencies, srs

    pulse = {"time": time, "kg": kg}
    if spec.corridor is not None and verdict.onset is not None:
        tau = time - verdict.onset
        upper, lower = corridor_limits(spec, tau)
        lo, hi = verdict.window
        inside = (time >= lo) & (time <= hi)
        pulse["ideal"] = ideal(spec.shape, tau, spec.peak.nominal, spec.duration.nominal)
        pulse["upper"] = np.where(inside, upper, np.nan)
        pulse["lower"] = np.where(inside, lower, np.nan)
    dt = time[1] - time[0]
    q = spec.srs_q if spec.srs is not None and spec.srs_q is not None else 10.0
    top = 0.1 / dt  # the SRS's highest frequency at this rate
    if spec.srs is not None:  # the requirement's band on a 1/12-octave grid, and its rows
        required_f = np.array(spec.srs.frequencies)
        lo, hi = required_f.min(), min(required_f.max(), top)
        grid = default_frequencies(lo, hi) if hi > lo else np.array([lo])
        frequencies = np.unique(np.concatenate([grid, required_f[required_f <= top]]))
    else:  # 100 Hz to 10 kHz, or below a tenth of a slow record's rate
        hi = min(10_000.0, top)
        frequencies = default_frequencies(min(100.0, hi / 16), hi)
    # on the record decimated to what the frequencies need: a 1 GHz record's would take
    # minutes and gigabytes at its own step, for the same spectrum
    spectral, step, factor = decimated_for(kg, dt, float(np.max(frequencies)))
    levels = srs(spectral, step, frequencies, q)
    spectra = {"frequencies": frequencies, "srs": levels, "q": q,
               "pv": pseudo_velocity(frequencies, levels),
               "equivalent": equivalent_half_sine(
                   step * np.arange(len(spectral)), spectral, frequencies, q),
               "step": (step, factor)}
    if spec.srs is not None:  # log-log between the requirement's rows
        required = np.exp(np.interp(np.log(frequencies), np.log(required_f),
                                    np.log(np.array(spec.srs.levels_kg))))
        spectra.update(required=required, lower=required * 10 ** (spec.srs_lower_db / 20),
                       upper=required * 10 ** (spec.srs_upper_db / 20))
    return pulse, spectra


def record_verdict(args, shot, verdict, output):
    """The verdict into the archive (a JSON file beside the shot's entries): a
    :class:`~airgun_xl.archive.verdicts.StoredVerdict`."""
    from ..archive.verdicts import store_verdict

    return store_verdict(args.archive, shot, verdict, args.recording, output,
                         tuple(args.argv))
