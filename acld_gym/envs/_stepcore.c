/*
 * acld_gym._stepcore: the compiled step of ACLDBeamEnv.
 *
 * ``StepCore.step(action)`` is ACLDBeamEnv.step's common path in C: one
 * matrix-vector product ``out = G z`` (plant, observer, measurement,
 * observation and info in one, see acld_gym.envs.step.output_matrix; the slots are
 * acld_gym.envs.step.StepLayout's, passed in as integers) plus the
 * bookkeeping (clipping, reward, limits, the 5-tuple and the info dict). It
 * returns None where the Python reference path must take over (an action that
 * is not a finite 1-element float32/float64 array, a step past the tabulated
 * episode, rendering); the Python path then validates, raises or steps. Both
 * paths share the state: the arrays belong to the env, the scalars (k, v,
 * y_meas, last) to this object.
 *
 * Why C: in CPython a Gymnasium step costs about 1 us of interpreter work
 * before any physics, and numpy adds ~0.7 us of call overhead to the product,
 * whose arithmetic takes ~0.5 us; in C the bookkeeping is cheaper than the
 * product (benchmarks/bench_env.py).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#include <math.h>
#include <string.h>
#include <time.h>

#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

enum { OBS_ESTIMATE = 0, OBS_MEASUREMENT = 1, OBS_FULL = 2 };

typedef struct {
    PyObject_HEAD
    PyArrayObject *G;      /* (m, nz) float64, C order: the step's fused matrix */
    PyArrayObject *z;      /* (nz,) float64: [x, xhat, y_meas, V, f0.., f1.., w'] */
    PyArrayObject *inputs; /* (max_steps, nz - i_in) float64: per-step [f0.., f1.., w'] */
    PyArrayObject *tipf;   /* (max_steps + 1,) float64: tip load at the period starts [N] */
    PyArrayObject *y_hist; /* (hist,) float64: last measurements [m] */
    PyArrayObject *last;   /* (m,) float64: G z of the last step (overwritten each step) */
    PyObject *info_template; /* the info dict's 7 keys, copied per step (no resizing) */
    double *Gt;            /* G transposed (nz, m), so the product runs down contiguous columns */
    npy_intp m, nz, n_x, n_xr, n_obs, n_in, hist;
    /* the layout (acld_gym.envs.step.StepLayout): z's updated state and its voltage and
       inputs slots; G z's measurement, deflection, x_r and estimate-observation slots */
    npy_intp n_state, i_volt, i_in, o_ymeas, o_y, o_xr, o_obs;
    long k, max_steps;
    int obs_mode, active;
    double v, y_meas, dt, y_ref, lam, v_max, limit, y_scale;
} StepCore;

static PyObject *k_tip, *k_volt, *k_load, *k_time, *k_xr, *k_clip, *k_req, *k_term;
static PyObject *s_limit, *s_nonfinite;  /* values of info["terminated_by"] */
#define N_INFO 8

/* out = G z, as a sum of G's columns: the inner loop is contiguous and
   vectorizes without reassociating a reduction. Columns with z_j = 0 (the
   load samples between pulses) are skipped. */
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

static int
check_array(PyObject *a, const char *name, int ndim, npy_intp cols)
{
    if (!PyArray_Check(a) || PyArray_TYPE((PyArrayObject *)a) != NPY_DOUBLE
        || !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)a)
        || !PyArray_ISNOTSWAPPED((PyArrayObject *)a) || !PyArray_ISALIGNED((PyArrayObject *)a)
        || !PyArray_ISWRITEABLE((PyArrayObject *)a)
        || PyArray_NDIM((PyArrayObject *)a) != ndim) {
        PyErr_Format(PyExc_ValueError, "StepCore: %s must be a writeable, aligned, "
                     "C-contiguous native float64 array with %d dimension(s)", name, ndim);
        return -1;
    }
    npy_intp *s = PyArray_DIMS((PyArrayObject *)a);
    if (ndim == 2 && cols >= 0 && s[1] != cols) {
        PyErr_Format(PyExc_ValueError, "StepCore: %s has the wrong shape", name);
        return -1;
    }
    return 0;
}

