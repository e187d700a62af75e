"""All-or-nothing output, in five small modules:

- :mod:`.checks`: which output names a command may write (``check_output``), ``display``;
- :mod:`.owners`: who owns a temp file (pid and start time, by psutil on every platform);
- :mod:`.locks`: the output folder's lock, and fsync;
- :mod:`.signals`: the command's signal state (``Interrupted``, signals held at a commit);
- :mod:`.publication`: staging, publishing and recovering a command's files together
  (``Publication``, ``atomic_path``, ``recover``).
"""
from .checks import check_output, display, same_folder, special_kind
from .locks import folder_lock, fsync
from .owners import owner_alive, owner_token
from .publication import SUFFIX, Publication, atomic_path, commit_after, for_file, recover
from .signals import (
    SIGNALS,
    Interrupted,
    note_signal,
    on_signal,
    reset_signals,
    signals_held,
)

__all__ = ["SIGNALS", "SUFFIX", "Interrupted", "Publication", "atomic_path", "check_output",
           "commit_after", "display", "folder_lock", "for_file", "fsync", "note_signal",
           "on_signal", "owner_alive", "owner_token", "recover", "reset_signals",
           "same_folder", "signals_held", "special_kind"]
