"""Measured pulses (issue 12): compare-measured, srs and calibrate, timed, and the
calibration's recovery of known parameters, printed as a table.

    python benchmarks/bench_measured.py [--repeat N]

The "measured" pulses are shot A's own (studies.calibrate.synthetic_measurement: 10 us
samples, 1 % noise, an 8 kHz mount ringing) under known parameters. Each command runs
in-process after a warm-up (medians of N) and once as a fresh process (imports included).
Issue 12's targets: compare-measured and SRS of one shot <= 1 s; a calibration of two shots
<= 10 s. A fresh process adds the imports: about 1.6 s of it is scipy.signal alone (it
imports scipy.stats), whichever command uses it.
"""
import contextlib
import io
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fill import TEMPLATE, run_table, timed_once  # noqa: E402

SPEEDS = (243.53532, 180.0)


def _csv(path, trace):
    lines = ["time [s],acceleration [kG]"]
    lines += [f"{t!r},{a!r}" for t, a in zip(trace.time.tolist(), trace.accel_kg.tolist())]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


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
    from airgun_xl.studies.calibrate import calibrate, synthetic_measurement

    p = airgun_xl.load(TEMPLATE).params
    truth = _truth_law()
    shots, measured, truths = [], [], []
    for i, v0 in enumerate(SPEEDS):
        q = p.replace(v31=v0, v32=v0, v33=v0)
        wb = openpyxl.load_workbook(TEMPLATE)
        wb.worksheets[0]["A28"] = v0
        wb.save(tmp / f"shot{i}.xlsx")
        shots.append(str(tmp / f"shot{i}.xlsx"))
        measured.append(_csv(tmp / f"m{i}.csv",
                             synthetic_measurement(q.replace(crush_law=truth), seed=i)))
        truths.append(q)
    pairs = [shots[0], measured[0], shots[1], measured[1]]
    commands = [
        ("compare-measured, shot A, CFC 1000 (ISO, FFT, SRS, rigid model, 3 charts)",
         ["compare-measured", shots[0], measured[0], "--cfc", "1000"], 1.0),
        ("srs, shot A (81 frequencies, Q = 10)", ["srs", shots[0]], 1.0),
        ("calibrate, 2 shots, the law (iteration + least squares), CFC 1000",
         ["calibrate", *pairs, "--cfc", "1000"], 10.0),
        ("calibrate, 2 shots, --fit E40,E43 (unfiltered)",
         ["calibrate", *pairs, "--fit", "E40,E43"], 10.0),
    ]
    out = []
    for label, argv, target in commands:
        def once():
            with contextlib.redirect_stdout(io.StringIO()):
                main([*argv, "--force", "-o", str(tmp / "out.xlsx")])
        once()
        warm = statistics.median(timed_once(once) for _ in range(repeat))
        cold = timed_once(lambda: subprocess.run(
            [sys.executable, "-m", "airgun_xl", *argv, "--force", "-o", str(tmp / "c.xlsx")],
            check=True, capture_output=True))
        out.append((label, f"in-process {warm:.3f} s", f"fresh process {cold:.2f} s",
                    f"target <= {target:g} s in-process: {'met' if warm <= target else 'NOT met'}"
                    ))

    # recovery of known values
    from airgun_xl.workbook.trace import read_trace

    traces = [read_trace(m) for m in measured]
    cal = calibrate([p.replace(v31=s, v32=s, v33=s) for s in SPEEDS], traces,
                    law=True, cfc=1000)
    lc = cal.law_calibration
    lo, hi = np.quantile(lc.velocity, [0.05, 0.95])
    v = np.linspace(lo, hi, 201)
    law = cal.params[0].crush_law
    whole = np.linspace(*law.v_range, 201)
    out.append(("recovery: another crush law, CFC 1000",
                f"{len(lc.iterations)} iterations, last {lc.iterations[-1].change:.2%}",
                f"law within {np.max(np.abs(law(v) / truth(v) - 1)):.2%} "
                f"({lo:.0f}-{hi:.0f} m/s)",
                f"{np.max(np.abs(law(whole) / truth(whole) - 1)):.1%} over the whole "
                f"{law.v_range[0]:.0f}-{law.v_range[1]:.0f} m/s"))
    for label, known, fit, cfc, ringing in (
            ("recovery: sigma_y x1.07, zeta 0.05, unfiltered, 2 % ringing",
             {"sigmay": p.sigmay * 1.07, "zeta": 0.05}, ["E40", "E43"], None, 0.02),
            ("recovery: sigma_y x1.07, CFC 1000, 10 % ringing",
             {"sigmay": p.sigmay * 1.07}, ["E40"], 1000, 0.1)):
        traces = [synthetic_measurement(p.replace(v31=s, v32=s, v33=s, **known), seed=i,
                                        ringing=ringing) for i, s in enumerate(SPEEDS)]
        cal = calibrate([p.replace(v31=s, v32=s, v33=s) for s in SPEEDS], traces, law=False,
                        fit=fit, cfc=cfc)
        e40 = cal.fitted["E40"] / known["sigmay"] - 1
        zeta = (f"E43 {cal.fitted['E43']:.4f} (known 0.05)" if "E43" in cal.fitted else "")
        out.append((label, f"E40 within {e40:+.2%}", zeta, f"{cal.seconds:.2f} s"))
    return out


if __name__ == "__main__":
    run_table(__doc__, benches)
