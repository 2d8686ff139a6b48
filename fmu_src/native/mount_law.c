/* C99 port of fmu_src/mount_law.py (see mount_law.h). */
#include "mount_law.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "friction_table.h"  /* generated from fmu_src/friction_elements.py */
#include "hydraulic.h"
#include "maxwell.h"
#include "messages.h"

static const char *const LAW_NAMES[ML_N_LAWS] = {
    "linear", "cubic", "piecewise", "piecewise_asym"};

ml_axis_params ml_default_params(void)
{
    ml_axis_params p;
    in_params q = in_default_params();  /* the inclined element's, in one place */
    p.law = ML_PIECEWISE;
    p.k1 = 91870.0;
    p.kc = 0.0;
    p.k2 = 513800.0;
    p.delta = 0.01225;
    p.delta_neg = 0.01225;
    p.c = 150.0;
    p.friction = 0;
    p.kf = 60000.0;
    p.mu = 1.0;
    p.n0 = 0.0;
    p.sliders = 1;
    p.spread = 0.0;
    p.fs_ratio = 1.0;
    p.friction_kind = 0;  /* the first registered element */
    p.theta_deg = q.theta_deg;
    p.k = q.k;
    p.kf2 = q.kf2;
    p.mu1 = q.mu1;
    p.mu2 = q.mu2;
    p.preload = q.preload;
    p.sigma1 = 0.0;  /* lugre.py's defaults */
    p.sigma2 = 0.0;
    p.stribeck_ratio = 1.0;
    p.v_stribeck = 0.01;
    p.maxwell_k1 = p.maxwell_c1 = 0.0;  /* no Maxwell branches */
    p.maxwell_k2 = p.maxwell_c2 = 0.0;
    p.maxwell_k3 = p.maxwell_c3 = 0.0;
    p.hyd_Ap = p.hyd_C1 = p.hyd_C2 = p.hyd_I_i = 0.0;  /* no fluid path */
    p.hyd_R_i = p.hyd_I_d = p.hyd_R_d = 0.0;
    return p;
}

void ml_elastic_force(double u, int law, double k1, double kc, double k2,
                      double delta, double delta_neg, double *f, double *k)
{
    double dneg;
    if (law == ML_LINEAR) {
        *f = k1 * u;
        *k = k1;
        return;
    }
    if (law == ML_CUBIC) {
        *f = k1 * u + kc * u * u * u;
        *k = k1 + 3.0 * kc * u * u;
        return;
    }
    /* piecewise: a linear spring plus a spring (k2 - k1) behind a gap */
    if (u > delta) {
        *f = k1 * u + (k2 - k1) * (u - delta);
        *k = k2;
        return;
    }
    dneg = law == ML_PIECEWISE_ASYM ? delta_neg : delta;
    if (u < -dneg) {
        *f = k1 * u + (k2 - k1) * (u + dneg);
        *k = k2;
        return;
    }
    *f = k1 * u;
    *k = k1;
}

/* ------------------------------------------------------------ friction elements */

/* The axis's element in the table (NULL without friction or with an invalid code). */
static const ml_element *element_of(const ml_axis_params *p)
{
    if (!p->friction || p->friction_kind < 0 || p->friction_kind >= ML_N_FRICTION_KINDS)
        return NULL;
    return ML_ELEMENTS[p->friction_kind];
}

int ml_state_size(const ml_axis_params *p)
{
    const ml_element *el = element_of(p);
    return (el ? el->state_size(p) : 1) + (ml_has_branches(p) ? 1 + ML_MAX_MAXWELL : 0)
        + (ml_has_hydraulic(p) ? ML_FLUID_STATE : 0);
}

void ml_state_start(const ml_axis_params *p, double w, double *state)
{
    const ml_element *el = element_of(p);
    int i, n = el ? el->state_size(p) : 1;
    if (el)
        el->start(p, w, state);
    else
        state[0] = w;
    if (ml_has_branches(p))   /* uc and every stroke relaxed at w */
        for (i = 0; i <= ML_MAX_MAXWELL; ++i)
            state[n + i] = w;
    if (ml_has_hydraulic(p))  /* the fluid at rest at w */
        ml_fluid_relaxed(p, w, state + n + 1 + ML_MAX_MAXWELL);
}

