"""What a command says on stderr: one line each, a progress bar's line cleared first, a
warning given once per command. Every subcommand's module prints through these."""
import sys


def _say(text):
    """One line to stderr, whatever the file names and records in it hold: a control
    character (an escape sequence in a profile's notes) shown as an escape, never sent to
    the terminal."""
    from ..untrusted_json import printable
    from .progress import clear_line

    stream = sys.stderr
    clear_line(stream)  # a progress bar's line
    encoding = getattr(stream, "encoding", None) or "utf-8"
    print(printable(text).encode(encoding, "backslashreplace").decode(encoding, "replace"),
          file=stream)


_WARNED: set = set()


_LATER: list = []


def later(messages):
    """Notices to print once the command has succeeded (an old spelling's): a refusal stays
    one line."""
    _LATER.extend(m for m in messages if m not in _LATER)


def say_later():
    """Print the notices held by :func:`later`, and forget them."""
    held = list(_LATER)
    _LATER.clear()
    note(held)


def note(messages):
    """Print notices (what a run will cost, before it starts), one line each, to stderr;
    none with ``--quiet``."""
    from .progress import QUIET

    if QUIET:
        return
    for message in messages:
        _say(f"airgun-xl: note: {message}")


def warn(messages):
    """Print warnings, one line each, to stderr; a warning already given by this command is
    not repeated (design warns about its solution, then the fill of it does)."""
    for message in messages:
        line = f"airgun-xl: warning: {message}"
        if line not in _WARNED:
            _WARNED.add(line)
            _say(line)


def report(outcome, lines, as_json=False, code=0):
    """Print a command's outcome (its JSON document with ``--json``, else ``lines``, each
    made printable), then its warnings on stderr; return ``code``, the exit status."""
    from ..untrusted_json import printable

    print(outcome.to_json() if as_json else "\n".join(printable(line) for line in lines))
    warn(list(outcome.warnings))
    return code
