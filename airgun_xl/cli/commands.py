"""The argument parser: one subparser per subcommand module, each of which hands off."""
import argparse
import re

from ..errors import OptionError
from ..version import __version__
from . import (
    accept,
    archive,
    calibrate,
    check,
    compare_measured,
    convergence,
    design,
    diff,
    fill,
    srs,
    sweep,
    template,
)
from .spec_options import PLAIN_OPTIONS, QUANTITY_OPTIONS

COMMANDS = (fill, diff, archive, check, convergence, design, sweep, srs, compare_measured,
            calibrate, accept, template)


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake becomes one line through the error tree."""

    def error(self, message):  # "fill: the following arguments are required: SHOT.xlsx"
        command = self.prog.removeprefix("airgun-xl").strip()
        raise OptionError(f"{command}: {message}" if command else message)


#: Options whose value may start with a minus sign as typed (``--srs-tol -3dB,+6dB``, and
#: ``--time-slack -1%``, refused by the grammar with its reason), which argparse would take
#: for an option.
DASHED_VALUES = ("--srs-tol", "--window",
                 *(option for _, option in QUANTITY_OPTIONS + PLAIN_OPTIONS))


def joined_values(argv):
    """``argv`` with ``--srs-tol -3dB,+6dB`` joined as ``--srs-tol=-3dB,+6dB``: a value
    that starts with a minus and a digit or a point."""
    out, k = [], 0
    while k < len(argv):
        if argv[k] in DASHED_VALUES and k + 1 < len(argv) and re.match(r"-[\d.]",
                                                                         argv[k + 1]):
            out.append(f"{argv[k]}={argv[k + 1]}")
            k += 2
        else:
            out.append(argv[k])
            k += 1
    return out


def build_parser():
    parser = _Parser(prog="airgun-xl",
                     description="ArtSim air gun impact simulation, from the report's workbook "
                                 "to a new workbook.")
    parser.add_argument("--version", action="version", version=f"airgun-xl {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for module in COMMANDS:
        module.add_parser(sub)
    return parser
