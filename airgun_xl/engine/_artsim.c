/*
 * Faithful port of ArtSim's position loop (ARL-TR-3559, Appendix A; shared/seed/ArtSim.bas).
 *
 * The macro walks a cell cursor down columns I..M; sheet row r is computed from rows r-1 and
 * r-2. Here sheet row k + 2 is array index k: index 0 is t = -delta, index 1 is t = 0. Names
 * follow the macro (xPlastic, cPlastic, crushFactor, dforce, forceCounter, maxmitdef, yPrime2,
 * ...) so the two can be read side by side. Every expression keeps the macro's operand order:
 * the port is judged to the last digits against the macro's own output. Build with
 * -ffp-contract=off so that no multiply-add is fused.
 *
 * Python interface (module airgun_xl.engine._artsim):
 *   legacy_kernel(params, rows, t, y1, y31, y32, y33, crush, m31, defl, xp, force, m1, v1, v31)
 *     params: a sequence of 30 floats in the order of the enum below (the crush-factor law's
 *     seven coefficients, constant term first, then the unloading variant: 0 the macro's,
 *     1 continuous, then the bound);
 *     the other arguments: writable, C-contiguous float64 buffers of length >= rows. The
 *     tracked columns from crush on may be None: they are then neither computed nor stored.
 *     Returns (final M1, final m31, first diverged row or -1, final x_plastic, max and min
 *     relative velocity while loading, largest crushed mass, largest deflection, unloading
 *     phases begun, row index of the second or -1). The GIL is released while
 *     stepping, which stops at the first row whose displacement is not finite or passes
 *     params[21], the bound no physical run exceeds.
 *   newmark_kernel(...): the same, with the average-acceleration Newmark scheme.
 */
#define PY_SSIZE_T_CLEAN
/* The limited API of Python 3.11 (buffers joined it then): one abi3 wheel per platform. */
#ifndef Py_LIMITED_API
#define Py_LIMITED_API 0x030B0000
#endif
#include <Python.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The macro's value of pi (3.141592653, not M_PI). */
#define PI_MACRO 3.141592653

enum { P_M1, P_M31, P_M32, P_M33, P_K2, P_K3, P_DELTA, P_RHO, P_RCONE, P_HCONE, P_HCYL,
       P_MMIT, P_VCONE, P_E, P_EC, P_SIGMAY, P_ZETA, P_V1, P_V31, P_V32, P_V33,
       P_LAW0, P_LAW1, P_LAW2, P_LAW3, P_LAW4, P_LAW5, P_LAW6, P_UNLOAD, P_BOUND, P_COUNT };

typedef struct {
    double *t, *y1, *y31, *y32, *y33, *crush, *m31, *defl, *xp, *force, *m1, *v1, *v31;
} Columns;

/* Strain-rate amplification of the crush force, Eq. (8): the polynomial c[0] + c[1] V + ...
 * + c[6] V^6, highest power first as the macro writes it. With the macro's coefficients (c[5]
 * and c[2] negative) it equals the macro's "- (0.000000000125438) * (V^5)" bit for bit: a + (-b)c
 * rounds as a - bc. */
static double crush_factor_poly(const double *c, double Vobr)
{
    double V = Vobr;
    return (c[6]) * (V * V * V * V * V * V) + (c[5]) * (V * V * V * V * V)
           + (c[4]) * (V * V * V * V) + (c[3]) * (V * V * V)
           + (c[2]) * (V * V) + (c[1]) * (V) + c[0];
}

/* The mitigator's state between steps (the macro's variables of the same names). */
typedef struct {
    double M1, m31, vcone, xPlastic, maxmitdef, mitigatordeflection, forceCounter, dforce;
    double Force, crushFactor;
    /* statistics for the checks (not in the macro): the unloading phases begun, the step of
     * the second (where the macro's force jumps) or -1, the step now, and the last branch */
    double max_Vobr, min_Vobr, max_temp, onsets, second_onset, step, was_unloading;
} Mitigator;

static void mitigator_start(Mitigator *s, const double *p)
{
    s->M1 = p[P_M1] + p[P_MMIT];
    s->m31 = p[P_M31];
    s->vcone = p[P_VCONE]; /* E28 is the starting "vcone"; a wedge step overwrites it */
    s->xPlastic = s->maxmitdef = s->mitigatordeflection = s->forceCounter = 0;
    s->dforce = s->Force = 0;
    s->crushFactor = NAN; /* Variant Empty until the first loading step */
    s->max_Vobr = -INFINITY;
    s->min_Vobr = INFINITY;
    s->max_temp = 0;
    s->onsets = 0;
    s->second_onset = -1;
    s->step = 1; /* the first call is step (row index) 2 */
    s->was_unloading = 0;
}

