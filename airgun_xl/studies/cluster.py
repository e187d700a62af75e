"""Studies past one machine: the shots on a Dask cluster.

The shots are cut into chunks in order; each chunk runs :func:`airgun_xl.engine.batch.run_batch`
on a worker and sends back only its figures (a few floats a shot, never a history). The chunks
come back in order, and a shot's figures do not depend on which chunk it ran in, so the result
equals the local run's bit for bit whatever the chunking. A worker lost mid-run is Dask's
business: its chunks run again elsewhere (up to ``allowed-failures`` times), and each shot is
counted once because each chunk's result is gathered once.

``distributed`` is imported only here, when a cluster is asked for (it costs 0.7 s).
"""
import os
import re

import numpy as np

from ..errors import OptionError

#: Shots a chunk: large enough that a task's overhead (about 1 ms) is small against its run
#: (512 shot-A shots at 0.5 µs: 0.2 s), small enough to spread 10,000 shots over many workers.
DEFAULT_CHUNK = 512

#: How long to wait for a scheduler before saying it does not answer.
CONNECT_TIMEOUT = "5s"


def run_chunk(params, integrator, host, extra=None):
    """One chunk on a worker: the batch kernel on one thread (the worker's threads run other
    chunks); returns (figures, diverged, kernel statistics, extras) only."""
    from ..engine.batch import run_batch

    batch = run_batch(params, integrator, host, threads=1, extra=extra)
    return batch.figures, batch.diverged, batch.stats, batch.extras


class ClusterRunner:
    """Runs a list of shots on a Dask cluster, with :func:`run_batch`'s interface.

    Parameters
    ----------
    client : distributed.Client
    chunk : int
        Shots a task.
    """

    def __init__(self, client, chunk=DEFAULT_CHUNK):
        if chunk < 1:
            raise OptionError(f"chunk: found {chunk!r}, expected a positive number of shots")
        self.client, self.chunk = client, int(chunk)

    def __call__(self, params, integrator="legacy", host="excel", progress=None, extra=None):
        from distributed import as_completed

        from ..engine.batch import FIGURES, Batch

        params = list(params)
        if not params:
            return Batch(np.zeros((0, len(FIGURES))), np.zeros(0, dtype=bool), [],
                         None if extra is None else np.zeros((0, extra.width)))
        starts = range(0, len(params), self.chunk)
        futures = [self.client.submit(run_chunk, params[i:i + self.chunk], integrator, host,
                                      extra, pure=False) for i in starts]
        index = {f.key: n for n, f in enumerate(futures)}
        parts: list = [None] * len(futures)
        for future in as_completed(futures):
            n = index[future.key]
            parts[n] = future.result()
            future.release()
            if progress is not None:
                progress(min(self.chunk, len(params) - starts[n]))
        return Batch(np.concatenate([f for f, _, _, _ in parts]),
                     np.concatenate([d for _, d, _, _ in parts]),
                     [s for _, _, stats, _ in parts for s in stats],
                     None if extra is None else np.concatenate([e for *_, e in parts]))


def max_workers():
    """Most local workers ``--workers`` may start: twice the cores, each a process."""
    return 2 * (os.cpu_count() or 1)


def connect(scheduler=None, workers=None):
    """A Dask client: to the scheduler at ``scheduler``, or to a local cluster of ``workers``
    processes (one thread each). Returns (client, close) where ``close()`` shuts down what was
    started here.

    Raises
    ------
    OptionError
        Without ``distributed`` installed, or for a scheduler that does not answer.
    """
    option = "--scheduler" if scheduler is not None else "--workers"
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise OptionError(f"{option}: needs dask.distributed, expected it installed "
                          "(pip install 'airgun-xl[cluster]')") from None
    if scheduler is not None:
        shown = scheduler if len(scheduler) <= 80 else scheduler[:77] + "..."
        if not re.fullmatch(r"(tcp|tls)://([^\s/:\[\]]+|\[[0-9a-fA-F:.]+\]):\d{1,5}",
                            scheduler):
            raise OptionError(f"--scheduler: found {shown!r}, expected the address of a running "
                              "`dask scheduler` as tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786")
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:  # distributed's own
            raise OptionError(f"--scheduler: found {shown!r}, which did not answer "
                              f"({type(exc).__name__}); expected the address of a running "
                              "`dask scheduler`, e.g. tcp://10.0.0.5:8786") from None
        return client, client.close
    most = max_workers()
    if not 1 <= workers <= most:
        raise OptionError(f"--workers: found {workers!r}, expected 1 to {most} (twice this "
                          f"machine's {os.cpu_count() or 1} cores; each worker is a process)")
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=":0")  # any free port: never a clash
    client = Client(cluster)

    def close():
        client.close()
        cluster.close()

    return client, close
