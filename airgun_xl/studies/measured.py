"""A prediction against the pulse that was measured: filtered alike, aligned, and scored.

Both traces are filtered with the same SAE J211 channel class (when one is given), each at its
own sample rate; the prediction is then interpolated onto the measurement's grid. Alignment
puts the measured trace's impact instant on the prediction's: the first sample at or above
``threshold`` of its own peak (``"threshold"``), or the lag that maximises their
cross-correlation (``"xcorr"``, scipy.signal). The scores are the headline figures of each
trace (peak, its time, the pulse duration by the Summary's 10 % rule, the velocity change)
with their errors, and Pearson's correlation of the aligned traces over their overlap.
"""
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .. import limits, units
from ..engine.summary import pulse
from ..errors import OptionError
from .recording_quality import (
    MIN_PRE_SAMPLES,
    Baseline,
    Expected,
    RecordingQuality,
    assess,
    baseline,
)
from .shock import cfc_filter

__all__ = ["Baseline", "baseline"]  # the rest and noise, read with the recording's quality

#: The impact instant: the first sample at or above this fraction of the trace's peak.
IMPACT_FRACTION = 0.05

#: kG to m/s^2, the macro's convention (a recorder's g is converted on reading: trace.py).
KG_MS2 = units.KG_MS2

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
    srs_frequencies: np.ndarray | None = None  # [Hz]
    predicted_srs: np.ndarray | None = None  # maximax, Q = 10 [kG]
    measured_srs: np.ndarray | None = None
    rigid_kg: np.ndarray | None = None  # the rigid model's prediction on ``time`` (Fig. 13)
    baseline: object = None  # the recording's Baseline: offset and noise (pre-trigger)
    noise_filtered: float = np.nan  # [kG], the pre-trigger noise after the filter
    level: float = IMPACT_FRACTION  # the impact level, a fraction of the peak
    shifts: dict = field(default_factory=dict)  # {"threshold": s, "xcorr": s}
    anti_alias: float | None = None  # [Hz] modelled on the prediction, or None
    srs_record: str = ""  # which record the SRS are of
    warnings: list = field(default_factory=list)


#: Rest prepended to the prediction before it is filtered [s]: the recorder is at rest before
#: the impact, and filtfilt's own edge padding (an odd reflection) would bend the rise.
REST_BEFORE = 2e-3

#: The impact level is at least this many standard deviations of the pre-trigger noise (after
#: the filter), so noise alone does not trigger it: 5 sigma is passed by chance once in 3.5
#: million samples.
NOISE_SIGMAS = 5.0

#: ...and the signal must stay above it this long [s] (at least 3 samples).
SUSTAIN = 5e-5

#: The threshold's and the cross-correlation's shifts may differ by this many samples before
#: a warning says which was used.
AGREE_SAMPLES = 2

#: The recorder's anti-alias filter, as modelled on the prediction: a Butterworth low-pass of
#: this order (causal, as an analog filter) at :data:`ANTI_ALIAS_FRACTION` of the sample rate
#: unless ``--anti-alias`` says otherwise. A prediction sampled from the model without it has
#: modes past the recorder's band; a recording has them filtered, and delayed (about 1.8
#: samples at fs/5).
ANTI_ALIAS_ORDER = 4
ANTI_ALIAS_FRACTION = 0.2



def anti_aliased(time, values, hz):
    """``values`` sampled at ``time`` [s] through the recorder's anti-alias model: a causal
    Butterworth low-pass of :data:`ANTI_ALIAS_ORDER` at ``hz`` (None: unchanged), from rest."""
    if hz is None:
        return np.asarray(values, dtype=float)
    from scipy.signal import sosfilt

    dt = float(time[1] - time[0])
    sos = _anti_alias_sos(float(hz), 1 / dt).copy()  # sosfilt wants it writable
    return sosfilt(sos, np.asarray(values, dtype=float))