/* One step of the mitigator force law, from the MEM and OBR front plate positions now (y1,
 * y31) and one step before (yn1, yn31); returns the force, clamped at >= 0, and updates the
 * masses. This is the macro's loop body down to "If (Force < 0)", in the macro's order. */
static double mitigator_force(Mitigator *s, const double *p, double y1, double yn1, double y31,
                              double yn31)
{
    const double delta = p[P_DELTA], rho = p[P_RHO], rcone = p[P_RCONE], hcone = p[P_HCONE];
    const double hcylinder = p[P_HCYL], E = p[P_E], ec = p[P_EC], sigmay = p[P_SIGMAY];
    double L = hcone + hcylinder - s->mitigatordeflection; /* previous step's deflection */
    double cPlastic, Area, k1;
    /* Plastic front: advances only when the relative increment is >= 0. */
    cPlastic = (y31 - yn31 - y1 + yn1) / (ec * delta);
    if (cPlastic >= 0)
        s->xPlastic = s->xPlastic + (cPlastic * delta);
    s->mitigatordeflection = y31 - y1;
    s->step = s->step + 1;
    if (s->mitigatordeflection < s->maxmitdef && s->was_unloading == 0) {
        s->onsets = s->onsets + 1;
        if (s->onsets == 2)
            s->second_onset = s->step;
    }
    s->was_unloading = s->mitigatordeflection < s->maxmitdef;
    if (s->mitigatordeflection < s->maxmitdef) {
        /* Unloading: elastic over the full area; the masses stay frozen. */
        Area = PI_MACRO * rcone * rcone;
        k1 = -((Area * E) / (L));
        if (s->forceCounter == 0) {
            s->Force = -k1 * (s->mitigatordeflection - hcone);
            s->dforce = s->Force - s->dforce; /* offset that keeps F continuous at the turn */
            s->forceCounter = 0 + 1; /* quirk: fourcecounter (Empty) + 1, never reset below */
        }
        s->Force = -k1 * (s->mitigatordeflection - hcone) - s->dforce;
    } else {
        /* Loading: plastic crush with mass transfer. */
        double h, temp, Vobr;
        s->maxmitdef = s->mitigatordeflection;
        if (s->xPlastic <= hcone) {
            h = s->xPlastic;
            Area = (PI_MACRO * rcone * rcone) * (h / hcone);
            temp = ((rho * Area * h) / 3.0);
            s->vcone = temp; /* the wedge's crushed mass replaces the E28 "volume" */
        } else {
            Area = PI_MACRO * rcone * rcone;
            h = s->xPlastic - hcone;
            temp = s->vcone + (rho * Area * h);
        }
        s->M1 = p[P_M1] + p[P_MMIT] - temp; /* Range("A2") + Range("E25") - temp */
        s->m31 = p[P_M31] + temp;
        Vobr = (((y31 - yn31) - (y1 - yn1)) / delta);
        s->crushFactor = crush_factor_poly(p + P_LAW0, Vobr);
        if (s->crushFactor < 1)
            s->crushFactor = 1;
        s->Force = sigmay * Area * s->crushFactor;
        s->dforce = s->Force;
        if (p[P_UNLOAD] != 0)
            s->forceCounter = 0; /* not the macro: each unloading starts from the force now */
        if (Area > 0 && Vobr > s->max_Vobr) s->max_Vobr = Vobr; /* while the law acts */
        if (Area > 0 && Vobr < s->min_Vobr) s->min_Vobr = Vobr;
        if (temp > s->max_temp) s->max_temp = temp;
    }
    if (s->Force < 0)
        s->Force = 0;
    return s->Force;
}

static void start_rows(const double *p, Py_ssize_t rows, Columns c)
{
    const double delta = p[P_DELTA];
    double currentTime = -delta;
    Py_ssize_t k;
    /* Time starts at -delta and accumulates by repeated addition. */
    for (k = 0; k < rows; k++) {
        c.t[k] = currentTime;
        currentTime = currentTime + delta;
    }
    /* Y(-delta) = -delta * v0, Y(0) = 0. */
    if (rows > 0) {
        c.y1[0] = -delta * p[P_V1];
        c.y31[0] = -delta * p[P_V31];
        c.y32[0] = -delta * p[P_V32];
        c.y33[0] = -delta * p[P_V33];
    }
    if (rows > 1)
        c.y1[1] = c.y31[1] = c.y32[1] = c.y33[1] = 0;
}

