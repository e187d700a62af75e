"""The kernel in pure Python: the reference stepper when the C extension is not built.

Same functions, arguments and results as ``_artsim.c`` (its header documents them), and the
same numbers to the last bit: every expression keeps the C code's (and so the macro's) operand
order, and Python floats are IEEE doubles with no fused multiply-add, as the extension is built
(-ffp-contract=off). ``tests/test_reference_kernel.py`` runs the legacy cases on it and compares
it with the extension bit for bit. It is 100-200 times slower: about 0.1 s for shot A at
0.5 µs, 10 s at 5 ns.

The names follow the macro (xPlastic, cPlastic, crushFactor, dforce, forceCounter, maxmitdef,
yPrime2) so that the three can be read side by side.
"""
import math

from .interface import FINAL_COUNT, PARAM_COUNT

#: The macro's value of pi (3.141592653, not math.pi).
PI_MACRO = 3.141592653

# Parameter order: engine/interface.py's PARAMS, as the C enum (tests/test_kernel_interface.py).
(P_M1, P_M31, P_M32, P_M33, P_K2, P_K3, P_DELTA, P_RHO, P_RCONE, P_HCONE, P_HCYL, P_MMIT,
 P_VCONE, P_E, P_EC, P_SIGMAY, P_ZETA, P_V1, P_V31, P_V32, P_V33, P_LAW0, P_LAW1, P_LAW2,
 P_LAW3, P_LAW4, P_LAW5, P_LAW6, P_UNLOAD, P_BOUND) = range(PARAM_COUNT)
P_COUNT = PARAM_COUNT
N_FINALS = FINAL_COUNT


def _div(a, b):
    """a / b as C divides doubles: a zero divisor gives an infinity or NaN, not an error."""
    try:
        return a / b
    except ZeroDivisionError:
        if a != a or a == 0:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)


def crush_factor_poly(c, Vobr):
    """Strain-rate amplification of the crush force, Eq. (8): the law's coefficients ``c``
    (constant term first), highest power first as the C code."""
    V = Vobr
    return ((c[6]) * (V * V * V * V * V * V) + (c[5]) * (V * V * V * V * V)
            + (c[4]) * (V * V * V * V) + (c[3]) * (V * V * V)
            + (c[2]) * (V * V) + (c[1]) * (V) + c[0])


class Mitigator:
    """The mitigator's state between steps (the macro's variables of the same names)."""

    __slots__ = ("M1", "m31", "vcone", "xPlastic", "maxmitdef", "mitigatordeflection",
                 "forceCounter", "dforce", "Force", "crushFactor", "max_Vobr", "min_Vobr",
                 "max_temp", "onsets", "second_onset", "step", "was_unloading")

    def __init__(self, p):
        self.M1 = p[P_M1] + p[P_MMIT]
        self.m31 = p[P_M31]
        self.vcone = p[P_VCONE]  # E28 is the starting "vcone"; a wedge step overwrites it
        self.xPlastic = self.maxmitdef = self.mitigatordeflection = self.forceCounter = 0.0
        self.dforce = self.Force = 0.0
        self.crushFactor = math.nan  # Variant Empty until the first loading step
        self.max_Vobr = -math.inf
        self.min_Vobr = math.inf
        self.max_temp = 0.0
        self.onsets, self.second_onset, self.step, self.was_unloading = 0.0, -1.0, 1.0, False

    def force(self, p, y1, yn1, y31, yn31):
        """One step of the force law (the macro's loop body down to "If (Force < 0)")."""
        delta, rho, rcone, hcone = p[P_DELTA], p[P_RHO], p[P_RCONE], p[P_HCONE]
        hcylinder, E, ec, sigmay = p[P_HCYL], p[P_E], p[P_EC], p[P_SIGMAY]
        L = hcone + hcylinder - self.mitigatordeflection  # previous step's deflection
        cPlastic = (y31 - yn31 - y1 + yn1) / (ec * delta)
        if cPlastic >= 0:  # the front advances only on a non-negative increment
            self.xPlastic = self.xPlastic + (cPlastic * delta)
        self.mitigatordeflection = y31 - y1
        self.step += 1
        if self.mitigatordeflection < self.maxmitdef and not self.was_unloading:
            self.onsets += 1  # an unloading phase begins (statistics, not in the macro)
            if self.onsets == 2:
                self.second_onset = self.step
        self.was_unloading = self.mitigatordeflection < self.maxmitdef
        if self.mitigatordeflection < self.maxmitdef:
            # unloading: elastic over the full area; the masses stay frozen
            Area = PI_MACRO * rcone * rcone
            k1 = -(_div(Area * E, L))
            if self.forceCounter == 0:
                self.Force = -k1 * (self.mitigatordeflection - hcone)
                self.dforce = self.Force - self.dforce  # keeps F continuous at the turn
                self.forceCounter = 0 + 1  # quirk: fourcecounter (Empty) + 1, never reset
            self.Force = -k1 * (self.mitigatordeflection - hcone) - self.dforce
        else:
            # loading: plastic crush with mass transfer
            self.maxmitdef = self.mitigatordeflection
            if self.xPlastic <= hcone:
                h = self.xPlastic
                Area = (PI_MACRO * rcone * rcone) * (h / hcone) if hcone else math.nan
                temp = ((rho * Area * h) / 3.0)
                self.vcone = temp  # the wedge's crushed mass replaces the E28 "volume"
            else:
                Area = PI_MACRO * rcone * rcone
                h = self.xPlastic - hcone
                temp = self.vcone + (rho * Area * h)
            self.M1 = p[P_M1] + p[P_MMIT] - temp
            self.m31 = p[P_M31] + temp
            Vobr = (((y31 - yn31) - (y1 - yn1)) / delta)
            self.crushFactor = crush_factor_poly(p[P_LAW0:P_LAW6 + 1], Vobr)
            if self.crushFactor < 1:
                self.crushFactor = 1.0
            self.Force = sigmay * Area * self.crushFactor
            self.dforce = self.Force
            if p[P_UNLOAD] != 0:
                self.forceCounter = 0.0  # not the macro: each unloading starts from F now
            if Area > 0 and Vobr > self.max_Vobr:  # while the law acts
                self.max_Vobr = Vobr
            if Area > 0 and Vobr < self.min_Vobr:
                self.min_Vobr = Vobr
            if temp > self.max_temp:
                self.max_temp = temp
        if self.Force < 0:
            self.Force = 0.0
        return self.Force

    def finals(self, bad):
        return [self.M1, self.m31, float(bad), self.xPlastic, self.max_Vobr, self.min_Vobr,
                self.max_temp, self.maxmitdef, self.onsets, self.second_onset]


