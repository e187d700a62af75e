"""The command's signal state: SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` where
the program is, so that cleanup runs, or are held back during a commit."""
import contextlib
from typing import Any


class Interrupted(KeyboardInterrupt):
    """SIGINT, SIGTERM or SIGHUP, raised where the program is, so that cleanup runs."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum
        self.rows: list = []  # a campaign's rows so far, when it stopped one


#: The signal state of this command: sections holding signals back, a signal that arrived
#: while held (or was swallowed by a finalizer), and whether a publication has committed.
SIGNALS: dict[str, Any] = {"held": 0, "pending": None, "committed": False}


def reset_signals():
    SIGNALS.update(held=0, pending=None, committed=False)


def on_signal(signum, frame=None):
    """The handler the CLI installs for SIGINT, SIGTERM and SIGHUP: raise :class:`Interrupted`,
    or, inside :func:`signals_held`, note the signal for the end of the section. Python runs
    it in the main thread, whichever thread the signal reached."""
    if SIGNALS["held"]:
        SIGNALS["pending"] = signum
        return
    raise Interrupted(signum)


def note_signal(signum):
    """A signal whose :class:`Interrupted` was swallowed (raised inside a finalizer)."""
    SIGNALS["pending"] = signum


@contextlib.contextmanager
def signals_held():
    """Hold SIGINT, SIGTERM and SIGHUP back (see :func:`on_signal`); one that arrived is
    raised when the section ends normally."""
    SIGNALS["held"] += 1
    try:
        yield
    finally:
        SIGNALS["held"] -= 1
    if not SIGNALS["held"] and SIGNALS["pending"] is not None:
        signum, SIGNALS["pending"] = SIGNALS["pending"], None
        raise Interrupted(signum)
