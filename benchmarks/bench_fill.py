"""Speed of the kernel and of `airgun-xl fill`, printed as a table.

    python benchmarks/bench_fill.py [--repeat N] [--quick]

Reports medians over N runs (after one warm-up run) and the machine they came from:
- kernel throughput on shot A at dt = 5 ns (1.2M steps), the C loop alone;
- `airgun-xl fill templates/shot_a.xlsx` as a fresh process: the full default output (legacy
  columns, Summary, Charts, Tracked, Spectrum), and a summary-only run for comparison;
- the bare xlsxwriter floor: a process that writes the same cells as the full fill's output
  (every sheet, read back with python-calamine) through xlsxwriter's public write_number and
  write_string, and the fill's time over it (issue 24.11: at most 0.6 s, or at most 0.6 times
  the floor);
- the same fill at dt = 5 ns (1.2M steps): wall time and peak RSS (of the fill's process);
- where the time of a full fill goes: imports, reading, kernel, derived, summary, writing.

Every benchmark takes ``--quick``: one repeat on a small case, to show that it still runs
(tests/test_benchmarks.py runs each so). Its figures measure nothing and its targets are not
judged.
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

#: Set by ``--quick`` (:func:`run_table`): one repeat on a small case.
QUICK = False


def quick():
    """Whether this run is ``--quick`` (read at call time: ``run_table`` sets it)."""
    return QUICK


def judged(ok):
    """A target's word: met or NOT met, and never judged in a quick run."""
    return "not judged (--quick)" if QUICK else "met" if ok else "NOT met"


#: A child that runs a command and prints its peak RSS [kB] (POSIX getrusage; the
#: benchmarks' machine, not the package's platforms).
PEAK_RSS = (
    "import resource, subprocess, sys\n"
    "subprocess.run(sys.argv[1:], check=True, capture_output=True)\n"
    "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
)


def measured_process(cmd, times, warm=True):
    """Run ``cmd`` once to warm up (unless not ``warm``), then ``times`` times: medians'
    inputs.

    Returns the wall times [s] and each run's peak RSS [MB].
    """
    cmd = [sys.executable, "-c", PEAK_RSS, *cmd]
    if warm:
        subprocess.run(cmd, check=True, capture_output=True)
    walls, rss = [], []
    for _ in range(times):
        started = time.perf_counter()
        done = subprocess.run(cmd, check=True, capture_output=True, text=True)
        walls.append(time.perf_counter() - started)
        rss.append(int(done.stdout.split()[-1]) / 1024)
    return walls, rss


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


def fill_cmd(shot, out, *flags):
    return [sys.executable, "-m", "airgun_xl", "fill", str(shot), "-o", str(out), "--force",
            *flags]


def timed(cmd, repeat, ok_codes=(0,)):
    """(median, min) wall time [s] of ``cmd`` as a process, after a warm-up run (none in a
    ``--quick`` run, which measures nothing); an exit code outside ``ok_codes`` stops the
    benchmark."""
    def run():
        done = subprocess.run(cmd, capture_output=True)
        if done.returncode not in ok_codes:
            raise subprocess.CalledProcessError(done.returncode, cmd, done.stdout, done.stderr)

    if not quick():
        run()  # warm-up (OS file cache)
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return statistics.median(times), min(times)


def timed_once(fn):
    """Wall time of one call of ``fn`` [s]."""
    started = time.perf_counter()
    fn()
    return time.perf_counter() - started


def bench_kernel(repeat):
    import airgun_xl
    from airgun_xl.engine.integrators import run_legacy

    params = airgun_xl.load(TEMPLATE).params.replace(delta=5e-9)
    run_legacy(params)
    steps = params.rows - 2
    rows = []
    for label, track in (("all step values tracked", None), ("positions only", ())):
        kwargs = {} if track is None else {"track": track}
        med = statistics.median(run_legacy(params, **kwargs).kernel_seconds
                                for _ in range(repeat))
        rows.append((f"kernel, shot A at 5 ns, {label}", f"{steps:,} steps",
                     f"{med * 1e3:.1f} ms", f"{steps / med:.3g} steps/s"))
    return rows


def bench_fills(repeat, tmp):
    out = tmp / "o.xlsx"
    full, full_min = timed(fill_cmd(TEMPLATE, out), repeat)
    only, _ = timed(fill_cmd(TEMPLATE, out, "--only", "summary"), repeat)
    return bench_floor(repeat, tmp, full) + [
            ("fill shot A 0.5 us, full output (process)", "12,002 rows", f"{full:.3f} s",
             f"min {full_min:.3f} s"),
            ("fill shot A 0.5 us, --only summary", "12,002 rows", f"{only:.3f} s",
             f"{full / only:.1f}x faster than full")]


FLOOR = """
import pickle, sys
import xlsxwriter
with open(sys.argv[1], "rb") as f:
    sheets = pickle.load(f)
wb = xlsxwriter.Workbook(sys.argv[2])
for name, rows in sheets:
    ws = wb.add_worksheet(name)
    for r, row in enumerate(rows):
        for c, v in enumerate(row):
            if isinstance(v, float):
                ws.write_number(r, c, v)
            elif v is not None:
                ws.write_string(r, c, v)
wb.close()
"""

#: Issue 24.11's target for the full fill of shot A as a process: an absolute time [s], or a
#: fraction of the bare xlsxwriter floor measured in the same run.
TARGET_FILL_SECONDS, TARGET_FLOOR_RATIO = 0.6, 0.6


