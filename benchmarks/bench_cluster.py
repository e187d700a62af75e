"""Shots per second of a study on this machine, local and on a Dask cluster, printed as a table.

    python benchmarks/bench_cluster.py [--repeat N] [--quick]

- the batch kernel on this machine (two threads, `run_batch`), shot A at 0.5 µs;
- the same shots on a `distributed.LocalCluster` of 2 worker processes, chunks of 512: what a
  machine gives as a Dask worker, overhead included (task scheduling, pickling the parameters,
  sending the figures back);
- from that rate, the time of a 1e7-shot study on N such machines (the scheduler's overhead
  per task is about 1 ms: at 512 shots a task it is far below a chunk's run).
"""
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fill import TEMPLATE, quick, run_table, timed_once  # noqa: E402

SHOTS = 4096


def _n():
    return 512 if quick() else SHOTS  # --quick: one chunk


def _shots(p):
    import numpy as np

    return [p.replace(v31=v, v32=v, v33=v) for v in np.linspace(100, 260, _n())]


def benches(repeat, tmp):
    import airgun_xl
    from airgun_xl.engine.batch import run_batch
    from airgun_xl.studies.cluster import ClusterRunner, connect

    p = airgun_xl.load(TEMPLATE).params
    shots = _shots(p)
    steps = _n() * (p.rows - 2)
    run_batch(shots[:256])
    local = statistics.median(timed_once(lambda: run_batch(shots)) for _ in range(repeat))
    client, close = connect(workers=2)
    try:
        runner = ClusterRunner(client, 512)
        runner(shots[:1024])  # warm the workers (imports, the kernel)
        remote = statistics.median(timed_once(lambda: runner(shots)) for _ in range(repeat))
    finally:
        close()
    rows = [
        (f"local batch kernel, {_n():,} shots of shot A at 0.5 us", f"{steps:.3g} steps",
         f"{local:.3f} s", f"{steps / local:.3g} shot-steps/s"),
        ("LocalCluster, 2 workers, chunks of 512", "", f"{remote:.3f} s",
         f"{steps / remote:.3g} shot-steps/s ({_n() / remote:,.0f} shots/s)"),
    ]
    per_machine = _n() / remote
    for machines in (1, 4, 16, 64):
        seconds = 1e7 / (per_machine * machines)
        rows.append((f"  estimate: 1e7 shots on {machines} such machines", "",
                     f"{seconds / 60:.1f} min", ""))
    return rows


if __name__ == "__main__":
    run_table(__doc__, benches)
