/*
 * acld_gym.envs._stepcore: the batched step of ACLDBeam in C.
 *
 * BatchCore runs the one step of acld_gym.envs.batch.BatchStep (its numpy
 * reference is BatchStep.advance) for N beams at once, on the arrays that
 * BatchStep owns: the state-and-input rows Z (N, nz), the outputs OUT (N, m),
 * the step counters, the tabulated sensor noise, the measurement histories and
 * the encoded tip loads. Per env and step:
 *
 *   1. the voltage and the period's load samples (evaluated here from the
 *      encoded load, with the same time points and the same sums as
 *      acld_gym.envs.step.load_schedule) and the new measurement's noise go
 *      into z;
 *   2. out = G z: plant (ZOH), observer, measurement, observation and the
 *      info's numbers in one product (acld_gym.envs.step.output_matrix; the
 *      slots are acld_gym.envs.step.StepLayout's, passed in as integers), by
 *      BLAS dgemm for a large batch sharing one G, else by a column loop;
 *   3. the state part of out replaces z's, the step count advances;
 *   4. reward and its terms on the true deflection, and the end of the episode
 *      (acld_gym.envs.step.reward_terms / termination_codes, mirrored here).
 *
 * ``step_one(action)`` is the single env's step (N = 1): it parses the action
 * and returns Gymnasium's 5-tuple with the info dict, or None where the Python
 * reference must take over (an action that is not a finite 1-element
 * float32/float64 array, a step past the tabulated episode). ``step(v)`` is the
 * vector env's: ``v`` are the N clipped voltages (validated in Python), and it
 * returns the results as new arrays.
 *
 * Why C: in CPython a Gymnasium step costs about 1 us of interpreter work before
 * any physics; here the bookkeeping costs less than the product
 * (benchmarks/bench_env.py).
 */
#define _GNU_SOURCE  /* sincos */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#include <math.h>
#include <string.h>
#include <time.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

enum { OBS_ESTIMATE = 0, OBS_MEASUREMENT = 1, OBS_FULL = 2 };
/* load components, as acld_gym.envs.loadcode encodes them: [type, start, end, p0, p1, p2,
   p3, p4] (one cache line each) */
enum { LOAD_PULSE = 1, LOAD_HARMONIC = 2, LOAD_SAMPLES = 3 };
#define COMP_WIDTH 8
/* termination codes (acld_gym.envs.step.TERMINATED_BY) */
enum { END_NONE = 0, END_LIMIT = 1, END_NONFINITE = 2 };
/* a batch sharing one G at least this large goes through dgemm */
#define DGEMM_MIN_ROWS 8

typedef void dgemm_t(char *transa, char *transb, int *m, int *n, int *k, double *alpha,
                     double *a, int *lda, double *b, int *ldb, double *beta, double *c,
                     int *ldc);

typedef struct {
    PyObject_HEAD
    PyArrayObject *GT;     /* (nz, m) shared or (N, nz, m) per env: G transposed */
    PyArrayObject *Z;      /* (N, nz): [x, xhat, y_meas, V, f0.., f1.., w'] */
    PyArrayObject *OUT;    /* (N, m): G z of the last step */
    PyArrayObject *k;      /* (N,) int64: steps taken */
    PyArrayObject *noise;  /* (N, steps + 1): sensor noise of the episode [m] */
    PyArrayObject *y_hist; /* (N, hist): last measurements [m] */
    PyArrayObject *comp;   /* (N, K, 7): encoded load components */
    PyArrayObject *ncomp;  /* (N,) int64: components per env */
    PyArrayObject *pool;   /* (N, P): sample values of Samples components [N] */
    PyArrayObject *times;  /* (s + 1,): sub-step edges within a period [s] */
    PyObject *info_template;
    dgemm_t *dgemm;
    npy_intp N, m, nz, K, P, hist, steps, s;
    int per_env, obs_mode, block_rows;
    npy_intp n_state, i_volt, i_loads, i_noise, o_ymeas, o_y, o_xr, o_obs, n_x, n_xr, n_obs;
    /* the actuator (acld_gym.envs.step.StepLayout; -1: none): the patch voltage in the
       output, the command reaching the amplifier, the voltage held over the last period and
       the amplifier's output this period (slew limit: at most slew_step per period) */
    npy_intp o_volt, i_cmd, i_held, i_amp;
    double slew_step;
    double dt, eps, y_ref, lam, v_max, limit, y_scale;
    double last_tip;  /* the single env's tip load at the end of its last step [N] */
} BatchCore;

static PyObject *k_tip, *k_volt, *k_req, *k_clip, *k_load, *k_time, *k_xr, *k_term, *k_ry, *k_rv;
/* the vector info's masks, "_" + key */
static PyObject *m_tip, *m_volt, *m_req, *m_clip, *m_load, *m_time, *m_xr, *m_term, *m_ry, *m_rv;
static PyObject *s_limit, *s_nonfinite;
#define N_INFO 10

/* out = G z as a sum of G's columns (Gt = G^T, nz x m): the inner loop is contiguous and
   vectorizes without reassociating a reduction; columns with z_j = 0 are skipped. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
static void product(const double *restrict Gt, const double *restrict z, double *restrict out,
                    npy_intp m, npy_intp nz)
{
    memset(out, 0, (size_t)m * sizeof(double));
    for (npy_intp j = 0; j < nz; j++) {
        const double zj = z[j];
        if (zj == 0.0) continue;
        const double *col = Gt + j * m;
        for (npy_intp i = 0; i < m; i++) out[i] += col[i] * zj;
    }
}

/* --- the tip load (acld_gym.physics.loads.TipLoad.__call__, component by component) ----- */

/* Samples on the grid start + step * j, j < n (linear in between, np.interp's formula):
   the segment j with x_j <= x < x_{j+1} of a point x and its slope. */
typedef struct {
    const double *v;
    npy_intp n, j;
    double start, step, xj, xj1, slope;
} Cursor;

/* the grid point x_j = start + step j */
static inline double grid(const Cursor *c, npy_intp j) { return c->start + c->step * (double)j; }