@functools.lru_cache(maxsize=64)
def _anti_alias_sos(hz, fs):
    """The anti-alias model's sections at ``hz`` for the rate ``fs`` [Hz], designed once: a
    calibration filters every trial run at the same two figures (half its time went into
    designing the same filter again)."""
    from scipy.signal import butter

    sos = butter(ANTI_ALIAS_ORDER, hz, fs=fs, output="sos")
    sos.setflags(write=False)
    return sos


def check_anti_alias(hz, dt_model, dt_record):
    """The anti-alias frequency to model [Hz] (``"auto"``: :data:`ANTI_ALIAS_FRACTION` of the
    record's rate; ``"none"``: None), refused past the model's or the record's Nyquist."""
    if hz in (None, "none"):
        return None
    value = ANTI_ALIAS_FRACTION / dt_record if hz == "auto" else hz
    try:
        value = float(value)
    except (TypeError, ValueError):
        value = math.nan
    limit = 0.5 / max(dt_model, dt_record)
    if not (0 < value < limit):
        raise OptionError(f"--anti-alias: found {hz!r}, expected a frequency in Hz below "
                          f"{limit:,.0f} Hz (half the slower of the model's and the record's "
                          "rates), 'auto' (a fifth of the record's rate) or 'none'")
    return value


def crossing(time, values, fraction=IMPACT_FRACTION, sustain=1):
    """The instant [s] a trace first reaches ``fraction`` of its peak and stays there for
    ``sustain`` samples, interpolated between samples (a whole-sample instant would misalign
    two pulses by up to a step)."""
    values = np.asarray(values, dtype=float)
    level = fraction * np.max(values)
    above = values >= level
    if sustain > 1:
        held = np.convolve(above.astype(np.int64), np.ones(sustain, dtype=np.int64),
                           "valid") == sustain
        k = int(np.argmax(held)) if held.any() else int(np.argmax(above))
    else:
        k = int(np.argmax(above))
    if k == 0:
        return float(time[0])
    a, b = values[k - 1], values[k]
    return float(time[k - 1] + (time[k] - time[k - 1]) * (level - a) / (b - a))


def filtered_from_rest(time, values, cfc, anti_alias=None):
    """(time, values) at rest for :data:`REST_BEFORE` before the first sample, then through
    the recorder's anti-alias model (``anti_alias`` [Hz], at the values' own rate) and
    filtered by channel class ``cfc``: the phaseless filter starts the rise before the
    impact, and that part is kept."""
    dt = float(time[1] - time[0])
    n = int(round(REST_BEFORE / dt))
    t = np.concatenate([time[0] - dt * np.arange(n, 0, -1), time])
    v = anti_aliased(t, np.concatenate([np.zeros(n), np.asarray(values, dtype=float)]),
                     anti_alias)
    return t, (cfc_filter(v, dt, cfc) if cfc else v)


@dataclass
class Recording:
    """A measured pulse made ready to compare: zeroed, filtered, its impact level set."""

    trace: object  # the Trace as read
    corrected: np.ndarray  # [kG], the baseline's offset removed (the unfiltered record)
    filtered: np.ndarray  # [kG], and through the CFC filter (or the same, without one)
    base: Baseline
    noise_filtered: float  # [kG], the pre-trigger's noise after the filter
    fraction: float  # the impact level, as a fraction of the peak
    sustain: int  # samples the level must hold
    cfc: object
    warnings: list = field(default_factory=list)
    anti_alias: float | None = None  # [Hz] modelled on the prediction, or None
    quality: RecordingQuality | None = None  # what the record says about itself


