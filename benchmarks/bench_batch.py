"""The batch kernel, lanes against one shot after another, printed as a table.

    python benchmarks/bench_batch.py [--repeat N] [--quick]

Shot A at 0.5 µs (12,000 steps a shot), 1,024 shots with different speeds: the compiled
`batch_kernel` alone, with the legacy scheme run LANES (8) shots at a time in SIMD registers,
and with the scalar loop it replaced (`lanes=False`), on one thread and on two (two halves, as
`run_batch` splits a block); then `run_batch` with its figures. Issue 13's target: 1e8
shot-steps/s on the 2 cores.
"""
import statistics
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fill import TEMPLATE, judged, quick, run_table, timed_once  # noqa: E402

SHOTS = 1024
TARGET = 1e8


def benches(repeat, tmp):
    import numpy as np

    import airgun_xl
    from airgun_xl.engine import _artsim
    from airgun_xl.engine.batch import N_FINALS, run_batch
    from airgun_xl.engine.integrators import displacement_bound, kernel_params, run_legacy

    n = 64 if quick() else SHOTS
    p = airgun_xl.load(TEMPLATE).params
    shots = [p.replace(v31=v, v32=v, v33=v) for v in np.linspace(100, 260, n)]
    matrix = np.array([kernel_params(q) + [displacement_bound(q)] for q in shots])
    rows, steps = p.rows, n * (p.rows - 2)

    def run(lanes, threads):
        halves = np.array_split(np.arange(n), threads)

        def work(index):
            t, y = np.empty(rows), np.empty((len(index), rows))
            f = np.empty((len(index), N_FINALS))
            _artsim.batch_kernel(matrix[index], rows, 0, 3, t, y, f, lanes)

        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(work, halves))

    out, rates = [], {}
    for lanes in (False, True):
        for threads in (1, 2):
            run(lanes, threads)
            med = statistics.median(timed_once(lambda: run(lanes, threads)) for _ in range(repeat))
            rates[lanes, threads] = steps / med
            out.append((f"batch_kernel, {'lanes of 8' if lanes else 'scalar loop'}, "
                        f"{threads} thread{'s' if threads > 1 else ''}", f"{steps:.3g} steps",
                        f"{med:.3f} s", f"{steps / med:.3g} shot-steps/s"))
    out.append(("  lanes against the scalar loop, 2 threads", "", "",
                f"{rates[True, 2] / rates[False, 2]:.2f}x"))
    out.append((f"  target (issue 13): >= {TARGET:.0e} shot-steps/s on 2 threads", "",
                judged(rates[True, 2] >= TARGET), ""))
    single = statistics.median(run_legacy(p, track=()).kernel_seconds for _ in range(repeat))
    out.append(("  one shot's kernel alone (positions only), for comparison",
                f"{p.rows - 2:,} steps", f"{single * 1e3:.2f} ms",
                f"{(p.rows - 2) / single:.3g} steps/s"))
    run_batch(shots[:64])
    med = statistics.median(timed_once(lambda: run_batch(shots)) for _ in range(repeat))
    out.append(("run_batch (kernel + figures), 2 threads", "", f"{med:.3f} s",
                f"{steps / med:.3g} shot-steps/s"))
    return out


if __name__ == "__main__":
    run_table(__doc__, benches)