/* Find the segment of x and its slope, starting from the last segment found (time only moves
   forward, so it is usually right or the next one). The encoding p keeps it: p[6] the
   segment, p[7] its slope (NaN: not computed yet). */
static void cursor_seek(Cursor *c, double x, double *p)
{
    npy_intp j = (npy_intp)p[6];
    if (j < 0 || j > c->n - 2 || !(grid(c, j) <= x) || !(x < grid(c, j + 2))) {
        j = (npy_intp)floor((x - c->start) / c->step);
        if (j < 0) j = 0;
        if (j > c->n - 2) j = c->n - 2;
    }
    while (j > 0 && grid(c, j) > x) j--;
    while (j < c->n - 2 && grid(c, j + 1) <= x) j++;
    c->j = j;
    c->xj = grid(c, j);
    c->xj1 = grid(c, j + 1);
    if (j == (npy_intp)p[6] && p[7] == p[7]) {
        c->slope = p[7];
    } else {
        c->slope = (c->v[j + 1] - c->v[j]) / (c->xj1 - c->xj);
        p[6] = (double)j;
        p[7] = c->slope;
    }
}

/* the largest number of load sub-steps per period the compiled step takes */
#define MAX_SUBSTEPS 256

/* The period's load samples and the tip load at its end: f0[j] = load(t_j + eps),
   f1[j] = load(t_{j+1} - eps), t_j = k dt + times[j] (acld_gym.envs.step.load_schedule),
   and *tip = load((k + 1) dt). In time order the points are x = [f0[0], f1[0], f0[1], ...,
   f1[s-1], tip]; each component adds its value at the points it covers, in component order
   (TipLoad.__call__'s sums). The last segment of each Samples component is kept in its
   encoding (slot 6) as the next step's starting guess. */
static void period_loads(const BatchCore *self, npy_intp i, long kk, double *f0, double *f1,
                         double *tip)
{
    const npy_intp s = self->s, np_ = 2 * s + 1;
    const double *times = PyArray_DATA(self->times);
    const double kd = (double)kk * self->dt, eps = self->eps;
    double x[2 * MAX_SUBSTEPS + 1], f[2 * MAX_SUBSTEPS + 1];
    for (npy_intp j = 0; j < s; j++) {
        x[2 * j] = (kd + times[j]) + eps;
        x[2 * j + 1] = (kd + times[j + 1]) - eps;
    }
    x[2 * s] = (double)(kk + 1) * self->dt;
    memset(f, 0, (size_t)np_ * sizeof(double));
    double *comp = (double *)PyArray_DATA(self->comp) + i * self->K * COMP_WIDTH;
    const double *pool = (const double *)PyArray_DATA(self->pool) + i * self->P;
    const npy_intp nc = ((const npy_int64 *)PyArray_DATA(self->ncomp))[i];
    for (npy_intp c = 0; c < nc; c++) {
        double *p = comp + c * COMP_WIDTH;
        const double start = p[1], end = p[2];
        if (end <= x[0] || start > x[np_ - 1]) continue;  /* off at every point */
        npy_intp q0 = 0, q1 = np_;  /* the points in [start, end) (x increases) */
        while (q0 < np_ && !(x[q0] >= start)) q0++;
        while (q1 > q0 && !(x[q1 - 1] < end)) q1--;
        const int type = (int)p[0];
        if (type == LOAD_PULSE) {
            for (npy_intp q = q0; q < q1; q++) f[q] = f[q] + p[3];
        } else if (type == LOAD_HARMONIC) {
            /* A sin(theta), theta = w (x - start) + phase. A sub-step's end point (odd q) lies
               2 eps before the next start point, so its sine comes from the next point's sine
               and cosine: sin(theta) = sin(theta') - cos(theta') d with d = theta' - theta
               (exact: the two are close), exact to rounding since d^2 < 1e-16; one sincos
               per sub-step instead of two sines. */
            const double A = p[3], w = p[4], ph = p[5];
            double sn = 0.0, cs = 0.0;
            int have = 0;  /* sn is the sine at point q (from the previous point) */
            for (npy_intp q = q0; q < q1; q++) {
                const double th = w * (x[q] - start) + ph;
                double val;
                if ((q & 1) && q + 1 < q1) {
                    const double th1 = w * (x[q + 1] - start) + ph;
                    sincos(th1, &sn, &cs);
                    have = 1;
                    val = sn - cs * (th1 - th);
                } else {
                    val = have ? sn : sin(th);
                    have = 0;
                }
                f[q] = f[q] + A * val;
            }
        } else {
            /* segment by segment: np.interp's slope (v[j+1] - v[j]) / (x_{j+1} - x_j) times
               (x - x_j) plus v[j] (its special case x = x_j gives v[j] here as well) */
            Cursor cur = {.v = pool + (npy_intp)p[4], .n = (npy_intp)p[5], .start = start,
                          .step = p[3]};
            for (npy_intp q = q0; q < q1;) {
                cursor_seek(&cur, x[q], p);
                npy_intp qe = q + 1;
                while (qe < q1 && x[qe] < cur.xj1) qe++;
                const double slope = cur.slope, xj = cur.xj, vj = cur.v[cur.j];
                for (npy_intp r = q; r < qe; r++) f[r] = f[r] + (slope * (x[r] - xj) + vj);
                q = qe;
            }
        }
    }
    for (npy_intp j = 0; j < s; j++) {
        f0[j] = f[2 * j];
        f1[j] = f[2 * j + 1];
    }
    *tip = f[2 * s];
}

/* the load of one component at t (start <= t < end) */
static double component_at(double *c, const double *pool, double t)
{
    switch ((int)c[0]) {
    case LOAD_PULSE: return c[3];
    case LOAD_HARMONIC: return c[3] * sin(c[4] * (t - c[1]) + c[5]);
    case LOAD_SAMPLES: {
        Cursor cur = {.v = pool + (npy_intp)c[4], .n = (npy_intp)c[5], .start = c[1],
                      .step = c[3]};
        cursor_seek(&cur, t, c);
        return cur.slope * (t - cur.xj) + cur.v[cur.j];
    }
    }
    return 0.0;
}

