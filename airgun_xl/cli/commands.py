"""The argument parser: one subparser per subcommand module, each of which hands off."""
import argparse
import difflib
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
    next_shot,
    recording,
    serve,
    srs,
    sweep,
    template,
)
from .spec_options import PLAIN_OPTIONS, QUANTITY_OPTIONS

COMMANDS = (fill, diff, archive, check, convergence, design, sweep, srs, compare_measured,
            calibrate, accept, next_shot, recording, serve, template)


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake becomes one line through the error tree."""

    def error(self, message):  # "fill: the following arguments are required: SHOT.xlsx"
        command = self.prog.removeprefix("airgun-xl").strip()
        raise OptionError(f"{command}: {message}" if command else message)

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but an argument no parser knows is refused by the command it was
        given to, with the nearest option it has (``fill: unrecognized arguments: --forse
        (did you mean --force?)``)."""
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            parser, sub = self, self._subcommand(parsed)
            while sub is not None:  # archive verify: the innermost command given
                parser, sub = sub, sub._subcommand(parsed)
            message = f"unrecognized arguments: {' '.join(extras)}"
            hints = [difflib.get_close_matches(extra.partition("=")[0], parser.options(), 1,
                                               0.75) for extra in extras
                     if extra.startswith("-")]
            hint = next((h[0] for h in hints if h), None)
            parser.error(message + (f" (did you mean {hint}?)" if hint else ""))
        return parsed

    def _subcommand(self, parsed):
        """The parser of the subcommand ``parsed`` names (None when there is none)."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                return action.choices.get(getattr(parsed, action.dest, None) or "")
        return None

    def options(self):
        """Every option string this parser takes (``--force``, ``-o``)."""
        return [s for action in self._actions for s in action.option_strings]


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
    for command in sub.choices.values():  # every command, the same way
        command.add_argument("--quiet", action="store_true",
                             help="print nothing but warnings and errors (and --json's "
                                  "document): no figures, notices or progress bar; the exit "
                                  "status is the same")
    return parser
