"""Named stages of a command, where a fault test can stop it: the tests' way to send a signal
or a kill at a known point, never after a guessed time (issue 43).

With ``$AIRGUN_XL_STAGES`` naming a folder, a command reaching stage NAME writes
``NAME.reached`` there (its process id in it), then waits while ``NAME.hold`` exists: a test
creates the hold files of the stages it means to interrupt, waits for ``NAME.reached`` to
appear, sends its signal, and removes the hold. A signal arrives in the wait as it would in
the work at that point (or is held back, where the command holds signals). Without the
variable a stage costs one environment lookup.

The stages (:data:`STAGES`): ``archive-made`` (a new archive's folder and marker written),
``record-stored`` (a law's or a verdict's record linked into place), ``entry-staged`` (an
archive entry's files written to its scratch folder), ``entry-renamed`` (the entry renamed
into place, its row not yet committed), ``publishing`` (a command's outputs staged as temps,
before the commit), ``published`` (the commit point passed); and ``next``'s own, after each
of its records: ``next-law-stored``, ``next-verdict-stored``, ``next-proposal-stored`` (its
commit point passed).
"""
import os
import time
from pathlib import Path

#: The environment variable naming the folder of the stage files.
STAGES_ENV = "AIRGUN_XL_STAGES"

STAGES = ("archive-made", "record-stored", "entry-staged", "entry-renamed", "publishing",
          "published", "next-law-stored", "next-verdict-stored", "next-proposal-stored")

#: How often a held stage looks for its hold file to go [s].
POLL = 0.002


def stage(name: str) -> None:
    """Mark stage ``name`` as reached and wait while its hold file exists (only with
    ``$AIRGUN_XL_STAGES`` set)."""
    folder = os.environ.get(STAGES_ENV)
    if not folder:
        return
    path = Path(folder)
    try:
        (path / f"{name}.reached").write_text(str(os.getpid()))
    except OSError:
        return
    hold = path / f"{name}.hold"
    while hold.exists():
        time.sleep(POLL)