static double load_at(const BatchCore *self, npy_intp i, double t)
{
    double *comp = (double *)PyArray_DATA(self->comp) + i * self->K * COMP_WIDTH;
    const double *pool = (const double *)PyArray_DATA(self->pool) + i * self->P;
    const npy_intp nc = ((const npy_int64 *)PyArray_DATA(self->ncomp))[i];
    double f = 0.0;
    for (npy_intp c = 0; c < nc; c++) {
        double *p = comp + c * COMP_WIDTH;
        if (t >= p[1] && t < p[2]) f = f + component_at(p, pool, t);
    }
    return f;
}

/* --- the step ------------------------------------------------------------------------------ */

/* whether x[0..n) are all finite: x - x is 0 for a finite x and NaN otherwise, so the sum of
   these (four running sums, each exactly 0 or NaN) is NaN if and only if one is not finite */
static int all_finite(const double *x, npy_intp n)
{
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    npy_intp j = 0;
    for (; j + 4 <= n; j += 4) {
        a0 += x[j] - x[j];
        a1 += x[j + 1] - x[j + 1];
        a2 += x[j + 2] - x[j + 2];
        a3 += x[j + 3] - x[j + 3];
    }
    for (; j < n; j++) a0 += x[j] - x[j];
    return (a0 + a1 + a2 + a3) == 0.0;
}

/* 4. reward terms and the end of the episode of env i after advance() */
static int outcome(const BatchCore *self, npy_intp i, double v, double *ry, double *rv,
                   double *reward)
{
    const double *o = (const double *)PyArray_DATA(self->OUT) + i * self->m;
    const double y = o[self->o_y];
    if (self->o_volt >= 0) v = o[self->o_volt];  /* the patch voltage at the end of the step */
    const double qy = y / self->y_ref, qv = v / self->v_max;
    *ry = -(qy * qy);
    *rv = -(self->lam * (qv * qv));
    *reward = *ry + *rv;
    if (!isfinite(*reward) || !all_finite(o, self->m)) return END_NONFINITE;
    return fabs(y) <= self->limit ? END_NONE : END_LIMIT;
}

/* the observation of env i from the current state, into d (float32) */
static void observe(const BatchCore *self, npy_intp i, float *d)
{
    const double *o = (const double *)PyArray_DATA(self->OUT) + i * self->m;
    const double *z = (const double *)PyArray_DATA(self->Z) + i * self->nz;
    if (self->obs_mode == OBS_ESTIMATE) {
        for (npy_intp j = 0; j < self->n_obs; j++) d[j] = (float)o[self->o_obs + j];
    } else if (self->obs_mode == OBS_FULL) {
        for (npy_intp j = 0; j < self->n_x; j++) d[j] = (float)z[j];
    } else {
        const double *h = (const double *)PyArray_DATA(self->y_hist) + i * self->hist;
        for (npy_intp j = 0; j < self->hist; j++) d[j] = (float)(h[j] / self->y_scale);
        d[self->hist] = (float)(z[self->i_volt] / self->v_max);
    }
}

/* the noise and the sample values an env's next step reads (its encoded load is in cache) */
static void prefetch_samples(const BatchCore *self, npy_intp a)
{
    const npy_int64 ka = ((const npy_int64 *)PyArray_DATA(self->k))[a];
    __builtin_prefetch((const double *)PyArray_DATA(self->noise) + a * (self->steps + 1) + ka + 1);
    const double *comp = (const double *)PyArray_DATA(self->comp) + a * self->K * COMP_WIDTH;
    const double *pool = (const double *)PyArray_DATA(self->pool) + a * self->P;
    const npy_intp nc = ((const npy_int64 *)PyArray_DATA(self->ncomp))[a];
    const double t = (double)ka * self->dt;
    for (npy_intp c = 0; c < nc; c++) {
        const double *p = comp + c * COMP_WIDTH;
        if ((int)p[0] != LOAD_SAMPLES || !(t >= p[1] && t < p[2])) continue;
        const npy_intp j = (npy_intp)((t - p[1]) / p[3]);
        if (j >= 0 && j + 1 < (npy_intp)p[5]) __builtin_prefetch(pool + (npy_intp)p[4] + j);
    }
}

/* Per-step results of the vector step (acld_gym.envs.batch.StepResult), one value per env. */
typedef struct {
    float *obs;
    double *reward, *ry, *rv, *y, *tip, *xr;
    npy_int8 *code;
    npy_bool *trunc;
    double *pv;  /* the patch voltage at the end of the step [V] */
} Results;

static int outcome(const BatchCore *self, npy_intp i, double v, double *ry, double *rv,
                   double *reward);
static void observe(const BatchCore *self, npy_intp i, float *d);
static double load_at(const BatchCore *self, npy_intp i, double t);

/* Rows per block of the step: a block's z and out rows stay in cache from the inputs
   through the product to the results. */
#define BLOCK_ROWS 64
/* rows ahead whose loads and noise are prefetched */
#define PREFETCH 32

/* 1.-4. for every env: inputs into z, out = G z, the new state into z, k += 1, and (r not
   NULL) the results */
