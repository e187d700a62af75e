"""Pulses and the recorders that record them, for the recording-quality tests (issue 42).

Pulses are drawn on a fine grid (4,000 points across D) from rest at t = 0: the ideal
half-sine, terminal-peak sawtooth (decaying over 0.1 D) and trapezoid (10 % ramps) of
studies/acceptance.py, and the air gun's own (shot A's predicted pulse, stretched so that its
width at 10 % of its peak is D). The recorder model is studies/recorder.py."""
import functools

import numpy as np
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.readers.recording import Trace
from airgun_xl.studies.acceptance import ideal
from airgun_xl.studies.recorder import Recorder

SHAPES = ("half-sine", "sawtooth", "trapezoid", "air gun")

#: Shot A's pulse is 5.0 ms wide at 10 % of its peak (0.054 to 5.041 ms).
AIR_GUN_WIDTH = 4.987e-3


@functools.lru_cache(maxsize=1)
def _air_gun():
    run = airgun_xl.load(TEMPLATE).run(track=())
    ok = np.isfinite(run.accel_kg)
    t, a = run.history.time[ok], run.accel_kg[ok]
    n = int(len(t) * 1.5)  # at rest after its run, as the bird flies off
    return np.arange(n) * float(t[1] - t[0]), np.concatenate([a, np.zeros(n - len(a))])


def pulse(shape, duration, peak):
    """(t [s], a [kG]): the pulse on its fine grid, at rest from t = 0 and for 1.5 D after."""
    if shape == "air gun":
        t, a = _air_gun()
        return t * (duration / AIR_GUN_WIDTH), a * (peak / float(np.max(a)))
    t = np.arange(0, 2.5 * duration, duration / 4000)
    return t, ideal(shape, t, peak, duration, 0.1 if shape == "sawtooth" else 0.0)


def record(shape, duration, peak, seed=0, **recorder):
    """The recorder's :class:`Trace` of a pulse (offset 0, axis along the macro's, clock at
    the impact unless ``recorder`` says otherwise)."""
    settings = {"offset_g": 0.0, "sign": 1.0, "clock": 0.0, "pre_trigger": 2e-3, **recorder}
    return Recorder(**settings).record_pulse(*pulse(shape, duration, peak), seed=seed)


def with_values(trace, values):
    """``trace`` with other acceleration values [kG]."""
    return Trace(trace.time, np.asarray(values, dtype=float), trace.dt, trace.name,
                 trace.units)
