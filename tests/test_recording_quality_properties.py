"""Issue 42: the recording-quality stage's properties (hypothesis, derandomized: the same
examples every run).

Random smooth pulses (tests/recorded_pulses.py: half-sine, terminal-peak sawtooth,
trapezoid, the air gun's own) of 0.1 to 10 ms and 0.1 to 100 kG through random recorders
(studies/recorder.py): 20 to 2,000 samples across D, an anti-alias filter or none, a
converter of 12, 14, 16 or 24 bits over 1.3 to 5 times the peak (or exact values), 0 to 1 LSB
of its own noise, noise of 0 or 0.01 % to 5 % of the peak (part of it AR(1) up to 0.8), an
offset up to ±50 g, any trigger phase, 0.5 to 2 D of pre-trigger. A trapezoid is named as
such (its flat top expected), as accept does when the specification names it.

The sizes that are always caught, stated:

- **a clip** that takes 20 % to 50 % off the peak, recorded at 50 samples or more across D
  (1,000 or more across the air gun pulse's width at 10 %, its top being 60 times narrower),
  with noise up to 3 % of the peak; a trapezoid's (its flat top expected) with noise of
  0.3 % to 3 % (below it, nothing tells its plateau from a clip);
- **a dropout** of max(8 samples, 5 % of the pulse above 25 % of its peak) at 50 samples or
  more across D: a run of the recorder's zero anywhere in the pulse above 25 % of its peak,
  or a hold of the last value on its rise (between 25 % and 90 % of its peak) that the
  signal leaves by 10 % of its peak or more, with noise up to 1 %.
"""
import math

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from recorded_pulses import SHAPES, pulse

from airgun_xl.studies.recorder import Recorder
from airgun_xl.studies.recording_quality import assess
from airgun_xl.units import KG_MS2, G

PROPERTY = settings(max_examples=200, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])


def _log(draw, lo, hi):
    return 10 ** draw(st.floats(math.log10(lo), math.log10(hi)))


@st.composite
def recorded(draw, shapes=SHAPES, least_per_d=20.0, clip=False, noise=(1e-4, 0.05),
             noisy=False):
    """(shape, its record, the recorder): with ``clip``, the pulse passes the converter's
    range by 20 % to 50 % of it; with ``noisy``, the noise is never 0."""
    shape = draw(st.sampled_from(shapes))
    duration, peak = _log(draw, 1e-4, 1e-2), _log(draw, 0.1, 100.0)
    per_d = _log(draw, max(least_per_d, 1000.0 if clip and shape == "air gun" else 0.0),
                 2000.0 if not clip or shape != "air gun" else 3000.0)
    level = _log(draw, *noise)
    offset_g = draw(st.floats(-50.0, 50.0))
    offset = offset_g * G / KG_MS2
    bits = draw(st.sampled_from([None, 12, 14, 16, 24]))
    if clip:
        full_scale = peak / (1 + draw(st.floats(0.2, 0.5))) + offset
    else:
        full_scale = peak * draw(st.floats(1.3, 5.0)) + abs(offset)
    recorder = Recorder(
        rate=per_d / duration, noise=level if noisy or draw(st.booleans()) else 0.0,
        colour=draw(st.floats(0.0, 0.8)), colour_share=draw(st.floats(0.0, 1.0)),
        full_scale=full_scale, bits=bits, adc_noise=draw(st.floats(0.0, 1.0)),
        phase=draw(st.floats(0.0, 0.999)), offset_g=offset_g, sign=1.0, clock=0.0,
        pre_trigger=duration * draw(st.floats(0.5, 2.0)), poles=draw(st.sampled_from([0, 4])))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    return shape, recorder.record_pulse(*pulse(shape, duration, peak), seed=seed), recorder


@PROPERTY
@given(recorded())
def test_a_smooth_pulse_through_any_recorder_is_never_called_clipped_or_dropped(case):
    shape, trace, _ = case
    q = assess(trace.time, trace.accel_kg, "r", flat_top=shape == "trapezoid")
    assert q.clip is None, q.warnings
    assert not q.dropouts, q.warnings
    assert not (q.starts_inside or q.ends_inside), q.warnings


@PROPERTY
@given(recorded(shapes=("half-sine", "sawtooth", "air gun"), least_per_d=50.0, clip=True,
                noise=(1e-4, 0.03)))
def test_a_clip_of_20_to_50_percent_is_always_caught(case):
    _, trace, recorder = case
    q = assess(trace.time, trace.accel_kg, "r")
    assert q.clip is not None and q.damaged, (recorder, q.lsb, q.base)


@PROPERTY
@given(recorded(shapes=("trapezoid",), least_per_d=50.0, clip=True, noise=(0.003, 0.03),
                noisy=True))
def test_a_clipped_trapezoid_is_caught_by_its_noise_though_its_flat_top_is_expected(case):
    _, trace, recorder = case
    q = assess(trace.time, trace.accel_kg, "r", flat_top=True)
    assert q.clip is not None, (recorder, q.lsb, q.base)


@PROPERTY
@given(recorded(least_per_d=50.0, noise=(1e-4, 0.03)), st.sampled_from(["zero", "hold"]),
       st.floats(0.0, 1.0))
def test_a_dropout_of_8_samples_or_5_percent_of_the_pulse_is_always_caught(case, kind, where):
    shape, trace, recorder = case
    q0 = assess(trace.time, trace.accel_kg, "r", flat_top=shape == "trapezoid")
    x = trace.accel_kg.copy()
    z = x - q0.base.offset
    peak = float(np.max(z))
    body = np.flatnonzero(z >= 0.25 * peak)
    length = max(8, int(0.05 * len(body)))
    if kind == "zero":
        assume(body[-1] - body[0] > length + 2)
        start = int(body[0] + 1 + where * (body[-1] - length - body[0] - 1))
        x[start:start + length] = q0.base.offset  # the recorder's zero
    else:
        assume(recorder.noise <= 0.01)
        top = int(np.argmax(z))
        rise = np.flatnonzero((z[:top] >= 0.25 * peak) & (z[:top] <= 0.9 * peak))
        assume(len(rise) >= length + 2)
        start = int(rise[0] + 1 + where * (rise[-1] - length + 1 - rise[0] - 1))
        assume(abs(z[start + length] - z[start - 1]) >= 0.1 * peak)
        x[start:start + length] = x[start - 1]  # the last value held
    q = assess(trace.time, x, "r", flat_top=shape == "trapezoid")
    assert q.dropouts or q.clip is not None, (kind, recorder, q.lsb, q.base)
