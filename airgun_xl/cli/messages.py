"""What a command says on stderr: one line each, a progress bar's line cleared first, a
warning given once per command. Every subcommand's module prints through these."""
import sys


def _say(text):
    """One line to stderr, whatever the file names in it hold."""
    from .progress import clear_line

    stream = sys.stderr
    clear_line(stream)  # a progress bar's line
    encoding = getattr(stream, "encoding", None) or "utf-8"
    print(text.encode(encoding, "backslashreplace").decode(encoding, "replace"), file=stream)


_WARNED: set = set()


def note(messages):
    """Print notices (what a run will cost, before it starts), one line each, to stderr."""
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