/* Record row k's tracked values; return 0, or 1 when a displacement left the bound. */
static int finish_row(const double *p, Columns c, Py_ssize_t k, const Mitigator *s)
{
    const double delta = p[P_DELTA], bound = p[P_BOUND];
    /* Tracked values (not in the macro): NULL columns are skipped. */
    if (c.crush) c.crush[k] = s->crushFactor;
    if (c.m31) c.m31[k] = s->m31;
    if (c.defl) c.defl[k] = s->mitigatordeflection;
    if (c.xp) c.xp[k] = s->xPlastic;
    if (c.force) c.force[k] = s->Force;
    if (c.m1) c.m1[k] = s->M1;
    /* central-difference velocities of MEM and OBR front plate, at the row before */
    if (c.v1) c.v1[k - 1] = (c.y1[k] - c.y1[k - 2]) / (2 * delta);
    if (c.v31) c.v31[k - 1] = (c.y31[k] - c.y31[k - 2]) / (2 * delta);
    /* divergence: a non-finite value, or growth no physical bound allows (not in the macro) */
    return !(fabs(c.y1[k]) <= bound && fabs(c.y31[k]) <= bound && fabs(c.y32[k]) <= bound
             && fabs(c.y33[k]) <= bound);
}

static void finish_run(const Mitigator *s, Py_ssize_t bad, double *out)
{
    out[0] = s->M1;
    out[1] = s->m31;
    out[2] = (double)bad;
    out[3] = s->xPlastic;
    out[4] = s->max_Vobr;
    out[5] = s->min_Vobr;
    out[6] = s->max_temp;
    out[7] = s->maxmitdef; /* the largest deflection: the maximum crush */
    out[8] = s->onsets;
    out[9] = s->second_onset;
}

#define N_FINALS 10

/* ArtSim's scheme: central differences with backward-difference damping velocities. */
static void legacy_steps(const double *p, Py_ssize_t rows, Columns c, double *out)
{
    const double m32 = p[P_M32], m33 = p[P_M33], k2 = p[P_K2], k3 = p[P_K3];
    const double delta = p[P_DELTA], zeta = p[P_ZETA];
    Mitigator s;
    double c2, c3;
    Py_ssize_t k, bad = -1;

    mitigator_start(&s, p);
    /* Damping from the initial masses, once. */
    c2 = 2 * zeta * sqrt(-k2 * (s.m31 + m32));
    c3 = 2 * zeta * sqrt(-k3 * (m32 + m33));
    start_rows(p, rows, c);
    for (k = 2; k < rows; k++) {
        double y1 = c.y1[k - 1], yn1 = c.y1[k - 2];
        double y31 = c.y31[k - 1], yn31 = c.y31[k - 2];
        double y32 = c.y32[k - 1], y33 = c.y33[k - 1];
        /* Backward-difference relative velocities, from the two previous rows. */
        double yPrime2 = ((y32 - c.y32[k - 2]) - (y31 - c.y31[k - 2])) / delta;
        double yPrime3 = ((y33 - c.y33[k - 2]) - (y32 - c.y32[k - 2])) / delta;
        double springValue, Force = mitigator_force(&s, p, y1, yn1, y31, yn31);
        double M1 = s.M1, m31 = s.m31;
        /* Central-difference updates, the four lines of the macro. */
        springValue = ((delta * delta) / M1) * (Force);
        c.y1[k] = 2 * y1 - yn1 + springValue;
        springValue = ((delta * delta) / m31) * (-Force + (k2 * (y31 - y32)) + (c2 * yPrime2));
        c.y31[k] = 2 * y31 - c.y31[k - 2] + springValue;
        springValue = ((delta * delta) / m32) * ((-k2 * y31) + (y32 * (k2 + k3)) - (k3 * y33)
                                                 - (c2 * yPrime2) + (c3 * yPrime3));
        c.y32[k] = 2 * y32 - c.y32[k - 2] + springValue;
        springValue = ((delta * delta) / m33) * ((k3 * y33) - (k3 * y32) - (c3 * yPrime3));
        c.y33[k] = 2 * y33 - c.y33[k - 2] + springValue;
        if (finish_row(p, c, k, &s)) {
            bad = k;
            break;
        }
    }
    finish_run(&s, bad, out);
}

/* Average-acceleration Newmark (beta = 1/4, gamma = 1/2) for the OBR chain, implicit in the
 * springs and dampers, so unconditionally stable for them; the mitigator force law is the
 * macro's, evaluated explicitly at the Newmark predictor. The MEM is coupled to the chain
 * only through that force. Not in the macro. */
