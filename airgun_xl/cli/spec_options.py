"""The specification options, defined once for every command that judges a pulse (fill,
design, accept): a profile, then the fields, each overriding the shot's Specification sheet."""
from ..specification import PLACEMENTS, SHAPES


def add_spec_options(p):
    g = p.add_argument_group("specification (override the shot's Specification sheet)")
    g.add_argument("--profile", metavar="NAME|FILE.json",
                   help="a tolerance profile: a JSON file of specification fields, or the name"
                        " of one shipped (mil-std-810h-half-sine, quoted, not checked)")
    g.add_argument("--shape", choices=SHAPES, help="the nominal pulse shape")
    g.add_argument("--peak", metavar="PEAK:TOL",
                   help="nominal peak and tolerance: 12kG:10%% or 11750g:-10%%,+20%%")
    g.add_argument("--duration", metavar="DURATION:TOL",
                   help="nominal duration (the shape's base) and tolerance: 0.3ms:10%%")
    g.add_argument("--velocity-change", metavar="DV:TOL",
                   help="nominal velocity change and tolerance: 35m/s:10%%")
    g.add_argument("--corridor", metavar="PCT",
                   help="corridor half-width round the ideal pulse, %% of the nominal peak: "
                        "20%%")
    g.add_argument("--time-slack", metavar="PCT",
                   help="time slack of the corridor, %% of the duration: 10%%")
    g.add_argument("--window", metavar="DURATION",
                   help="monitoring window before and after the pulse: 0.5ms (default: half "
                        "the duration)")
    g.add_argument("--placement", choices=PLACEMENTS,
                   help="where the ideal pulse sits: least squares (default) or on the peak")
    g.add_argument("--record", metavar="unfiltered|CFC",
                   help="the record judged: unfiltered (default) or a J211 class, cfc600")
    g.add_argument("--srs", metavar="REQ.csv",
                   help="an SRS requirement (CSV: 'frequency [Hz],srs [g]')")
    g.add_argument("--srs-tol", metavar="LO,HI", help="its tolerance in dB: -3dB,+6dB "
                                                      "(the default)")
    g.add_argument("--srs-q", type=float, default=10.0, help="its quality factor (default 10)")
    g.add_argument("--srs-outside", type=float, default=0.0, metavar="PCT",
                   help="%% of its frequencies allowed outside the tolerance (default 0)")


def options_spec(args):
    """The specification fields the command line gives (``--record unfiltered`` included),
    without the profile; None when it gives none."""
    import dataclasses
    import re

    from ..errors import OptionError
    from ..specification import Specification

    record = None
    if args.record:
        text = args.record.strip().lower()
        match = re.fullmatch(r"cfc\s*(\d+)", text)
        if text != "unfiltered" and not match:
            raise OptionError(f"--record: found {args.record!r}, expected unfiltered or "
                              "cfc60, cfc180, cfc600, cfc1000")
        record = int(match.group(1)) if match else 0  # 0: unfiltered, over a sheet's CFC
    spec = from_options(args, record)
    if spec == dataclasses.replace(Specification(), source="options"):
        return None
    return spec


def resolve_spec(shot, args):
    """The specification a command judges by: the profile, then the shot's sheet, then the
    options, each overriding the one before field by field; None when nothing is specified.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    from ..specification import combine

    return combine(args.profile, shot.spec, options_spec(args))


def from_options(args, record=None):
    """The fields given on the command line (``--peak 12kG:10%``...), as a specification to
    merge over the sheet's or the profile's."""
    from ..errors import OptionError
    from ..specification import (
        Specification,
        SrsRequirement,
        check,
        parse_db_pair,
        parse_tolerance,
        parse_velocity,
    )
    from ..units import parse_duration, parse_peak
    from ..workbook.trace import read_spectrum

    srs = None
    if getattr(args, "srs", None):
        freqs, levels = read_spectrum(args.srs, getattr(args, "accel_unit", None))
        lower, upper = parse_db_pair(args.srs_tol) if args.srs_tol else (-3.0, 6.0)
        srs = SrsRequirement(tuple(map(float, freqs)), tuple(map(float, levels)),
                             args.srs_q, lower, upper, args.srs_outside / 100)
        check(Specification(srs=srs), "--srs")
    elif getattr(args, "srs_tol", None):
        raise OptionError("--srs-tol: found without --srs, expected the requirement it "
                          "applies to")
    return Specification(
        shape=args.shape or "none",
        peak=parse_tolerance(args.peak, "--peak", parse_peak) if args.peak else None,
        duration=(parse_tolerance(args.duration, "--duration", parse_duration)
                  if args.duration else None),
        velocity_change=(parse_tolerance(args.velocity_change, "--velocity-change",
                                         lambda t, o: parse_velocity(t, o))
                         if args.velocity_change else None),
        corridor=None if args.corridor is None else _percent_option(args.corridor,
                                                                    "--corridor"),
        time_slack=(0.0 if args.time_slack is None else
                    _percent_option(args.time_slack, "--time-slack")),
        window=(None if args.window is None else parse_duration(args.window, "--window")),
        srs=srs, cfc=record, placement=args.placement or "least-squares",
        source="options")


def _percent_option(text, option):
    from ..specification import _fraction

    return _fraction(str(text), option, str(text))[1]
