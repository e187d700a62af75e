"""An exclusive lock on an output folder, and fsync of a file or a folder (shared by the
publication and the archive)."""
import contextlib
import os


@contextlib.contextmanager
def folder_lock(folder):
    """An exclusive ``flock`` on a folder (no lock file is created); a no-op off POSIX."""
    try:
        import fcntl
    except ImportError:  # Windows: publication is still atomic per file
        yield
        return
    fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def fsync(path, directory=False):
    """Flush ``path`` (a file, or a folder's entries with ``directory``) to disk; where the
    platform cannot (a folder on Windows), nothing."""
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
