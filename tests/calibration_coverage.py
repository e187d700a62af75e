"""One seed of the coverage study of issue 33 (tests/test_calibration_intervals.py): the
recorder model's three shots of the trust tests (tests/test_recorder.py: 243.5, 200 and
150 m/s at 20, 50 and 30 kHz, 3 % noise, a 50 g offset, the axis reversed), calibrated, and
what the printed intervals claim against the truth. A module of its own, so that the
coverage test's worker processes (spawned) can import it."""
import functools

import numpy as np

SPEEDS = (243.53532, 200.0, 150.0)

#: What is calibrated (what, cfc, noise): the law unfiltered under white and the most
#: correlated noise and through CFC 600 under the most correlated, E40 under the most
#: correlated (3 x 7 law nodes and 1 E40: 22 intervals); and over how many noise seeds. (The
#: half-white AR(1) of 0.6 lies between the two; ``main`` runs it too.)
STUDIES = (("law", None, "white"), ("law", None, "ar0.8"), ("law", 600, "ar0.8"),
           ("E40", None, "ar0.8"))
SEEDS = 100
RATES = (20_000.0, 50_000.0, 30_000.0)


@functools.lru_cache(maxsize=1)
def setup():
    """Shot A at 1 us, and the trust tests' other law (the macro's times 1.15 - 0.0006 V,
    refitted at degree 6, so a fitted law can equal it); once a process (both are frozen)."""
    from conftest import TEMPLATE
    from numpy.polynomial import Polynomial

    import airgun_xl
    from airgun_xl.crush_law import LEGACY_LAW, CrushLaw

    shot = airgun_xl.load(TEMPLATE).params.replace(delta=1e-6)
    v = np.linspace(0, 250, 200)
    truth = CrushLaw(tuple(Polynomial.fit(v, LEGACY_LAW.poly(v) * (1.15 - 0.0006 * v), 6)
                           .convert().coef), (0, 250), "fitted")
    return shot, truth


#: The noise of the recorder model's recordings: white (3 % of the peak, the trust tests'),
#: and the same variance half white and half an AR(1) of 0.6, or all an AR(1) of 0.8.
NOISES = {"white": {}, "ar0.6": {"colour": 0.6, "colour_share": 0.5},
          "ar0.8": {"colour": 0.8, "colour_share": 1.0}}


def recordings(shot, changes, seed, shots=tuple(zip(SPEEDS, RATES, strict=True)),
               noise="white"):
    """Each (speed, rate)'s run with ``changes`` through the recorder model (seed + its
    index, noise as :data:`NOISES` names it), read with the recorder's axis reversed (as
    --sign -1)."""
    import airgun_xl
    from airgun_xl.readers.recording import Trace
    from airgun_xl.studies.recorder import Recorder

    out = []
    for i, (v, rate) in enumerate(shots):
        run = airgun_xl.Shot(shot.replace(v31=v, v32=v, v33=v, **changes)).run(track=())
        trace = Recorder(rate=rate, **NOISES[noise]).record(run, seed=seed + i)
        out.append(Trace(trace.time, -trace.accel_kg, trace.dt, f"s{i}", trace.units))
    return out


def one_seed(job):
    """``job`` = (what, cfc, seed[, noise]): "law" (the law from the macro's, as the trust
    test) or "E40" (sigma_y x 1.07 and zeta 0.04 in the shots, E40 fitted alone, as the
    trust test); the noise a :data:`NOISES` key (white by default). Returns (estimates,
    truths, standard errors, nodes or None, each node weakly pinned or None)."""
    from airgun_xl.studies.calibrate import calibrate

    what, cfc, seed, *rest = job
    noise = rest[0] if rest else "white"
    shot, truth = setup()
    starts = [shot.replace(v31=v, v32=v, v33=v) for v in SPEEDS]
    if what == "law":
        cal = calibrate(starts, recordings(shot, {"crush_law": truth}, seed, noise=noise),
                        law=True, cfc=cfc)
        nodes = np.asarray(cal.law_nodes)
        return (cal.params[0].crush_law(nodes), truth(nodes), np.asarray(cal.law_errors),
                nodes, np.array([n.weak for n in cal.law_intervals]))
    changes = {"sigmay": shot.sigmay * 1.07, "zeta": 0.04}
    cal = calibrate(starts, recordings(shot, changes, seed, noise=noise), law=False,
                    fit=["E40"], cfc=cfc)
    return (np.array([cal.fitted["E40"]]), np.array([changes["sigmay"]]),
            np.array([cal.errors["E40"]]), None, None)


def main():
    """Print each study's coverage at each node, and its weak flags' rate, over the seeds
    (what tests/test_calibration_intervals.py asserts; docs/studies.md quotes it)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from airgun_xl.studies.calibrate import Z95

    studies = (*STUDIES, ("law", None, "ar0.6"))
    jobs = [(w, c, 1000 * s, n) for w, c, n in studies for s in range(SEEDS)]
    with ProcessPoolExecutor(2, multiprocessing.get_context("spawn")) as pool:
        results = list(pool.map(one_seed, jobs, chunksize=8))
    for k, study in enumerate(studies):
        rows = results[SEEDS * k:SEEDS * (k + 1)]
        est, truth, err = (np.array([r[i] for r in rows]) for i in range(3))
        hits = (np.abs(est - truth) <= Z95 * err).sum(axis=0)
        weak = np.array([r[4] for r in rows]).mean(axis=0) if rows[0][4] is not None else None
        print(study, "hits", hits.tolist(), "weak", None if weak is None else
              np.round(100 * weak).astype(int).tolist())


if __name__ == "__main__":
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