static void newmark_steps(const double *p, Py_ssize_t rows, Columns c, double *out)
{
    const double m32 = p[P_M32], m33 = p[P_M33], kk2 = -p[P_K2], kk3 = -p[P_K3];
    const double dt = p[P_DELTA], zeta = p[P_ZETA];
    const double beta = 0.25, gamma = 0.5;
    Mitigator s;
    double c2, c3, y[4], v[4], a[4];
    Py_ssize_t k, bad = -1;
    int i;

    mitigator_start(&s, p);
    c2 = 2 * zeta * sqrt(kk2 * (s.m31 + m32));
    c3 = 2 * zeta * sqrt(kk3 * (m32 + m33));
    start_rows(p, rows, c);
    for (i = 0; i < 4; i++) y[i] = 0;
    v[0] = p[P_V1]; v[1] = p[P_V31]; v[2] = p[P_V32]; v[3] = p[P_V33];
    /* a(0): no force yet; the chain's dampers act on the initial relative velocities */
    a[0] = 0;
    a[1] = (c2 * (v[2] - v[1])) / s.m31;
    a[2] = (-c2 * (v[2] - v[1]) + c3 * (v[3] - v[2])) / m32;
    a[3] = (-c3 * (v[3] - v[2])) / m33;
    for (k = 2; k < rows; k++) {
        double yp[4], vp[4], F, m31, r[3], d[3], lo[3], up[3];
        for (i = 0; i < 4; i++) {
            yp[i] = y[i] + dt * v[i] + (0.5 - beta) * dt * dt * a[i];
            vp[i] = v[i] + (1 - gamma) * dt * a[i];
        }
        F = mitigator_force(&s, p, yp[0], y[0], yp[1], y[1]);
        m31 = s.m31;
        /* MEM: only the mitigator force */
        a[0] = F / s.M1;
        /* chain: (M + gamma dt C + beta dt^2 K) a = f - C vp - K yp, tridiagonal */
        d[0] = m31 + gamma * dt * c2 + beta * dt * dt * kk2;
        d[1] = m32 + gamma * dt * (c2 + c3) + beta * dt * dt * (kk2 + kk3);
        d[2] = m33 + gamma * dt * c3 + beta * dt * dt * kk3;
        up[0] = lo[1] = -(gamma * dt * c2 + beta * dt * dt * kk2);
        up[1] = lo[2] = -(gamma * dt * c3 + beta * dt * dt * kk3);
        r[0] = -F - (c2 * (vp[1] - vp[2])) - (kk2 * (yp[1] - yp[2]));
        r[1] = -(c2 * (vp[2] - vp[1]) + c3 * (vp[2] - vp[3]))
               - (kk2 * (yp[2] - yp[1]) + kk3 * (yp[2] - yp[3]));
        r[2] = -(c3 * (vp[3] - vp[2])) - (kk3 * (yp[3] - yp[2]));
        /* Thomas algorithm */
        for (i = 1; i < 3; i++) {
            double w = lo[i] / d[i - 1];
            d[i] -= w * up[i - 1];
            r[i] -= w * r[i - 1];
        }
        a[3] = r[2] / d[2];
        a[2] = (r[1] - up[1] * a[3]) / d[1];
        a[1] = (r[0] - up[0] * a[2]) / d[0];
        for (i = 0; i < 4; i++) {
            y[i] = yp[i] + beta * dt * dt * a[i];
            v[i] = vp[i] + gamma * dt * a[i];
        }
        c.y1[k] = y[0];
        c.y31[k] = y[1];
        c.y32[k] = y[2];
        c.y33[k] = y[3];
        if (finish_row(p, c, k, &s)) {
            bad = k;
            break;
        }
    }
    finish_run(&s, bad, out);
}

#define N_COLUMNS 13
#define N_REQUIRED 5

typedef void (*Stepper)(const double *, Py_ssize_t, Columns, double *);

static PyObject *run_kernel(PyObject *args, Stepper steps)
{
    PyObject *params, *seq, *objs[N_COLUMNS];
    Py_buffer views[N_COLUMNS];
    double p[P_COUNT], finals[N_FINALS];
    double *ptrs[N_COLUMNS];
    Py_ssize_t rows, i;
    int got = 0;
    Columns c;

    if (!PyArg_ParseTuple(args, "OnOOOOOOOOOOOOO", &params, &rows, &objs[0], &objs[1],
                          &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7], &objs[8],
                          &objs[9], &objs[10], &objs[11], &objs[12]))
        return NULL;
    seq = params;
    if (PySequence_Size(seq) != P_COUNT) {
        if (!PyErr_Occurred())
            PyErr_Format(PyExc_ValueError, "params must hold %d values", P_COUNT);
        return NULL;
    }
    for (i = 0; i < P_COUNT; i++) {
        PyObject *item = PySequence_GetItem(seq, i);
        if (item == NULL)
            return NULL;
        p[i] = PyFloat_AsDouble(item);
        Py_DECREF(item);
        if (p[i] == -1.0 && PyErr_Occurred())
            return NULL;
    }
    /* rows x 8 bytes must not overflow: compare lengths by division, never by a product */
    if (rows < 0 || rows > PY_SSIZE_T_MAX / (Py_ssize_t)sizeof(double))
        return PyErr_Format(PyExc_ValueError, "rows must be >= 0 and fit the address space");
    for (got = 0; got < N_COLUMNS; got++) {
        if (got >= N_REQUIRED && objs[got] == Py_None) {
            views[got].obj = NULL;
            ptrs[got] = NULL;
            continue;
        }
        if (PyObject_GetBuffer(objs[got], &views[got], PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS
                               | PyBUF_FORMAT) < 0)
            goto fail;
        if (views[got].itemsize != sizeof(double) || views[got].format == NULL
            || strcmp(views[got].format, "d") != 0
            || views[got].len / (Py_ssize_t)sizeof(double) < rows) {
            PyBuffer_Release(&views[got]);
            PyErr_SetString(PyExc_ValueError, "columns must be float64 buffers of length >= rows");
            goto fail;
        }
        ptrs[got] = (double *)views[got].buf;
    }
    c.t = ptrs[0]; c.y1 = ptrs[1]; c.y31 = ptrs[2]; c.y32 = ptrs[3]; c.y33 = ptrs[4];
    c.crush = ptrs[5]; c.m31 = ptrs[6]; c.defl = ptrs[7]; c.xp = ptrs[8]; c.force = ptrs[9];
    c.m1 = ptrs[10]; c.v1 = ptrs[11]; c.v31 = ptrs[12];
    Py_BEGIN_ALLOW_THREADS
    steps(p, rows, c, finals);
    Py_END_ALLOW_THREADS
    for (i = 0; i < N_COLUMNS; i++)
        if (views[i].obj != NULL)
            PyBuffer_Release(&views[i]);
    return Py_BuildValue("ddnddddddd", finals[0], finals[1], (Py_ssize_t)finals[2], finals[3],
                         finals[4], finals[5], finals[6], finals[7], finals[8], finals[9]);