static void advance(BatchCore *self, const double *v, Results *r)
{
    const npy_intp N = self->N, m = self->m, nz = self->nz, s = self->s;
    double *Z = PyArray_DATA(self->Z), *OUT = PyArray_DATA(self->OUT);
    npy_int64 *k = PyArray_DATA(self->k);
    const double *noise = PyArray_DATA(self->noise);
    const double *GT = PyArray_DATA(self->GT);
    const npy_intp B = self->block_rows > 0 ? self->block_rows : N;
    for (npy_intp i0 = 0; i0 < N; i0 += B) {
        const npy_intp i1 = i0 + B < N ? i0 + B : N, nb = i1 - i0;
        for (npy_intp i = i0; i < i1; i++) {
            double *z = Z + i * nz;
            const long kk = (long)k[i];
            if (i + 2 * PREFETCH < N) {  /* an env's encoded load, two distances ahead */
                const char *cp = (const char *)PyArray_DATA(self->comp)
                                 + (i + 2 * PREFETCH) * self->K * COMP_WIDTH * sizeof(double);
                for (npy_intp b = 0; b < self->K * COMP_WIDTH * (npy_intp)sizeof(double); b += 64)
                    __builtin_prefetch(cp + b);
            }
            if (i + PREFETCH < N) prefetch_samples(self, i + PREFETCH);
            z[self->i_volt] = v[i];
            period_loads(self, i, kk, z + self->i_loads, z + self->i_loads + s,
                         r != NULL ? r->tip + i : &self->last_tip);
            z[self->i_noise] = noise[i * (self->steps + 1)
                                     + (kk < self->steps ? kk + 1 : self->steps)];
            if (self->slew_step > 0) {  /* the amplifier moves towards the command */
                const double held = z[self->i_held], d = z[self->i_cmd] - held;
                z[self->i_amp] = held + (d < -self->slew_step ? -self->slew_step
                                         : (d > self->slew_step ? self->slew_step : d));
            }
        }
        if (self->per_env) {
            for (npy_intp i = i0; i < i1; i++)
                product(GT + i * nz * m, Z + i * nz, OUT + i * m, m, nz);
        } else if (nb >= DGEMM_MIN_ROWS && self->dgemm != NULL) {
            int mi = (int)m, ni = (int)nb, ki = (int)nz;
            double one = 1.0, zero = 0.0;
            char tr = 'N';
            self->dgemm(&tr, &tr, &mi, &ni, &ki, &one, (double *)GT, &mi, Z + i0 * nz, &ki,
                        &zero, OUT + i0 * m, &mi);
        } else {
            for (npy_intp i = i0; i < i1; i++) product(GT, Z + i * nz, OUT + i * m, m, nz);
        }
        for (npy_intp i = i0; i < i1; i++) {
            const double *o = OUT + i * m;
            memcpy(Z + i * nz, o, (size_t)self->n_state * sizeof(double));
            k[i] += 1;
            if (self->obs_mode == OBS_MEASUREMENT) {
                double *h = (double *)PyArray_DATA(self->y_hist) + i * self->hist;
                memmove(h, h + 1, (size_t)(self->hist - 1) * sizeof(double));
                h[self->hist - 1] = o[self->o_ymeas];
            }
            if (r == NULL) continue;
            r->code[i] = (npy_int8)outcome(self, i, v[i], r->ry + i, r->rv + i, r->reward + i);
            r->trunc[i] = k[i] >= self->steps;
            observe(self, i, r->obs + i * self->n_obs);
            r->y[i] = o[self->o_y];
            r->pv[i] = self->o_volt >= 0 ? o[self->o_volt] : v[i];
            memcpy(r->xr + i * self->n_xr, o + self->o_xr, (size_t)self->n_xr * sizeof(double));
        }
    }
}

/* --- construction -------------------------------------------------------------------------- */

static int
check_array(PyObject *a, const char *name, int ndim, int type)
{
    if (!PyArray_Check(a) || PyArray_TYPE((PyArrayObject *)a) != type
        || !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)a)
        || !PyArray_ISNOTSWAPPED((PyArrayObject *)a) || !PyArray_ISALIGNED((PyArrayObject *)a)
        || !PyArray_ISWRITEABLE((PyArrayObject *)a)
        || PyArray_NDIM((PyArrayObject *)a) != ndim) {
        PyErr_Format(PyExc_ValueError, "BatchCore: %s must be a writeable, aligned, "
                     "C-contiguous native %s array with %d dimension(s)", name,
                     type == NPY_DOUBLE ? "float64" : "int64", ndim);
        return -1;
    }
    return 0;
}

static void
core_clear(BatchCore *self)
{
    Py_CLEAR(self->GT); Py_CLEAR(self->Z); Py_CLEAR(self->OUT); Py_CLEAR(self->k);
    Py_CLEAR(self->noise); Py_CLEAR(self->y_hist); Py_CLEAR(self->comp); Py_CLEAR(self->ncomp);
    Py_CLEAR(self->pool); Py_CLEAR(self->times); Py_CLEAR(self->info_template);
}