def prepare(trace, cfc=None, anti_alias=None, dt_model=None, flat_top=False, expected=None,
            nominal_duration=None):
    """Zero, check and filter a recording; the impact level above its noise; the anti-alias
    frequency to model on predictions of step ``dt_model`` (:func:`check_anti_alias`). The
    recording's quality is read once here (:func:`~.recording_quality.assess`, with
    ``flat_top``, ``expected`` and ``nominal_duration``), its findings among the warnings.

    Raises
    ------
    OptionError
        For a pulse mostly negative (the recorder's axis reversed: ``--sign -1``) or flat.
    """
    from .shock import check_cfc

    warnings = list(getattr(trace, "notes", ()))  # what the reading found (a unit given)
    warnings += check_cfc(cfc, trace.dt) if cfc else []
    huge = np.flatnonzero(~(np.abs(np.asarray(trace.accel_kg, dtype=float))
                            <= limits.MAX_RECORD_KG))
    if len(huge):
        k = int(huge[0])
        raise OptionError(f"{trace.name}: found {float(trace.accel_kg[k]):.4g} kG at "
                          f"{float(trace.time[k]) * 1e3:.4f} ms ({len(huge):,} such sample"
                          f"{'s' * (len(huge) != 1)}), expected a recording within "
                          f"±{limits.MAX_RECORD_KG:.0e} kG (a recorder's range)")
    quality = assess(trace.time, trace.accel_kg, trace.name, flat_top, expected,
                     nominal_duration)
    base = quality.base
    if base.where == "none":
        warnings.append(f"{trace.name}: no {MIN_PRE_SAMPLES} samples at rest before or after "
                        "the pulse: no baseline (offset taken as 0) and the noise unknown; "
                        "the impact is found at the plain threshold")
    elif base.where == "after":
        warnings.append(f"{trace.name}: no record at rest before the pulse (it starts in the "
                        f"pulse's rise): the baseline and the noise are taken from "
                        f"{base.samples:,} samples at rest after it")
    corrected = np.asarray(trace.accel_kg, dtype=float) - base.offset
    filtered = cfc_filter(corrected, trace.dt, cfc) if cfc else corrected
    if not np.isfinite(filtered).all() or np.max(np.abs(filtered)) == 0:
        raise OptionError(f"{trace.name}: the recording is flat (every sample "
                          f"{base.offset:.4g} kG), expected a pulse")
    if np.max(filtered) < -np.min(filtered):
        raise OptionError(f"--sign: the measured pulse is mostly negative (from "
                          f"{np.min(filtered):.4g} to {np.max(filtered):.4g} kG after its "
                          f"{base.offset:.4g} kG offset), expected the macro's sign, a "
                          "deceleration positive (try --sign -1)")
    rest = filtered[base.start:base.start + base.samples] if base.where != "none" else \
        filtered[:0]
    with np.errstate(over="ignore", invalid="ignore"):
        noise = float(np.std(rest)) if len(rest) else 0.0
    if not math.isfinite(noise):  # a 1e200 spike: its square overflows
        raise OptionError(f"{trace.name}: found {float(np.max(np.abs(rest))):.4g} kG in the "
                          f"samples at rest {base.where} the pulse, too large for their noise "
                          "to be measured, expected a recording within a recorder's range")
    fraction = max(IMPACT_FRACTION, NOISE_SIGMAS * noise / float(np.max(filtered)))
    if fraction > 0.5:
        raise OptionError(f"{trace.name}: the pre-trigger noise ({noise:.4g} kG, 1 sigma) is "
                          f"{noise / np.max(filtered):.0%} of the pulse's peak, expected a "
                          "pulse that stands out of its noise (a CFC filter, --cfc, helps)")
    sustain = max(3, int(round(SUSTAIN / trace.dt)))
    hz = check_anti_alias(anti_alias, dt_model or trace.dt, trace.dt)
    return Recording(trace, corrected, filtered, base, noise, fraction, sustain, cfc,
                     warnings + quality.warnings, hz, quality)


def check_prediction(pred_kg):
    """Refuse a prediction with no pulse to align (issue 23.7: a shot whose bird never meets
    the mitigator, A27 = A28 = 0)."""
    if not np.any(np.asarray(pred_kg) > 0):
        raise OptionError("the shot's predicted pulse is zero everywhere (nothing crushes the "
                          "mitigator: A27..A30), expected a shot whose bird hits the MEM")