int ml_slider_index(const ml_axis_params *p, int slot)
{
    const ml_element *el = element_of(p);
    if (el == NULL || el->slider_index == NULL || slot < 0)
        return -1;
    return el->slider_index(p, slot);
}

int ml_friction_kinds(void)
{
    return ML_N_FRICTION_KINDS;
}

int ml_state_tag(const ml_axis_params *p)
{
    const ml_element *el = element_of(p);
    return el && el->named_state ? p->friction_kind + 1 : 0;
}

double ml_state_position(const double *state, int n, int tag)
{
    if (tag > 0 && tag <= ML_N_FRICTION_KINDS)
        return ML_ELEMENTS[tag - 1]->position(state, n);
    return ml_mean_slider(state, n);
}

void ml_normal_forces(const ml_axis_params *p, const double *w, double fs, double *n1,
                      double *n2)
{
    const ml_element *el = element_of(p);
    *n1 = *n2 = 0.0;
    if (el)
        el->normal_forces(p, w, fs, n1, n2);
}

int ml_axis_force_w(double u, double v, const double *w, const ml_axis_params *p,
                    double fs, double *w_new, ml_axis_result *r, char *msg,
                    size_t size)
{
    return ml_axis_force_dt(u, v, 0.0, w, p, fs, w_new, r, msg, size);
}

/* mount_law._maxwell_axis_force: the element (if any) on the first entries of the
 * state, the branches on uc and the strokes after them; the sums in the Python
 * order (f_el + c v + friction + branches). */
static int maxwell_axis_force(double u, double v, double dt, const double *w,
                              const ml_axis_params *p, double fs, double *w_new,
                              ml_axis_result *r, char *msg, size_t size,
                              const ml_element *el, double f_el, double k_el,
                              ml_fluid_prop *cache)
{
    ml_axis_result out;
    ml_friction_step st;
    double f_m, k_m;
    int n = el ? el->state_size(p) : 1;
    ml_maxwell_forces(p, w[n], w + n + 1, u, dt, w_new + n + 1, &f_m, &k_m);
    if (ml_has_hydraulic(p)) {   /* mount_law._fluid_step, added to the branches */
        ml_fluid_prop scratch;
        const ml_fluid_prop *prop = dt > 0.0 ? ml_fluid_cached(p, dt, cache, &scratch)
                                             : NULL;
        double f_h, k_h;
        int at = n + 1 + ML_MAX_MAXWELL;
        ml_fluid_step(p, prop, w + at, w[n], u, dt, w_new + at, &f_h, &k_h);
        f_m += f_h;
        k_m += k_h;
    }
    w_new[n] = u;
    if (el == NULL) {
        out.friction = 0.0;
        out.w_new = w_new[0] = w[0];
        out.slipping = 0;
        out.dissipated = 0.0;
        out.force = f_el + p->c * v + 0.0 + f_m;
        out.tangent = k_el + 0.0 + k_m;
        *r = out;
        return 0;
    }
    if (el->step(u, v, w, p, fs, dt, w_new, &st, msg, size))
        return 1;
    out.friction = st.force;
    out.w_new = el->named_state ? el->position(w_new, n) : w_new[0];
    out.slipping = st.slipping;
    out.dissipated = st.dissipated;
    out.force = f_el + p->c * v + st.force + f_m;
    out.tangent = k_el + st.tangent + k_m;
    *r = out;
    return 0;
}

int ml_axis_force_dt(double u, double v, double dt, const double *w,
                     const ml_axis_params *p, double fs, double *w_new,
                     ml_axis_result *r, char *msg, size_t size)
{
    return ml_axis_force_dtc(u, v, dt, w, p, fs, w_new, r, msg, size, NULL);
}

