"""Speed of the kernel and of `airgun-xl fill`, printed as a table.

    python benchmarks/bench_fill.py [--repeat N]

Reports medians over N runs (after one warm-up run) and the machine they came from:
- kernel throughput on shot A at dt = 5 ns (1.2M steps), the C loop alone;
- `airgun-xl fill templates/shot_a.xlsx` end to end at dt = 0.5 us, as a fresh process;
- where the time of a fill goes: imports, reading, kernel, derived columns, writing.
"""
import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "templates" / "shot_a.xlsx"


def machine():
    cpu = "unknown cpu"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{platform.node()}: {cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def bench_kernel(repeat):
    import airgun_xl
    from airgun_xl.engine.integrators import run_legacy

    params = airgun_xl.load(TEMPLATE).params.replace(delta=5e-9)
    run_legacy(params)
    times = [run_legacy(params).kernel_seconds for _ in range(repeat)]
    steps = params.rows - 2
    med = statistics.median(times)
    return [("kernel, shot A at 5 ns", f"{steps:,} steps", f"{med * 1e3:.1f} ms",
             f"{steps / med:.3g} steps/s")]


def bench_fill_process(repeat):
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "o.xlsx"
        cmd = [sys.executable, "-m", "airgun_xl", "fill", str(TEMPLATE), "-o", str(out),
               "--force"]
        subprocess.run(cmd, check=True, capture_output=True)  # warm-up (OS file cache)
        times = []
        for _ in range(repeat):
            started = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            times.append(time.perf_counter() - started)
    return [("airgun-xl fill shot A at 0.5 us (process)", "12,002 rows",
             f"{statistics.median(times):.3f} s", f"min {min(times):.3f} s")]


STAGES = """
import time, sys
t0 = time.perf_counter()
import airgun_xl
from airgun_xl.engine import filtered_acceleration, get_integrator, test_item_derivatives
t1 = time.perf_counter()
shot = airgun_xl.load(sys.argv[1])
t2 = time.perf_counter()
history = get_integrator("legacy")(shot.params)
t3 = time.perf_counter()
result = shot.run()
t4 = time.perf_counter()
result.write(sys.argv[2], force=True)
t5 = time.perf_counter()
derived = (t4 - t3) - history.kernel_seconds
print(t1 - t0, t2 - t1, history.kernel_seconds, derived, t5 - t4)
"""


def bench_stages(repeat):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "o.xlsx")
        cmd = [sys.executable, "-c", STAGES, str(TEMPLATE), out]
        subprocess.run(cmd, check=True, capture_output=True)
        samples = [list(map(float, subprocess.run(cmd, check=True, capture_output=True,
                                                   text=True).stdout.split()))
                   for _ in range(repeat)]
    names = ["imports (numpy, package)", "reading (openpyxl, formulas)", "kernel",
             "derived + filtered columns", "writing (xlsxwriter)"]
    medians = [statistics.median(s[i] for s in samples) for i in range(len(names))]
    total = sum(medians)
    for name, med in zip(names, medians):
        rows.append((f"  stage: {name}", "", f"{med * 1e3:.1f} ms", f"{med / total:.0%}"))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    rows = bench_kernel(args.repeat) + bench_fill_process(args.repeat) + \
        bench_stages(args.repeat)
    print(f"machine: {machine()}")
    print(f"medians of {args.repeat} runs after a warm-up\n")
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    for r in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths)))


if __name__ == "__main__":
    main()