static void
core_dealloc(BatchCore *self)
{
    core_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int
check_loads(PyObject *comp, PyObject *ncomp, PyObject *pool, npy_intp N)
{
    if (check_array(comp, "comp", 3, NPY_DOUBLE) || check_array(ncomp, "ncomp", 1, NPY_INT64)
        || check_array(pool, "pool", 2, NPY_DOUBLE))
        return -1;
    PyArrayObject *c = (PyArrayObject *)comp, *p = (PyArrayObject *)pool;
    if (PyArray_DIM(c, 0) != N || PyArray_DIM(c, 2) != COMP_WIDTH
        || PyArray_DIM((PyArrayObject *)ncomp, 0) != N || PyArray_DIM(p, 0) != N) {
        PyErr_SetString(PyExc_ValueError, "BatchCore: the load arrays do not fit the batch");
        return -1;
    }
    /* every component within its arrays (a bad encoding must not read out of bounds) */
    const npy_intp K = PyArray_DIM(c, 1), P = PyArray_DIM(p, 1);
    const npy_int64 *nc = PyArray_DATA((PyArrayObject *)ncomp);
    for (npy_intp i = 0; i < N; i++) {
        if (nc[i] < 0 || nc[i] > K) goto bad;
        for (npy_intp j = 0; j < nc[i]; j++) {
            const double *q = (const double *)PyArray_DATA(c) + (i * K + j) * COMP_WIDTH;
            const int type = (int)q[0];
            if (type < LOAD_PULSE || type > LOAD_SAMPLES || q[0] != (double)type) goto bad;
            if (type == LOAD_SAMPLES && !(q[3] > 0 && q[4] >= 0 && q[5] >= 2
                                          && q[4] + q[5] <= (double)P))
                goto bad;
        }
    }
    return 0;
bad:
    PyErr_SetString(PyExc_ValueError, "BatchCore: a load component is not encoded correctly");
    return -1;
}

static int
core_init(BatchCore *self, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"GT", "Z", "OUT", "k", "noise", "y_hist", "comp", "ncomp", "pool",
                             "times", "n_state", "i_voltage", "i_loads", "i_noise", "o_ymeas",
                             "o_y", "o_xr", "o_obs", "n_x", "n_xr", "o_volt", "i_cmd", "i_held",
                             "i_amp", "obs_mode", "n_obs", "dt", "y_ref", "lam", "v_max",
                             "limit", "y_scale", "slew_step", "dgemm", NULL};
    PyObject *GT, *Z, *OUT, *k, *noise, *y_hist, *comp, *ncomp, *pool, *times, *cap = Py_None;
    Py_ssize_t n_state, i_volt, i_loads, i_noise, o_ymeas, o_y, o_xr, o_obs, n_x, n_xr, n_obs;
    Py_ssize_t o_volt, i_cmd, i_held, i_amp;
    int obs_mode;
    double dt, y_ref, lam, v_max, limit, y_scale, slew_step;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "$OOOOOOOOOOnnnnnnnnnnnnnnindddddddO", kwlist,
                                     &GT, &Z, &OUT, &k, &noise, &y_hist, &comp, &ncomp, &pool,
                                     &times, &n_state, &i_volt, &i_loads, &i_noise, &o_ymeas,
                                     &o_y, &o_xr, &o_obs, &n_x, &n_xr, &o_volt, &i_cmd, &i_held,
                                     &i_amp, &obs_mode, &n_obs, &dt, &y_ref, &lam, &v_max,
                                     &limit, &y_scale, &slew_step, &cap))
        return -1;
    if (check_array(Z, "Z", 2, NPY_DOUBLE) || check_array(OUT, "OUT", 2, NPY_DOUBLE)
        || check_array(k, "k", 1, NPY_INT64) || check_array(noise, "noise", 2, NPY_DOUBLE)
        || check_array(y_hist, "y_hist", 2, NPY_DOUBLE) || check_array(times, "times", 1, NPY_DOUBLE))
        return -1;
    const npy_intp N = PyArray_DIM((PyArrayObject *)Z, 0), nz = PyArray_DIM((PyArrayObject *)Z, 1);
    const npy_intp m = PyArray_DIM((PyArrayObject *)OUT, 1);
    if (!PyArray_Check(GT) || (PyArray_NDIM((PyArrayObject *)GT) != 2
                               && PyArray_NDIM((PyArrayObject *)GT) != 3))
        goto gt_bad;
    const int per_env = PyArray_NDIM((PyArrayObject *)GT) == 3;
    if (check_array(GT, "GT", per_env ? 3 : 2, NPY_DOUBLE)) return -1;
    PyArrayObject *g = (PyArrayObject *)GT;
    if ((per_env && (PyArray_DIM(g, 0) != N || PyArray_DIM(g, 1) != nz || PyArray_DIM(g, 2) != m))
        || (!per_env && (PyArray_DIM(g, 0) != nz || PyArray_DIM(g, 1) != m)))
        goto gt_bad;
    const npy_intp s = PyArray_DIM((PyArrayObject *)times, 0) - 1;
    const npy_intp steps = PyArray_DIM((PyArrayObject *)noise, 1) - 1;
    const npy_intp hist = PyArray_DIM((PyArrayObject *)y_hist, 1);
    /* every slot inside its vector, the updated state before the voltage and inputs */
    if (N < 1 || PyArray_DIM((PyArrayObject *)OUT, 0) != N || PyArray_DIM((PyArrayObject *)k, 0) != N
        || PyArray_DIM((PyArrayObject *)noise, 0) != N || PyArray_DIM((PyArrayObject *)y_hist, 0) != N
        || s < 1 || s > MAX_SUBSTEPS || steps < 1 || hist < 1 || n_state < 1 || n_x < 1
        || n_x > n_state
        || n_state > m || i_volt < n_state || i_loads <= i_volt || i_loads + 2 * s > i_noise
        || i_noise >= nz || n_xr < 0 || o_ymeas < 0 || o_ymeas >= m || o_y < 0 || o_y >= m
        || o_xr < 0 || o_xr + n_xr > m || o_obs < 0 || o_obs > m || m > INT32_MAX
        || nz > INT32_MAX || N > INT32_MAX || o_volt < -1 || o_volt >= n_state
        || i_cmd < 0 || i_cmd >= nz || i_held < -1 || i_held >= n_state
        || i_amp < -1 || i_amp >= nz || !(slew_step >= 0)
        || (slew_step > 0 && (i_held < 0 || i_amp <= i_noise))) {
        PyErr_SetString(PyExc_ValueError, "BatchCore: inconsistent sizes of the arrays and the layout");
        return -1;
    }
    if (check_loads(comp, ncomp, pool, N)) return -1;
    int ok = (obs_mode == OBS_ESTIMATE && o_obs + n_obs <= m)
             || (obs_mode == OBS_MEASUREMENT && n_obs == hist + 1)
             || (obs_mode == OBS_FULL && n_obs == n_x);
    if (!ok || n_obs < 1) {
        PyErr_SetString(PyExc_ValueError, "BatchCore: obs_mode (0, 1, 2) and n_obs do not fit");
        return -1;
    }
    dgemm_t *fn = NULL;
    if (cap != Py_None) {
        if (!PyCapsule_CheckExact(cap)) {
            PyErr_SetString(PyExc_ValueError, "BatchCore: dgemm must be a capsule "
                            "(scipy.linalg.cython_blas) or None");
            return -1;
        }
        fn = (dgemm_t *)PyCapsule_GetPointer(cap, PyCapsule_GetName(cap));
        if (fn == NULL) return -1;
    }
    PyObject *tmpl = PyDict_New();
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_req, k_clip, k_load, k_time, k_xr, k_term, k_ry,
                              k_rv};
    for (int j = 0; tmpl != NULL && j < N_INFO; j++)
        if (PyDict_SetItem(tmpl, keys[j], Py_None) < 0) Py_CLEAR(tmpl);
    if (tmpl == NULL) return -1;
    core_clear(self);
    PyObject *arrs[] = {GT, Z, OUT, k, noise, y_hist, comp, ncomp, pool, times};
    for (int j = 0; j < 10; j++) Py_INCREF(arrs[j]);
    self->GT = g; self->Z = (PyArrayObject *)Z; self->OUT = (PyArrayObject *)OUT;
    self->k = (PyArrayObject *)k; self->noise = (PyArrayObject *)noise;
    self->y_hist = (PyArrayObject *)y_hist; self->comp = (PyArrayObject *)comp;
    self->ncomp = (PyArrayObject *)ncomp; self->pool = (PyArrayObject *)pool;
    self->times = (PyArrayObject *)times;
    self->info_template = tmpl;
    self->dgemm = fn;
    self->N = N; self->m = m; self->nz = nz; self->s = s; self->steps = steps; self->hist = hist;
    self->K = PyArray_DIM((PyArrayObject *)comp, 1); self->P = PyArray_DIM((PyArrayObject *)pool, 1);
    self->per_env = per_env; self->obs_mode = obs_mode; self->block_rows = BLOCK_ROWS;
    self->n_state = n_state; self->i_volt = i_volt; self->i_loads = i_loads;
    self->i_noise = i_noise; self->o_ymeas = o_ymeas; self->o_y = o_y; self->o_xr = o_xr;
    self->o_obs = o_obs; self->n_x = n_x; self->n_xr = n_xr; self->n_obs = n_obs;
    self->o_volt = o_volt; self->i_cmd = i_cmd; self->i_held = i_held; self->i_amp = i_amp;
    self->slew_step = slew_step;
    self->dt = dt; self->eps = 1e-9 * dt; self->y_ref = y_ref; self->lam = lam;
    self->v_max = v_max; self->limit = limit; self->y_scale = y_scale;
    return 0;