int ml_axis_force_dtc(double u, double v, double dt, const double *w,
                      const ml_axis_params *p, double fs, double *w_new,
                      ml_axis_result *r, char *msg, size_t size, ml_fluid_prop *cache)
{
    ml_axis_result out;
    ml_friction_step st;
    double f_el, k_el;
    const ml_element *el = element_of(p);
    ml_elastic_force(u, p->law, p->k1, p->kc, p->k2, p->delta, p->delta_neg, &f_el,
                     &k_el);
    if (ml_has_branches(p))
        return maxwell_axis_force(u, v, dt, w, p, fs, w_new, r, msg, size, el, f_el,
                                  k_el, cache);
    if (el == NULL) {
        out.force = f_el + p->c * v;
        out.friction = 0.0;
        out.w_new = w_new[0] = w[0];
        out.tangent = k_el;
        out.slipping = 0;
        out.dissipated = 0.0;
        *r = out;
        return 0;
    }
    if (el->step(u, v, w, p, fs, dt, w_new, &st, msg, size))
        return 1;
    out.friction = st.force;
    out.w_new = el->named_state ? el->position(w_new, el->state_size(p)) : w_new[0];
    out.slipping = st.slipping;
    out.dissipated = st.dissipated;
    out.force = f_el + p->c * v + st.force;
    out.tangent = k_el + st.tangent;
    *r = out;
    return 0;
}

ml_axis_result ml_axis_force(double u, double v, double w, int law, double k1,
                             double kc, double k2, double delta, double delta_neg,
                             double c, double kf, double fs)
{
    ml_axis_params p = ml_default_params();
    ml_axis_result r;
    double w_new;
    p.law = law;
    p.k1 = k1;
    p.kc = kc;
    p.k2 = k2;
    p.delta = delta;
    p.delta_neg = delta_neg;
    p.c = c;
    p.friction = kf > 0.0;
    p.kf = kf;
    ml_axis_force_w(u, v, &w, &p, fs, &w_new, &r, NULL, 0);  /* cannot fail */
    return r;
}

double ml_slip_force(const ml_axis_params *p, double n)
{
    /* A negative normal force means lost contact: Fs = mu * max(n, 0). */
    if (!p->friction)
        return 0.0;
    return n > 0.0 ? p->mu * n : 0.0;
}

int ml_axis_force_p(double u, double v, double dt, const double *w,
                    const ml_axis_params *p, double n, double *w_new,
                    ml_axis_result *r, char *msg, size_t size)
{
    return ml_axis_force_dt(u, v, dt, w, p, ml_slip_force(p, n), w_new, r, msg,
                            size);
}

int ml_axis_force_pc(double u, double v, double dt, const double *w,
                     const ml_axis_params *p, double n, double *w_new,
                     ml_axis_result *r, char *msg, size_t size, ml_fluid_prop *cache)
{
    return ml_axis_force_dtc(u, v, dt, w, p, ml_slip_force(p, n), w_new, r, msg,
                             size, cache);
}

static int finite_and(double value, int strict)
{
    return isfinite(value) && (strict ? value > 0 : value >= 0);
}

/* "`<prefix><name>` must be finite and >= 0" (strict: "> 0") if value breaks it. */
static void finite_problem(const char *name, double value, int strict,
                           const char *prefix, char *buf, size_t size, int *count)
{
    char text[256], val[40];
    if (finite_and(value, strict))
        return;
    ml_repr_double(value, val, sizeof val);
    snprintf(text, sizeof text, "`%s%s` must be finite and %s, got %s", prefix, name,
             strict ? "> 0" : ">= 0", val);
    ml_append_problem(buf, size, count, text);
}

