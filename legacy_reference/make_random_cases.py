"""Random shots around shot A, run through the original macro: the held-out kind of check of
issue 18 ("random shots whose macro runs stay bounded fill with --host calc and agree").

    python legacy_reference/make_random_cases.py SEED COUNT

Each shot varies the masses, springs, velocities, honeycomb, mitigator and filter over wide
ranges (numpy's default_rng(SEED)); shots whose OBR chain is unstable at their step are
skipped (fill refuses them, as the macro overflows). Writes random_SEED_NN_input.xlsx and
_legacy.xlsx with make_case.py and prints the cases.json entries (host "calc").
"""
import sys

import numpy as np
from make_case import main as make_case

import airgun_xl
from airgun_xl.cells import BY_NAME
from airgun_xl.engine.stability import critical_time_step

BASE = "shot_a_appendix_5us_input.xlsx"


def random_shots(seed, count):
    from pathlib import Path

    base = airgun_xl.load(Path(__file__).resolve().parent / BASE).params
    rng = np.random.default_rng(seed)

    def lu(a, b):
        return float(10 ** rng.uniform(np.log10(a), np.log10(b)))

    found = []
    while len(found) < count:
        v = float(rng.uniform(5, 300))
        delta = float(rng.choice([1e-6, 2e-6, 2.5e-6, 4e-6]))
        q = base.replace(
            v31=v, v32=v * float(rng.uniform(0.95, 1.05)), v33=v * float(rng.uniform(0.95, 1.05)),
            v1=float(rng.choice([0.0, 0.0, rng.uniform(-20, 40)])),
            sigmay=base.sigmay * lu(0.2, 4), E=base.E * lu(0.01, 10),
            hcone=float(rng.choice([0.0, 0.02, base.hcone, 0.2])),
            hcylinder=base.hcylinder * lu(0.1, 1), zeta=float(rng.uniform(0, 0.3)),
            m1=base.m1 * lu(0.02, 3), m31=base.m31 * lu(0.3, 3), m32=base.m32 * lu(0.3, 3),
            m33=base.m33 * lu(0.3, 3), k2=base.k2 * lu(0.1, 3), k3=base.k3 * lu(0.1, 3),
            ec=float(rng.uniform(0.3, 0.9)), delta=delta,
            max_time=float(rng.choice([1.5e-3, 2e-3, 3e-3])) if delta >= 2e-6 else 1.5e-3,
            filter_frequency=1 / (delta * int(rng.choice([1, 2, 5, 10, 20]))))
        if critical_time_step(q).ratio > 1:
            continue
        found.append({BY_NAME[k].address: v for k, v in q.as_dict().items() if k in BY_NAME})
    return found


if __name__ == "__main__":
    seed, count = int(sys.argv[1]), int(sys.argv[2])
    for i, cells in enumerate(random_shots(seed, count), 1):
        make_case(f"random_{seed}_{i:02d}", cells)
