"""The ``airgun-xl`` command: parses arguments and hands off to one module per subcommand.

Exit codes: 0 done, 1 a comparison found differences, 2 bad input (one line on stderr, nothing
written), 128 + N for signal N. SIGTERM and SIGHUP clean up like Ctrl-C (temp files go, nothing
is half published); SIGXFSZ is ignored, so a file-size limit (``ulimit -f``) is a write error.
"""
import argparse
import contextlib
import os
import signal
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


class Interrupted(KeyboardInterrupt):
    """A termination signal, raised where the program is, so that cleanup runs."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _raise_interrupted(signum, frame):
    raise Interrupted(signum)


@contextlib.contextmanager
def _signals():
    """SIGTERM and SIGHUP raise like SIGINT; SIGXFSZ is ignored (in the main thread only)."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    wanted = {getattr(signal, n): _raise_interrupted for n in ("SIGTERM", "SIGHUP")
              if hasattr(signal, n)}
    if hasattr(signal, "SIGXFSZ"):
        wanted[signal.SIGXFSZ] = signal.SIG_IGN
    saved = {s: signal.signal(s, h) for s, h in wanted.items()}
    try:
        yield
    finally:
        for s, h in saved.items():
            signal.signal(s, h)


def _say(text):
    """One line to stderr, whatever the file names in it hold."""
    stream = sys.stderr
    encoding = getattr(stream, "encoding", None) or "utf-8"
    print(text.encode(encoding, "backslashreplace").decode(encoding, "replace"), file=stream)


def main(argv=None):
    """Run the CLI; return the exit code (0 ok, 1 differences, 2 bad input, 128+N signal N)."""
    for stream in (sys.stdout, sys.stderr):  # a file name may hold undecodable bytes
        with contextlib.suppress(AttributeError, ValueError, OSError):
            stream.reconfigure(errors="backslashreplace")
    parser = build_parser()
    try:
        with _signals():
            args = parser.parse_args(argv)
            args.argv = ["airgun-xl", *(sys.argv[1:] if argv is None else argv)]
            if args.command is None:
                parser.print_help()
                return 2
            return args.run(args)
    except AirgunXlError as exc:
        _say(f"airgun-xl: error: {exc}")
        return exc.exit_code
    except Interrupted as exc:
        _say(f"airgun-xl: stopped by signal {exc.signum}; nothing was left half-written")
        return 128 + exc.signum
    except KeyboardInterrupt:
        _say("airgun-xl: interrupted; nothing was left half-written")
        return 130
    except BrokenPipeError:  # e.g. `airgun-xl history | head`
        sys.stdout = open(os.devnull, "w")
        return 0


def warn(messages):
    """Print warnings, one line each, to stderr."""
    for message in messages:
        _say(f"airgun-xl: warning: {message}")
