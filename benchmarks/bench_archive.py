"""Speed of the archive: an archived fill and a 100-shot archived campaign, with the index in
the folder (SQLite) and on a PostgreSQL server over TCP on the loopback (issue 36).

    python benchmarks/bench_archive.py [--repeat N] [--quick]

The server is started for the benchmark from its own binaries, as the tests start theirs
(tests/pg_server.py; Debian's postgresql package), with fsync off as in the tests: what is
measured is the tool's round trips, not the server's disk. Reports the medians over N runs of
`airgun-xl fill templates/shot_a.xlsx --only summary --archive DIR` as a fresh process, on
each back end, and the wall time per shot of `fill DAY --jobs 2 --archive DIR` over 100
copies of shot A. The target: the server costs at most 50 ms more a fill than SQLite.
"""
import os
import shutil
import statistics
import subprocess
import sys
import time

from bench_fill import ROOT, TEMPLATE, judged, quick, run_table, timed

TARGET_EXTRA_SECONDS = 0.050

sys.path.insert(0, str(ROOT / "tests"))
import pg_server  # noqa: E402


def _archives(tmp, server):
    """(label, archive folder, environment) of each back end."""
    local = tmp / "local"
    env_local = dict(os.environ)
    env_server = dict(os.environ, AIRGUN_XL_INDEX=server.address, PGPASSWORD=pg_server.PASSWORD)
    remote = tmp / "server"
    # made by the schema's owner for the engineers' role, as README's administrator does
    subprocess.run([sys.executable, "-m", "airgun_xl", "archive", "init", str(remote),
                    "--index", server.owner_address, "--writers", "lab"],
                   check=True, capture_output=True, env=env_server)
    return [("SQLite in the folder", local, env_local),
            ("PostgreSQL on the loopback (TCP)", remote, env_server)]


def _timed_env(cmd, repeat, env):
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)
    try:
        return timed(cmd, repeat)
    finally:
        os.environ.clear()
        os.environ.update(saved)


def bench_archive(repeat, tmp):
    if not pg_server.available():
        return [("archived fill on a server", "skipped", "-", pg_server.WHY_SKIPPED)]
    server = pg_server.start_server()
    try:
        rows, fills = [], {}
        shots = 4 if quick() else 100
        day = tmp / "day"
        day.mkdir()
        for k in range(shots):
            shutil.copy(TEMPLATE, day / f"shot_{k:03d}.xlsx")
        for label, root, env in _archives(tmp, server):
            cmd = [sys.executable, "-m", "airgun_xl", "fill", str(TEMPLATE), "-o",
                   str(tmp / "o.xlsx"), "--force", "--only", "summary", "--archive", str(root)]
            med, low = _timed_env(cmd, repeat, env)
            fills[label] = med
            rows.append((f"archived fill of shot A (summary only), {label}", "wall",
                         f"{med:.3f} s", f"min {low:.3f} s"))
            per_shot = []
            for _ in range(max(1, repeat // 3)):
                for out in day.glob("*.out.xlsx"):
                    out.unlink()
                started = time.perf_counter()
                subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(day), "--jobs",
                                "2", "--only", "summary", "--archive", str(root)],
                               check=True, capture_output=True, env=env)
                per_shot.append((time.perf_counter() - started) / shots)
            listed = subprocess.run([sys.executable, "-m", "airgun_xl", "history", "--archive",
                                     str(root), "--json"], check=True, capture_output=True,
                                    env=env, text=True).stdout
            import json

            written = sum(1 for r in json.loads(listed) if r["shot"][5:].isdigit())
            if written != shots * len(per_shot):
                raise RuntimeError(f"{label}: {written} campaign entries in the archive, "
                                   f"expected {shots * len(per_shot)}")
            rows.append((f"archived campaign of {shots} shots, --jobs 2, {label}",
                         "wall per shot", f"{statistics.median(per_shot):.3f} s",
                         f"{written} entries in the archive, counted"))
        extra = fills["PostgreSQL on the loopback (TCP)"] - fills["SQLite in the folder"]
        rows.append(("the server's cost over SQLite, one archived fill", "wall",
                     f"{extra * 1e3:+.0f} ms",
                     f"target at most {TARGET_EXTRA_SECONDS * 1e3:.0f} ms "
                     f"{judged(extra <= TARGET_EXTRA_SECONDS)}"))
        return rows
    finally:
        pg_server.remove_server(server)


def main():
    run_table(__doc__, bench_archive)


if __name__ == "__main__":
    main()
