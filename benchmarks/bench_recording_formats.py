"""Reading a recording in each format (issue 47): a 1 s channel at 1 MHz (1,000,000 samples
of a 5 ms half-sine with noise, seed 0, in g, beside a second channel), read as the reading
commands read it (`read_trace`: the file's bytes, its format told, the channel and its time
checked), as a fresh process.

    python benchmarks/bench_recording_formats.py [--repeat N] [--quick]

Formats: CSV (time and acceleration, repr), LabVIEW TDMS (npTDMS writes it), MATLAB v5
uncompressed and v7 compressed (scipy's savemat writes them, airgun-xl's reader reads them),
v7.3 (h5py writes it, with MATLAB's header), ASAM MDF 4.10 (asammdf writes it; read in a
child process), enDAQ IDE (ebmlite writes it on idelib's schema: 16-bit counts and a
calibration, blocks of 4,096 samples), and UFF dataset 58 binary and ASCII (pyuff
writes and reads them; pyuff parses every dataset of the file, both channels here).
Reports each one's file size, the median wall time over N runs after a warm-up and the peak
RSS; the process's import of airgun-xl is in every figure (the first row, a process that
reads nothing, is that floor). --quick: 100,000 samples.

Then a file far larger than its pulse, in each format that reads a window (MDF, TDMS): a
10 s channel at 1 MHz (float32, the half-sine at 4.2 s) beside channels of zeros that make
the file AIRGUN_BENCH_LARGE_GB gigabytes (20 by default, 0 to leave this part out; with
--quick, 3 s beside 64 MB, still past the samples read whole); the page cache
is dropped before each run where the machine lets us (root on Linux), so the file is read
from the disk.
"""
import os
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from bench_fill import measured_process, quick, run_table  # noqa: E402


def _pulse(n):
    t = np.arange(n) / 1e6
    a = np.where((t > 0.1) & (t < 0.105), 1000 * np.sin(np.pi * (t - 0.1) / 0.005), 0.0)
    return t, a + np.random.default_rng(0).normal(0, 5, n)


def files(tmp, n):
    """{format: path} of the same channel in each format."""
    from scipy.io import savemat

    t, a = _pulse(n)
    out = {"CSV": tmp / "r.csv"}
    out["CSV"].write_text("time [s],acceleration [g]\n" + "".join(
        f"{x!r},{y!r}\n" for x, y in zip(t.tolist(), a.tolist(), strict=True)))
    try:
        import nptdms

        with nptdms.TdmsWriter(str(tmp / "r.tdms")) as writer:
            writer.write_segment([
                nptdms.ChannelObject("Recorder", "accel", a, properties={
                    "wf_increment": 1e-6, "wf_start_offset": 0.0, "unit_string": "g"}),
                nptdms.ChannelObject("Recorder", "strain", a * 0.5, properties={
                    "wf_increment": 1e-6, "wf_start_offset": 0.0})])
        out["TDMS"] = tmp / "r.tdms"
    except ImportError:
        pass
    variables = {"time": t, "time_unit": "s", "accel": a, "accel_unit": "g", "strain": a * 0.5}
    savemat(tmp / "v5.mat", variables, format="5", oned_as="column")
    savemat(tmp / "v7.mat", variables, do_compression=True, oned_as="column")
    out["MATLAB v5"] = tmp / "v5.mat"
    out["MATLAB v7 (compressed)"] = tmp / "v7.mat"
    try:
        from test_recording_formats import _write_v73

        out["MATLAB v7.3 (HDF5)"] = _write_v73(tmp / "v73.mat", variables)
    except ImportError:
        pass
    try:
        from test_recording_formats import _write_mdf

        out["ASAM MDF 4.10 (asammdf, in a child process)"] = _write_mdf(tmp / "r.mf4", t, a)
    except ImportError:
        pass
    try:
        from test_recording_formats import _write_ide

        out["enDAQ IDE (idelib)"], _ = _write_ide(tmp / "r.ide", tmp / "ide.csv", a,
                                                  rate=1_000_000, per_block=4096)
    except ImportError:
        pass
    try:
        from test_recording_formats import _write_uff58

        for binary, name in ((1, "UFF 58b (binary)"), (0, "UFF 58 (ASCII)")):
            out[name] = _write_uff58(tmp / f"r{binary}.uff", binary,
                                     [("accel", a, "g", t), ("strain", a * 0.5, "g", t)])
    except ImportError:
        pass
    return out


