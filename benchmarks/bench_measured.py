"""Measured pulses (issue 12): compare-measured, srs and calibrate, timed, and the
calibration's recovery of known parameters, printed as a table.

    python benchmarks/bench_measured.py [--repeat N] [--quick]

The "measured" pulses are recordings of the recorder model (studies/recorder.py: 20, 50 and
30 kHz through a 4-pole anti-alias filter at fs/5, 3 % noise, +50 g offset, 1.5 ms
pre-trigger, the axis reversed, CSV in ms and g with metadata lines) of runs under known
parameters. Each command runs in-process after a warm-up (medians of N) and once as a fresh
process (imports included). Issue 19's targets: compare-measured <= 1 s; a calibration of
three shots <= 10 s, in-process. A fresh process adds the imports: about 1.6 s of it is
scipy.signal alone (it imports scipy.stats), whichever command uses it.
"""
import contextlib
import io
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fill import TEMPLATE, judged, run_table, timed_once  # noqa: E402

SPEEDS = (243.53532, 200.0, 150.0)
RATES = (20_000.0, 50_000.0, 30_000.0)


def _truth_law():
    import numpy as np
    from numpy.polynomial import Polynomial

    from airgun_xl.crush_law import LEGACY_LAW, CrushLaw

    v = np.linspace(0, 250, 200)
    poly = Polynomial.fit(v, LEGACY_LAW.poly(v) * (1.15 - 0.0006 * v), 6).convert()
    return CrushLaw(tuple(poly.coef), (0, 250), "fitted")


def benches(repeat, tmp):
    import numpy as np
    import openpyxl

    import airgun_xl
    from airgun_xl.cli import main
    from airgun_xl.readers.recording import read_trace
    from airgun_xl.studies.calibrate import calibrate
    from airgun_xl.studies.recorder import Recorder

    p = airgun_xl.load(TEMPLATE).params.replace(delta=1e-6)
    truth = _truth_law()

    def recordings(known, prefix):
        out = []
        for i, (v0, rate) in enumerate(zip(SPEEDS, RATES, strict=True)):
            rec = Recorder(rate=rate)
            run = airgun_xl.Shot(p.replace(v31=v0, v32=v0, v33=v0, **known)).run(track=())
            out.append(str(rec.csv(rec.record(run, seed=i), tmp / f"{prefix}{i}.csv",
                                   metadata=("recorder model", f"{rate:g} Hz"))))
        return out

    shots = []
    for i, v0 in enumerate(SPEEDS):
        wb = openpyxl.load_workbook(TEMPLATE)
        wb.worksheets[0]["A28"] = v0
        wb.worksheets[0]["E2"] = 1e-6
        wb.save(tmp / f"shot{i}.xlsx")
        shots.append(str(tmp / f"shot{i}.xlsx"))
    measured = recordings({"crush_law": truth}, "law")
    fitted = recordings({"sigmay": p.sigmay * 1.07}, "e40")
    law_pairs = [x for pair in zip(shots, measured, strict=True) for x in pair]
    e40_pairs = [x for pair in zip(shots, fitted, strict=True) for x in pair]
    commands = [
        ("compare-measured, shot A at 20 kHz, CFC 1000 (ISO, FFT, SRS, rigid model, 3 charts)",
         ["compare-measured", shots[0], measured[0], "--sign", "-1", "--cfc", "1000"], 1.0),
        ("srs, shot A (81 frequencies, Q = 10)", ["srs", shots[0]], 1.0),
        ("calibrate, 3 shots, the law (iteration + least squares), CFC 600",
         ["calibrate", *law_pairs, "--sign", "-1", "--cfc", "600"], 10.0),
        ("calibrate, 3 shots, --fit E40 (unfiltered)",
         ["calibrate", *e40_pairs, "--sign", "-1", "--fit", "E40"], 10.0),
    ]
    out = []
    for label, argv, target in commands:
        def once():
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                main([*argv, "--force", "-o", str(tmp / "out.xlsx")])
        once()
        warm = statistics.median(timed_once(once) for _ in range(repeat))
        cold = timed_once(lambda: subprocess.run(
            [sys.executable, "-m", "airgun_xl", *argv, "--force", "-o", str(tmp / "c.xlsx")],
            capture_output=True))
        out.append((label, f"in-process {warm:.3f} s", f"fresh process {cold:.2f} s",
                    f"target <= {target:g} s in-process: {judged(warm <= target)}"
                    ))

    # recovery of known values from the recorder model's CSVs, as read by the commands
    for cfc in (None, 600):
        traces = [read_trace(m, sign=-1.0) for m in measured]
        cal = calibrate([p.replace(v31=s, v32=s, v33=s) for s in SPEEDS], traces,
                        law=True, cfc=cfc)
        lc = cal.law_calibration
        v = np.linspace(20, 220, 201)
        law = cal.params[0].crush_law
        out.append((f"recovery: another crush law, {'CFC 600' if cfc else 'unfiltered'}",
                    f"{len(lc.iterations)} iterations, last {lc.iterations[-1].change:.2%}",
                    f"law within {np.max(np.abs(law(v) / truth(v) - 1)):.2%} (20-220 m/s)",
                    f"valid {law.v_range[0]:.0f}-{law.v_range[1]:.0f} m/s; "
                    f"{'trusted' if cal.trusted else 'NOT trusted'}"))
    traces = [read_trace(m, sign=-1.0) for m in fitted]
    cal = calibrate([p.replace(v31=s, v32=s, v33=s) for s in SPEEDS], traces, law=False,
                    fit=["E40"])
    e40 = cal.fitted["E40"] / (p.sigmay * 1.07) - 1
    out.append(("recovery: sigma_y x1.07, unfiltered", f"E40 within {e40:+.2%}",
                f"standard error {cal.errors['E40'] / cal.fitted['E40']:.2%}",
                f"{cal.seconds:.2f} s"))
    return out


if __name__ == "__main__":
    run_table(__doc__, benches)
