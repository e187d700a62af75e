"""A prediction against the pulse that was measured: filtered alike, aligned, and scored.

Both traces are filtered with the same SAE J211 channel class (when one is given), each at its
own sample rate; the prediction is then interpolated onto the measurement's grid. Alignment
puts the measured trace's impact instant on the prediction's: the first sample at or above
``threshold`` of its own peak (``"threshold"``), or the lag that maximises their
cross-correlation (``"xcorr"``, scipy.signal). The scores are the headline figures of each
trace (peak, its time, the pulse duration by the Summary's 10 % rule, the velocity change)
with their errors, and Pearson's correlation of the aligned traces over their overlap.
"""
from dataclasses import dataclass, field

import numpy as np

from ..engine.summary import pulse
from ..errors import OptionError
from .shock import cfc_filter

#: The impact instant: the first sample at or above this fraction of the trace's peak.
IMPACT_FRACTION = 0.05

#: kG to m/s^2, the macro's convention.
KG_MS2 = 9800.0

ALIGNMENTS = ("threshold", "xcorr")


@dataclass
class Figures:
    peak_kg: float
    time_of_peak: float  # [s] after the impact instant
    pulse_duration: float  # [s]
    delta_v: float  # [m/s], the integral of the acceleration over the trace


@dataclass
class Comparison:
    """The two traces on one grid and their scores."""

    time: np.ndarray  # [s] after the prediction's impact instant
    predicted_kg: np.ndarray
    measured_kg: np.ndarray
    shift: float  # [s] added to the measured time to align it
    alignment: str
    cfc: object
    predicted: Figures
    measured: Figures
    correlation: float
    errors: dict = field(default_factory=dict)
    iso: object = None  # iso18571.Rating of the prediction against the test
    interval: tuple = (np.nan, np.nan)  # the rating's evaluation interval [s], as ``time``
    predicted_spectrum: object = None  # engine.summary.Spectrum of the aligned traces
    measured_spectrum: object = None
    srs_frequencies: np.ndarray = None  # [Hz]
    predicted_srs: np.ndarray = None  # maximax, Q = 10 [kG]
    measured_srs: np.ndarray = None
    rigid_kg: np.ndarray = None  # the rigid model's prediction on ``time`` (Fig. 13)


#: Rest prepended to the prediction before it is filtered [s]: the recorder is at rest before
#: the impact, and filtfilt's own edge padding (an odd reflection) would bend the rise.
REST_BEFORE = 2e-3


def crossing(time, values, fraction=IMPACT_FRACTION):
    """The instant [s] a trace first reaches ``fraction`` of its peak, interpolated between
    samples (a whole-sample instant would misalign two pulses by up to a step)."""
    level = fraction * np.max(values)
    k = int(np.argmax(values >= level))
    if k == 0:
        return float(time[0])
    a, b = values[k - 1], values[k]
    return float(time[k - 1] + (time[k] - time[k - 1]) * (level - a) / (b - a))


def filtered_from_rest(time, values, cfc):
    """(time, values) at rest for :data:`REST_BEFORE` before the first sample, then filtered
    by channel class ``cfc``: the phaseless filter starts the rise before the impact, and
    that part is kept."""
    dt = float(time[1] - time[0])
    n = int(round(REST_BEFORE / dt))
    t = np.concatenate([time[0] - dt * np.arange(n, 0, -1), time])
    v = np.concatenate([np.zeros(n), np.asarray(values, dtype=float)])
    return t, (cfc_filter(v, dt, cfc) if cfc else v)


def threshold_shift(pred_time, pred_kg, trace, meas, cfc):
    """(shift, impact, filtered prediction): the shift [s] to add to the measured time so that
    both impact instants coincide (:func:`crossing` of each filtered pulse), the prediction's
    impact instant [s], and its filtered (time, values) from rest."""
    pred_time, pred = filtered_from_rest(pred_time, pred_kg, cfc)
    impact = crossing(pred_time, pred)
    return impact - crossing(trace.time, meas), impact, (pred_time, pred)


def on_measured_grid(time, pred_time, pred_kg, dt, cfc):
    """The raw prediction at the measured samples ``time`` (at rest before it, holding its last
    value after), then the measurement's filter at its rate: filtered alike, literally."""
    on_grid = np.interp(time, pred_time, np.asarray(pred_kg, float), left=0.0)
    return cfc_filter(on_grid, dt, cfc) if cfc else on_grid


def _figures(time, accel, impact):
    from scipy.integrate import trapezoid

    peak_index = int(np.argmax(accel))
    _, _, duration = pulse(time, accel)
    return Figures(float(accel[peak_index]), float(time[peak_index] - impact), duration,
                   float(trapezoid(accel, time) * KG_MS2))