def bench_floor(repeat, tmp, full):
    """The bare xlsxwriter write of the full fill's cells, as a process; ``full`` is the fill's
    median [s] from :func:`bench_fills`."""
    import pickle

    from python_calamine import CalamineWorkbook

    out = tmp / "floor_source.xlsx"
    subprocess.run(fill_cmd(TEMPLATE, out), check=True, capture_output=True)
    book = CalamineWorkbook.from_path(str(out))
    sheets, cells = [], 0
    for name in book.sheet_names:
        rows = [[v if v is None or isinstance(v, float) else
                 float(v) if isinstance(v, int) else str(v) for v in row]
                for row in book.get_sheet_by_name(name).to_python()]
        rows = [[None if v == "" else v for v in row] for row in rows]
        cells += sum(v is not None for row in rows for v in row)
        sheets.append((name, rows))
    with open(tmp / "cells.pkl", "wb") as f:
        pickle.dump(sheets, f)
    floor, _ = timed([sys.executable, "-c", FLOOR, str(tmp / "cells.pkl"),
                      str(tmp / "floor.xlsx")], repeat)
    ratio = full / floor
    met = judged(full <= TARGET_FILL_SECONDS or ratio <= TARGET_FLOOR_RATIO)
    return [("bare xlsxwriter floor: the same cells, public API (process)",
             f"{cells:,} cells", f"{floor:.3f} s", f"fill / floor = {ratio:.2f}"),
            (f"  target (issue 24.11): fill <= {TARGET_FILL_SECONDS:g} s or <= "
             f"{TARGET_FLOOR_RATIO:g} x floor", "", met, f"fill {full:.3f} s")]


def bench_long(repeat, tmp):
    import openpyxl

    shot = tmp / "shot_5ns.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    delta = 5e-8 if quick() else 5e-9  # quick: 120,000 steps
    wb["Sheet1"]["E2"] = delta
    wb.save(shot)
    walls, rss = measured_process(fill_cmd(shot, tmp / "o5.xlsx"),
                                  1 if quick() else max(3, repeat // 2))
    wall, peak = statistics.median(walls), max(rss)
    met = judged(wall <= TARGET_SECONDS and peak <= TARGET_MB)
    rows = round(6e-3 / delta) + 2
    return [(f"fill shot A {delta * 1e9:g} ns ({rows - 2:,} steps, sheet 1 in parts + "
             "sidecar)", f"{rows:,} rows",
             f"{wall:.3f} s", f"peak RSS {peak:.0f} MB"),
            (f"  target (issue 10): <= {TARGET_SECONDS:g} s and <= {TARGET_MB} MB", "", met,
             f"min {min(walls):.3f} s, max {max(walls):.3f} s")]


#: Issue 10's target for the 5 ns fill of shot A on a quiet machine.
TARGET_SECONDS, TARGET_MB = 4.0, 400


STAGES = """
import time, sys
t0 = time.perf_counter()
import airgun_xl
from airgun_xl.engine.summary import summarize
t1 = time.perf_counter()
shot = airgun_xl.load(sys.argv[1])
t2 = time.perf_counter()
result = shot.run()
t3 = time.perf_counter()
summary = summarize(result)
t4 = time.perf_counter()
result.write(sys.argv[2], force=True, summary=summary)
t5 = time.perf_counter()
kernel = result.history.kernel_seconds
print(t1 - t0, t2 - t1, kernel, (t3 - t2) - kernel, t4 - t3, t5 - t4)
"""


def bench_stages(repeat, tmp):
    cmd = [sys.executable, "-c", STAGES, str(TEMPLATE), str(tmp / "s.xlsx")]
    subprocess.run(cmd, check=True, capture_output=True)
    samples = [list(map(float, subprocess.run(cmd, check=True, capture_output=True,
                                               text=True).stdout.split()))
               for _ in range(repeat)]
    names = ["imports (numpy, package)", "reading (openpyxl, formulas)", "kernel",
             "derived + filtered columns", "summary + spectrum", "writing (all sheets)"]
    medians = [statistics.median(s[i] for s in samples) for i in range(len(names))]
    total = sum(medians)
    return [(f"  stage: {name}", "", f"{med * 1e3:.1f} ms", f"{med / total:.0%}")
            for name, med in zip(names, medians, strict=True)]


def warm_bytecode():
    """The warmed-up cache the timings assume: this machine sets PYTHONDONTWRITEBYTECODE, so
    the package's own modules would be compiled again by every process."""
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "airgun_xl")],
                   check=True)


def run_table(doc, benches):
    """Parse --repeat, warm the bytecode cache, run ``benches(repeat, tmp)`` and print its rows
    as a table under the machine's name."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--quick", action="store_true",
                        help="one repeat on a small case: shows the benchmark runs, measures "
                             "nothing")
    args = parser.parse_args()
    global QUICK
    QUICK = args.quick
    repeat = 1 if args.quick else args.repeat
    warm_bytecode()
    with tempfile.TemporaryDirectory() as tmp:
        rows = benches(repeat, Path(tmp))
    print(f"machine: {machine()}")
    print("--quick: one repeat on a small case; these figures measure nothing\n" if args.quick
          else f"medians of {repeat} runs after a warm-up\n")
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    for r in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)))


def main():
    run_table(__doc__, lambda repeat, tmp: bench_kernel(repeat) + bench_fills(repeat, tmp)
              + bench_long(repeat, tmp) + bench_stages(repeat, tmp))


if __name__ == "__main__":
    main()
