/* Berg's smooth friction element (fmu_src/berg.py), operation by operation as the
 * Python element: F = Fxs + kf d A / (A + kf |d|) from the last reversal (xs, Fxs),
 * A = Fm - s Fxs. State: (F, uc, xs, Fxs, s). */
#include "mount_law.h"

#include <math.h>

static int berg_step(double u, double v, const double *w, const ml_axis_params *p,
                     double fs, double dt, double *w_new, ml_friction_step *out,
                     char *msg, size_t size)
{
    double kf = p->kf, f0 = w[0], uc = w[1], xs = w[2], fxs = w[3], s0 = w[4];
    double fm = fs, du = u - uc, s, fr, a, t0, t1, h, den, f1, work, diss;
    (void)v;
    (void)dt;
    (void)msg;
    (void)size;
    if (fm <= 0.0) {  /* lost contact: no force, the stored energy is released */
        w_new[0] = out->force = out->tangent = 0.0;
        w_new[1] = w_new[2] = u;
        w_new[3] = w_new[4] = 0.0;
        out->slipping = du != 0.0;
        out->dissipated = f0 * f0 / (2.0 * kf);
        return 0;
    }
    if (du == 0.0) {
        int i;
        for (i = 0; i < 5; ++i)
            w_new[i] = w[i];
        out->force = f0;
        out->tangent = kf;
        out->slipping = 0;
        out->dissipated = 0.0;
        return 0;
    }
    s = du > 0.0 ? 1.0 : -1.0;
    if (s != s0) {  /* a reversal (or the first motion): the reference moves here */
        xs = uc;
        fxs = f0;
    }
    fr = (-fm <= fxs && fxs <= fm) ? fxs : (fxs > fm ? fm : -fm);
    a = fm - s * fr;
    t0 = kf * s * (uc - xs);
    t1 = kf * s * (u - xs);
    h = kf * fabs(du);
    den = a + t1;
    f1 = fr + s * a * t1 / den;
    work = (s * fr + a) * h;
    if (a > 0.0)
        work -= a * a * log1p(h / (a + t0));
    diss = work / kf - (f1 * f1 - f0 * f0) / (2.0 * kf);
    w_new[0] = out->force = f1;
    w_new[1] = u;
    w_new[2] = xs;
    w_new[3] = fxs;
    w_new[4] = s;
    out->tangent = kf * a * a / (den * den);
    out->slipping = 1;
    out->dissipated = diss > 0.0 ? diss : 0.0;
    return 0;
}

static int berg_state_size(const ml_axis_params *p)
{
    (void)p;
    return 5;
}

static void berg_start(const ml_axis_params *p, double w, double *state)
{
    (void)p;
    state[0] = 0.0;
    state[1] = w;
    state[2] = w;
    state[3] = 0.0;
    state[4] = 0.0;
}

static double berg_position(const double *state, int n)
{
    (void)n;
    return state[1];
}

ML_ELEMENT_DEF const ml_element ml_berg = {
    "berg", 1, berg_state_size, berg_start, berg_position, berg_step,
    ml_contact_normal_forces, NULL, NULL};
