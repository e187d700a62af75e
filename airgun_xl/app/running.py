"""Where a study's shots run: this machine's batch kernel, or a Dask cluster (shared by
sweep and design)."""
from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from ..errors import OptionError


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
    if scheduler is None and workers is None:
        if chunk is not None:
            raise OptionError("--chunk: found it without --scheduler or --workers, expected "
                              "one of them (chunks are for a cluster)")
        yield None
        return
    from ..studies.cluster import DEFAULT_CHUNK, ClusterRunner, connect

    client, close = connect(scheduler, workers)
    try:
        yield ClusterRunner(client, chunk if chunk is not None else DEFAULT_CHUNK)
    finally:
        close()