fail:
    for (i = 0; i < got; i++)
        if (views[i].obj != NULL)
            PyBuffer_Release(&views[i]);
    return NULL;
}

static PyObject *py_legacy_kernel(PyObject *self, PyObject *args)
{
    return run_kernel(args, legacy_steps);
}

static PyObject *py_newmark_kernel(PyObject *self, PyObject *args)
{
    return run_kernel(args, newmark_steps);
}


/* The legacy scheme for LANES shots at once, for the batch: structure of arrays, every branch
 * of the step (loading or unloading, wedge or cylinder, first unloading step, clamps,
 * statistics) as a select between both sides, so the lane loop has no branch and the compiler
 * runs it in SIMD registers (an AVX2 clone where the CPU has it). Each lane computes exactly
 * the scalar step's expressions in the same order, and -ffp-contract=off forbids fused
 * multiply-adds, so every lane equals legacy_steps on its shot bit for bit. A lane that leaves
 * the bound stops writing and keeps its finals from that row, as the scalar kernel breaks
 * there; the others go on. */
#define LANES 8

#if defined(_MSC_VER) && !defined(restrict)
#define restrict __restrict
#endif

#if defined(__GNUC__) && !defined(__clang__) && (defined(__x86_64__) || defined(__i386__))
#define LANE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LANE_CLONES
#endif

typedef struct {
    double m1[LANES], mmit[LANES], m31p[LANES], m32[LANES], m33[LANES], k2[LANES], k3[LANES];
    double rho[LANES], rcone[LANES], hcone[LANES], hcyl[LANES], E[LANES], ec[LANES];
    double sigmay[LANES], c2[LANES], c3[LANES], delta[LANES], dd[LANES], unload[LANES];
    double law[7][LANES];
} LaneParams;

typedef struct {
    double y1[LANES], yn1[LANES], y31[LANES], yn31[LANES], y32[LANES], yn32[LANES];
    double y33[LANES], yn33[LANES];
    double M1[LANES], m31[LANES], vcone[LANES], xP[LANES], maxdef[LANES], defl[LANES];
    double fcount[LANES], dforce[LANES], maxV[LANES], minV[LANES], maxT[LANES];
    double wasU[LANES], ons[LANES], second[LANES], step; /* statistics, as Mitigator's */
    double ny1[LANES], ny31[LANES], ny32[LANES], ny33[LANES];
} LaneState;

