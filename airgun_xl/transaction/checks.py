"""Output names a command may write: a new regular file, in a writable folder, not an input;
and how a path is shown in a message."""
import contextlib
import os
import stat
from pathlib import Path

from ..errors import OutputError


def display(path):
    """A path as printable text (undecodable bytes of a name become \\x escapes)."""
    return os.fsdecode(path).encode("utf-8", "backslashreplace").decode("utf-8")


_KINDS = ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def special_kind(mode):
    """``"a FIFO"``, ``"a character device"``... for a file that is neither a regular file,
    a folder nor a symlink; None otherwise."""
    return next((kind for test, kind in _KINDS if test(mode)), None)


def check_output(path, force=False, inputs=(), suffixes=(".xlsx",), force_word="--force"):
    """Refuse an output that cannot be written as a new regular file.

    Refused: a name without one of ``suffixes``; a folder, FIFO, device or socket; an
    existing file or symlink without ``force`` (with it, a symlink itself is replaced, never
    its target); one of ``inputs``; a missing or read-only folder.

    Raises
    ------
    OutputError
    """
    path = Path(path)
    shown = display(path)
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise OutputError(f"{shown}: cannot be checked ({exc.strerror})") from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{shown}: is a folder, expected an output file name")
        kind = special_kind(st.st_mode)
        if kind is not None:
            raise OutputError(f"{shown}: is {kind}, expected a regular file name")
        if not force:
            link = " (a symbolic link)" if stat.S_ISLNK(st.st_mode) else ""
            raise OutputError(f"{shown}: already exists{link}, expected a new file name or "
                              f"{force_word}")
    if suffixes and path.suffix.lower() not in suffixes:
        raise OutputError(f"{shown}: has the extension {path.suffix or '(none)'!s}, expected "
                          f"{' or '.join(suffixes)}")
    for given in inputs:
        with contextlib.suppress(OSError):
            if os.path.exists(path) and os.path.samefile(path, given):
                raise OutputError(f"{shown}: is the input workbook, expected a different "
                                  "output file (the input is never modified)")
    folder = path.parent
    if not folder.is_dir():
        raise OutputError(f"{shown}: its folder {display(folder)} does not exist, expected an "
                          "existing folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{shown}: its folder {display(folder)} is not writable, expected a "
                          "writable folder")


def same_folder(a, b):
    """Whether files ``a`` and ``b`` name one folder, by whatever path (``x/`` and
    ``/abs/x/``, a symlinked folder): two missing folders compare by their names."""
    first, second = Path(a).parent, Path(b).parent
    try:
        return os.path.samefile(first, second)
    except OSError:
        return os.path.abspath(first) == os.path.abspath(second)