def threshold_shift(pred_time, pred_kg, rec):
    """(shift, impact, filtered prediction): the shift [s] to add to the measured time so that
    both impact instants coincide (:func:`crossing` of each filtered pulse at the recording's
    level, held), the prediction's impact instant [s], and its filtered (time, values) from
    rest."""
    check_prediction(pred_kg)
    pred_time, pred = filtered_from_rest(pred_time, pred_kg, rec.cfc, rec.anti_alias)
    impact = crossing(pred_time, pred, rec.fraction)
    measured = crossing(rec.trace.time, rec.filtered, rec.fraction, rec.sustain)
    return impact - measured, impact, (pred_time, pred)


def xcorr_shift(f_time, f_pred, rec):
    """The shift [s] that maximises the cross-correlation of the filtered prediction (on the
    measurement's step) with the filtered recording (scipy.signal)."""
    from scipy.signal import correlate, correlation_lags

    dt = rec.trace.dt
    limits.check_memory(8 * 4 * (len(f_time) * (f_time[1] - f_time[0]) / dt
                                 + len(rec.filtered)),
                        "the cross-correlation of the two pulses",
                        "a recording and a prediction of fewer samples")
    grid = np.arange(f_time[0], f_time[-1], dt)
    pred_grid = np.interp(grid, f_time, f_pred)
    lags = correlation_lags(len(pred_grid), len(rec.filtered))
    k = lags[np.argmax(correlate(pred_grid, rec.filtered))]
    return float(grid[0] + k * dt - rec.trace.time[0])


def alignment_shift(pred_time, pred_kg, rec, alignment="threshold"):
    """(shift, impact, both shifts, warnings): the alignment asked for, cross-checked against
    the other; a disagreement over :data:`AGREE_SAMPLES` samples is a warning naming both."""
    shift, impact, (f_time, f_pred) = threshold_shift(pred_time, pred_kg, rec)
    other = xcorr_shift(f_time, f_pred, rec)
    shifts = {"threshold": shift, "xcorr": other}
    used = shifts[alignment]
    apart = abs(shift - other) / rec.trace.dt
    warnings = []
    if apart > AGREE_SAMPLES:
        warnings.append(f"alignment: the threshold puts the impact at a shift of "
                        f"{shift * 1e3:.4f} ms and the cross-correlation at {other * 1e3:.4f} "
                        f"ms, {apart:.1f} samples apart (more than {AGREE_SAMPLES}); used "
                        f"{alignment} (--align)")
    return used, impact, shifts, warnings


def on_measured_grid(time, pred_time, pred_kg, dt, cfc, anti_alias=None):
    """The raw prediction through the recorder's anti-alias model (at its own rate), at the
    measured samples ``time`` (at rest before it, holding its last value after), then the
    measurement's filter at its rate: filtered alike, literally."""
    pred = anti_aliased(pred_time, pred_kg, anti_alias)
    on_grid = np.interp(time, pred_time, pred, left=0.0)
    return cfc_filter(on_grid, dt, cfc) if cfc else on_grid


def _figures(time, accel, impact):
    from .integrals import trapezoid

    peak_index = int(np.argmax(accel))
    _, _, duration = pulse(time, accel)
    return Figures(float(accel[peak_index]), float(time[peak_index] - impact), duration,
                   float(trapezoid(accel, time) * KG_MS2))


