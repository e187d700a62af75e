"""Issue 13: the batch kernel runs the legacy scheme LANES shots at a time (SIMD, branches as
selects); every lane equals the single-shot kernel bit for bit, on the legacy cases and on
random batches, and a lane that diverges stops alone."""
import json
import zlib

import numpy as np
import pytest
from conftest import CASES, REFERENCE

import airgun_xl
from airgun_xl.engine.batch import N_FINALS
from airgun_xl.engine.integrators import displacement_bound, kernel_params, run_legacy

compiled = pytest.importorskip("airgun_xl.engine._artsim")

UNSTABLE = json.loads((REFERENCE / "unstable_cases.json").read_text())
INPUTS = sorted({c["input"] for c in CASES.values()} | {c["input"] for c in UNSTABLE.values()})
SHOT_A = airgun_xl.load(REFERENCE / CASES["shot_a_appendix_5us"]["input"]).params


def _batch(shots, lanes=True, last=3):
    rows = shots[0].rows
    matrix = np.array([kernel_params(p) + [displacement_bound(p)] for p in shots])
    t, y, finals = np.empty(rows), np.empty((len(shots), rows)), np.empty((len(shots), N_FINALS))
    compiled.batch_kernel(matrix, rows, 0, last, t, y, finals, lanes)
    return t, y, finals


def _random_shots(seed, n, base=SHOT_A):
    """Shots around ``base`` over the valid ranges: speeds 0-320 m/s, yield stress, wedge
    (none, short, as shot A), damping, MEM speed; some stiff enough to diverge."""
    rng = np.random.default_rng(seed)
    shots = []
    for _ in range(n):
        v = float(rng.uniform(0, 320))
        q = base.replace(v31=v, v32=v, v33=v, v1=float(rng.choice([0.0, 0.0, 30.0])),
                         sigmay=float(rng.uniform(2e7, 3.2e7)),
                         hcone=float(rng.choice([0.0, 0.02, base.hcone])),
                         zeta=float(rng.uniform(0, 0.3)))
        if rng.random() < 0.15:
            q = q.replace(k3=-5e13)  # far past the critical step: diverges
        shots.append(q)
    return shots


@pytest.mark.parametrize("name", INPUTS)
def test_each_legacy_case_in_a_batch_equals_its_single_shot_run(name):
    """The case in lane 3 of a batch of 11 (its neighbours differ), against legacy_kernel."""
    p = airgun_xl.load(REFERENCE / name).params
    others = _random_shots(zlib.crc32(name.encode()) % 1000, 10, base=p)  # fixed, not hash()
    _, y, finals = _batch(others[:3] + [p] + others[3:], last=p.bird_masses)
    try:
        solo = run_legacy(p, track=())
    except airgun_xl.DivergenceError as caught:  # chain_just_unstable: it stops at that row
        assert finals[3, 2] == caught.row
        return
    if solo.stats.past_bound is not None:  # the unloading quirk's run: the lane stops there
        assert finals[3, 2] == solo.stats.past_bound
        return
    assert np.array_equal(y[3], (solo.y31, solo.y32, solo.y33)[p.bird_masses - 1])
    assert (finals[3, 0], finals[3, 1], finals[3, 2]) == (solo.final_m1, solo.final_m31, -1)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_batches_equal_the_scalar_loop_bit_for_bit(seed):
    shots = _random_shots(seed, 37)  # 37: four full groups of 8 lanes and a part
    lanes, scalar = _batch(shots, lanes=True), _batch(shots, lanes=False)
    for a, b in zip(lanes, scalar, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert 0 < (lanes[2][:, 2] >= 0).sum() < len(shots)  # some lanes diverged, not all


def test_a_diverging_lane_stops_alone():
    """Lanes 2 and 5 diverge; the other six run to the end, each equal to its solo run."""
    shots = [SHOT_A.replace(v31=v, v32=v, v33=v) for v in np.linspace(150, 260, 8)]
    shots[2] = shots[5] = SHOT_A.replace(k3=-5e13)
    _, y, finals = _batch(shots)
    stopped = finals[:, 2]
    assert (stopped[[2, 5]] > 0).all() and (np.delete(stopped, [2, 5]) == -1).all()
    assert (y[2, int(stopped[2]) + 1:] == 0).all()  # nothing written after the stop
    for i in (0, 7):
        assert np.array_equal(y[i], run_legacy(shots[i], track=()).y33)
