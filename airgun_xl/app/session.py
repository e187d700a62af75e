"""A command's process: how signals and a full disk behave while it runs.

SIGTERM and SIGHUP raise like SIGINT (:class:`Interrupted`), so temp files go and nothing is
half published; SIGXFSZ is ignored, so a file-size limit (``ulimit -f``) is a write error.
The CLI enters :func:`command_signals` around every command; an embedding program (a
notebook, a server) keeps its own handlers and calls the app's functions directly.
Light at import: the standard library and :mod:`airgun_xl.transaction`.
"""
from __future__ import annotations

import contextlib
import errno
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

from ..transaction import SIGNALS, Interrupted, note_signal, on_signal, reset_signals

__all__ = ["Interrupted", "archive_notices", "command_signals", "interrupt_behind", "late_signal",
           "quiet_full_disk"]


@contextlib.contextmanager
def command_signals(restore: bool = True) -> Iterator[None]:
    """SIGTERM and SIGHUP raise like SIGINT; SIGXFSZ is ignored (in the main thread only).

    Afterwards the handlers are restored, or, for the command itself (``restore=False``),
    the signals are ignored: the work is done, and interpreter shutdown must not turn a late
    Ctrl-C into a traceback."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    wanted: dict[Any, Any] = {getattr(signal, n): on_signal
                              for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)}
    if hasattr(signal, "SIGXFSZ"):
        wanted[signal.SIGXFSZ] = signal.SIG_IGN
    reset_signals()
    saved = {s: signal.signal(s, h) for s, h in wanted.items()}
    hook = sys.unraisablehook

    def swallowed(unraisable: Any) -> None:  # an interrupt inside a finalizer: kept for later
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


def interrupt_behind(exc: BaseException | None) -> Interrupted | None:
    """The :class:`Interrupted` a signal raised inside an import, which the importing module
    (numpy, for one) turned into an ImportError; None when there is none."""
    seen = 0
    while exc is not None and seen < 20:
        if isinstance(exc, Interrupted):
            return exc
        exc = exc.__cause__ or exc.__context__
        seen += 1
    return None


def late_signal() -> int | None:
    """The signal that arrived after the command's outputs were complete (nothing lost), or
    None."""
    pending = SIGNALS["pending"]
    return int(pending) if pending is not None and SIGNALS["committed"] else None


#: Write errors a full disk or ``ulimit -f`` gives: already said in one line by the command.
_FULL = (errno.EFBIG, errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))


def quiet_full_disk(hook: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """An unraisable-exception hook that drops a full disk's second report: a zip file the
    failed write left open retries its flush when it is collected (ZipFile.__del__), and would
    print a traceback after the one-line error (issue 23.16)."""
    def quiet(unraisable: Any) -> None:
        error = unraisable.exc_value
        if isinstance(error, OSError) and error.errno in _FULL:
            return
        hook(unraisable)
    return quiet


def archive_notices() -> list[str]:
    """What the archive's index noticed while the command ran (a server role that may rewrite
    history), taken so that the next in-process command starts clean; [] when no archive
    was opened (the index is not loaded for that)."""
    index = sys.modules.get("airgun_xl.archive.index")
    return list(index.take_notices()) if index is not None else []