class _Rows:
    """The run's columns as Python lists (fast to index), copied into the caller's buffers at
    the end; ``written`` rows of each (C writes rows 0..bad and leaves the rest alone)."""

    def __init__(self, p, rows, tracked):
        delta = p[P_DELTA]
        t, current = [], -delta
        for _ in range(rows):  # time by repeated addition, from -delta
            t.append(current)
            current = current + delta
        self.t = t
        self.y = [[0.0] * rows for _ in range(4)]
        if rows > 0:
            for i, v in enumerate((p[P_V1], p[P_V31], p[P_V32], p[P_V33])):
                self.y[i][0] = -delta * v  # Y(-delta) = -delta * v0; Y(0) = 0
        self.tracked = {name: [math.nan] * rows for name in tracked}
        self.written = min(rows, 2)

    def finish_row(self, p, k, s):
        """Record row k's tracked values; True when a displacement left the bound."""
        delta, bound, tr = p[P_DELTA], p[P_BOUND], self.tracked
        y1, y31, y32, y33 = self.y
        if "crush" in tr:
            tr["crush"][k] = s.crushFactor
        if "m31" in tr:
            tr["m31"][k] = s.m31
        if "defl" in tr:
            tr["defl"][k] = s.mitigatordeflection
        if "xp" in tr:
            tr["xp"][k] = s.xPlastic
        if "force" in tr:
            tr["force"][k] = s.Force
        if "m1" in tr:
            tr["m1"][k] = s.M1
        if "v1" in tr:
            tr["v1"][k - 1] = (y1[k] - y1[k - 2]) / (2 * delta)
        if "v31" in tr:
            tr["v31"][k - 1] = (y31[k] - y31[k - 2]) / (2 * delta)
        self.written = k + 1
        return not (abs(y1[k]) <= bound and abs(y31[k]) <= bound and abs(y32[k]) <= bound
                    and abs(y33[k]) <= bound)

    def copy_to(self, arrays):
        """Into the caller's buffers: t and Y for every row, as C does; the rest up to the last
        row written (v1, v31 one row less)."""
        n = self.written
        t, y1, y31, y32, y33 = arrays[:5]
        t[:len(self.t)] = self.t
        for out, values in zip((y1, y31, y32, y33), self.y, strict=True):
            out[:n] = values[:n]
        for name, out in zip(TRACKED_NAMES, arrays[5:], strict=True):
            if out is not None:
                stop = n - 1 if name in ("v1", "v31") else n
                if stop > 0:
                    out[:stop] = self.tracked[name][:stop]


