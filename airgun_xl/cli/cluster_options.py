"""``--scheduler ADDRESS`` and ``--workers N``, shared by ``sweep`` and ``design``."""


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


def cluster_runner(args):
    """The runner the options ask for (:func:`airgun_xl.app.running.cluster_runner`)."""
    from ..app.running import cluster_runner

    return cluster_runner(args.scheduler, args.workers, args.chunk)