static void
core_clear_refs(StepCore *self)
{
    Py_CLEAR(self->G);
    Py_CLEAR(self->z);
    Py_CLEAR(self->inputs);
    Py_CLEAR(self->tipf);
    Py_CLEAR(self->y_hist);
    Py_CLEAR(self->last);
    Py_CLEAR(self->info_template);
    PyMem_Free(self->Gt);
    self->Gt = NULL;
}

static void
core_dealloc(StepCore *self)
{
    core_clear_refs(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int
core_init(StepCore *self, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"G", "z", "inputs", "tipf", "y_hist", "n_state", "i_voltage",
                             "i_inputs", "o_ymeas", "o_y", "o_xr", "o_obs", "n_x", "n_xr",
                             "obs_mode", "n_obs", "dt", "y_ref", "lam", "v_max", "limit",
                             "y_scale", NULL};
    PyObject *G, *z, *inputs, *tipf, *y_hist;
    Py_ssize_t n_state, i_volt, i_in, o_ymeas, o_y, o_xr, o_obs, n_x, n_xr, n_obs;
    int obs_mode;
    double dt, y_ref, lam, v_max, limit, y_scale;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "$OOOOOnnnnnnnnnindddddd", kwlist, &G, &z,
                                     &inputs, &tipf, &y_hist, &n_state, &i_volt, &i_in,
                                     &o_ymeas, &o_y, &o_xr, &o_obs, &n_x, &n_xr, &obs_mode,
                                     &n_obs, &dt, &y_ref, &lam, &v_max, &limit, &y_scale))
        return -1;
    if (check_array(G, "G", 2, -1) || check_array(z, "z", 1, -1))
        return -1;
    npy_intp m = PyArray_DIM((PyArrayObject *)G, 0), nz = PyArray_DIM((PyArrayObject *)G, 1);
    npy_intp n_in = nz - i_in;
    /* every slot inside its vector, the updated state before the voltage and inputs */
    if (PyArray_DIM((PyArrayObject *)z, 0) != nz || n_state < 1 || n_x < 1 || n_x > n_state
        || i_volt < n_state || i_volt >= nz || i_in <= i_volt || n_in < 1 || n_xr < 0
        || n_state > m || o_ymeas < 0 || o_ymeas >= m || o_y < 0 || o_y >= m
        || o_xr < 0 || o_xr + n_xr > m || o_obs < 0 || o_obs > m) {
        PyErr_SetString(PyExc_ValueError, "StepCore: inconsistent sizes of G, z and the layout");
        return -1;
    }
    if (check_array(inputs, "inputs", 2, n_in) || check_array(tipf, "tipf", 1, -1)
        || check_array(y_hist, "y_hist", 1, -1))
        return -1;
    npy_intp max_steps = PyArray_DIM((PyArrayObject *)inputs, 0);
    if (PyArray_DIM((PyArrayObject *)tipf, 0) != max_steps + 1) {
        PyErr_SetString(PyExc_ValueError, "StepCore: tipf must hold max_steps + 1 values");
        return -1;
    }
    npy_intp hist = PyArray_DIM((PyArrayObject *)y_hist, 0);
    /* estimate: the last n_obs outputs, after [x', xhat', y_meas', y', x_r'] */
    int ok = (obs_mode == OBS_ESTIMATE && o_obs + n_obs <= m)
             || (obs_mode == OBS_MEASUREMENT && n_obs == hist + 1)
             || (obs_mode == OBS_FULL && n_obs == n_x);
    if (!ok || n_obs < 1 || hist < 1) {
        PyErr_SetString(PyExc_ValueError, "StepCore: obs_mode (0, 1, 2) and n_obs do not fit");
        return -1;
    }
    double *Gt = PyMem_Malloc((size_t)(m * nz) * sizeof(double));
    if (Gt == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    const double *g = PyArray_DATA((PyArrayObject *)G);
    for (npy_intp i = 0; i < m; i++)
        for (npy_intp j = 0; j < nz; j++) Gt[j * m + i] = g[i * nz + j];
    PyObject *last = PyArray_ZEROS(1, &m, NPY_DOUBLE, 0);
    PyObject *tmpl = PyDict_New();
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_load, k_time, k_xr, k_clip, k_req, k_term};
    for (int i = 0; tmpl != NULL && i < N_INFO; i++) {
        if (PyDict_SetItem(tmpl, keys[i], Py_None) < 0) Py_CLEAR(tmpl);
    }
    if (last == NULL || tmpl == NULL) {
        Py_XDECREF(last);
        Py_XDECREF(tmpl);
        PyMem_Free(Gt);
        return -1;
    }
    core_clear_refs(self);
    Py_INCREF(G); Py_INCREF(z); Py_INCREF(inputs); Py_INCREF(tipf); Py_INCREF(y_hist);
    self->G = (PyArrayObject *)G;
    self->z = (PyArrayObject *)z;
    self->inputs = (PyArrayObject *)inputs;
    self->tipf = (PyArrayObject *)tipf;
    self->y_hist = (PyArrayObject *)y_hist;
    self->last = (PyArrayObject *)last;
    self->info_template = tmpl;
    self->Gt = Gt;
    self->m = m; self->nz = nz; self->n_x = n_x; self->n_xr = n_xr;
    self->n_state = n_state; self->i_volt = i_volt; self->i_in = i_in;
    self->o_ymeas = o_ymeas; self->o_y = o_y; self->o_xr = o_xr; self->o_obs = o_obs;
    self->n_obs = n_obs;
    self->n_in = n_in; self->hist = hist; self->max_steps = (long)max_steps;
    self->obs_mode = obs_mode; self->k = 0; self->v = 0.0; self->y_meas = 0.0;
    self->dt = dt; self->y_ref = y_ref; self->lam = lam; self->v_max = v_max;
    self->limit = limit; self->y_scale = y_scale; self->active = 1;
    return 0;
}