gt_bad:
    PyErr_SetString(PyExc_ValueError, "BatchCore: GT must be G^T (nz, m) or per env (N, nz, m)");
    return -1;
}

static int ready(const BatchCore *self)
{
    if (self->Z == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "BatchCore was not initialized");
        return 0;
    }
    return 1;
}

/* --- methods ------------------------------------------------------------------------------- */

static PyObject *
core_set_loads(BatchCore *self, PyObject *args)
{
    PyObject *comp, *ncomp, *pool;
    if (!PyArg_ParseTuple(args, "OOO", &comp, &ncomp, &pool) || !ready(self)) return NULL;
    if (check_loads(comp, ncomp, pool, self->N)) return NULL;
    Py_INCREF(comp); Py_INCREF(ncomp); Py_INCREF(pool);
    Py_SETREF(self->comp, (PyArrayObject *)comp);
    Py_SETREF(self->ncomp, (PyArrayObject *)ncomp);
    Py_SETREF(self->pool, (PyArrayObject *)pool);
    self->K = PyArray_DIM(self->comp, 1);
    self->P = PyArray_DIM(self->pool, 1);
    Py_RETURN_NONE;
}

static PyObject *
core_step_one(BatchCore *self, PyObject *action)
{
    /* the common path only: anything else goes to the Python reference step */
    if (self->Z == NULL || self->N != 1 || !PyArray_CheckExact(action)) Py_RETURN_NONE;
    PyArrayObject *a = (PyArrayObject *)action;
    if (PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != 1 || !PyArray_ISNOTSWAPPED(a)
        || !PyArray_ISALIGNED(a))
        Py_RETURN_NONE;
    double requested;
    if (PyArray_TYPE(a) == NPY_FLOAT32) requested = *(float *)PyArray_DATA(a);
    else if (PyArray_TYPE(a) == NPY_DOUBLE) requested = *(double *)PyArray_DATA(a);
    else Py_RETURN_NONE;
    const npy_int64 k0 = *(npy_int64 *)PyArray_DATA(self->k);
    if (!isfinite(requested) || k0 < 0 || k0 >= self->steps) Py_RETURN_NONE;
    const double v = requested < -self->v_max ? -self->v_max
                     : (requested > self->v_max ? self->v_max : requested);
    advance(self, &v, NULL);
    double ry, rv, reward;
    const int code = outcome(self, 0, v, &ry, &rv, &reward);
    const long kk = (long)(k0 + 1);
    const double *o = PyArray_DATA(self->OUT);
    npy_intp n_obs = self->n_obs;
    PyObject *obs = PyArray_SimpleNew(1, &n_obs, NPY_FLOAT32);
    PyObject *xr = PyArray_SimpleNew(1, &self->n_xr, NPY_DOUBLE);
    PyObject *info = PyDict_Copy(self->info_template);
    if (obs == NULL || xr == NULL || info == NULL) {
        Py_XDECREF(obs); Py_XDECREF(xr); Py_XDECREF(info);
        return NULL;
    }
    observe(self, 0, PyArray_DATA((PyArrayObject *)obs));
    memcpy(PyArray_DATA((PyArrayObject *)xr), o + self->o_xr, (size_t)self->n_xr * sizeof(double));
    PyObject *why = code == END_NONFINITE ? s_nonfinite : (code == END_LIMIT ? s_limit : Py_None);
    Py_INCREF(why);
    PyObject *vals[N_INFO] = {PyFloat_FromDouble(o[self->o_y]),
                              PyFloat_FromDouble(self->o_volt >= 0 ? o[self->o_volt] : v),
                              PyFloat_FromDouble(requested), PyBool_FromLong(requested != v),
                              PyFloat_FromDouble(self->last_tip),
                              PyFloat_FromDouble((double)kk * self->dt), xr, why,
                              PyFloat_FromDouble(ry), PyFloat_FromDouble(rv)};
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_req, k_clip, k_load, k_time, k_xr, k_term, k_ry,
                              k_rv};
    int bad = 0;
    for (int j = 0; j < N_INFO; j++) {
        if (!bad && (vals[j] == NULL || PyDict_SetItem(info, keys[j], vals[j]) < 0)) bad = 1;
        Py_XDECREF(vals[j]);
    }
    PyObject *r = bad ? NULL : PyFloat_FromDouble(reward);
    if (r == NULL) {
        Py_DECREF(info); Py_DECREF(obs);
        return NULL;
    }
    PyObject *te = PyBool_FromLong(code != END_NONE), *tr = PyBool_FromLong(kk >= self->steps);
    PyObject *res = PyTuple_Pack(5, obs, r, te, tr, info);
    Py_DECREF(obs); Py_DECREF(r); Py_DECREF(te); Py_DECREF(tr); Py_DECREF(info);
    return res;
}

