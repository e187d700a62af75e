"""Speed of reading and judging a long recording: events, a recorder's clock (issue 62).

    python benchmarks/bench_events.py [--repeat N] [--quick]

Each case is `airgun-xl accept` (or `recording --events`) as a fresh process, its verdict
workbook written; the median wall time over N runs after one warm-up, and the peak RSS:

- the longest real channel here: mps_4ch_accel.uff's first (222,400 samples at 3.2 kHz in
  m/s^2, an MPS system's export; tests/data/real), judged against 0.02 g +/- 50 % (it
  passes: a FAIL exits 3);
- a session of 500,000 samples (10 s at 50 kHz) holding three 4 ms half-sines of 300, 450
  and 350 g in 0.5 g of noise (seed 1), its time stamped as a block recorder stamps it (blocks
  of 256 samples, each block's time code off by up to 0.2 of a step, the clock 200 ppm fast),
  so that the events are found and the clock fitted: `recording --events`, then `accept`
  judging the largest event (the default) and the first (`--event 1`);
- a real recorder's channel of 500,000 samples: test1.IDE's 100 g piezoelectric Y (enDAQ's
  own recording, tests/data/real), its 49,924 samples and their stamps (the real block jitter)
  repeated end to end ten times (each copy after the last by one median step), read by
  idelib, written as a CSV in g, judged by accept against 0.3 g +/- 90 % (it passes, 0.21 g,
  whether once or ten times: a FAIL exits 3; the X channel's sign flips between the two, and
  a refusal measures nothing). Needs idelib (the `ide` extra).

Target (issue 62): a 500,000-sample channel read and judged in under 3 s and 300 MB. --quick:
50,000 samples, one repeat.
"""
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fill import TEMPLATE, judged, measured_process, quick, run_table  # noqa: E402

REAL = Path(__file__).resolve().parents[1] / "tests" / "data" / "real"

#: Issue 62's target for a 500,000-sample channel read and judged [s], [MB].
TARGET_SECONDS, TARGET_MB = 3.0, 300


def session(path, samples, rate=50_000.0, block=256, ppm=200.0):
    """The session's CSV (see the module's notes)."""
    rng = np.random.default_rng(1)
    true = np.arange(samples) / (rate * (1 + ppm * 1e-6))
    stamps = true.copy()
    for first in range(0, samples, block):
        stamps[first:first + block] += rng.uniform(-0.2, 0.2) / rate
    a = rng.normal(0.0, 0.5, samples)
    span = true[-1]
    for share, peak in ((0.2, 300.0), (0.5, 450.0), (0.8, 350.0)):
        x = (true - share * span) / 0.004
        inside = (x >= 0) & (x <= 1)
        a[inside] += peak * np.sin(np.pi * x[inside])
    path.write_text("time [s],acceleration [g]\n" + "".join(
        f"{t!r},{v!r}\n" for t, v in zip(stamps.tolist(), a.tolist(), strict=True)))
    return path


def real_channel(path, copies=10):
    """test1.IDE's 100 g Y repeated ``copies`` times (see the module's notes), as a CSV."""
    import idelib

    doc = idelib.importFile(str(REAL / "test1.IDE"))
    try:
        sub = next(s for ch in doc.channels.values() for s in ch.subchannels
                   if s.name == "Y (100g)")
        data = np.asarray(sub.getSession().arraySlice(), float)
    finally:
        doc.close()
    t, g = data[0] * 1e-6, data[1]
    step = float(np.median(np.diff(t)))
    span = t[-1] - t[0] + step
    times = np.concatenate([t + k * span for k in range(copies)])
    path.write_text("time [s],acceleration [g]\n" + "".join(
        f"{a!r},{b!r}\n" for a, b in zip(times.tolist(), np.tile(g, copies).tolist(),
                                         strict=True)))
    return path, len(times)


def _row(label, cmd, repeat, target=False):
    walls, rss = measured_process(cmd, repeat)
    wall, peak = statistics.median(walls), max(rss)
    rows = [(label, "", f"{wall:.2f} s", f"peak RSS {peak:.0f} MB")]
    if target:
        rows.append((f"  target (issue 62): <= {TARGET_SECONDS:g} s and <= {TARGET_MB} MB",
                     "", judged(wall <= TARGET_SECONDS and peak <= TARGET_MB),
                     f"min {min(walls):.2f} s"))
    return rows


def bench(repeat, tmp):
    samples = 50_000 if quick() else 500_000
    path = session(tmp / "session.csv", samples)
    base = [sys.executable, "-m", "airgun_xl"]
    out = ["-o", str(tmp / "v.xlsx"), "--force"]
    real = REAL / "mps_4ch_accel.uff"
    rows = []
    try:
        long_real, n_real = real_channel(tmp / "real.csv", 1 if quick() else 10)
        rows = _row(f"accept, test1.IDE's 100 g Y repeated: {n_real:,} real samples", [
            *base, "accept", str(TEMPLATE), str(long_real), "--peak", "0.3g:90%", *out],
            repeat, target=not quick())
    except ImportError:
        rows = [("accept, the real 500,000-sample channel", "", "needs idelib", "")]
    return rows + (
        _row("accept, the real 222,400-sample UFF channel", [
            *base, "accept", str(TEMPLATE), str(real), "--channel", "1", "--peak", "0.02g:50%",
            *out], repeat)
        + _row(f"recording --events, a {samples:,}-sample session", [
            *base, "recording", str(path), "--events"], repeat)
        + _row(f"accept, the {samples:,}-sample session, the largest event", [
            *base, "accept", str(TEMPLATE), str(path), "--peak", "450g:10%", *out], repeat,
            target=True)
        + _row(f"accept, the {samples:,}-sample session, --event 1", [
            *base, "accept", str(TEMPLATE), str(path), "--peak", "300g:10%", "--event", "1",
            *out], repeat, target=True))


def main():
    run_table(__doc__, bench)


if __name__ == "__main__":
    main()