/* A new float32 array of n values src[0..n) * scale (the observation). */
static PyObject *
float32_copy(const double *src, npy_intp n, double scale)
{
    PyObject *a = PyArray_SimpleNew(1, &n, NPY_FLOAT32);
    if (a == NULL) return NULL;
    float *d = PyArray_DATA((PyArrayObject *)a);
    for (npy_intp i = 0; i < n; i++) d[i] = (float)(src[i] * scale);
    return a;
}

static PyObject *
core_step(StepCore *self, PyObject *action)
{
    /* The common path only: anything else goes to the Python reference step. */
    if (!self->active || self->Gt == NULL || self->k < 0 || self->k >= self->max_steps
        || !PyArray_CheckExact(action))
        Py_RETURN_NONE;
    PyArrayObject *a = (PyArrayObject *)action;
    if (PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != 1 || !PyArray_ISNOTSWAPPED(a)
        || !PyArray_ISALIGNED(a))
        Py_RETURN_NONE;
    double requested;
    if (PyArray_TYPE(a) == NPY_FLOAT32) requested = *(float *)PyArray_DATA(a);
    else if (PyArray_TYPE(a) == NPY_DOUBLE) requested = *(double *)PyArray_DATA(a);
    else Py_RETURN_NONE;
    if (!isfinite(requested)) Py_RETURN_NONE;  /* the Python path raises, state untouched */

    const double v = requested < -self->v_max ? -self->v_max
                     : (requested > self->v_max ? self->v_max : requested);
    const npy_intp m = self->m;
    double *z = PyArray_DATA(self->z);
    double *o = PyArray_DATA(self->last);
    PyObject *xr = PyArray_SimpleNew(1, &self->n_xr, NPY_DOUBLE);  /* info's own copy */
    if (xr == NULL) return NULL;

    /* 1.-3. plant (ZOH), observer and the new measurement: one product */
    z[self->i_volt] = v;
    memcpy(z + self->i_in, (double *)PyArray_DATA(self->inputs) + self->k * self->n_in,
           (size_t)self->n_in * sizeof(double));
    product(self->Gt, z, o, m, self->nz);
    memcpy(z, o, (size_t)self->n_state * sizeof(double));
    const long k = ++self->k;
    self->v = v;
    self->y_meas = o[self->o_ymeas];
    const double y = o[self->o_y];

    /* 4. reward on the true deflection, 5. limits: beyond the deflection limit, or any
       non-finite number in the new state (never passed off as a normal step) */
    const double ry = y / self->y_ref, rv = v / self->v_max;
    const double reward = -(ry * ry) - self->lam * (rv * rv);
    int finite = isfinite(reward);
    for (npy_intp i = 0; finite && i < m; i++) finite = isfinite(o[i]);
    const int over = !(fabs(y) <= self->limit);
    const int terminated = over || !finite, truncated = k >= self->max_steps;

    PyObject *obs;
    if (self->obs_mode == OBS_ESTIMATE) {
        obs = float32_copy(o + self->o_obs, self->n_obs, 1.0);
    } else if (self->obs_mode == OBS_FULL) {
        obs = float32_copy(z, self->n_x, 1.0);
    } else {
        double *h = PyArray_DATA(self->y_hist);
        memmove(h, h + 1, (size_t)(self->hist - 1) * sizeof(double));
        h[self->hist - 1] = self->y_meas;
        obs = PyArray_SimpleNew(1, &self->n_obs, NPY_FLOAT32);
        if (obs != NULL) {
            float *d = PyArray_DATA((PyArrayObject *)obs);
            for (npy_intp i = 0; i < self->hist; i++) d[i] = (float)(h[i] / self->y_scale);
            d[self->hist] = (float)(v / self->v_max);
        }
    }
    if (obs == NULL) {
        Py_DECREF(xr);
        return NULL;
    }
    memcpy(PyArray_DATA((PyArrayObject *)xr), o + self->o_xr, (size_t)self->n_xr * sizeof(double));
    const double tip_load = ((double *)PyArray_DATA(self->tipf))[k];
    PyObject *info = PyDict_Copy(self->info_template);
    PyObject *why = !finite ? s_nonfinite : (over ? s_limit : Py_None);
    Py_INCREF(why);
    PyObject *vals[N_INFO] = {PyFloat_FromDouble(y), PyFloat_FromDouble(v),
                              PyFloat_FromDouble(tip_load),
                              PyFloat_FromDouble((double)k * self->dt), xr,
                              PyBool_FromLong(requested != v), PyFloat_FromDouble(requested),
                              why};
    PyObject *keys[N_INFO] = {k_tip, k_volt, k_load, k_time, k_xr, k_clip, k_req, k_term};
    int bad = info == NULL;
    for (int i = 0; i < N_INFO; i++) {
        if (!bad && (vals[i] == NULL || PyDict_SetItem(info, keys[i], vals[i]) < 0)) bad = 1;
        Py_XDECREF(vals[i]);
    }
    if (bad) {
        Py_XDECREF(info);
        Py_DECREF(obs);
        return NULL;
    }
    PyObject *r = PyFloat_FromDouble(reward);
    if (r == NULL) {
        Py_DECREF(info);
        Py_DECREF(obs);
        return NULL;
    }
    PyObject *te = PyBool_FromLong(terminated), *tr = PyBool_FromLong(truncated);
    PyObject *res = PyTuple_Pack(5, obs, r, te, tr, info);
    Py_DECREF(obs); Py_DECREF(r); Py_DECREF(te); Py_DECREF(tr); Py_DECREF(info);
    return res;
}