/* the voltages of a vector step's actions: N finite float32/float64 values of shape (N,)
   or (N, 1) -> requested and clipped; 0 where the Python path must check them */
static int read_actions(const BatchCore *self, PyObject *action, double *req, double *v)
{
    if (!PyArray_CheckExact(action)) return 0;
    PyArrayObject *a = (PyArrayObject *)action;
    const int nd = PyArray_NDIM(a), type = PyArray_TYPE(a);
    if (!((nd == 1 && PyArray_DIM(a, 0) == self->N)
          || (nd == 2 && PyArray_DIM(a, 0) == self->N && PyArray_DIM(a, 1) == 1))
        || !PyArray_ISNOTSWAPPED(a) || !PyArray_ISALIGNED(a)
        || (type != NPY_FLOAT32 && type != NPY_DOUBLE))
        return 0;
    const char *d = PyArray_DATA(a);
    const npy_intp stride = PyArray_STRIDE(a, 0);
    for (npy_intp i = 0; i < self->N; i++) {
        const double x = type == NPY_FLOAT32 ? (double)*(const float *)(d + i * stride)
                                             : *(const double *)(d + i * stride);
        if (!isfinite(x)) return 0;
        req[i] = x;
        v[i] = x < -self->v_max ? -self->v_max : (x > self->v_max ? self->v_max : x);
    }
    return 1;
}

static PyObject *
core_step(BatchCore *self, PyObject *action)
{
    /* step(actions) -> (obs, reward, terminated, truncated, info) of the vector env, info
       with the keys of acld_gym.envs.step.INFO_KEYS and their masks; or None where the Python
       path must check the actions (it then steps with their clipped values as float64) */
    if (!ready(self)) return NULL;
    npy_intp N = self->N, d_obs[2] = {N, self->n_obs}, d_xr[2] = {N, self->n_xr};
    enum { OBS, REW, TERM, TRUNC, Y, V, REQ, CLIP, TIP, TIME, XR, WHYA, RY, RV, ONES, PV, NA };
    const int types[NA] = {NPY_FLOAT32, NPY_DOUBLE, NPY_BOOL, NPY_BOOL, NPY_DOUBLE, NPY_DOUBLE,
                           NPY_DOUBLE, NPY_BOOL, NPY_DOUBLE, NPY_DOUBLE, NPY_DOUBLE, NPY_OBJECT,
                           NPY_DOUBLE, NPY_DOUBLE, NPY_BOOL, NPY_DOUBLE};
    PyObject *arr[NA] = {NULL};
    for (int j = 0; j < NA; j++) {
        arr[j] = j == OBS ? PyArray_SimpleNew(2, d_obs, types[j])
                 : (j == XR ? PyArray_SimpleNew(2, d_xr, types[j]) : PyArray_SimpleNew(1, &N, types[j]));
        if (arr[j] == NULL) goto fail;
    }
#define D(j) ((double *)PyArray_DATA((PyArrayObject *)arr[j]))
#define B(j) ((npy_bool *)PyArray_DATA((PyArrayObject *)arr[j]))
    if (!read_actions(self, action, D(REQ), D(V))) {
        for (int j = 0; j < NA; j++) Py_XDECREF(arr[j]);
        Py_RETURN_NONE;
    }
    npy_int8 *code = PyMem_Malloc((size_t)N);
    if (code == NULL) { PyErr_NoMemory(); goto fail; }
    Results r = {(float *)PyArray_DATA((PyArrayObject *)arr[OBS]), D(REW), D(RY), D(RV), D(Y),
                 D(TIP), D(XR), code, B(TRUNC), D(PV)};
    advance(self, D(V), &r);
    PyObject **why = PyArray_DATA((PyArrayObject *)arr[WHYA]);
    const npy_int64 *k = PyArray_DATA(self->k);
    for (npy_intp i = 0; i < N; i++) {
        B(TERM)[i] = code[i] != END_NONE;
        B(CLIP)[i] = D(REQ)[i] != D(V)[i];
        B(ONES)[i] = 1;
        D(TIME)[i] = (double)k[i] * self->dt;
        PyObject *w = code[i] == END_NONFINITE ? s_nonfinite : (code[i] == END_LIMIT ? s_limit : Py_None);
        Py_INCREF(w);
        why[i] = w;  /* the new object array holds NULLs */
    }
    PyMem_Free(code);
    PyObject *info = PyDict_New();
    if (info == NULL) goto fail;
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_req, k_clip, k_load, k_time, k_xr, k_term, k_ry,
                              k_rv};
    PyObject *mask_keys[N_INFO] = {m_tip, m_volt, m_req, m_clip, m_load, m_time, m_xr, m_term,
                                   m_ry, m_rv};
    const int vals[N_INFO] = {Y, PV, REQ, CLIP, TIP, TIME, XR, WHYA, RY, RV};
    for (int j = 0; j < N_INFO; j++) {
        if (PyDict_SetItem(info, keys[j], arr[vals[j]]) < 0
            || PyDict_SetItem(info, mask_keys[j], arr[ONES]) < 0) {
            Py_DECREF(info);
            goto fail;
        }
    }
    PyObject *res = PyTuple_Pack(5, arr[OBS], arr[REW], arr[TERM], arr[TRUNC], info);
    Py_DECREF(info);
    for (int j = 0; j < NA; j++) Py_DECREF(arr[j]);
    return res;
#undef D
#undef B
fail:
    for (int j = 0; j < NA; j++) Py_XDECREF(arr[j]);
    return NULL;
}

static PyObject *
core_names(BatchCore *self, PyObject *Py_UNUSED(ignored))
{
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_req, k_clip, k_load, k_time, k_xr, k_term, k_ry,
                              k_rv};
    PyObject *t = PyTuple_New(N_INFO);
    if (t == NULL) return NULL;
    for (int j = 0; j < N_INFO; j++) {
        Py_INCREF(keys[j]);
        PyTuple_SET_ITEM(t, j, keys[j]);
    }
    return t;
}