def compare(pred_time, pred_kg, trace, cfc=None, alignment="threshold", rigid=None,
            anti_alias="auto"):
    """Score a predicted pulse against a measured :class:`~airgun_xl.readers.recording.Trace`.

    Parameters
    ----------
    pred_time, pred_kg : numpy.ndarray
        The prediction: time [s] and acceleration [kG] (finite samples).
    trace : Trace
    cfc : int, optional
        SAE J211 channel class for both traces.
    alignment : {"threshold", "xcorr"}
        Which shift is used; the other cross-checks it.
    rigid : (numpy.ndarray, numpy.ndarray), optional
        The rigid model's time [s] and acceleration [kG], filtered and placed as the
        prediction, for the report's Fig. 13.
    anti_alias : float, "auto" or "none"
        The recorder's anti-alias filter modelled on the prediction [Hz]
        (:func:`check_anti_alias`).

    Returns
    -------
    Comparison
    """
    if alignment not in ALIGNMENTS:
        raise OptionError(f"--align: found {alignment!r}, expected one of "
                          f"{', '.join(ALIGNMENTS)}")
    rec = prepare(trace, cfc, anti_alias, float(pred_time[1] - pred_time[0]),
                  expected=Expected.of_pulse(pred_time, pred_kg))
    hz = rec.anti_alias
    shift, impact_pred, shifts, said = alignment_shift(pred_time, pred_kg, rec, alignment)
    time = trace.time + shift
    inside = (time >= min(pred_time[0], impact_pred)) & (time <= pred_time[-1])
    if inside.sum() < 16:
        raise OptionError("--align: the aligned traces overlap in fewer than 16 samples, "
                          "expected the measured pulse to cover the predicted one")
    t = time[inside]
    measured = rec.filtered[inside]
    predicted = on_measured_grid(time, pred_time, pred_kg, trace.dt, cfc, hz)[inside]
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
    out.baseline, out.noise_filtered, out.level = rec.base, rec.noise_filtered, rec.fraction
    out.shifts, out.anti_alias = shifts, hz
    out.warnings = rec.warnings + said
    raw_pred = on_measured_grid(time, pred_time, pred_kg, trace.dt, None, hz)[inside]
    _spectra_and_rating(out, trace.dt, raw_pred, rec.corrected[inside])
    if rigid is not None:
        r_time, r_kg = rigid
        r_time, r = filtered_from_rest(r_time, r_kg, cfc, hz)
        out.rigid_kg = np.interp(t, r_time, r)
    return out


def _spectra_and_rating(c, dt, raw_predicted, raw_measured):
    """The ISO/TS 18571 rating over the measured pulse (10 % rule) widened by a tenth of its
    duration each side, when it can be computed (a warning says why not); both amplitude
    spectra with their peaks and the errors of the dominant one; both SRS (maximax, Q = 10,
    100 Hz to 10 kHz or a tenth of the rate) of the unfiltered records, as shock practice
    takes it (the recording zeroed, the prediction through the anti-alias model only)."""
    from ..engine.summary import amplitude_spectrum
    from .iso18571 import rating
    from .shock import default_frequencies, srs

    start, end, duration = pulse(c.time, c.measured_kg)
    margin = 0.1 * duration
    c.interval = (max(c.time[0], start - margin), min(c.time[-1], end + margin))
    try:
        c.iso = rating(c.time, c.measured_kg, c.predicted_kg, *c.interval)
    except ValueError as why:  # too short a pulse for the standard's 10 kHz resampling
        c.iso = None
        c.warnings.append(f"ISO/TS 18571: the rating cannot be computed: {why}; the other "
                          "scores stand")
    c.predicted_spectrum = amplitude_spectrum(c.predicted_kg, dt)
    c.measured_spectrum = amplitude_spectrum(c.measured_kg, dt)
    if c.predicted_spectrum.peaks and c.measured_spectrum.peaks:
        fp, fm = c.predicted_spectrum.peaks[0], c.measured_spectrum.peaks[0]
        c.errors["dominant_frequency"] = (fp - fm) / fm
    c.srs_frequencies = default_frequencies(100.0, min(10_000.0, 0.1 / dt))
    c.predicted_srs = srs(raw_predicted, dt, c.srs_frequencies)
    c.measured_srs = srs(raw_measured, dt, c.srs_frequencies)
    c.srs_record = ("unfiltered (the recording less its offset; the prediction through the "
                    "anti-alias model only)")
    c.errors["srs_peak"] = float(c.predicted_srs.max() / c.measured_srs.max() - 1)
