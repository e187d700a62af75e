"""Speed of a campaign: `airgun-xl fill DAY --jobs 2` over 100 copies of shot A at 0.5 us,
full default output (legacy columns, Summary, Charts, Tracked, Spectrum, Parameters), against
a lone `airgun-xl fill` of one of them.

    python benchmarks/bench_campaign.py [--repeat N] [--quick]

Reports the median over N runs of the batch's wall time per shot, and of a lone fill as a
fresh process (the issue's "about 1 s a shot today"), with the machine they came from. The
target (issue 21): at most 0.5 s of wall time per shot on 2 cores.
"""
import shutil
import statistics
import subprocess
import sys
import time

from bench_fill import TEMPLATE, fill_cmd, judged, quick, run_table, timed

TARGET_SECONDS_PER_SHOT = 0.5


def bench_campaign(repeat, shots, jobs, tmp):
    day = tmp / "day"
    day.mkdir()
    for k in range(shots):
        shutil.copy(TEMPLATE, day / f"shot_{k:03d}.xlsx")
    cmd = [sys.executable, "-m", "airgun_xl", "fill", str(day), "--jobs", str(jobs),
           "--force"]
    subprocess.run(cmd, check=True, capture_output=True)  # warm-up (OS file cache)
    per_shot = []
    for _ in range(repeat):
        started = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        per_shot.append((time.perf_counter() - started) / shots)
    lone, _ = timed(fill_cmd(day / "shot_000.xlsx", tmp / "lone.xlsx"), repeat)
    median = statistics.median(per_shot)
    met = judged(median <= TARGET_SECONDS_PER_SHOT)
    return [(f"fill of {shots} copies of shot A at 0.5 us, --jobs {jobs}", "wall per shot",
             f"{median:.3f} s", f"min {min(per_shot):.3f} s; target "
                                f"{TARGET_SECONDS_PER_SHOT} s {met}"),
            ("one fill of shot A at 0.5 us, a fresh process", "wall", f"{lone:.3f} s",
             f"ratio lone / batch per shot {lone / median:.1f}")]


def main():
    run_table(__doc__, lambda repeat, tmp: bench_campaign(repeat, 4 if quick() else 100, 2,
                                                                tmp))


if __name__ == "__main__":
    main()