def compare(pred_time, pred_kg, trace, cfc=None, alignment="threshold", rigid=None):
    """Score a predicted pulse against a measured :class:`~airgun_xl.workbook.trace.Trace`.

    Parameters
    ----------
    pred_time, pred_kg : numpy.ndarray
        The prediction: time [s] and acceleration [kG] (finite samples).
    trace : Trace
    cfc : int, optional
        SAE J211 channel class for both traces.
    alignment : {"threshold", "xcorr"}
    rigid : (numpy.ndarray, numpy.ndarray), optional
        The rigid model's time [s] and acceleration [kG], filtered and placed as the
        prediction, for the report's Fig. 13.

    Returns
    -------
    Comparison
    """
    if alignment not in ALIGNMENTS:
        raise OptionError(f"--align: found {alignment!r}, expected one of "
                          f"{', '.join(ALIGNMENTS)}")
    meas = cfc_filter(trace.accel_kg, trace.dt, cfc) if cfc else trace.accel_kg
    if np.max(meas) < -np.min(meas):
        raise OptionError(f"--sign: the measured pulse is mostly negative (from "
                          f"{np.min(meas):.4g} to {np.max(meas):.4g} kG), expected the macro's "
                          "sign, a deceleration positive (try --sign -1)")
    shift, impact_pred, (f_time, f_pred) = threshold_shift(pred_time, pred_kg, trace, meas, cfc)
    if alignment == "xcorr":
        from scipy.signal import correlate, correlation_lags

        # the prediction on the measurement's step; pred_grid[n + k] ~ meas[n] at the best k
        grid = np.arange(f_time[0], f_time[-1], trace.dt)
        pred_grid = np.interp(grid, f_time, f_pred)
        lags = correlation_lags(len(pred_grid), len(meas))
        k = lags[np.argmax(correlate(pred_grid, meas))]
        shift = float(grid[0] + k * trace.dt - trace.time[0])
    time = trace.time + shift
    inside = (time >= min(pred_time[0], impact_pred)) & (time <= pred_time[-1])
    if inside.sum() < 16:
        raise OptionError("--align: the aligned traces overlap in fewer than 16 samples, "
                          "expected the measured pulse to cover the predicted one")
    t = time[inside]
    measured = meas[inside]
    predicted = on_measured_grid(time, pred_time, pred_kg, trace.dt, cfc)[inside]
    p_fig = _figures(t, predicted, impact_pred)
    m_fig = _figures(t, measured, impact_pred)
    correlation = float(np.corrcoef(predicted, measured)[0, 1])
    errors = {
        "peak_kg": (p_fig.peak_kg - m_fig.peak_kg) / m_fig.peak_kg,
        "time_of_peak": p_fig.time_of_peak - m_fig.time_of_peak,
        "pulse_duration": (p_fig.pulse_duration - m_fig.pulse_duration)
        / m_fig.pulse_duration if m_fig.pulse_duration else np.nan,
        "delta_v": (p_fig.delta_v - m_fig.delta_v) / m_fig.delta_v if m_fig.delta_v else np.nan,
    }
    out = Comparison(t - impact_pred, predicted, measured, shift, alignment, cfc, p_fig,
                     m_fig, correlation, errors)
    _spectra_and_rating(out, trace.dt)
    if rigid is not None:
        r_time, r_kg = rigid
        r_time, r = filtered_from_rest(r_time, r_kg, cfc)
        out.rigid_kg = np.interp(t, r_time, r)
    return out


def _spectra_and_rating(c, dt):
    """The ISO/TS 18571 rating over the measured pulse (10 % rule) widened by a tenth of its
    duration each side; both amplitude spectra with their peaks and the errors of the
    dominant one; both SRS (maximax, Q = 10, 100 Hz to 10 kHz or a tenth of the rate)."""
    from ..engine.summary import amplitude_spectrum
    from .iso18571 import rating
    from .shock import default_frequencies, srs

    start, end, duration = pulse(c.time, c.measured_kg)
    margin = 0.1 * duration
    c.interval = (max(c.time[0], start - margin), min(c.time[-1], end + margin))
    c.iso = rating(c.time, c.measured_kg, c.predicted_kg, *c.interval)
    c.predicted_spectrum = amplitude_spectrum(c.predicted_kg, dt)
    c.measured_spectrum = amplitude_spectrum(c.measured_kg, dt)
    if c.predicted_spectrum.peaks and c.measured_spectrum.peaks:
        fp, fm = c.predicted_spectrum.peaks[0], c.measured_spectrum.peaks[0]
        c.errors["dominant_frequency"] = (fp - fm) / fm
    c.srs_frequencies = default_frequencies(100.0, min(10_000.0, 0.1 / dt))
    c.predicted_srs = srs(c.predicted_kg, dt, c.srs_frequencies)
    c.measured_srs = srs(c.measured_kg, dt, c.srs_frequencies)
    c.errors["srs_peak"] = float(c.predicted_srs.max() / c.measured_srs.max() - 1)