TRACKED_NAMES = ("crush", "m31", "defl", "xp", "force", "m1", "v1", "v31")


def _legacy_steps(p, rows, cols):
    """ArtSim's scheme: central differences with backward-difference damping velocities."""
    m32, m33, k2, k3 = p[P_M32], p[P_M33], p[P_K2], p[P_K3]
    delta, zeta = p[P_DELTA], p[P_ZETA]
    s = Mitigator(p)
    c2 = 2 * zeta * math.sqrt(-k2 * (s.m31 + m32))  # damping from the initial masses, once
    c3 = 2 * zeta * math.sqrt(-k3 * (m32 + m33))
    Y1, Y31, Y32, Y33 = cols.y
    dd = delta * delta
    bad = -1
    for k in range(2, rows):
        y1, yn1 = Y1[k - 1], Y1[k - 2]
        y31, yn31 = Y31[k - 1], Y31[k - 2]
        y32, y33 = Y32[k - 1], Y33[k - 1]
        # backward-difference relative velocities, from the two previous rows
        yPrime2 = ((y32 - Y32[k - 2]) - (y31 - Y31[k - 2])) / delta
        yPrime3 = ((y33 - Y33[k - 2]) - (y32 - Y32[k - 2])) / delta
        Force = s.force(p, y1, yn1, y31, yn31)
        M1, m31 = s.M1, s.m31
        # central-difference updates, the four lines of the macro
        springValue = _div(dd, M1) * (Force)
        Y1[k] = 2 * y1 - yn1 + springValue
        springValue = (dd / m31) * (-Force + (k2 * (y31 - y32)) + (c2 * yPrime2))
        Y31[k] = 2 * y31 - Y31[k - 2] + springValue
        springValue = (dd / m32) * ((-k2 * y31) + (y32 * (k2 + k3)) - (k3 * y33)
                                    - (c2 * yPrime2) + (c3 * yPrime3))
        Y32[k] = 2 * y32 - Y32[k - 2] + springValue
        springValue = (dd / m33) * ((k3 * y33) - (k3 * y32) - (c3 * yPrime3))
        Y33[k] = 2 * y33 - Y33[k - 2] + springValue
        if cols.finish_row(p, k, s):
            bad = k
            break
    return s.finals(bad)


def _newmark_steps(p, rows, cols):
    """Average-acceleration Newmark for the OBR chain (see ``newmark_steps`` in the C)."""
    m32, m33, kk2, kk3 = p[P_M32], p[P_M33], -p[P_K2], -p[P_K3]
    dt, zeta = p[P_DELTA], p[P_ZETA]
    beta, gamma = 0.25, 0.5
    s = Mitigator(p)
    c2 = 2 * zeta * math.sqrt(kk2 * (s.m31 + m32))
    c3 = 2 * zeta * math.sqrt(kk3 * (m32 + m33))
    y = [0.0, 0.0, 0.0, 0.0]
    v = [p[P_V1], p[P_V31], p[P_V32], p[P_V33]]
    a = [0.0,
         (c2 * (v[2] - v[1])) / s.m31,
         (-c2 * (v[2] - v[1]) + c3 * (v[3] - v[2])) / m32,
         (-c3 * (v[3] - v[2])) / m33]
    Y = cols.y
    bad = -1
    for k in range(2, rows):
        yp = [y[i] + dt * v[i] + (0.5 - beta) * dt * dt * a[i] for i in range(4)]
        vp = [v[i] + (1 - gamma) * dt * a[i] for i in range(4)]
        F = s.force(p, yp[0], y[0], yp[1], y[1])
        m31 = s.m31
        a[0] = _div(F, s.M1)
        d = [m31 + gamma * dt * c2 + beta * dt * dt * kk2,
             m32 + gamma * dt * (c2 + c3) + beta * dt * dt * (kk2 + kk3),
             m33 + gamma * dt * c3 + beta * dt * dt * kk3]
        up0 = lo1 = -(gamma * dt * c2 + beta * dt * dt * kk2)
        up1 = lo2 = -(gamma * dt * c3 + beta * dt * dt * kk3)
        up, lo = [up0, up1], [0.0, lo1, lo2]
        r = [-F - (c2 * (vp[1] - vp[2])) - (kk2 * (yp[1] - yp[2])),
             -(c2 * (vp[2] - vp[1]) + c3 * (vp[2] - vp[3]))
             - (kk2 * (yp[2] - yp[1]) + kk3 * (yp[2] - yp[3])),
             -(c3 * (vp[3] - vp[2])) - (kk3 * (yp[3] - yp[2]))]
        for i in (1, 2):  # Thomas algorithm
            w = lo[i] / d[i - 1]
            d[i] -= w * up[i - 1]
            r[i] -= w * r[i - 1]
        a[3] = r[2] / d[2]
        a[2] = (r[1] - up[1] * a[3]) / d[1]
        a[1] = (r[0] - up[0] * a[2]) / d[0]
        for i in range(4):
            y[i] = yp[i] + beta * dt * dt * a[i]
            v[i] = vp[i] + gamma * dt * a[i]
            Y[i][k] = y[i]
        if cols.finish_row(p, k, s):
            bad = k
            break
    return s.finals(bad)


