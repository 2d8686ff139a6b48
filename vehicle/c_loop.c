/* The stepping loop of vehicle.backends.FMUBackend.run in C (vehicle/c_loop.py).
 *
 * Per step k of [k0, k1): for every mount e, one set of its inputs (from row k of
 * the row buffer), one get of its outputs (into row k), one doStep(t_k, h); then
 * the linear update rec[k+1, :n_next] = W @ rec[k, o_x:] through the same BLAS
 * dgemv NumPy's W.dot calls (the pointer is handed in from Python and checked bit
 * for bit against W.dot before use), so the results equal the Python loop's.
 * FMI 2.0 (fmi2SetReal / fmi2GetReal / fmi2DoStep) or FMI 3.0 (fmi3SetFloat64 /
 * fmi3GetFloat64 / fmi3DoStep). No allocation, no callback into Python.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

typedef int (*fmi2_rw)(void *, const unsigned int *, size_t, double *);
typedef int (*fmi2_step)(void *, double, double, int);
typedef int (*fmi3_rw)(void *, const unsigned int *, size_t, double *, size_t);
typedef int (*fmi3_step)(void *, double, double, bool, bool *, bool *, bool *,
                         double *);
/* cblas_dgemv of an ILP64 OpenBLAS (64-bit integers) */
typedef void (*dgemv64)(int, int, int64_t, int64_t, double, const double *, int64_t,
                        const double *, int64_t, double, double *, int64_t);

enum { ROW_MAJOR = 101, NO_TRANS = 111 };

/* One mount: its instance, functions and the references of its inputs/outputs. */
typedef struct {
    void *component;
    void *set, *get, *step;
    const unsigned int *vin, *vout;
    int64_t nin, nout, uv_off, out_off;
} dm_mount;

/* Where the loop stopped on a failure: the step, the mount, which call
 * (1 set, 2 get, 3 step) and its status. */
typedef struct {
    int64_t k, e, which, status;
} dm_fail;

int64_t dm_run(int fmi, const dm_mount *mounts, int64_t n_mounts, double *rec,
               int64_t width, int64_t o_x, int64_t n_next, int64_t n_cols,
               const double *W, void *gemv, const double *times, double h,
               int64_t k0, int64_t k1, dm_fail *fail)
{
    dgemv64 dgemv = (dgemv64)gemv;
    bool flags[3];
    double last = 0.0;
    for (int64_t k = k0; k < k1; ++k) {
        double *row = rec + k * width;
        double t = times[k - k0];
        for (int64_t e = 0; e < n_mounts; ++e) {
            const dm_mount *m = mounts + e;
            int st;
            double *in = row + m->uv_off, *out = row + m->out_off;
            if (fmi == 2)
                st = ((fmi2_rw)m->set)(m->component, m->vin, (size_t)m->nin, in);
            else
                st = ((fmi3_rw)m->set)(m->component, m->vin, (size_t)m->nin, in,
                                       (size_t)m->nin);
            if (st > 1) { fail->which = 1; goto failed; }
            if (fmi == 2)
                st = ((fmi2_rw)m->get)(m->component, m->vout, (size_t)m->nout, out);
            else
                st = ((fmi3_rw)m->get)(m->component, m->vout, (size_t)m->nout, out,
                                       (size_t)m->nout);
            if (st > 1) { fail->which = 2; goto failed; }
            if (fmi == 2)
                st = ((fmi2_step)m->step)(m->component, t, h, 1);
            else
                st = ((fmi3_step)m->step)(m->component, t, h, true, flags,
                                          flags + 1, flags + 2, &last);
            if (st > 1) { fail->which = 3; goto failed; }
            continue;
        failed:
            fail->k = k;
            fail->e = e;
            fail->status = st;
            return k - k0;
        }
        dgemv(ROW_MAJOR, NO_TRANS, n_next, n_cols, 1.0, W, n_cols, row + o_x, 1,
              0.0, rec + (k + 1) * width, 1);
    }
    return k1 - k0;
}
