"""The ``airgun-xl`` command: parses arguments and hands off to one module per subcommand."""
import argparse
import os
import sys

from .. import __version__
from ..errors import AirgunXlError, OptionError
from . import archive, check, convergence, design, diff, fill, sweep, template

COMMANDS = (fill, diff, archive, check, convergence, design, sweep, template)


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage mistake becomes one line through the error tree."""

    def error(self, message):
        raise OptionError(f"{self.prog}: {message}")


def build_parser():
    parser = _Parser(prog="airgun-xl",
                     description="ArtSim air gun impact simulation, from the report's workbook "
                                 "to a new workbook.")
    parser.add_argument("--version", action="version", version=f"airgun-xl {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for module in COMMANDS:
        module.add_parser(sub)
    return parser


def main(argv=None):
    """Run the CLI; return the exit code (0 ok, 2 bad input)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        args.argv = ["airgun-xl", *(sys.argv[1:] if argv is None else argv)]
        if args.command is None:
            parser.print_help()
            return 2
        return args.run(args)
    except AirgunXlError as exc:
        print(f"airgun-xl: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("airgun-xl: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `airgun-xl history | head`
        sys.stdout = open(os.devnull, "w")
        return 0


def warn(messages):
    """Print warnings, one line each, to stderr."""
    for message in messages:
        print(f"airgun-xl: warning: {message}", file=sys.stderr)