/* One step of every lane: the mitigator force law and the four central-difference lines. */
LANE_CLONES static void lane_step(const LaneParams *restrict q, LaneState *restrict s)
{
    int i;
    s->step = s->step + 1;
#pragma GCC ivdep
    for (i = 0; i < LANES; i++) {
        double y1 = s->y1[i], yn1 = s->yn1[i], y31 = s->y31[i], yn31 = s->yn31[i];
        double y32 = s->y32[i], yn32 = s->yn32[i], y33 = s->y33[i], yn33 = s->yn33[i];
        double delta = q->delta[i], hcone = q->hcone[i];
        double L = hcone + q->hcyl[i] - s->defl[i];
        double cPlastic = (y31 - yn31 - y1 + yn1) / (q->ec[i] * delta);
        /* every side computed first, then selected: no FP operation is conditional, so the
         * compiler may if-convert (it keeps branches around ops that could trap) */
        double xPadv = s->xP[i] + (cPlastic * delta);
        double xPn = cPlastic >= 0 ? xPadv : s->xP[i];
        double d = y31 - y1;
        int unload = d < s->maxdef[i];
        double AreaFull = PI_MACRO * q->rcone[i] * q->rcone[i];
        double k1 = -((AreaFull * q->E[i]) / (L));
        int first = unload & (s->fcount[i] == 0);
        int onset = unload & (s->wasU[i] == 0);
        double Ffirst = -k1 * (d - hcone);
        double dfFirst = Ffirst - s->dforce[i];
        double dfu = first ? dfFirst : s->dforce[i];
        double Fu = -k1 * (d - hcone) - dfu;
        int wedge = xPn <= hcone;
        double Aw = (PI_MACRO * q->rcone[i] * q->rcone[i]) * (xPn / hcone);
        double tw = ((q->rho[i] * Aw * xPn) / 3.0);
        double tc = s->vcone[i] + (q->rho[i] * AreaFull * (xPn - hcone));
        double Al = wedge ? Aw : AreaFull;
        double temp = wedge ? tw : tc;
        double V = (((y31 - yn31) - (y1 - yn1)) / delta);
        double cf = (q->law[6][i]) * (V * V * V * V * V * V) + (q->law[5][i]) * (V * V * V * V * V)
                    + (q->law[4][i]) * (V * V * V * V) + (q->law[3][i]) * (V * V * V)
                    + (q->law[2][i]) * (V * V) + (q->law[1][i]) * (V) + q->law[0][i];
        double Fl, F, M1n, m31n, M1l, m31l, yP2, yP3, sv, dd = q->dd[i], k2 = q->k2[i];
        double k3 = q->k3[i];
        double c2 = q->c2[i], c3 = q->c3[i];
        int loading = !unload;
        cf = cf < 1 ? 1 : cf;
        Fl = q->sigmay[i] * Al * cf;
        M1l = q->m1[i] + q->mmit[i] - temp;
        m31l = q->m31p[i] + temp;
        M1n = unload ? s->M1[i] : M1l;
        m31n = unload ? s->m31[i] : m31l;
        F = unload ? Fu : Fl;
        F = F < 0 ? 0 : F;
        /* statistics (not in the macro), while the law acts */
        s->maxV[i] = (loading & (Al > 0) & (V > s->maxV[i])) ? V : s->maxV[i];
        s->minV[i] = (loading & (Al > 0) & (V < s->minV[i])) ? V : s->minV[i];
        s->maxT[i] = (loading & (temp > s->maxT[i])) ? temp : s->maxT[i];
        s->xP[i] = xPn;
        s->defl[i] = d;
        s->fcount[i] = first ? 0 + 1 : (loading & (q->unload[i] != 0)) ? 0 : s->fcount[i];
        s->ons[i] = onset ? s->ons[i] + 1 : s->ons[i];
        s->second[i] = (onset & (s->ons[i] == 2)) ? s->step : s->second[i];
        s->wasU[i] = unload;
        s->dforce[i] = unload ? dfu : Fl;
        s->maxdef[i] = unload ? s->maxdef[i] : d;
        s->vcone[i] = (loading & wedge) ? tw : s->vcone[i];
        s->M1[i] = M1n;
        s->m31[i] = m31n;
        yP2 = ((y32 - yn32) - (y31 - yn31)) / delta;
        yP3 = ((y33 - yn33) - (y32 - yn32)) / delta;
        sv = ((dd) / M1n) * (F);
        s->ny1[i] = 2 * y1 - yn1 + sv;
        sv = ((dd) / m31n) * (-F + (k2 * (y31 - y32)) + (c2 * yP2));
        s->ny31[i] = 2 * y31 - yn31 + sv;
        sv = ((dd) / q->m32[i]) * ((-k2 * y31) + (y32 * (k2 + k3)) - (k3 * y33) - (c2 * yP2)
                                   + (c3 * yP3));
        s->ny32[i] = 2 * y32 - yn32 + sv;
        sv = ((dd) / q->m33[i]) * ((k3 * y33) - (k3 * y32) - (c3 * yP3));
        s->ny33[i] = 2 * y33 - yn33 + sv;
    }
}

static void lane_finals(const LaneState *s, int i, Py_ssize_t bad, double *f)
{
    f[0] = s->M1[i]; f[1] = s->m31[i]; f[2] = (double)bad; f[3] = s->xP[i];
    f[4] = s->maxV[i]; f[5] = s->minV[i]; f[6] = s->maxT[i]; f[7] = s->maxdef[i];
    f[8] = s->ons[i]; f[9] = s->second[i];
}

