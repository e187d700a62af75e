"""A shock recorder, modelled: what a lab's data acquisition makes of a shot's pulse.

The tests and the benchmarks feed compare-measured and calibrate recordings that have what
real ones have, from a run whose parameters are known:

- an analog anti-alias filter (a causal Butterworth low-pass, 4 poles at a fifth of the rate
  by default), applied at the model's own fine step before sampling;
- sampling at the recorder's rate, on its own clock (``clock`` [s] ahead of the run's);
- a pre-trigger record (the run is at rest before its impact);
- a zero offset (in g), white noise (a fraction of the peak), a decaying mount ringing;
- the recorder's axis, which may point against the macro's (``sign`` -1).

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
        Of the Butterworth anti-alias filter.
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

    @property
    def corner(self):
        return self.anti_alias if self.anti_alias is not None else self.rate / 5

    def record(self, result, seed=0, name="recorder"):
        """The recording of a run (a :class:`~airgun_xl.result.Result`) as a
        :class:`~airgun_xl.readers.recording.Trace` in kG, on the recorder's clock."""
        from scipy.signal import butter, sosfilt

        from ..readers.recording import Trace

        ok = np.isfinite(result.accel_kg)
        t_run, a_run = result.history.time[ok], result.accel_kg[ok]
        fine = float(t_run[1] - t_run[0])
        rest = int(round(self.pre_trigger / fine)) + 1
        t_fine = np.concatenate([t_run[0] - fine * np.arange(rest, 0, -1), t_run])
        a_fine = np.concatenate([np.zeros(rest), a_run])
        sos = butter(self.poles, self.corner, fs=1 / fine, output="sos")
        analog = sosfilt(sos, a_fine)
        time = np.arange(-self.pre_trigger, t_run[-1], 1 / self.rate)
        accel = np.interp(time, t_fine, analog)
        peak = float(np.max(accel))
        after = np.clip(time, 0, None)
        ring = self.ringing * peak * np.sin(2 * np.pi * self.ringing_hz * after) * np.exp(
            -after / 1e-3)
        rng = np.random.default_rng(seed)
        accel = (accel + np.where(time > 0, ring, 0.0)
                 + self.noise * peak * rng.standard_normal(len(time)))
        offset_kg = self.offset_g * G / KG_MS2
        return Trace(time + self.clock, self.sign * (accel + offset_kg), 1 / self.rate, name,
                     ("s", "kG"))

    def csv(self, trace, path, time_unit="ms", accel_unit="g", metadata=(), delimiter=",",
            decimal="."):
        """Write ``trace`` as a data-acquisition export: ``metadata`` lines (``# ...``) above
        a header with the units, the values in ``time_unit`` and ``accel_unit``."""
        from ..readers.recording import ACCEL_UNITS, TIME_UNITS

        t = trace.time / TIME_UNITS[time_unit]
        a = trace.accel_kg / ACCEL_UNITS[accel_unit]
        lines = [f"# {m}" for m in metadata]
        lines.append(f"time [{time_unit}]{delimiter}acceleration [{accel_unit}]")
        for x, y in zip(t.tolist(), a.tolist(), strict=True):
            row = f"{x!r}{delimiter}{y!r}"
            lines.append(row.replace(".", decimal) if decimal != "." else row)
        with open(path, "w", encoding="utf-8") as out:
            out.write("\n".join(lines) + "\n")
        return path