int ml_axis_problems(const ml_axis_params *p, const char *prefix, char *buf,
                     size_t size)
{
    char text[256], val[40];
    int count = 0, kind_ok;
    if (size)
        buf[0] = '\0';
    if (p->law < 0 || p->law >= ML_N_LAWS) {
        snprintf(text, sizeof text, "`%slaw` must be one of 0 = %s, 1 = %s, 2 = %s, "
                 "3 = %s, got %d", prefix, LAW_NAMES[0], LAW_NAMES[1], LAW_NAMES[2],
                 LAW_NAMES[3], p->law);
        ml_append_problem(buf, size, &count, text);
    }
    kind_ok = p->friction_kind >= 0 && p->friction_kind < ML_N_FRICTION_KINDS;
    if (!kind_ok) {
        int i, len = snprintf(text, sizeof text, "`%sfriction_kind` must be one of ",
                              prefix);
        for (i = 0; i < ML_N_FRICTION_KINDS && len < (int)sizeof text; ++i)
            len += snprintf(text + len, sizeof text - len, "%d = %s, ", i,
                            ML_ELEMENTS[i]->name);
        if (len < (int)sizeof text)
            snprintf(text + len, sizeof text - len, "got %d", p->friction_kind);
        ml_append_problem(buf, size, &count, text);
    }
    /* the order of the Python checks: the law's fields, then the Jenkins
     * element's fields in their declared order (fmu_src/jenkins.py) */
    finite_problem("k1", p->k1, 0, prefix, buf, size, &count);
    finite_problem("kc", p->kc, 0, prefix, buf, size, &count);
    finite_problem("k2", p->k2, 0, prefix, buf, size, &count);
    finite_problem("delta", p->delta, 1, prefix, buf, size, &count);
    finite_problem("delta_neg", p->delta_neg, 1, prefix, buf, size, &count);
    finite_problem("c", p->c, 0, prefix, buf, size, &count);
    if (!isfinite(p->kf) || (p->friction && p->kf <= 0) || p->kf < 0) {
        ml_repr_double(p->kf, val, sizeof val);
        snprintf(text, sizeof text, "`%skf` must be finite and %s, got %s", prefix,
                 p->friction ? "> 0 when friction is on" : ">= 0", val);
        ml_append_problem(buf, size, &count, text);
    }
    finite_problem("mu", p->mu, 0, prefix, buf, size, &count);
    finite_problem("n0", p->n0, 0, prefix, buf, size, &count);
    if (p->sliders < 1 || p->sliders > ML_MAX_SLIDERS) {
        snprintf(text, sizeof text, "`%ssliders` must be an integer from 1 to %d (the "
                 "number of Jenkins elements of the micro-slip element), got %d",
                 prefix, ML_MAX_SLIDERS, p->sliders);
        ml_append_problem(buf, size, &count, text);
    }
    if (!(isfinite(p->spread) && p->spread >= 0.0 && p->spread < 1.0)) {
        ml_repr_double(p->spread, val, sizeof val);
        snprintf(text, sizeof text, "`%sspread` must be finite and in [0, 1) (half-width "
                 "of the sliders' slip displacements / eps), got %s", prefix, val);
        ml_append_problem(buf, size, &count, text);
    }
    finite_problem("fs_ratio", p->fs_ratio, 0, prefix, buf, size, &count);
    if (kind_ok && p->friction && ML_ELEMENTS[p->friction_kind]->problems)
        count += ML_ELEMENTS[p->friction_kind]->problems(p, prefix, buf, size, count);
    count += ml_maxwell_problems(p, prefix, buf, size, count);
    count += ml_hydraulic_problems(p, prefix, buf, size, count);
    return count;
}

/* CPython's math_fsum (Shewchuk's partials, then the half-even correction): the
 * mean slider position and the hydraulic propagator sum with it. A non-finite term
 * or an intermediate overflow (where Python raises) gives the plain sum. At most 64
 * partials: non-overlapping partials of finite doubles span distinct exponent
 * ranges, about 40 of them. */
double ml_fsum(const double *xs, int n)
{
    double partials[64], x, y, t, hi, yr, lo = 0.0, plain = 0.0;
    int i, j, k, m = 0;
    for (k = 0; k < n; ++k) {
        x = xs[k];
        plain += x;
        for (i = j = 0; j < m; ++j) {
            y = partials[j];
            if (fabs(x) < fabs(y)) {
                t = x;
                x = y;
                y = t;
            }
            hi = x + y;
            yr = hi - x;
            lo = y - yr;
            if (lo != 0.0)
                partials[i++] = lo;
            x = hi;
        }
        m = i;
        if (x != 0.0) {
            if (!isfinite(x))
                return plain;
            partials[m++] = x;
        }
    }
    if (!isfinite(plain))
        return plain;
    hi = 0.0;
    if (m > 0) {
        hi = partials[--m];
        while (m > 0) {   /* sum_exact(ps, hi) from the top, stop when inexact */
            x = hi;
            y = partials[--m];
            hi = x + y;
            yr = hi - x;
            lo = y - yr;
            if (lo != 0.0)
                break;
        }
        if (m > 0 && ((lo < 0.0 && partials[m - 1] < 0.0)
                      || (lo > 0.0 && partials[m - 1] > 0.0))) {
            y = lo * 2.0;   /* half-even rounding across several partials */
            x = hi + y;
            yr = x - hi;
            if (y == yr)
                hi = x;
        }
    }
    return hi;
}
