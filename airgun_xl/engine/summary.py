"""Headline figures of a run, as the report judges a shot (section 4.3, Figs. 12-19).

Pure functions of arrays in SI units; :func:`summarize` gathers them for a
:class:`airgun_xl.result.Result`.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..result import Result

#: Pulse duration: the span where the acceleration is at least this fraction of its peak.
PULSE_FRACTION = 0.10

#: Spectrum band charted and searched for dominant frequencies [Hz] (the report's Figs. 14-15).
SPECTRUM_MAX_HZ = 15_000.0

#: Dominant frequencies: local maxima of the amplitude spectrum above this frequency [Hz]; below
#: it the spectrum is the pulse's own envelope (a 5 ms pulse has its content under 1 kHz).
PEAK_MIN_HZ = 1_000.0


def log_prominences(amplitude: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Topographic prominence of each peak on a log scale: ln(peak / its higher base).

    The base on each side is the lowest point before the spectrum rises above the peak again
    (or ends). This ranks a sharp resonance above a tall shoulder of the envelope. Written out
    because importing scipy.signal (its ``peak_prominences``) takes 1.8 s here, more than a
    whole fill.
    """
    out = np.empty(len(peaks))
    n = len(amplitude)
    for k, i in enumerate(peaks):
        bases = []
        for step in (-1, 1):
            j, low = i, amplitude[i]
            while 0 <= j + step < n and amplitude[j + step] <= amplitude[i]:
                j += step
                low = min(low, amplitude[j])
            bases.append(low)
        out[k] = np.log(amplitude[i] / max(max(bases), 1e-300))
    return out


def natural_frequencies(masses: Sequence[float], springs: Sequence[float]) -> list[float]:
    """Natural frequencies [Hz] of a free chain of masses joined by springs.

    Parameters
    ----------
    masses : sequence of float
        Chain masses [kg], e.g. (m31, m32, m33).
    springs : sequence of float
        Stiffness between neighbours [N/m], positive (one fewer than masses).

    Returns
    -------
    list of float
        The non-zero frequencies, ascending (the rigid-body mode is left out).
    """
    n = len(masses)
    if n < 2:
        return []
    K = np.zeros((n, n))
    for i, k in enumerate(springs):
        K[i:i + 2, i:i + 2] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    A = K / np.asarray(masses)[:, None]
    if not np.isfinite(A).all():
        return [math.nan] * (n - 1)  # beyond floating point: no frequency to report
    w2 = np.sort(np.real(np.linalg.eigvals(A)))
    return [float(np.sqrt(max(w, 0.0)) / (2 * np.pi)) for w in w2[1:]]

KG = -9800.0  # the macro's m/s^2 -> kG divisor


@dataclass
class Spectrum:
    """Single-sided amplitude spectrum of the test-item acceleration.

    Attributes
    ----------
    frequency : numpy.ndarray
        Frequency [Hz], 0 to :data:`SPECTRUM_MAX_HZ`.
    amplitude : numpy.ndarray
        2|FFT|/N of the acceleration in kG [kG] (the DC bin is |FFT|/N, the mean).
    peaks : list of float
        Dominant frequencies [Hz], most prominent first, from ``band_start`` on.
    band_start : float
        Where the pulse's own lobe ends (:func:`lobe_end`) [Hz]: peaks and the chart from here.
    """

    frequency: np.ndarray
    amplitude: np.ndarray
    peaks: list[float] = field(default_factory=list)
    band_start: float = PEAK_MIN_HZ


def amplitude_spectrum(accel_kg: np.ndarray, delta: float, max_hz: float = SPECTRUM_MAX_HZ,
                       n_peaks: int = 3) -> Spectrum:
    """Amplitude spectrum of an acceleration history, by numpy's real FFT.

    Parameters
    ----------
    accel_kg : numpy.ndarray
        Acceleration [kG] on a uniform time grid; NaN ends (where the macro writes nothing) are
        dropped.
    delta : float
        Time step [s].
    max_hz : float
        Highest frequency kept [Hz].
    n_peaks : int
        How many dominant frequencies to report.

    Returns
    -------
    Spectrum
    """
    a = accel_kg[np.isfinite(accel_kg)]
    if len(a) < 2:
        return Spectrum(np.zeros(0), np.zeros(0), [])
    amp = np.abs(np.fft.rfft(a)) * (2.0 / len(a))
    amp[0] /= 2
    freq = np.fft.rfftfreq(len(a), delta)
    keep = freq <= max_hz
    freq, amp = freq[keep], amp[keep]
    start = lobe_end(freq, amp)
    inner = np.arange(1, len(amp) - 1)
    is_peak = (amp[inner] > amp[inner - 1]) & (amp[inner] >= amp[inner + 1])
    candidates = inner[is_peak & (freq[inner] >= start)]
    order = np.argsort(-log_prominences(amp, candidates), kind="stable")
    return Spectrum(freq, amp, [float(freq[candidates[i]]) for i in order[:n_peaks]], start)


