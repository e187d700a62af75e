"""Shock-lab signal processing: SAE J211 / ISO 6487 channel frequency class filters, and the
shock response spectrum (SRS).

- :func:`cfc_filter`: the J211 two-pole Butterworth, run forward and backward (four poles,
  no phase shift), with the standard's own coefficients for a channel frequency class
  (CFC 60, 180, 600, 1000). Its response is -0.45 dB at the CFC and -3 dB at 5/3 of it.
- :func:`srs`: the maximax absolute-acceleration SRS of a pulse, each frequency's single
  degree of freedom stepped by Smallwood's ramp-invariant recursive filter (scipy.signal.lfilter);
  the pulse is padded with zeros so that the residual response after it counts.

Both are pure functions of arrays in SI units (or any one unit: the SRS keeps the input's).
"""
import math

import numpy as np

from ..errors import OptionError

#: The channel frequency classes of SAE J211 / ISO 6487 [Hz].
CFC_CLASSES = (60, 180, 600, 1000)

#: Most samples of rest the SRS appends to a pulse (1.5 periods of its lowest frequency):
#: 160 MB of doubles; a lowest frequency of 1 mHz would ask for 22 GiB (issue 23.3).
MAX_PADDING = 20_000_000

#: The SRS's default quality factor (damping 5 %), as shock specifications are written.
DEFAULT_Q = 10.0


def cfc_coefficients(cfc, dt):
    """(b, a) of the J211 two-pole filter for channel class ``cfc`` [Hz] at step ``dt`` [s].

    SAE J211-1, Appendix C: wd = 2 pi CFC 2.0775, wa = tan(wd dt / 2), and the biquad
    a0 = wa^2 / (1 + sqrt2 wa + wa^2), a1 = 2 a0, a2 = a0, b1 = -2 (wa^2 - 1) / (...),
    b2 = (-1 + sqrt2 wa - wa^2) / (...), in scipy's sign convention.
    """
    if cfc not in CFC_CLASSES:
        raise OptionError(f"--cfc: found {cfc!r}, expected one of "
                          f"{', '.join(map(str, CFC_CLASSES))}")
    wd = 2 * math.pi * cfc * 2.0775
    wa = math.sin(wd * dt / 2) / math.cos(wd * dt / 2)
    den = 1 + math.sqrt(2) * wa + wa * wa
    a0 = wa * wa / den
    b1 = -2 * (wa * wa - 1) / den
    b2 = (-1 + math.sqrt(2) * wa - wa * wa) / den
    return np.array([a0, 2 * a0, a0]), np.array([1.0, -b1, -b2])


#: The J211 biquad's design frequency is 2.0775 x the class; its bilinear prewarp tan(wd dt/2)
#: passes pi/2, and the poles leave the unit circle, below a sample rate of twice that.
UNSTABLE_BELOW = 2 * 2.0775

#: The sample rate J211-1 asks for a class, as analysis tools quote it: 10 x the class (about
#: 6 x its -3 dB frequency, 1.65 x the class): 10 kHz for CFC 1000, 6 kHz for CFC 600.
RECOMMENDED_RATE = 10.0


def check_cfc(cfc, dt):
    """Refuse a channel class whose J211 filter is unstable at step ``dt`` [s]; return the
    warning (a list of one, or none) when the rate is below J211's recommendation."""
    if cfc not in CFC_CLASSES:
        cfc_coefficients(cfc, dt)  # its one-line error
    rate = 1 / dt
    if not rate > UNSTABLE_BELOW * cfc:
        raise OptionError(f"--cfc: found {cfc} for a record sampled at {rate:,.0f} Hz, where "
                          f"the J211 filter is unstable (below {UNSTABLE_BELOW:g} x the class,"
                          f" {UNSTABLE_BELOW * cfc:,.0f} Hz); expected a lower class or a "
                          "faster record")
    if rate < RECOMMENDED_RATE * cfc:
        return [f"--cfc: {cfc} on a record sampled at {rate:,.0f} Hz, below the "
                f"{RECOMMENDED_RATE * cfc:,.0f} Hz J211 asks for the class: the filtered "
                "pulse is rounded off more than the standard's corridor allows"]
    return []


def cfc_filter(values, dt, cfc):
    """``values`` filtered by channel class ``cfc``, forward and backward (phaseless).

    Parameters
    ----------
    values : numpy.ndarray
        Samples at a constant step.
    dt : float
        Sample step [s]; the rate must pass :data:`UNSTABLE_BELOW` x ``cfc`` (:func:`check_cfc`).
    cfc : int
        60, 180, 600 or 1000 [Hz].
    """
    from scipy.signal import filtfilt

    check_cfc(cfc, dt)
    b, a = cfc_coefficients(cfc, dt)
    return filtfilt(b, a, np.asarray(values, dtype=float))


