/* Maxwell branches of a mount axis: see maxwell.h. */
#include <math.h>
#include <stdio.h>

#include "hydraulic.h"
#include "maxwell.h"

#define MAXWELL_PAIR(p, i, k, c) do { \
    k = (i) == 0 ? (p)->maxwell_k1 : (i) == 1 ? (p)->maxwell_k2 : (p)->maxwell_k3; \
    c = (i) == 0 ? (p)->maxwell_c1 : (i) == 1 ? (p)->maxwell_c2 : (p)->maxwell_c3; \
} while (0)

int ml_has_maxwell(const ml_axis_params *p)
{
    int i;
    double k, c;
    for (i = 0; i < ML_MAX_MAXWELL; ++i) {
        MAXWELL_PAIR(p, i, k, c);
        if (k > 0.0 && c > 0.0)
            return 1;
    }
    return 0;
}

void ml_maxwell_step(double k, double c, double uc, double w0, double u, double dt,
                     double *f, double *w, double *kt)
{
    double x, g, e, ratio;
    if (k == 0.0 || c == 0.0) {
        *f = 0.0;
        *w = u;
        *kt = 0.0;
        return;
    }
    if (dt <= 0.0) {
        *f = k * (u - w0);
        *w = w0;
        *kt = k;
        return;
    }
    x = dt * k / c;
    g = -expm1(-x);   /* 1 - e */
    e = 1.0 - g;
    ratio = g / x;
    *f = k * ((uc - w0) * e + (u - uc) * ratio);
    *w = u - *f / k;
    *kt = k * ratio;
}

void ml_maxwell_forces(const ml_axis_params *p, double uc, const double *strokes,
                       double u, double dt, double *strokes_new, double *f, double *kt)
{
    int i;
    double k, c, fi, ki, f_m = 0.0, k_m = 0.0;
    for (i = 0; i < ML_MAX_MAXWELL; ++i) {
        MAXWELL_PAIR(p, i, k, c);
        ml_maxwell_step(k, c, uc, strokes[i], u, dt, &fi, &strokes_new[i], &ki);
        f_m += fi;
        k_m += ki;
    }
    *f = f_m;
    *kt = k_m;
}

int ml_inner_size(const ml_axis_params *p, int n)
{
    if (ml_has_branches(p) && n == ml_state_size(p))   /* and the fluid's states */
        return n - 1 - ML_MAX_MAXWELL - (ml_has_hydraulic(p) ? ML_FLUID_STATE : 0);
    return n;
}

double ml_state_position_p(const ml_axis_params *p, const double *state, int n, int tag)
{
    n = ml_inner_size(p, n);
    if (n > ML_MAX_SLIDERS)   /* a state of other parameters: its sliders' part */
        n = ML_MAX_SLIDERS;
    return ml_state_position(state, n, tag);
}

int ml_maxwell_problems(const ml_axis_params *p, const char *prefix, char *buf,
                        size_t size, int count)
{
    static const char *const names[2 * ML_MAX_MAXWELL] = {
        "maxwell_k1", "maxwell_c1", "maxwell_k2", "maxwell_c2", "maxwell_k3",
        "maxwell_c3"};
    double values[2 * ML_MAX_MAXWELL];
    char text[256], val[40];
    int i, added = 0;
    values[0] = p->maxwell_k1;
    values[1] = p->maxwell_c1;
    values[2] = p->maxwell_k2;
    values[3] = p->maxwell_c2;
    values[4] = p->maxwell_k3;
    values[5] = p->maxwell_c3;
    for (i = 0; i < 2 * ML_MAX_MAXWELL; ++i) {
        if (isfinite(values[i]) && values[i] >= 0.0)
            continue;
        ml_repr_double(values[i], val, sizeof val);
        snprintf(text, sizeof text, "`%s%s` must be finite and >= 0 (a Maxwell "
                 "branch; 0: absent), got %s", prefix, names[i], val);
        ml_append_problem(buf, size, &count, text);
        ++added;
    }
    return added;
}
