/* The LuGre friction element (fmu_src/lugre.py), operation by operation as the Python
 * element: the bristle z over an increment at the constant rate (u - uc) / dt by the
 * exponential integrator, the force sigma0 z + sigma1 dz/dt + sigma2 v at the input
 * rate v (sigma0 = kf). State: (z, uc). */
#include "mount_law.h"

#include <math.h>
#include <stdio.h>

#include "messages.h"

/* lugre._stribeck: g(v) into *g, dg/dv into *gp (dfs = Fs - Fc) */
static void stribeck(double v, double fc, double dfs, double vs, double *g, double *gp)
{
    double x = v / vs, e = exp(-(x * x));
    if (e == 0.0) {
        *g = fc;
        *gp = 0.0;
        return;
    }
    *g = fc + dfs * e;
    *gp = dfs * e * (-2.0 * x / vs);
}

/* lugre._bristle: z after the increment into *z1, dz/du into *dz; returns the
 * bristle's dissipated energy */
static double bristle(double z0, double du, double dt, const ml_axis_params *p,
                      double fc, double dfs, double *z1, double *dz)
{
    double s0 = p->kf, g, gu, gr, s, q, zss, e, de, work;
    if (du == 0.0) {
        *z1 = z0;
        *dz = 1.0;
        return 0.0;
    }
    if (dt > 0.0) {
        stribeck(du / dt, fc, dfs, p->v_stribeck, &g, &gr);
        gu = gr / dt;
    } else {  /* an instantaneous jump: the Coulomb level */
        g = fc;
        gu = 0.0;
    }
    s = du > 0.0 ? 1.0 : -1.0;
    q = fabs(du);
    zss = s * g / s0;
    e = exp(-s0 * q / g);
    *z1 = zss + (z0 - zss) * e;
    de = e * (s0 * q * gu / (g * g) - s0 * s / g);
    *dz = s * gu / s0 * (1.0 - e) + (z0 - zss) * de;
    work = s * (s0 * zss * q + (z0 - zss) * g * (1.0 - e));
    return work - s0 * (*z1 * *z1 - z0 * z0) / 2.0;
}

static int lugre_step(double u, double v, const double *w, const ml_axis_params *p,
                      double fs, double dt, double *w_new, ml_friction_step *out,
                      char *msg, size_t size)
{
    double kf = p->kf, sg1 = p->sigma1, sg2 = p->sigma2;
    double z0 = w[0], du = u - w[1], fc = fs, dfs, z1, dz, diss, gv, gvp, av, zdot;
    (void)msg;
    (void)size;
    w_new[1] = u;
    if (fc <= 0.0) {  /* lost contact: no force, the bristle energy is released */
        w_new[0] = out->force = out->tangent = 0.0;
        out->slipping = du != 0.0;
        out->dissipated = kf * z0 * z0 / 2.0;
        return 0;
    }
    dfs = p->stribeck_ratio * fc - fc;
    diss = bristle(z0, du, dt, p, fc, dfs, &z1, &dz);
    stribeck(v, fc, dfs, p->v_stribeck, &gv, &gvp);
    av = fabs(v);
    zdot = v - kf * av * z1 / gv;
    w_new[0] = z1;
    out->force = kf * z1 + sg1 * zdot + sg2 * v;
    out->tangent = (kf - sg1 * kf * av / gv) * dz;
    diss += (sg1 * zdot + sg2 * v) * v * dt;
    out->slipping = du != 0.0;
    out->dissipated = diss > 0.0 ? diss : 0.0;
    return 0;
}

static int lugre_state_size(const ml_axis_params *p)
{
    (void)p;
    return 2;
}

static void lugre_start(const ml_axis_params *p, double w, double *state)
{
    (void)p;
    state[0] = 0.0;
    state[1] = w;
}

static double lugre_position(const double *state, int n)
{
    (void)n;
    return state[1];
}

/* the rules of the LuGre element's own fields (lugre._FIELDS), in their order */
static int lugre_problems(const ml_axis_params *p, const char *prefix, char *buf,
                          size_t size, int count)
{
    struct { const char *name; double v; int positive; } r[4];
    char text[256], val[40];
    int i, n = count;
    r[0].name = "sigma1"; r[0].v = p->sigma1; r[0].positive = 0;
    r[1].name = "sigma2"; r[1].v = p->sigma2; r[1].positive = 0;
    r[2].name = "stribeck_ratio"; r[2].v = p->stribeck_ratio; r[2].positive = 1;
    r[3].name = "v_stribeck"; r[3].v = p->v_stribeck; r[3].positive = 1;
    for (i = 0; i < 4; ++i) {
        if (isfinite(r[i].v) && (r[i].positive ? r[i].v > 0.0 : r[i].v >= 0.0))
            continue;
        ml_repr_double(r[i].v, val, sizeof val);
        snprintf(text, sizeof text, "`%s%s` must be finite and %s, got %s", prefix,
                 r[i].name, r[i].positive ? "> 0" : ">= 0", val);
        ml_append_problem(buf, size, &n, text);
    }
    return n - count;
}

ML_ELEMENT_DEF const ml_element ml_lugre = {
    "lugre", 1, lugre_state_size, lugre_start, lugre_position, lugre_step,
    ml_contact_normal_forces, lugre_problems, NULL};