static PyObject *
core_product_seconds(StepCore *self, PyObject *arg)
{
    /* Wall time of one ``G z`` in C, averaged over n products (for the benchmark's
       breakdown of a step into arithmetic and the rest); z is left unchanged. */
    long n = PyLong_AsLong(arg);
    if (n == -1 && PyErr_Occurred()) return NULL;
    if (n < 1) {
        PyErr_SetString(PyExc_ValueError, "product_seconds: n must be a positive integer");
        return NULL;
    }
    if (self->Gt == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "product_seconds: StepCore was not initialized");
        return NULL;
    }
    double *buf = PyMem_Malloc((size_t)self->m * sizeof(double));
    if (buf == NULL) return PyErr_NoMemory();
    const double *z = PyArray_DATA(self->z);
    struct timespec t0, t1;
    volatile double sink = 0.0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long i = 0; i < n; i++) {
        product(self->Gt, z, buf, self->m, self->nz);
        sink += buf[i % self->m];
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    (void)sink;
    PyMem_Free(buf);
    return PyFloat_FromDouble(((t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec)) / n);
}

static PyMethodDef core_methods[] = {
    {"step", (PyCFunction)core_step, METH_O,
     "step(action) -> (obs, reward, terminated, truncated, info), or None where the Python "
     "reference step must take over."},
    {"product_seconds", (PyCFunction)core_product_seconds, METH_O,
     "product_seconds(n) -> mean wall time [s] of the step's matrix-vector product alone."},
    {NULL}
};