static PyObject *
core_tip_loads(BatchCore *self, PyObject *arg)
{
    /* tip_loads(rows): the tip load [N] of each env in rows at its current time k dt */
    if (!ready(self)) return NULL;
    PyArrayObject *rows = (PyArrayObject *)PyArray_FROMANY(arg, NPY_INTP, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (rows == NULL) return NULL;
    npy_intp n = PyArray_DIM(rows, 0);
    PyObject *out = PyArray_SimpleNew(1, &n, NPY_DOUBLE);
    if (out == NULL) { Py_DECREF(rows); return NULL; }
    const npy_intp *r = PyArray_DATA(rows);
    const npy_int64 *k = PyArray_DATA(self->k);
    double *d = PyArray_DATA((PyArrayObject *)out);
    for (npy_intp j = 0; j < n; j++) {
        if (r[j] < 0 || r[j] >= self->N) {
            Py_DECREF(rows); Py_DECREF(out);
            PyErr_SetString(PyExc_ValueError, "BatchCore.tip_loads: row out of range");
            return NULL;
        }
        d[j] = load_at(self, r[j], (double)k[r[j]] * self->dt);
    }
    Py_DECREF(rows);
    return out;
}

static PyObject *
core_product_seconds(BatchCore *self, PyObject *arg)
{
    /* Wall time of env 0's product G z in C, averaged over n products (for the benchmark's
       breakdown of a step into arithmetic and the rest); the state is left unchanged. */
    long n = PyLong_AsLong(arg);
    if (n == -1 && PyErr_Occurred()) return NULL;
    if (n < 1) {
        PyErr_SetString(PyExc_ValueError, "product_seconds: n must be a positive integer");
        return NULL;
    }
    if (!ready(self)) return NULL;
    double *buf = PyMem_Malloc((size_t)self->m * sizeof(double));
    if (buf == NULL) return PyErr_NoMemory();
    const double *z = PyArray_DATA(self->Z), *GT = PyArray_DATA(self->GT);
    struct timespec t0, t1;
    volatile double sink = 0.0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long i = 0; i < n; i++) {
        product(GT, z, buf, self->m, self->nz);
        sink += buf[i % self->m];
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    (void)sink;
    PyMem_Free(buf);
    return PyFloat_FromDouble(((t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec)) / n);
}

static PyMethodDef core_methods[] = {
    {"step_one", (PyCFunction)core_step_one, METH_O,
     "step_one(action) -> (obs, reward, terminated, truncated, info) of the single env, or "
     "None where the Python reference step must take over."},
    {"step", (PyCFunction)core_step, METH_O,
     "step(actions) -> (obs, reward, terminated, truncated, info) of the vector env, or None "
     "where the Python path must check the actions."},
    {"names", (PyCFunction)core_names, METH_NOARGS,
     "names() -> the info's keys in order (acld_gym.envs.step.INFO_KEYS mirrored)."},
    {"set_loads", (PyCFunction)core_set_loads, METH_VARARGS,
     "set_loads(comp, ncomp, pool): the encoded loads' new arrays (after they grew)."},
    {"tip_loads", (PyCFunction)core_tip_loads, METH_O,
     "tip_loads(rows) -> the tip load [N] of these envs at their current time."},
    {"product_seconds", (PyCFunction)core_product_seconds, METH_O,
     "product_seconds(n) -> mean wall time [s] of env 0's matrix-vector product alone."},
    {NULL}
};

static PyMemberDef core_members[] = {
    {"num_envs", T_PYSSIZET, offsetof(BatchCore, N), READONLY, "N, the batch size"},
    {"per_env", T_INT, offsetof(BatchCore, per_env), READONLY,
     "1 if each env has its own G (per-env products)"},
    {"block_rows", T_INT, offsetof(BatchCore, block_rows), 0,
     "rows per block of the step (0: the whole batch at once; benchmarks compare them)"},
    {NULL}
};

static PyTypeObject BatchCoreType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "acld_gym.envs._stepcore.BatchCore",
    .tp_basicsize = sizeof(BatchCore),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The batched step of ACLDBeam in C (see the module docstring).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)core_init,
    .tp_dealloc = (destructor)core_dealloc,
    .tp_methods = core_methods,
    .tp_members = core_members,
};

static struct PyModuleDef moduledef = {
    PyModuleDef_HEAD_INIT, "_stepcore", "The batched step of ACLDBeam in C.", -1,
    NULL, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC
PyInit__stepcore(void)
{
    import_array();
    if (PyType_Ready(&BatchCoreType) < 0) return NULL;
    const char *names[N_INFO] = {"tip_deflection", "voltage", "requested_voltage", "clipped",
                                 "tip_load", "time", "xr_true", "terminated_by",
                                 "reward_deflection", "reward_voltage"};
    PyObject **keys[N_INFO] = {&k_tip, &k_volt, &k_req, &k_clip, &k_load, &k_time, &k_xr,
                               &k_term, &k_ry, &k_rv};
    PyObject **masks[N_INFO] = {&m_tip, &m_volt, &m_req, &m_clip, &m_load, &m_time, &m_xr,
                                &m_term, &m_ry, &m_rv};
    for (int j = 0; j < N_INFO; j++) {
        if ((*keys[j] = PyUnicode_InternFromString(names[j])) == NULL) return NULL;
        if ((*masks[j] = PyUnicode_FromFormat("_%s", names[j])) == NULL) return NULL;
    }
    s_limit = PyUnicode_InternFromString("deflection_limit");
    s_nonfinite = PyUnicode_InternFromString("non_finite_state");
    if (!s_limit || !s_nonfinite) return NULL;
    PyObject *mod = PyModule_Create(&moduledef);
    if (mod == NULL) return NULL;
    Py_INCREF(&BatchCoreType);
    if (PyModule_AddObject(mod, "BatchCore", (PyObject *)&BatchCoreType) < 0) {
        Py_DECREF(&BatchCoreType);
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