def _check(params, rows):
    p = [float(x) for x in params]
    if len(p) != P_COUNT:
        raise ValueError(f"params must hold {P_COUNT} values")
    if rows < 0:
        raise ValueError("rows must be >= 0")
    return p


#: Largest byte count a buffer may have (Py_ssize_t), as the C kernel bounds ``rows`` by it.
_SSIZE_MAX = 2**63 - 1


def float64_count(buffer, writable=True, refusal="buffers must be float64"):
    """The buffer's element count, refused as the C extensions refuse it (the kernel and
    the sheet XML twin alike): not a buffer, not C-contiguous, not float64 (``refusal``), or
    read-only when ``writable``."""
    try:
        view = memoryview(buffer)
    except TypeError:
        raise TypeError(f"a bytes-like object is required, not '{type(buffer).__name__}'") \
            from None
    if not view.c_contiguous:  # as numpy refuses PyBUF_C_CONTIGUOUS
        raise ValueError("ndarray is not C-contiguous")
    if view.format != "d" or view.itemsize != 8 or (writable and view.readonly):
        raise ValueError(refusal)
    return view.nbytes // 8


def _check_columns(arrays, rows):
    if rows > _SSIZE_MAX // 8:
        raise ValueError("rows must be >= 0 and fit the address space")
    for k, out in enumerate(arrays):
        if out is None and k >= 5:
            continue
        try:
            n = float64_count(out)
        except ValueError:
            n = -1
        if n < rows:
            raise ValueError("columns must be float64 buffers of length >= rows")


def _run(steps, params, rows, arrays):
    p = _check(params, rows)
    _check_columns(arrays, rows)
    tracked = [name for name, out in zip(TRACKED_NAMES, arrays[5:], strict=True) if out is not None]
    cols = _Rows(p, rows, tracked)
    finals = steps(p, rows, cols)
    cols.copy_to(arrays)
    return (finals[0], finals[1], int(finals[2]), *finals[3:])


def legacy_kernel(params, rows, *arrays):
    """As ``_artsim.legacy_kernel``."""
    return _run(_legacy_steps, params, rows, arrays)


def newmark_kernel(params, rows, *arrays):
    """As ``_artsim.newmark_kernel``."""
    return _run(_newmark_steps, params, rows, arrays)


def batch_kernel(params, rows, integrator, last, t, y, finals, lanes=True):
    """As ``_artsim.batch_kernel``: each row of ``params`` stepped alone (``lanes`` changes
    nothing here: the C lanes give the same numbers)."""
    import numpy as np

    if last not in (1, 2, 3):
        raise ValueError("last must be 1 (Y31), 2 (Y32) or 3 (Y33)")
    sizes = [float64_count(params, writable=False)] + [float64_count(b) for b in (t, y, finals)]
    n = sizes[0] // P_COUNT
    if (rows < 0 or rows > _SSIZE_MAX // 32 or sizes[0] != n * P_COUNT or sizes[1] < rows
            or (rows > 0 and sizes[2] // rows < n) or sizes[3] // N_FINALS < n):
        raise ValueError(f"buffer sizes do not match (n x {P_COUNT}, rows, n x rows, "
                         f"n x {N_FINALS})")
    steps = _newmark_steps if integrator else _legacy_steps
    for i, shot in enumerate(np.asarray(params).reshape(-1, P_COUNT)):
        p = _check(shot, rows)
        cols = _Rows(p, rows, ())
        finals[i, :] = steps(p, rows, cols)
        t[:rows] = cols.t
        y[i, :] = 0.0
        n = cols.written
        y[i, :n] = cols.y[last][:n]