static void legacy_lanes(const double *params, int n, Py_ssize_t rows, double **out_rows,
                         double *finals, int last)
{
    LaneParams q;
    LaneState s;
    double bound[LANES];
    int alive[LANES], i, j;
    Py_ssize_t k;
    for (i = 0; i < LANES; i++) {
        const double *p = params + (Py_ssize_t)(i < n ? i : 0) * P_COUNT; /* pad: shot 0 */
        q.m1[i] = p[P_M1]; q.mmit[i] = p[P_MMIT]; q.m31p[i] = p[P_M31]; q.m32[i] = p[P_M32];
        q.m33[i] = p[P_M33]; q.k2[i] = p[P_K2]; q.k3[i] = p[P_K3]; q.rho[i] = p[P_RHO];
        q.rcone[i] = p[P_RCONE]; q.hcone[i] = p[P_HCONE]; q.hcyl[i] = p[P_HCYL];
        q.E[i] = p[P_E]; q.ec[i] = p[P_EC]; q.sigmay[i] = p[P_SIGMAY];
        q.delta[i] = p[P_DELTA]; q.dd[i] = p[P_DELTA] * p[P_DELTA];
        bound[i] = p[P_BOUND];
        q.unload[i] = p[P_UNLOAD];
        for (j = 0; j < 7; j++)
            q.law[j][i] = p[P_LAW0 + j];
        s.M1[i] = p[P_M1] + p[P_MMIT];
        s.m31[i] = p[P_M31];
        s.vcone[i] = p[P_VCONE];
        s.xP[i] = s.maxdef[i] = s.defl[i] = s.fcount[i] = s.dforce[i] = 0;
        s.maxV[i] = -INFINITY; s.minV[i] = INFINITY; s.maxT[i] = 0;
        s.wasU[i] = 0; s.ons[i] = 0; s.second[i] = -1;
        q.c2[i] = 2 * p[P_ZETA] * sqrt(-p[P_K2] * (s.m31[i] + p[P_M32]));
        q.c3[i] = 2 * p[P_ZETA] * sqrt(-p[P_K3] * (p[P_M32] + p[P_M33]));
        s.yn1[i] = -p[P_DELTA] * p[P_V1]; s.yn31[i] = -p[P_DELTA] * p[P_V31];
        s.yn32[i] = -p[P_DELTA] * p[P_V32]; s.yn33[i] = -p[P_DELTA] * p[P_V33];
        s.y1[i] = s.y31[i] = s.y32[i] = s.y33[i] = 0;
        alive[i] = i < n;
    }
    s.step = 1; /* the first lane_step is step (row index) 2 */
    for (i = 0; i < n; i++) {
        if (rows > 0) out_rows[i][0] = last == 1 ? s.yn31[i] : last == 2 ? s.yn32[i] : s.yn33[i];
        if (rows > 1) out_rows[i][1] = 0;
    }
    for (k = 2; k < rows; k++) {
        int any = 0;
        lane_step(&q, &s);
        for (i = 0; i < n; i++) {
            double a, b, c, e;
            if (!alive[i])
                continue;
            a = s.ny1[i]; b = s.ny31[i]; c = s.ny32[i]; e = s.ny33[i];
            out_rows[i][k] = last == 1 ? b : last == 2 ? c : e;
            if (!(fabs(a) <= bound[i] && fabs(b) <= bound[i] && fabs(c) <= bound[i]
                  && fabs(e) <= bound[i])) {
                alive[i] = 0; /* diverged: this lane stops, the batch goes on */
                lane_finals(&s, i, k, finals + (Py_ssize_t)i * N_FINALS);
                continue;
            }
            any = 1;
        }
        for (i = 0; i < LANES; i++) {
            s.yn1[i] = s.y1[i]; s.y1[i] = s.ny1[i];
            s.yn31[i] = s.y31[i]; s.y31[i] = s.ny31[i];
            s.yn32[i] = s.y32[i]; s.y32[i] = s.ny32[i];
            s.yn33[i] = s.y33[i]; s.y33[i] = s.ny33[i];
        }
        if (!any)
            break;
    }
    for (i = 0; i < n; i++)
        if (alive[i])
            lane_finals(&s, i, -1, finals + (Py_ssize_t)i * N_FINALS);
}

/* Many shots of equal row count, for sweeps: params (n x P_COUNT), and for each shot its Y33
 * row (n x rows) and its finals (n x N_FINALS, as the single-shot kernel returns them). The
 * legacy scheme runs LANES shots at a time (legacy_lanes), newmark one shot after another;
 * both give the single-shot results to the last bit. ``last`` picks the displacement
 * returned (the bird's last mass, Y33 or Y32/Y31). The GIL is released: two threads on two
 * halves use both cores. */
