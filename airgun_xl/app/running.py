"""Where a study's shots run (this machine's batch kernel, or a Dask cluster) and how their
progress is told: shared by sweep and design."""
from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any

from ..errors import OptionError


def check_cluster(scheduler: str | None = None, workers: int | None = None,
                  chunk: int | None = None) -> None:
    """Refuse ``chunk`` without a cluster: called before any work (and by
    :func:`cluster_runner`)."""
    if scheduler is None and workers is None and chunk is not None:
        raise OptionError("--chunk: found it without --scheduler or --workers, expected one "
                          "of them (chunks are for a cluster)")


@contextlib.contextmanager
def cluster_runner(scheduler: str | None = None, workers: int | None = None,
                   chunk: int | None = None) -> Iterator[Any]:
    """None (this machine's batch kernel) or a
    :class:`~airgun_xl.studies.cluster.ClusterRunner` on the cluster at ``scheduler`` (an
    address) or on a local one of ``workers`` processes, ``chunk`` shots a task; shut down
    on leaving.

    Raises
    ------
    airgun_xl.errors.OptionError
        ``chunk`` without a cluster.
    """
    check_cluster(scheduler, workers, chunk)
    if scheduler is None and workers is None:
        yield None
        return
    from ..studies.cluster import DEFAULT_CHUNK, ClusterRunner, connect

    client, close = connect(scheduler, workers)
    try:
        yield ClusterRunner(client, chunk if chunk is not None else DEFAULT_CHUNK)
    finally:
        close()


@contextlib.contextmanager
def shots_progress(progress_for: Callable[[int], Any] | None,
                   total: int) -> Iterator[Callable[[int], None] | None]:
    """The callback ``progress_for`` makes for ``total`` shots (None without one): its
    ``advance``, told ``k`` as ``k`` shots end (or the callback itself, if a plain
    function); closed on leaving, if it has ``close``."""
    made = progress_for(total) if progress_for is not None else None
    try:
        yield getattr(made, "advance", made)
    finally:
        close = getattr(made, "close", None)
        if close is not None:
            close()
