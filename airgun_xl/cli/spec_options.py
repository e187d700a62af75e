"""The specification options, defined once for every command that judges a pulse (fill,
design, accept): a profile, then the fields, each overriding the shot's Specification sheet.

Every value is read by the specification's grammar (:data:`airgun_xl.specification.KEYS`),
the one the profile and the sheet use; a value an option gives overrides the sheet's and the
profile's even when it equals the default (``--time-slack 0%``)."""
from ..app.specifying import PLAIN_OPTIONS, QUANTITY_OPTIONS  # noqa: F401 (the CLI's names)
from ..specification import DURATION_DEFS, PLACEMENTS, SHAPES

#: The help of the record judged, where ``--cfc`` is a field of the specification.
RECORD_HELP = ("the record judged: N through SAE J211 CFC N (60, 180, 600 or 1000), none "
               "the unfiltered record; given by no source, the tool's default (a 4-pole "
               "Bessel low-pass at K/D, whatever the record's noise); the Specification "
               "sheet's 'record' field")


def add_spec_options(p, cfc=True):
    """The specification's options; ``cfc`` False where the command's recording options
    already give ``--cfc`` (accept), the record judged all the same."""
    from .cfc_option import CfcOption, RecordAlias, cfc_value, record_value
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
    _add_windows(g)
    if cfc:
        g.add_argument("--cfc", type=cfc_value, default=None, metavar="N|none",
                       action=CfcOption, help=RECORD_HELP)
    g.add_argument("--record", type=record_value, metavar="unfiltered|cfcN", dest="cfc",
                   action=RecordAlias)
    _add_srs(g)


def _add_windows(g):
    """Where the velocity change and the corridor are judged, and how the pulse is read."""
    from .vocabulary import Once

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


def _add_srs(g):
    """An SRS requirement and its tolerance."""
    from .vocabulary import Once

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
    gives none (:func:`airgun_xl.app.specifying.options_spec`).

    Raises
    ------
    airgun_xl.errors.OptionError
        Naming the option and what it expects.
    """
    from ..app.specifying import SpecFields, options_spec

    return options_spec(SpecFields.of(args))


def resolve_spec(shot, args):
    """The specification a command judges by: the profile, then the shot's sheet, then the
    options (:func:`airgun_xl.app.specifying.resolve`); None when nothing is specified.

    Raises
    ------
    airgun_xl.errors.OptionError
    """
    from ..app.specifying import SpecFields, resolve

    return resolve(shot, SpecFields.of(args))
