"""Speed of convergence, design and sweep, printed as a table.

    python benchmarks/bench_tools.py [--repeat N] [--quick]

Medians over N runs after a warm-up, with the machine they came from:
- `airgun-xl convergence templates/shot_a.xlsx` (default ladder 0.5 us .. 5 ns) as a process;
- a design solve for 8 kG at 0.5 us: the solve alone (scipy imported) and the process;
- the batch kernel: 1,000 shots x 12,002 rows, shot-steps/s, beside one shot's kernel.
"""
import statistics
import sys
import time

from bench_fill import TEMPLATE, run_table, timed


def bench_convergence(repeat, tmp):
    cmd = [sys.executable, "-m", "airgun_xl", "convergence", str(TEMPLATE), "-o",
           str(tmp / "c.xlsx"), "--force"]
    med, low = timed(cmd, repeat)
    return [("convergence, default ladder (7 levels, 2.3M steps)", "process",
             f"{med:.3f} s", f"min {low:.3f} s")]


def bench_design(repeat, tmp):
    import airgun_xl
    from airgun_xl.studies.design import VARIABLES, solve_peak

    p = airgun_xl.load(TEMPLATE).params
    solve_peak(p, 8.0, VARIABLES["A28"])  # imports scipy, warms caches
    times, evaluations = [], 0
    for _ in range(repeat):
        started = time.perf_counter()
        evaluations = solve_peak(p, 8.0, VARIABLES["A28"]).evaluations
        times.append(time.perf_counter() - started)
    cmd = [sys.executable, "-m", "airgun_xl", "design", str(TEMPLATE), "--target-peak", "8kG",
           "-o", str(tmp / "d.xlsx"), "--force"]
    med, _ = timed(cmd, repeat)
    return [("design solve, 8 kG at 0.5 us (in-process)", f"{evaluations} simulations",
             f"{statistics.median(times) * 1e3:.0f} ms", ""),
            ("design, whole process (solve + fill of the design)", "", f"{med:.3f} s", "")]


def bench_sweep(repeat):
    import numpy as np

    import airgun_xl
    from airgun_xl.engine.batch import run_batch
    from airgun_xl.engine.integrators import run_legacy

    p = airgun_xl.load(TEMPLATE).params
    params = [p.replace(v31=v, v32=v, v33=v) for v in np.linspace(100, 260, 1000)]
    run_batch(params[:10])
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        run_batch(params)
        times.append(time.perf_counter() - started)
    med = statistics.median(times)
    steps = 1000 * (p.rows - 2)
    single = statistics.median(run_legacy(p, track=()).kernel_seconds for _ in range(repeat))
    return [("sweep batch: 1,000 shots x 12,002 rows, 2 threads", f"{steps:,} shot-steps",
             f"{med:.3f} s", f"{steps / med:.3g} shot-steps/s"),
            ("  one shot's kernel alone, for comparison", f"{p.rows - 2:,} steps",
             f"{single * 1e3:.2f} ms", f"{(p.rows - 2) / single:.3g} steps/s")]


def main():
    run_table(__doc__, lambda repeat, tmp: bench_convergence(repeat, tmp)
              + bench_design(repeat, tmp) + bench_sweep(repeat))


if __name__ == "__main__":
    main()