def bench_formats(repeat, tmp):
    n = 100_000 if quick() else 1_000_000
    rows = []
    floor = [sys.executable, "-c", "import airgun_xl.readers.recording"]
    walls, rss = measured_process(floor, repeat)
    rows.append(("import only (the floor)", "", f"{statistics.median(walls):.2f} s",
                 f"peak RSS {max(rss):.0f} MB"))
    for name, path in files(tmp, n).items():
        # their slow channel comes first
        channel = {".mf4": "accel", ".ide": "Acceleration/X"}.get(path.suffix)
        cmd = [sys.executable, "-c", "import sys; from airgun_xl.readers.recording import "
               "read_trace; read_trace(sys.argv[1], channel=sys.argv[2] or None)", str(path),
               channel or ""]
        walls, rss = measured_process(cmd, repeat)
        rows.append((f"{name}, {n:,} samples at 1 MHz",
                     f"{path.stat().st_size / 2**20:.1f} MB",
                     f"{statistics.median(walls):.2f} s", f"peak RSS {max(rss):.0f} MB"))
    return rows


def _long_pulse(n):
    t = np.arange(n) / 1e6
    a = np.random.default_rng(0).normal(0, 5, n).astype(np.float32)
    k = n * 42 // 100
    a[k:k + 5000] += (1000 * np.sin(np.pi * np.arange(5000) / 5000)).astype(np.float32)
    return t, a


def large_files(tmp, gb, n, bulk):
    """{format: path} of a file of about ``gb`` GB holding one pulse in a channel of ``n``
    samples, the rest in blocks of ``bulk`` samples and their times."""
    blocks = max(1, round(gb * 2**30 / (bulk * 8 * 2)))
    t, a = _long_pulse(n)
    out = {}
    try:
        from asammdf import MDF, Signal

        mdf = MDF(version="4.10")
        mdf.append([Signal(a, t, name="accel", unit="g")])
        bulk_t = np.arange(bulk, dtype=float)
        for k in range(blocks):
            mdf.append([Signal(np.zeros(bulk), bulk_t, name=f"bulk{k}")])
        mdf.save(tmp / "large.mf4", overwrite=True)
        mdf.close()
        out["ASAM MDF 4.10"] = tmp / "large.mf4"
    except ImportError:
        pass
    try:
        import nptdms

        with nptdms.TdmsWriter(str(tmp / "large.tdms")) as writer:
            writer.write_segment([nptdms.ChannelObject("Recorder", "accel", a, properties={
                "wf_increment": 1e-6, "wf_start_offset": 0.0, "unit_string": "g"})])
            zeros = np.zeros(bulk * 2)
            for k in range(blocks):
                writer.write_segment([nptdms.ChannelObject("Bulk", f"bulk{k}", zeros,
                                                           properties={"wf_increment": 1.0})])
        out["TDMS"] = tmp / "large.tdms"
    except ImportError:
        pass
    return out


def _drop_caches():
    """Empty the page cache (root on Linux), so a read comes from the disk: True if done."""
    try:
        os.sync()
        Path("/proc/sys/vm/drop_caches").write_text("3\n")
        return True
    except OSError:
        return False


def bench_large(repeat, tmp):
    gb, n, bulk = ((0.0625, 3_000_000, 2**21) if quick() else
                   (float(os.environ.get("AIRGUN_BENCH_LARGE_GB", "20")), 10_000_000, 2**25))
    rows = []
    if gb <= 0:
        return rows
    for name, path in large_files(tmp, gb, n, bulk).items():
        cmd = [sys.executable, "-c", "import sys; from airgun_xl.readers.recording import "
               "read_trace; read_trace(sys.argv[1])", str(path)]
        walls, rss, cold = [], [], True
        for _ in range(repeat):
            cold = _drop_caches() and cold
            wall, peak = measured_process(cmd, 1, warm=False)
            walls += wall
            rss += peak
        size = path.stat().st_size
        rows.append((f"{name}, {n:,} samples at 1 MHz in a large file"
                     f"{'' if cold else ' (page cache kept)'}",
                     f"{size / 2**30:.2f} GB", f"{statistics.median(walls):.2f} s",
                     f"peak RSS {max(rss):.0f} MB"))
        path.unlink()
    return rows


def main():
    run_table(__doc__, lambda repeat, tmp: bench_formats(repeat, tmp)
              + bench_large(repeat, tmp))


if __name__ == "__main__":
    main()
