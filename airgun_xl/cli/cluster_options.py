"""``--scheduler ADDRESS`` and ``--workers N``, shared by ``sweep`` and ``design``."""
import contextlib


def add_cluster_options(p):
    group = p.add_mutually_exclusive_group()
    group.add_argument("--scheduler", metavar="ADDRESS",
                       help="run the shots on a Dask cluster: the address of its scheduler, "
                            "e.g. tcp://10.0.0.5:8786 (docs/studies.md, 'Studies on several "
                            "machines')")
    group.add_argument("--workers", type=int, metavar="N",
                       help="run the shots on a local Dask cluster of N worker processes")
    p.add_argument("--chunk", type=int, metavar="SHOTS", default=None,
                   help="shots a cluster task (default 512)")


@contextlib.contextmanager
def cluster_runner(args):
    """The runner the options ask for: None (this machine's batch kernel) or a
    :class:`~airgun_xl.studies.cluster.ClusterRunner`, shut down on leaving."""
    if args.scheduler is None and args.workers is None:
        if args.chunk is not None:
            from ..errors import OptionError

            raise OptionError("--chunk: found it without --scheduler or --workers, expected "
                              "one of them (chunks are for a cluster)")
        yield None
        return
    from ..studies.cluster import DEFAULT_CHUNK, ClusterRunner, connect

    client, close = connect(args.scheduler, args.workers)
    try:
        yield ClusterRunner(client, args.chunk if args.chunk is not None else DEFAULT_CHUNK)
    finally:
        close()