def lobe_end(freq: np.ndarray, amp: np.ndarray, min_hz: float = PEAK_MIN_HZ) -> float:
    """Where the pulse's own spectrum (the lobe from 0 Hz) ends [Hz]: past ``min_hz``, each
    local maximum whose nearest higher ground to its left lies below ``min_hz`` is a shoulder
    of that lobe, not a mode (shot A's 1.33 kHz); the band starts at the first local minimum
    after the last of them. Dominant frequencies are sought, and the chart drawn, from there.
    """
    start = min_hz
    inner = np.arange(1, len(amp) - 1)
    peaks = inner[(amp[inner] > amp[inner - 1]) & (amp[inner] >= amp[inner + 1])
                  & (freq[inner] >= min_hz)]
    for i in peaks:
        higher = np.flatnonzero(amp[:i] > amp[i])
        if len(higher) and freq[higher[-1]] < min_hz:  # a shoulder of the lobe from 0 Hz
            after = np.flatnonzero((amp[i + 1:-1] <= amp[i:-2]) & (amp[i + 1:-1] < amp[i + 2:]))
            start = float(freq[i + 1 + after[0]]) if len(after) else float(freq[-1])
        elif freq[i] > start:
            break
    return start


def pulse(time: np.ndarray, accel_kg: np.ndarray, fraction: float = PULSE_FRACTION
          ) -> tuple[float, float, float]:
    """Start, end and duration [s] of the span where acceleration >= fraction x peak."""
    if not np.isfinite(accel_kg).any():
        return np.nan, np.nan, np.nan
    peak = np.nanmax(accel_kg)
    if peak <= 0:
        return np.nan, np.nan, 0.0
    above = np.flatnonzero(accel_kg >= fraction * peak)
    start, end = float(time[above[0]]), float(time[above[-1]])
    return start, end, end - start


@dataclass
class Summary:
    """The figures of the Summary sheet; every value in SI units unless the name says kG."""

    peak_kg: float
    time_of_peak: float
    filtered_peak_kg: float
    time_of_filtered_peak: float
    pulse_start: float
    pulse_end: float
    pulse_duration: float
    max_crush: float
    final_length: float
    final_m1: float
    final_m31: float
    obr_exit_velocity: float
    mem_final_velocity: float
    spectrum: Spectrum
    natural_initial: list[float]
    natural_final: list[float]


def _last_finite(values: np.ndarray | None) -> float:
    if values is None:
        return np.nan
    finite = np.flatnonzero(np.isfinite(values))
    return float(values[finite[-1]]) if len(finite) else np.nan


def summarize(result: Result) -> Summary:
    """The :class:`Summary` of a :class:`airgun_xl.result.Result`."""
    h, p = result.history, result.params
    time = h.time
    finite = np.isfinite(result.accel_kg)
    if finite.any():
        i = int(np.nanargmax(result.accel_kg))
        peak, t_peak = float(result.accel_kg[i]), float(time[i])
    else:
        peak, t_peak = np.nan, np.nan
    f_rows, f_values = result.filtered.rows, result.filtered.values
    inside = f_rows < len(time)
    if inside.any() and p.samplerate >= 1:  # below a row, AB is no acceleration (quirk)
        kg = f_values[inside] / KG
        j = int(np.argmax(kg))
        f_peak, t_f_peak = float(kg[j]), float(time[f_rows[inside][j]])
    else:
        f_peak, t_f_peak = np.nan, np.nan
    start, end, duration = pulse(time, result.accel_kg)
    chain = (p.m31, p.m32, p.m33)[:p.bird_masses]
    springs = (-p.k2, -p.k3)[:p.bird_masses - 1]
    max_crush = float(np.nanmax(h.deflection)) if h.deflection is not None else np.nan
    return Summary(
        peak_kg=peak, time_of_peak=t_peak, filtered_peak_kg=f_peak,
        time_of_filtered_peak=t_f_peak, pulse_start=start, pulse_end=end,
        pulse_duration=duration, max_crush=max_crush,
        final_length=p.hcone + p.hcylinder - max_crush,
        final_m1=h.final_m1, final_m31=h.final_m31,
        obr_exit_velocity=_last_finite(h.v31), mem_final_velocity=_last_finite(h.v1),
        spectrum=amplitude_spectrum(result.accel_kg, p.delta),
        natural_initial=natural_frequencies(chain, springs),
        natural_final=natural_frequencies((h.final_m31,) + chain[1:], springs),
    )