def default_frequencies(lo=100.0, hi=10_000.0, per_octave=12):
    """Natural frequencies [Hz] from ``lo`` to ``hi`` on a geometric grid of about
    ``per_octave`` points a doubling.

    Raises
    ------
    OptionError
        A span of more than :data:`airgun_xl.limits.MAX_SRS_OCTAVES` octaves (1e-308 to 1e308
        Hz would overflow the count).
    """
    from .. import limits
    from ..errors import OptionError

    octaves = math.log2(hi) - math.log2(lo)  # not log2(hi / lo): that quotient overflows
    if not octaves <= limits.MAX_SRS_OCTAVES:
        raise OptionError(f"--from/--to: found {lo:g} and {hi:g} Hz, {octaves:,.0f} octaves "
                          f"apart, expected at most {limits.MAX_SRS_OCTAVES} octaves")
    n = int(round(per_octave * octaves)) + 1
    return np.geomspace(lo, hi, n)


def smallwood_coefficients(fn, dt, q=DEFAULT_Q):
    """(b, a) of Smallwood's ramp-invariant filter for the absolute acceleration of an SDOF
    system of natural frequency ``fn`` [Hz] and quality factor ``q``, at step ``dt`` [s]."""
    zeta = 1 / (2 * q)
    omega = 2 * math.pi * fn
    omega_d = omega * math.sqrt(1 - zeta * zeta)
    E = math.exp(-zeta * omega * dt)
    K = omega_d * dt
    C, S = E * math.cos(K), E * math.sin(K)
    Sp = S / K
    return (np.array([1 - Sp, 2 * (Sp - C), E * E - Sp]),
            np.array([1.0, -2 * C, E * E]))


def srs(values, dt, frequencies, q=DEFAULT_Q):
    """Maximax shock response spectrum of a pulse.

    Parameters
    ----------
    values : numpy.ndarray
        Base acceleration at a constant step (any unit; the SRS is in the same one).
    dt : float
        Sample step [s]; frequencies must lie below a tenth of the sample rate for the
        recursive filter to hold its accuracy.
    frequencies : numpy.ndarray
        Natural frequencies [Hz].
    q : float
        Quality factor, 1/(2 zeta).

    Returns
    -------
    numpy.ndarray
        Largest absolute response acceleration at each frequency, during the pulse and after
        it (the pulse is padded with zeros for 1.5 periods of the lowest frequency).
    """
    from scipy.signal import lfilter

    frequencies = np.asarray(frequencies, dtype=float)
    if not (len(frequencies) and np.all(np.isfinite(frequencies)) and np.all(frequencies > 0)
            and q > 0.5):
        raise OptionError(f"the SRS: found Q = {q!r} or frequencies {frequencies[:3]!r}..., "
                          "expected finite positive frequencies and a quality factor above 0.5")
    if frequencies.max() > 0.1 / dt:
        raise OptionError(f"the SRS: a natural frequency of {frequencies.max():,.0f} Hz, "
                          f"expected at most a tenth of the pulse's sample rate "
                          f"({0.1 / dt:,.0f} Hz)")
    pad = 1.5 / (frequencies.min() * dt)  # samples of rest after the pulse, estimated first
    if not pad <= MAX_PADDING:
        raise OptionError(f"the SRS: a natural frequency of {frequencies.min():.3g} Hz needs "
                          f"{pad:.3g} samples of rest after the pulse at its step, over the "
                          f"{MAX_PADDING:,} allowed; expected a lowest frequency of at least "
                          f"{1.5 / (MAX_PADDING * dt):.3g} Hz")
    x = np.asarray(values, dtype=float)
    x = np.concatenate([x, np.zeros(int(math.ceil(pad)))])
    out = np.empty(len(frequencies))
    for i, fn in enumerate(frequencies):
        b, a = smallwood_coefficients(fn, dt, q)
        out[i] = np.max(np.abs(lfilter(b, a, x)))
    return out


#: A record decimated for a spectrum keeps this many samples a period of its highest
#: frequency (four times the tenth of the rate :func:`srs` asks for: a pulse far shorter than
#: a period then keeps its SRS there to 0.5 %, as tests/test_recording_quality.py measures).
SPECTRUM_SAMPLES_PER_PERIOD = 40


#: Samples of the decimated record added at rest each side (resample_poly's filter reaches
#: 10 of them), so a record shorter than a decimated step still has a pulse to show.
DECIMATION_REST = 16


def decimated_for(values, dt, top):
    """``values`` at step ``dt`` [s] decimated to what a spectrum up to ``top`` [Hz] needs:
    (values, step [s], factor). The factor is the largest whole one keeping
    :data:`SPECTRUM_SAMPLES_PER_PERIOD` samples a period of ``top`` (1: unchanged); the
    low-pass before it is scipy's polyphase FIR (resample_poly, a Kaiser window), whose gain
    at zero frequency is 1, so the record's integral (its velocity change) is kept; the
    record is taken as at rest beyond its ends (:data:`DECIMATION_REST` decimated samples
    of rest are added each side)."""
    values = np.asarray(values, dtype=float)
    factor = int(1 / (SPECTRUM_SAMPLES_PER_PERIOD * top * dt))
    if factor < 2:
        return values, dt, 1
    from scipy.signal import resample_poly

    rest = np.zeros(DECIMATION_REST * factor)  # the filter's reach, at rest, each side
    out = resample_poly(np.concatenate([rest, values, rest]), 1, factor, padtype="constant")
    return out, dt * factor, factor