static PyObject *py_batch_kernel(PyObject *self, PyObject *args)
{
    PyObject *objs[4];
    Py_buffer views[4];
    Py_ssize_t rows, n, i, k;
    int integrator, last, got, lanes = 1;
    double *scratch = NULL;

    if (!PyArg_ParseTuple(args, "OniiOOO|p", &objs[0], &rows, &integrator, &last, &objs[1],
                          &objs[2], &objs[3], &lanes))
        return NULL;
    if (last < 1 || last > 3)
        return PyErr_Format(PyExc_ValueError, "last must be 1 (Y31), 2 (Y32) or 3 (Y33)");
    for (got = 0; got < 4; got++) {
        int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (got ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(objs[got], &views[got], flags) < 0)
            goto fail;
        if (views[got].itemsize != sizeof(double) || views[got].format == NULL
            || strcmp(views[got].format, "d")) {
            PyErr_SetString(PyExc_ValueError, "buffers must be float64");
            got++;
            goto fail;
        }
    }
    n = views[0].len / (Py_ssize_t)(P_COUNT * sizeof(double));
    /* every size by division, so that no product overflows; the scratch is rows x 4 doubles */
    if (rows < 0 || rows > PY_SSIZE_T_MAX / (Py_ssize_t)(4 * sizeof(double))
        || views[0].len != n * P_COUNT * (Py_ssize_t)sizeof(double)
        || views[1].len / (Py_ssize_t)sizeof(double) < rows
        || (rows > 0 && views[2].len / (Py_ssize_t)sizeof(double) / rows < n)
        || views[3].len / (Py_ssize_t)(N_FINALS * sizeof(double)) < n) {
        PyErr_Format(PyExc_ValueError, "buffer sizes do not match (n x %d, rows, n x rows, "
                                       "n x %d)", P_COUNT, N_FINALS);
        goto fail;
    }
    scratch = malloc((size_t)(rows > 0 ? rows : 1) * 4 * sizeof(double));
    if (scratch == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    Py_BEGIN_ALLOW_THREADS
    if (integrator == 0 && lanes) { /* the legacy scheme, LANES shots at a time */
        const double *all = (const double *)views[0].buf;
        double *t = (double *)views[1].buf, currentTime;
        for (i = 0; i < n; i += LANES) {
            double *out_rows[LANES];
            int m = (int)(n - i < LANES ? n - i : LANES), j;
            for (j = 0; j < m; j++) {
                out_rows[j] = (double *)views[2].buf + (i + j) * rows;
                for (k = 0; k < rows; k++)
                    out_rows[j][k] = 0;
            }
            legacy_lanes(all + i * P_COUNT, m, rows, out_rows,
                         (double *)views[3].buf + i * N_FINALS, last);
        }
        /* time as start_rows writes it, from the last shot's step (as the scalar loop) */
        currentTime = n > 0 ? -all[(n - 1) * P_COUNT + P_DELTA] : 0;
        for (k = 0; k < rows && n > 0; k++) {
            t[k] = currentTime;
            currentTime = currentTime + all[(n - 1) * P_COUNT + P_DELTA];
        }
        n = 0; /* done: skip the scalar loop below */
    }
    for (i = 0; i < n; i++) {
        Columns c = {0};
        double *row = (double *)views[2].buf + i * rows, **mine;
        c.t = (double *)views[1].buf;
        c.y1 = scratch;
        c.y31 = scratch + rows;
        c.y32 = scratch + 2 * rows;
        c.y33 = scratch + 3 * rows;
        mine = last == 1 ? &c.y31 : last == 2 ? &c.y32 : &c.y33;
        *mine = row; /* the bird's last mass goes to the output */
        for (k = 0; k < rows; k++)
            row[k] = 0;
        (integrator ? newmark_steps : legacy_steps)((double *)views[0].buf + i * P_COUNT, rows,
                                                    c, (double *)views[3].buf + i * N_FINALS);
    }
    Py_END_ALLOW_THREADS
    free(scratch);
    for (i = 0; i < 4; i++)
        PyBuffer_Release(&views[i]);
    Py_RETURN_NONE;
fail:
    for (i = 0; i < got && i < 4; i++)
        PyBuffer_Release(&views[i]);
    return NULL;
}

static PyMethodDef methods[] = {
    {"legacy_kernel", py_legacy_kernel, METH_VARARGS,
     "legacy_kernel(params, rows, t, y1, y31, y32, y33, crush, m31, defl, xp, force, m1, v1, "
     "v31)\nRun ArtSim's position loop into the given float64 buffers; return (M1, m31)."},
    {"newmark_kernel", py_newmark_kernel, METH_VARARGS,
     "newmark_kernel(...): as legacy_kernel, with the average-acceleration Newmark scheme."},
    {"batch_kernel", py_batch_kernel, METH_VARARGS,
     "batch_kernel(params, rows, integrator, last, t, y, finals, lanes=True): many shots of "
     "equal rows (integrator 0 legacy, 1 newmark; last 1..3: which of Y31..Y33 goes to y; "
     "lanes: the legacy scheme LANES shots at a time, else one shot after another)."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_artsim",
                                    "Compiled ArtSim kernel (faithful port).", -1, methods};

PyMODINIT_FUNC PyInit__artsim(void) { return PyModule_Create(&module); }
