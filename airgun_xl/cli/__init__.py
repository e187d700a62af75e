"""The ``airgun-xl`` command: parses arguments and hands off to one module per subcommand.

Exit codes: 0 done, 1 a comparison found differences, 2 bad input (one line on stderr, nothing
written), 3 a shot or a design that fails its specification (accept, design --confidence),
128 + N for signal N. SIGTERM and SIGHUP clean up like Ctrl-C (temp files go, nothing
is half published); SIGXFSZ is ignored, so a file-size limit (``ulimit -f``) is a write error.
"""
import contextlib
import errno
import os
import signal
import sys
import warnings

from ..errors import AirgunXlError
from ..transaction import SIGNALS, Interrupted, note_signal, on_signal, reset_signals
from .messages import _LATER, _WARNED, _say, note, say_later, warn

__all__ = ["main", "note", "warn"]


@contextlib.contextmanager
def _signals(restore=True):
    """SIGTERM and SIGHUP raise like SIGINT; SIGXFSZ is ignored (in the main thread only).

    Afterwards the handlers are restored, or, for the command itself (``restore=False``),
    the signals are ignored: the work is done, and interpreter shutdown must not turn a late
    Ctrl-C into a traceback."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    wanted: dict = {getattr(signal, n): on_signal for n in ("SIGINT", "SIGTERM", "SIGHUP")
                    if hasattr(signal, n)}
    if hasattr(signal, "SIGXFSZ"):
        wanted[signal.SIGXFSZ] = signal.SIG_IGN
    reset_signals()
    saved = {s: signal.signal(s, h) for s, h in wanted.items()}
    hook = sys.unraisablehook

    def swallowed(unraisable):  # an interrupt raised inside a finalizer: keep it for later
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            note_signal(getattr(unraisable.exc_value, "signum", signal.SIGINT))
        else:
            hook(unraisable)

    sys.unraisablehook = swallowed
    try:
        yield
    finally:
        for s, h in saved.items():
            signal.signal(s, h if restore else signal.SIG_IGN)
        sys.unraisablehook = hook


def _interrupt_behind(exc):
    """The :class:`Interrupted` a signal raised inside an import, which the importing module
    (numpy, for one) turned into an ImportError; None when there is none."""
    seen = 0
    while exc is not None and seen < 20:
        if isinstance(exc, Interrupted):
            return exc
        exc = exc.__cause__ or exc.__context__
        seen += 1
    return None


#: Write errors a full disk or ``ulimit -f`` gives: already said in one line by the command.
_FULL = (errno.EFBIG, errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))


def _unraisable(hook):
    """An unraisable-exception hook that drops a full disk's second report: a zip file the
    failed write left open retries its flush when it is collected (ZipFile.__del__), and would
    print a traceback after the one-line error (issue 23.16)."""
    def quiet(unraisable):
        error = unraisable.exc_value
        if isinstance(error, OSError) and error.errno in _FULL:
            return
        hook(unraisable)
    return quiet


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


def main(argv=None):
    """Run the CLI; return the exit code (0 ok, 1 differences, 2 bad input, 128+N signal N)."""
    _WARNED.clear()
    _LATER.clear()
    archive_index = sys.modules.get("airgun_xl.archive.index")
    if archive_index is not None:  # an earlier in-process command's
        archive_index.take_notices()
    if argv is None:  # the command itself, not a caller's in-process run
        sys.unraisablehook = _unraisable(sys.unraisablehook)
    for stream in (sys.stdout, sys.stderr):  # a file name may hold undecodable bytes
        reconfigure = getattr(stream, "reconfigure", None)  # a TextIOWrapper's
        with contextlib.suppress(ValueError, OSError):
            if reconfigure is not None:
                reconfigure(errors="backslashreplace")
    try:
        with _signals(restore=argv is not None):  # before numpy and the engine load
            from .commands import build_parser, joined_values

            parser = build_parser()
            args = parser.parse_args(joined_values(sys.argv[1:] if argv is None else argv))
            args.argv = ["airgun-xl", *(sys.argv[1:] if argv is None else argv)]
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
            archive_index = sys.modules.get("airgun_xl.archive.index")  # loaded if used
            if archive_index is not None:
                warn(archive_index.take_notices())  # a server role that may rewrite history
            if SIGNALS["pending"] is not None and SIGNALS["committed"]:
                _say(f"airgun-xl: signal {SIGNALS['pending']} arrived after the outputs were "
                     "complete; nothing was lost")
            return code
    except AirgunXlError as exc:
        _say(f"airgun-xl: error: {exc}")
        return exc.exit_code
    except Interrupted as exc:
        _say(f"airgun-xl: stopped by signal {exc.signum}; nothing was left half-written")
        return 128 + exc.signum
    except ImportError as exc:  # a signal during a lazy import: the import reports it
        signal_error = _interrupt_behind(exc)
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
