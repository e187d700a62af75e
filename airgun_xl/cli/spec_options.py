"""The specification options, defined once for every command that judges a pulse (fill,
design, accept): a profile, then the fields, each overriding the shot's Specification sheet.

Every value is read by the specification's grammar (:data:`airgun_xl.specification.KEYS`),
the one the profile and the sheet use; a value an option gives overrides the sheet's and the
profile's even when it equals the default (``--time-slack 0%``)."""
from ..specification import DURATION_DEFS, OPTIONS, PLACEMENTS, SHAPES

#: The options with the grammar keys they give, from the one table
#: (:data:`airgun_xl.specification.OPTIONS`): a quantity's option gives its tolerance too
#: (``--peak 12kG:10%``), ``--srs-tol`` gives the two dB sides, every other option one key.
QUANTITY_OPTIONS = tuple((key, option) for key, option in OPTIONS.items()
                         if f"{key}_tolerance" in OPTIONS)
PLAIN_OPTIONS = tuple((key, option) for key, option in OPTIONS.items()
                      if option not in dict(QUANTITY_OPTIONS).values()
                      and option not in ("--srs-tol", "--cfc"))

#: The help of the record judged, where ``--cfc`` is a field of the specification.
RECORD_HELP = ("the record judged: N through SAE J211 CFC N (60, 180, 600 or 1000), none "
               "the unfiltered record; given by no source, the tool's default (noise-bounded: "
               "unfiltered while its noise at rest is within 0.5 %% of its peak, else a "
               "4-pole Bessel low-pass at K/D); the Specification sheet's 'record' field")


def add_spec_options(p, cfc=True):
    """The specification's options; ``cfc`` False where the command's recording options
    already give ``--cfc`` (accept), the record judged all the same."""
    from .recording_options import CfcOption, RecordAlias, cfc_value, record_value
    from .vocabulary import Once

    g = p.add_argument_group("specification (override the shot's Specification sheet and the"
                             " profile, field by field)")
    g.add_argument("--profile", action=Once, metavar="NAME|FILE.json",
                   help="a tolerance profile: a JSON file of specification fields, or the name"
                        " of one shipped (mil-std-810h-half-sine, quoted, not checked)")
    g.add_argument("--shape", action=Once, metavar="|".join(SHAPES), help="the nominal pulse shape")
    g.add_argument("--peak", action=Once, metavar="PEAK[:TOL]",
                   help="nominal peak and tolerance: 12kG:10%% or 11750g:-10%%,+20%% (units "
                        "kG, g, m/s^2)")
    g.add_argument("--duration", action=Once, metavar="DURATION[:TOL]",
                   help="nominal duration (the shape's base) and tolerance: 0.3ms:10%% "
                        "(units s, ms, us, ns)")
    g.add_argument("--velocity-change", action=Once, metavar="DV[:TOL]",
                   help="nominal velocity change and tolerance: 35m/s:10%%")
    g.add_argument("--corridor", action=Once, metavar="PCT",
                   help="corridor half-width round the ideal pulse, %% of the nominal peak: "
                        "20%%")
    g.add_argument("--time-slack", action=Once, metavar="PCT",
                   help="time slack of the corridor, %% of the duration: 10%% (default 0%%)")
    g.add_argument("--dv-window", action=Once, metavar="BEFORE,AFTER",
                   help="the velocity change's window before and after the pulse, in time or"
                        " in nominal durations: 0.4D,0.1D or 1ms,0.5ms (default 0.5D,0.5D)")
    g.add_argument("--monitor", action=Once, metavar="BEFORE,AFTER",
                   help="the corridor's monitoring window before and after the pulse: "
                        "0.5D,2D (default 1D,1D)")
    g.add_argument("--window", action=Once, metavar="DURATION",
                   help="(alias for one release) both windows, the same each side: 0.5ms")
    g.add_argument("--duration-def", action=Once, metavar="|".join(DURATION_DEFS),
                   help="the duration judged: each shape's base (a sawtooth's rise; the "
                        "default) or the width at 10%% of the peak")
    g.add_argument("--decay", action=Once, metavar="PCT",
                   help="the terminal-peak sawtooth's decay allowance, %% of the duration: "
                        "10%% (the default)")
    g.add_argument("--placement", action=Once, metavar="|".join(PLACEMENTS),
                   help="where the ideal pulse sits: least squares (default) or on the peak")
    if cfc:
        g.add_argument("--cfc", type=cfc_value, default=None, metavar="N|none",
                       action=CfcOption, help=RECORD_HELP)
    g.add_argument("--record", type=record_value, metavar="unfiltered|cfcN", dest="cfc",
                   action=RecordAlias)
    g.add_argument("--srs", action=Once, metavar="REQ.csv",
                   help="an SRS requirement (CSV: 'frequency [Hz],srs [g]')")
    g.add_argument("--srs-tol", action=Once, metavar="LO,HI", help="its tolerance in dB: -3dB,+6dB "
                                                      "(default)")
    g.add_argument("--srs-q", action=Once, metavar="Q", help="its quality factor (default 10)")
    g.add_argument("--srs-outside", action=Once, metavar="PCT",
                   help="%% of its frequencies allowed outside the tolerance: 5%% (default "
                        "0%%)")


