"""Atomic file output: write a temporary file beside the target, then rename it into place."""
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

from ..errors import OutputError


def check_output(path, force=False, inputs=()):
    """Refuse an output that exists (without ``force``), is an input, or has no usable folder.

    Raises
    ------
    OutputError
    """
    path = Path(path)
    for given in inputs:
        if Path(given).exists() and path.exists() and path.resolve() == Path(given).resolve():
            raise OutputError(f"{path}: is the input workbook, expected a different output "
                              "file (the input is never modified)")
    if path.exists() and not force:
        raise OutputError(f"{path}: already exists, expected a new file name or --force")
    if path.exists() and path.is_dir():
        raise OutputError(f"{path}: is a folder, expected an output file name")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{path}: its folder {folder} does not exist, expected an existing "
                          "folder")
    if not os.access(folder, os.W_OK):
        raise OutputError(f"{path}: its folder {folder} is not writable, expected a writable "
                          "folder")


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; rename it onto ``path`` only on success."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
