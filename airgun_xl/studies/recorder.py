"""A shock recorder, modelled: what a lab's data acquisition makes of a shot's pulse.

The tests and the benchmarks feed compare-measured and calibrate recordings that have what
real ones have, from a run whose parameters are known:

- an analog anti-alias filter (a causal Butterworth low-pass, 4 poles at a fifth of the rate
  by default), applied at the model's own fine step before sampling;
- sampling at the recorder's rate, on its own clock (``clock`` [s] ahead of the run's);
- a pre-trigger record (the run is at rest before its impact);
- a zero offset (in g), noise (a fraction of the peak: white, or part of it correlated from
  sample to sample, an AR(1) of coefficient ``colour``), a decaying mount ringing;
- the recorder's axis, which may point against the macro's (``sign`` -1);
- the converter: its range (``full_scale``, where a pulse past it is clipped), its
  resolution (``bits``) and its own noise (``adc_noise`` [LSB]), and the trigger's phase
  against the pulse (``phase``, a fraction of a sample).

:meth:`Recorder.csv` writes it as a data-acquisition export would (ms and g by default).
"""
from dataclasses import dataclass

import numpy as np

from ..units import KG_MS2, G


@dataclass(frozen=True)
class Recorder:
    """A recorder's settings.

    Attributes
    ----------
    rate : float
        Sample rate [Hz].
    anti_alias : float or None
        Anti-alias corner [Hz]; None: a fifth of ``rate``.
    poles : int
        Of the Butterworth anti-alias filter (0: none, the pulse sampled as it is).
    noise : float
        White noise, standard deviation as a fraction of the peak [-].
    offset_g : float
        Zero offset [g].
    pre_trigger : float
        Record before the impact [s].
    sign : float
        +1, or -1 for an axis against the macro's (a deceleration negative).
    ringing, ringing_hz : float
        A mount ringing from the impact: amplitude as a fraction of the peak [-], frequency
        [Hz], decaying over 1 ms.
    clock : float
        The recorder's clock ahead of the run's [s]: the shift an alignment must find is
        ``-clock``.
    colour, colour_share : float
        The noise's correlated part: an AR(1) of coefficient ``colour`` [-] carrying
        ``colour_share`` of its variance (the rest white).
    full_scale : float or None
        The converter's range, ± [kG] (the recorded value, offset and axis included): past it
        the record holds at its end code (clipped). None: no range.
    bits : int or None
        The converter's resolution over the range (needs ``full_scale``); None: exact values.
    adc_noise : float
        The converter's own white noise [LSB], after the anti-alias filter.
    phase : float
        The first sample's lag behind the sampling grid through the impact [samples, 0-1).
    """

    rate: float = 50_000.0
    anti_alias: float | None = None
    poles: int = 4
    noise: float = 0.03
    offset_g: float = 50.0
    pre_trigger: float = 1.5e-3
    sign: float = -1.0
    ringing: float = 0.0
    ringing_hz: float = 8000.0
    clock: float = 2e-3
    colour: float = 0.0
    colour_share: float = 1.0
    full_scale: float | None = None
    bits: int | None = None
    adc_noise: float = 0.0
    phase: float = 0.0

    @property
    def corner(self):
        return self.anti_alias if self.anti_alias is not None else self.rate / 5

    @property
    def lsb(self):
        """The converter's step [kG], or 0 without a resolution."""
        if self.bits is None or self.full_scale is None:
            return 0.0
        return 2 * self.full_scale / 2 ** self.bits

    def record(self, result, seed=0, name="recorder"):
        """The recording of a run (a :class:`~airgun_xl.result.Result`) as a
        :class:`~airgun_xl.readers.recording.Trace` in kG, on the recorder's clock."""
        ok = np.isfinite(result.accel_kg)
        return self.record_pulse(result.history.time[ok], result.accel_kg[ok], seed, name)

    def record_pulse(self, t_run, a_run, seed=0, name="recorder"):
        """The recording of a pulse ``a_run`` [kG] on the fine grid ``t_run`` [s] (at rest
        before its first sample, the impact) as a
        :class:`~airgun_xl.readers.recording.Trace` in kG, on the recorder's clock."""
        from scipy.signal import butter, lfilter, sosfilt

        from ..readers.recording import Trace

        t_run, a_run = np.asarray(t_run, dtype=float), np.asarray(a_run, dtype=float)
        fine = float(t_run[1] - t_run[0])
        rest = int(round(self.pre_trigger / fine)) + 1
        t_fine = np.concatenate([t_run[0] - fine * np.arange(rest, 0, -1), t_run])
        a_fine = np.concatenate([np.zeros(rest), a_run])
        analog = sosfilt(butter(self.poles, self.corner, fs=1 / fine, output="sos"),
                         a_fine) if self.poles else a_fine
        time = np.arange(-self.pre_trigger + self.phase / self.rate, t_run[-1], 1 / self.rate)
        accel = np.interp(time, t_fine, analog)
        peak = float(np.max(accel))
        after = np.clip(time, 0, None)
        ring = self.ringing * peak * np.sin(2 * np.pi * self.ringing_hz * after) * np.exp(
            -after / 1e-3)
        rng = np.random.default_rng(seed)
        white = rng.standard_normal(len(time))
        if self.colour:  # part of the variance an AR(1), stationary from its first sample
            w = rng.standard_normal(len(time)) * np.sqrt(1 - self.colour ** 2)
            w[0] = rng.standard_normal()
            ar = lfilter([1.0], [1.0, -self.colour], w)
            white = np.sqrt(1 - self.colour_share) * white + np.sqrt(self.colour_share) * ar
        accel = (accel + np.where(time > 0, ring, 0.0) + self.noise * peak * white)
        offset_kg = self.offset_g * G / KG_MS2
        value = self.sign * (accel + offset_kg)
        if self.full_scale is not None:
            q = self.lsb
            if q and self.bits is not None:
                codes = np.round(value / q + self.adc_noise * rng.standard_normal(len(value)))
                top = 2 ** (self.bits - 1)
                value = np.clip(codes, -top, top - 1) * q
            else:
                value = np.clip(value, -self.full_scale, self.full_scale)
        return Trace(time + self.clock, value, 1 / self.rate, name, ("s", "kG"))

    def csv(self, trace, path, time_unit="ms", accel_unit="g", metadata=(), delimiter=",",
            decimal=".", digits=None):
        """Write ``trace`` as a data-acquisition export: ``metadata`` lines (``# ...``) above
        a header with the units, the values in ``time_unit`` and ``accel_unit`` (the
        acceleration to ``digits`` significant digits, or exactly)."""
        from ..readers.recording import ACCEL_UNITS, TIME_UNITS

        t = trace.time / TIME_UNITS[time_unit]
        a = trace.accel_kg / ACCEL_UNITS[accel_unit]
        lines = [f"# {m}" for m in metadata]
        lines.append(f"time [{time_unit}]{delimiter}acceleration [{accel_unit}]")
        for x, y in zip(t.tolist(), a.tolist(), strict=True):
            row = f"{x!r}{delimiter}" + (f"{y!r}" if digits is None else f"{y:.{digits}g}")
            lines.append(row.replace(".", decimal) if decimal != "." else row)
        with open(path, "w", encoding="utf-8") as out:
            out.write("\n".join(lines) + "\n")
        return path