def options_spec(args):
    """The specification fields the command line gives, without the profile; None when it
    gives none.

    Raises
    ------
    airgun_xl.errors.OptionError
        Naming the option and what it expects.
    """
    from ..readers.recording import read_spectrum
    from ..specification import (
        ALIASES,
        KEYS,
        OPTIONS,
        SHOWN_UNITS,
        SrsRequirement,
        cfc_record,
        parse_db_pair,
        parse_window,
        spec_of_keys,
        typed_unit,
    )

    parsed = {}
    for key, option in QUANTITY_OPTIONS:
        text = getattr(args, key, None)
        if text is not None:
            parsed.update(_quantity_option(key, option, text))
    for key, option in PLAIN_OPTIONS:
        text = getattr(args, key, None)
        if text is not None:
            parsed[key] = KEYS[key].parse(text, option)
    if getattr(args, "window", None) is not None:  # the alias: what the options do not say
        window = parse_window(args.window, "--window")
        for key in ALIASES["window"]:
            parsed.setdefault(key, window)
    if getattr(args, "cfc_given", None):  # --cfc none: the unfiltered record, said
        parsed["record"] = cfc_record(args.cfc)
    if getattr(args, "srs_tol", None) is not None:
        parsed["srs_lower_db"], parsed["srs_upper_db"] = parse_db_pair(args.srs_tol)
    srs = None
    if getattr(args, "srs", None) is not None:
        freqs, levels = read_spectrum(args.srs, getattr(args, "accel_unit", None))
        srs = SrsRequirement(tuple(map(float, freqs)), tuple(map(float, levels)))
    if not parsed and srs is None:
        return None
    units = {key: typed_unit(getattr(args, key)) for key, _ in QUANTITY_OPTIONS
             if key in SHOWN_UNITS and getattr(args, key, None) is not None}
    places = {key: option for key, option in OPTIONS.items() if key in parsed}
    if "record" in parsed:
        places["record"] = args.cfc_given  # --cfc, or its old spelling as typed
    if getattr(args, "window", None) is not None:
        places.update({k: "--window" for k in ALIASES["window"] if k not in places or
                       getattr(args, k, None) is None})
    return spec_of_keys(parsed, "options", srs, {**places, "srs": "--srs"}, units)


def _quantity_option(key, option, text):
    """``12kG:10%`` -> {key: 12.0, key_tolerance: (0.1, 0.1)}; ``12kG`` -> the nominal only
    (its tolerance from the sheet or the profile)."""
    from ..specification import KEYS

    value, sep, tolerance = str(text).partition(":")
    parsed = {key: KEYS[key].parse(value, option)}
    if sep:
        parsed[f"{key}_tolerance"] = KEYS[f"{key}_tolerance"].parse(tolerance, option)
    return parsed


def resolve_spec(shot, args):
    """The specification a command judges by: the profile, then the shot's sheet, then the
    options, each overriding the one before field by field; None when nothing is specified.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    from ..specification import combine

    return combine(args.profile, shot.spec, options_spec(args))
