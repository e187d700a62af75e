"""The ``airgun-xl`` command: parses arguments and hands off to one module per subcommand.

Exit codes: 0 done, 1 a comparison found differences, 2 bad input (one line on stderr, nothing
written), 3 a shot or a design that fails its specification (accept, design --confidence),
128 + N for signal N. SIGTERM and SIGHUP clean up like Ctrl-C (temp files go, nothing
is half published); SIGXFSZ is ignored, so a file-size limit (``ulimit -f``) is a write error.
"""
import contextlib
import os
import sys
import warnings

from ..app.session import (
    Interrupted,
    archive_notices,
    command_signals,
    interrupt_behind,
    late_signal,
    quiet_full_disk,
)
from ..errors import AirgunXlError
from .messages import _LATER, _WARNED, _say, note, say_later, warn

__all__ = ["main", "note", "warn"]


def _run(args):
    """The command, its stdout silenced with ``--quiet`` (but for ``--json``'s document),
    and no notice or progress bar."""
    from .progress import QUIET

    if not getattr(args, "quiet", False):
        return args.run(args)
    QUIET[:] = [True]
    try:
        if getattr(args, "json", False):
            return args.run(args)
        with contextlib.redirect_stdout(open(os.devnull, "w")) as sink:
            try:
                return args.run(args)
            finally:
                sink.close()
    finally:
        QUIET.clear()


def _fresh(argv):
    """What an earlier in-process command left is forgotten; the streams take any name."""
    _WARNED.clear()
    _LATER.clear()
    archive_notices()  # an earlier in-process command's
    if argv is None:  # the command itself, not a caller's in-process run
        sys.unraisablehook = quiet_full_disk(sys.unraisablehook)
    for stream in (sys.stdout, sys.stderr):  # a file name may hold undecodable bytes
        reconfigure = getattr(stream, "reconfigure", None)  # a TextIOWrapper's
        with contextlib.suppress(ValueError, OSError):
            if reconfigure is not None:
                reconfigure(errors="backslashreplace")


def _command(argv):
    """Parse and run the command; after a success, what it must still say."""
    from .commands import build_parser, joined_values

    given = sys.argv[1:] if argv is None else argv
    parser = build_parser()
    args = parser.parse_args(joined_values(given))
    args.argv = ["airgun-xl", *given]
    if args.command is None:  # the usage goes with the exit status, to stderr (23.26)
        parser.print_help(sys.stderr)
        return 2
    with warnings.catch_warnings(record=True) as caught:  # libraries' own (23.23)
        warnings.simplefilter("always")
        for developers in (DeprecationWarning, PendingDeprecationWarning, FutureWarning,
                           ImportWarning, ResourceWarning):  # not the user's business
            warnings.simplefilter("ignore", developers)
        code = _run(args)
    say_later()  # an old spelling's note: after a success, a refusal stays one line
    # after a success, said as the tool's own warnings; a refusal drops them (one line)
    warn(sorted({f"{w.category.__name__} from a library: {str(w.message)[:300]}"
                 for w in caught}))
    warn(archive_notices())  # a server role that may rewrite history
    if late_signal() is not None:
        _say(f"airgun-xl: signal {late_signal()} arrived after the outputs were complete; "
             "nothing was lost")
    return code


def main(argv=None):
    """Run the CLI; return the exit code (0 ok, 1 differences, 2 bad input, 128+N signal N)."""
    _fresh(argv)
    try:
        with command_signals(restore=argv is not None):  # before numpy and the engine load
            return _command(argv)
    except AirgunXlError as exc:
        _say(f"airgun-xl: error: {exc}")
        return exc.exit_code
    except Interrupted as exc:
        _say(f"airgun-xl: stopped by signal {exc.signum}; nothing was left half-written")
        return 128 + exc.signum
    except ImportError as exc:  # a signal during a lazy import: the import reports it
        signal_error = interrupt_behind(exc)
        if signal_error is None:
            raise
        _say(f"airgun-xl: stopped by signal {signal_error.signum}; nothing was left "
             "half-written")
        return 128 + signal_error.signum
    except KeyboardInterrupt:
        _say("airgun-xl: interrupted; nothing was left half-written")
        return 130
    except MemoryError:  # past the estimate (ulimit -v, another process): one line (23.5)
        _say("airgun-xl: error: out of memory during the run; expected a smaller run (fewer "
             "rows, shots or samples) or more memory ($AIRGUN_XL_MEMORY sets the budget the "
             "estimates check); nothing was left half-written")
        return 2
    except BrokenPipeError:  # e.g. `airgun-xl history | head`
        sys.stdout = open(os.devnull, "w")
        return 0
