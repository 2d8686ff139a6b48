/* The Dahl friction element (fmu_src/dahl.py), operation by operation as the Python
 * element: F = s Fc - (s Fc - F0) exp(-kf |du| / Fc) for an increment du, s its sign.
 * State: (F, uc). */
#include "mount_law.h"

#include <math.h>

static int dahl_step(double u, double v, const double *w, const ml_axis_params *p,
                     double fs, double dt, double *w_new, ml_friction_step *out,
                     char *msg, size_t size)
{
    double f0 = w[0], du = u - w[1], fc = fs, s, sfc, f1, work, diss;
    (void)v;
    (void)dt;
    (void)msg;
    (void)size;
    w_new[1] = u;
    if (fc <= 0.0) {  /* lost contact: no force, the stored energy is released */
        w_new[0] = out->force = out->tangent = 0.0;
        out->slipping = du != 0.0;
        out->dissipated = f0 * f0 / (2.0 * p->kf);
        return 0;
    }
    if (du == 0.0) {
        w_new[0] = out->force = f0;
        out->tangent = p->kf;
        out->slipping = 0;
        out->dissipated = 0.0;
        return 0;
    }
    s = du > 0.0 ? 1.0 : -1.0;
    sfc = s * fc;
    f1 = sfc - (sfc - f0) * exp(-p->kf * fabs(du) / fc);
    work = fc * fabs(du) - s * (fc / p->kf) * (f1 - f0);
    diss = work - (f1 * f1 - f0 * f0) / (2.0 * p->kf);
    w_new[0] = out->force = f1;
    out->tangent = p->kf * (1.0 - s * f1 / fc);
    out->slipping = 1;
    out->dissipated = diss > 0.0 ? diss : 0.0;
    return 0;
}

static int dahl_state_size(const ml_axis_params *p)
{
    (void)p;
    return 2;
}

static void dahl_start(const ml_axis_params *p, double w, double *state)
{
    (void)p;
    state[0] = 0.0;
    state[1] = w;
}

static double dahl_position(const double *state, int n)
{
    (void)n;
    return state[1];
}

ML_ELEMENT_DEF const ml_element ml_dahl = {
    "dahl", 1, dahl_state_size, dahl_start, dahl_position, dahl_step,
    ml_contact_normal_forces, NULL, NULL};