static PyMemberDef core_members[] = {
    {"k", T_LONG, offsetof(StepCore, k), 0, "steps taken in the episode"},
    {"v", T_DOUBLE, offsetof(StepCore, v), 0, "applied voltage of the last step [V]"},
    {"y_meas", T_DOUBLE, offsetof(StepCore, y_meas), 0, "last tip measurement [m]"},
    {"last", T_OBJECT_EX, offsetof(StepCore, last), READONLY,
     "G z of the last step (one buffer, overwritten by each step)"},
    {"active", T_INT, offsetof(StepCore, active), 0,
     "0 sends every step to the Python path (rendering)"},
    {NULL}
};

static PyTypeObject StepCoreType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "acld_gym._stepcore.StepCore",
    .tp_basicsize = sizeof(StepCore),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The compiled common path of ACLDBeamEnv.step (see the module docstring).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)core_init,
    .tp_dealloc = (destructor)core_dealloc,
    .tp_methods = core_methods,
    .tp_members = core_members,
};

static struct PyModuleDef moduledef = {
    PyModuleDef_HEAD_INIT, "_stepcore",
    "The compiled common path of ACLDBeamEnv.step.", -1, NULL, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC
PyInit__stepcore(void)
{
    import_array();
    if (PyType_Ready(&StepCoreType) < 0) return NULL;
    k_tip = PyUnicode_InternFromString("tip_deflection");
    k_volt = PyUnicode_InternFromString("voltage");
    k_load = PyUnicode_InternFromString("tip_load");
    k_time = PyUnicode_InternFromString("time");
    k_xr = PyUnicode_InternFromString("xr_true");
    k_clip = PyUnicode_InternFromString("clipped");
    k_req = PyUnicode_InternFromString("requested_voltage");
    k_term = PyUnicode_InternFromString("terminated_by");
    s_limit = PyUnicode_InternFromString("deflection_limit");
    s_nonfinite = PyUnicode_InternFromString("non_finite_state");
    if (!k_tip || !k_volt || !k_load || !k_time || !k_xr || !k_clip || !k_req || !k_term
        || !s_limit || !s_nonfinite)
        return NULL;
    PyObject *mod = PyModule_Create(&moduledef);
    if (mod == NULL) return NULL;
    Py_INCREF(&StepCoreType);
    if (PyModule_AddObject(mod, "StepCore", (PyObject *)&StepCoreType) < 0) {
        Py_DECREF(&StepCoreType);
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
