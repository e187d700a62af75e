"""The archive of shots: every run kept with its inputs, outputs and provenance.

- :mod:`.store`: the folder, its entries and how they are committed (light: the standard
  library only, so ``history`` and ``show`` start fast);
- :mod:`.index`: the index, in the folder (SQLite) or on a PostgreSQL server;
- :mod:`.agent`: the helper process that holds a server index's connections (psycopg loads
  there, beside the command);
- :mod:`.entry`: what a fill puts in an entry (imported by the fill when it archives);
- :mod:`.laws`: the library of fitted crush laws, kept by name (calibrate stores, fill runs).
"""
from .index import INDEX_ENV
from .store import (
    ENV,
    FORMAT,
    INDEX,
    MANIFEST,
    MARKER,
    SCRATCH,
    Archive,
    Entry,
    PendingEntry,
    archive_dir,
    safe_name,
    sha256,
)

__all__ = ["ENV", "INDEX_ENV", "FORMAT", "INDEX", "MANIFEST", "MARKER", "SCRATCH", "Archive",
           "Entry", "PendingEntry", "archive_dir", "safe_name", "sha256"]
