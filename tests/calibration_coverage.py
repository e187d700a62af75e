"""One seed of the coverage study of issue 33 (tests/test_calibration_intervals.py): the
recorder model's three shots of the trust tests (tests/test_recorder.py: 243.5, 200 and
150 m/s at 20, 50 and 30 kHz, 3 % noise, a 50 g offset, the axis reversed), calibrated, and
what the printed intervals claim against the truth. A module of its own, so that the
coverage test's worker processes (spawned) can import it."""
import numpy as np

SPEEDS = (243.53532, 200.0, 150.0)
RATES = (20_000.0, 50_000.0, 30_000.0)


def setup():
    """Shot A at 1 us, and the trust tests' other law (the macro's times 1.15 - 0.0006 V,
    refitted at degree 6, so a fitted law can equal it)."""
    from conftest import TEMPLATE
    from numpy.polynomial import Polynomial

    import airgun_xl
    from airgun_xl.crush_law import LEGACY_LAW, CrushLaw

    shot = airgun_xl.load(TEMPLATE).params.replace(delta=1e-6)
    v = np.linspace(0, 250, 200)
    truth = CrushLaw(tuple(Polynomial.fit(v, LEGACY_LAW.poly(v) * (1.15 - 0.0006 * v), 6)
                           .convert().coef), (0, 250), "fitted")
    return shot, truth


def recordings(shot, changes, seed, shots=tuple(zip(SPEEDS, RATES, strict=True))):
    """Each (speed, rate)'s run with ``changes`` through the recorder model (seed + its
    index), read with the recorder's axis reversed (as --sign -1)."""
    import airgun_xl
    from airgun_xl.readers.recording import Trace
    from airgun_xl.studies.recorder import Recorder

    out = []
    for i, (v, rate) in enumerate(shots):
        run = airgun_xl.Shot(shot.replace(v31=v, v32=v, v33=v, **changes)).run(track=())
        trace = Recorder(rate=rate).record(run, seed=seed + i)
        out.append(Trace(trace.time, -trace.accel_kg, trace.dt, f"s{i}", trace.units))
    return out


def one_seed(job):
    """``job`` = (what, cfc, seed): "law" (the law from the macro's, as the trust test) or
    "E40" (sigma_y x 1.07 and zeta 0.04 in the shots, E40 fitted alone, as the trust
    test). Returns (estimates, truths, standard errors, nodes or None)."""
    from airgun_xl.studies.calibrate import calibrate

    what, cfc, seed = job
    shot, truth = setup()
    starts = [shot.replace(v31=v, v32=v, v33=v) for v in SPEEDS]
    if what == "law":
        cal = calibrate(starts, recordings(shot, {"crush_law": truth}, seed), law=True,
                        cfc=cfc)
        nodes = np.asarray(cal.law_nodes)
        return cal.params[0].crush_law(nodes), truth(nodes), np.asarray(cal.law_errors), nodes
    changes = {"sigmay": shot.sigmay * 1.07, "zeta": 0.04}
    cal = calibrate(starts, recordings(shot, changes, seed), law=False, fit=["E40"], cfc=cfc)
    return (np.array([cal.fitted["E40"]]), np.array([changes["sigmay"]]),
            np.array([cal.errors["E40"]]), None)
