"""What the checks on untrusted files cost, and how much memory hostile files take, as a table.

    python benchmarks/bench_guard.py [--repeat N] [--quick]

Medians over N runs after a warm-up, with the machine they came from:
- the guard of ``fill`` on the template (regular file, zip members, defusedxml on the members
  parsed whole, each sheet's prolog);
- the extent scan that ``diff`` runs before python-calamine, against the whole read, on the
  largest legacy case and on a 20,005-row filled workbook;
- ``fill`` and ``diff`` of hostile files as processes: time and peak resident memory.
"""
import statistics
import sys
import time
from pathlib import Path

from bench_fill import TEMPLATE, quick, run_table

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "hostile"))


def _median(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        fn()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def bench_reading(repeat, tmp):
    import airgun_xl
    from airgun_xl.app.diff import read_results
    from airgun_xl.outputs import Outputs
    from airgun_xl.readers import guard

    def fill_guard():
        data, _ = guard.read_input(TEMPLATE)
        guard.open_zip(TEMPLATE, data)

    t_guard = _median(fill_guard, repeat)
    rows = [("fill's guard on the template", "7.7 kB", f"{t_guard * 1e3:.1f} ms", "")]
    big = tmp / "rows20k.xlsx"
    shot = airgun_xl.load(TEMPLATE).with_params(delta=3e-7)
    shot.run().write(big, outputs=Outputs(groups=frozenset({"positions", "crush", "accel"})))
    for path in (ROOT / "legacy_reference" / "shot_a_appendix_5us_legacy.xlsx", big):
        def scan(path=path):
            data, _ = guard.read_input(path)
            zf = guard.open_zip(path, data)
            return guard.sheet_extent(path, zf, guard.first_sheet_member(path, zf))

        extent = scan()
        cells = extent[0] * extent[1]
        t_scan = _median(scan, repeat)
        t_read = _median(lambda path=path: read_results(path), repeat)
        rows.append((f"diff's extent scan, {path.name}", f"{cells:,} cells",
                     f"{t_scan * 1e3:.0f} ms", f"{cells / t_scan:.3g} cells/s; whole read "
                                               f"{t_read * 1e3:.0f} ms"))
    return rows


def bench_hostile(repeat, tmp):
    import builders
    from support import run_child

    rows = []
    cases = (("far cell XFD1048576", builders.far_cell),
             ("400 MB whitespace bomb", builders.whitespace_bomb),
             ("1M-row sheet", builders.million_rows))
    for name, build in cases[:1] if quick() else cases:
        path = tmp / "hostile.xlsx"
        path.write_bytes(build())
        for command in (["fill", path, "-o", tmp / "o.xlsx", "--force", "--only", "summary"],
                        ["diff", path, path]):
            times, peaks, code = [], [], None
            for _ in range(max(1, repeat // 3)):
                started = time.perf_counter()
                code, _, rss = run_child(tmp, command)
                times.append(time.perf_counter() - started)
                peaks.append(rss)
            rows.append((f"{command[0]} of a {name}", f"{path.stat().st_size / 1024:,.0f} kB",
                         f"{statistics.median(times):.2f} s",
                         f"exit {code}, peak RSS {max(peaks) / 2**20:.0f} MB"))
    return rows


def main():
    run_table(__doc__, lambda repeat, tmp: bench_reading(repeat, tmp)
              + bench_hostile(repeat, tmp))


if __name__ == "__main__":
    main()
