"""The options of a measured recording, defined once for every command that reads one
(compare-measured, calibrate): its channel, units, sign, the CFC filter and the recorder's
anti-alias model."""
import argparse

from ..app.declared import RECORDING_HELP
from .cfc_option import CfcOption, cfc_value

__all__ = ["RECORDING_HELP"]


def sign_value(text):
    """``--sign``: 1 or -1 (``+1``, ``1.0`` and ``-1.0`` read the same) [-]."""
    try:
        value = float(text)
    except ValueError:
        value = None
    if value not in (1.0, -1.0):
        raise argparse.ArgumentTypeError(f"found {text!r}, expected 1 or -1")
    return value


def anti_alias_value(text):
    """``--anti-alias``: a frequency in Hz, ``auto`` or ``none`` (checked against the rates
    once they are known: studies.measured.check_anti_alias)."""
    lowered = str(text).strip().lower()
    if lowered in ("auto", "none"):
        return lowered
    try:
        return float(text)
    except ValueError:
        return text  # refused by check_anti_alias, naming the option


#: The help of a command's recording argument (compare-measured, accept).


def add_recording_options(p, channel_help="the channel of a file of several (TDMS, .mat, .mf4, "
                                          ".uff, .mme): "
                                          "its name, or its number as 'airgun-xl recording "
                                          "FILE' lists it (default: the first)",
                          anti_alias=True,
                          cfc_help=None):
    """The recording's options; ``anti_alias`` False for a command with no prediction to put
    through the recorder's filter (accept: the option would be accepted and ignored)."""
    from ..app.declared import EventFields
    from .declared import add_declared

    p.add_argument("--channel", metavar="NAME|N", help=channel_help)
    add_declared(p, EventFields)
    p.add_argument("--cfc", type=cfc_value, default=None, metavar="N|none", action=CfcOption,
                   help=cfc_help or "filter both pulses: SAE J211 class 60, 180, 600 or 1000, "
                        "or none (the default) "
                        "(refused where the filter is unstable, below 4.155 x the class in "
                        "samples a second; a warning below J211's 10 x)")
    p.add_argument("--sign", type=sign_value, default=1.0, metavar="1|-1",
                   help="1 (the default), or -1 when the recorder's axis is opposite to the "
                        "macro's")
    p.add_argument("--time-unit", help="s, ms or us (default: from the header)")
    p.add_argument("--accel-unit", help="g, kG or m/s^2 (default: from the header); g is "
                                        "standard gravity, 9.80665 m/s^2")
    if not anti_alias:
        return
    p.add_argument("--anti-alias", type=anti_alias_value, default="auto", metavar="HZ",
                   help="the recorder's anti-alias filter, modelled on the prediction as a "
                        "4-pole Butterworth at HZ: auto (a fifth of the record's rate, the "
                        "default), a frequency, or none")
