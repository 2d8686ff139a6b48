/* C99 port of fmu_src/mount_law.py (see mount_law.h). */
#include "mount_law.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const LAW_NAMES[ML_N_LAWS] = {
    "linear", "cubic", "piecewise", "piecewise_asym"};
static const char *const KIND_NAMES[ML_N_FRICTION_KINDS] = {"jenkins", "inclined"};

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
    p.friction_kind = ML_JENKINS;
    p.theta_deg = q.theta_deg;
    p.k = q.k;
    p.kf2 = q.kf2;
    p.mu1 = q.mu1;
    p.mu2 = q.mu2;
    p.preload = q.preload;
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

double ml_slider_update(double u, double w, double kf, double fs_pos, double fs_neg,
                        double *w_new, double *tangent, int *slipping)
{
    double trial = kf * (u - w);
    if (trial > fs_pos) {
        *w_new = u - fs_pos / kf;
        *tangent = 0.0;
        *slipping = 1;
        return fs_pos;
    }
    if (trial < -fs_neg) {
        *w_new = u + fs_neg / kf;
        *tangent = 0.0;
        *slipping = 1;
        return -fs_neg;
    }
    *w_new = w;
    *tangent = kf;
    *slipping = 0;
    return trial;
}

/* The symmetric element: ml_slider_update with fs_pos = fs_neg = fs (the same
 * arithmetic as the Python jenkins_update). */
double ml_jenkins_update(double u, double w, double kf, double fs, double *w_new,
                         double *tangent, int *slipping)
{
    return ml_slider_update(u, w, kf, fs, fs, w_new, tangent, slipping);
}

ml_axis_result ml_iwan_update(double u, const double *w, const ml_axis_params *p,
                              double fs, double *w_new)
{
    /* slider_bank: k_i = kf / S, r_i = 1 + spread ((2 i + 1) / S - 1),
     * fs_pos_i = Fs r_i / S, fs_neg_i = Fs r_i fs_ratio / S (same operation order) */
    ml_axis_result r;
    int n = p->sliders, i;
    double k = p->kf / n, f = 0.0, kt = 0.0, diss = 0.0;
    int slipping = 0;
    for (i = 0; i < n; ++i) {
        double ri = 1.0 + p->spread * ((double)(2 * i + 1) / n - 1.0);
        double fp = fs * ri / n, fn = fs * ri * p->fs_ratio / n;
        double wi = w[i], trial = k * (u - wi), wn;
        if (trial > fp) {
            wn = u - fp / k;
            f += fp;
            diss += fp * (wn - wi);
            slipping = 1;
        } else if (trial < -fn) {
            wn = u + fn / k;
            f -= fn;
            diss += fn * (wi - wn);
            slipping = 1;
        } else {
            wn = wi;
            f += trial;
            kt += k;
        }
        w_new[i] = wn;
    }
    r.force = f;
    r.friction = f;
    r.w_new = w_new[0];
    r.tangent = kt;
    r.slipping = slipping;
    r.dissipated = diss;
    return r;
}

int ml_is_inclined(const ml_axis_params *p)
{
    return p->friction && p->friction_kind == ML_INCLINED;
}

int ml_state_size(const ml_axis_params *p)
{
    if (ml_is_inclined(p))
        return 3;
    return p->friction && p->sliders > 1 ? p->sliders : 1;
}

in_params ml_inclined_params(const ml_axis_params *p)
{
    in_params q;
    q.theta_deg = p->theta_deg;
    q.k = p->k;
    q.kf = p->kf;
    q.kf2 = p->kf2;
    q.mu1 = p->mu1;
    q.mu2 = p->mu2;
    q.preload = p->preload;
    return q;
}

void ml_relaxed_state(const ml_axis_params *p, double u, double *w)
{
    in_params q = ml_inclined_params(p);
    double s, c;
    in_sc(&q, &s, &c);
    w[0] = -u / s;
    w[1] = -u * c / s;
    w[2] = u;
}

void ml_normal_forces(const ml_axis_params *p, const double *w, double fs, double *n1,
                      double *n2)
{
    *n1 = *n2 = 0.0;
    if (!p->friction)
        return;
    if (p->friction_kind == ML_INCLINED) {  /* inclined.axis_normal_forces */
        in_params q = ml_inclined_params(p);
        double f[4];
        in_forces(-w[2], w[0], w[1], &q, 0, 0, f);
        *n1 = f[2];
        *n2 = f[3];
        return;
    }
    *n1 = p->mu > 0 ? fs / p->mu : p->n0;
}

/* math.fsum (CPython's Shewchuk summation with its half-even correction) of n <=
 * ML_MAX_SLIDERS finite values; a non-finite term or an intermediate overflow (where
 * Python raises) gives the plain sum. */
static double exact_sum(const double *values, int n)
{
    double part[ML_MAX_SLIDERS + 1], x, y, t, hi = 0.0, lo = 0.0, yr, plain = 0.0;
    int np = 0, i, j, k;
    for (k = 0; k < n; ++k)
        plain += values[k];
    if (!isfinite(plain))
        return plain;
    for (k = 0; k < n; ++k) {
        x = values[k];
        for (i = j = 0; j < np; ++j) {
            y = part[j];
            if (fabs(x) < fabs(y)) {
                t = x;
                x = y;
                y = t;
            }
            hi = x + y;
            yr = hi - x;
            lo = y - yr;
            if (lo != 0.0)
                part[i++] = lo;
            x = hi;
        }
        np = i;
        if (x != 0.0) {
            if (!isfinite(x))
                return plain;
            part[np++] = x;
        }
    }
    hi = 0.0;
    if (np > 0) {
        hi = part[--np];
        while (np > 0) {
            x = hi;
            y = part[--np];
            hi = x + y;
            yr = hi - x;
            lo = y - yr;
            if (lo != 0.0)
                break;
        }
        if (np > 0 && ((lo < 0.0 && part[np - 1] < 0.0)
                       || (lo > 0.0 && part[np - 1] > 0.0))) {
            y = lo * 2.0;
            x = hi + y;
            yr = x - hi;
            if (y == yr)
                hi = x;
        }
    }
    return hi;
}

double ml_mean_slider(const double *w, int n)
{
    int i;
    if (n <= 1)
        return w[0];
    for (i = 1; i < n; ++i)
        if (!(w[i] == w[0]))
            return exact_sum(w, n) / n;
    return w[0];
}

/* The inclined element on an axis (mount_law._friction, inclined.axis_step): element
 * deflection x = -u from the committed -uc, friction force -N2. */
static int inclined_friction(double u, const double *w, const ml_axis_params *p,
                             double *w_new, double *f_fr, double *k_fr,
                             ml_axis_result *r, char *msg, size_t size)
{
    in_params q = ml_inclined_params(p);
    in_step st;
    if (in_update(-u, -w[2], w[0], w[1], &q, &st, msg, size) != IN_OK)
        return 1;
    *f_fr = -st.force;
    *k_fr = st.tangent;
    r->slipping = st.slip1 || st.slip2;
    r->dissipated = st.dissipated;
    w_new[0] = st.w1;
    w_new[1] = st.w2;
    w_new[2] = u;
    r->w_new = u;
    return 0;
}

int ml_axis_force_w(double u, double v, const double *w, const ml_axis_params *p,
                    double fs, double *w_new, ml_axis_result *r, char *msg,
                    size_t size)
{
    ml_axis_result out;
    double f_el, k_el, k_fr, f_fr;
    ml_elastic_force(u, p->law, p->k1, p->kc, p->k2, p->delta, p->delta_neg, &f_el,
                     &k_el);
    if (!p->friction) {
        out.force = f_el + p->c * v;
        out.friction = 0.0;
        out.w_new = w_new[0] = w[0];
        out.tangent = k_el;
        out.slipping = 0;
        out.dissipated = 0.0;
        *r = out;
        return 0;
    }
    if (p->friction_kind == ML_INCLINED) {
        if (inclined_friction(u, w, p, w_new, &f_fr, &k_fr, &out, msg, size))
            return 1;
    } else if (p->sliders > 1) {  /* micro-slip (mount_law._friction) */
        ml_axis_result fr = ml_iwan_update(u, w, p, fs, w_new);
        f_fr = fr.force;
        out.w_new = fr.w_new;
        k_fr = fr.tangent;
        out.slipping = fr.slipping;
        out.dissipated = fr.dissipated;
    } else if (p->fs_ratio != 1.0) {  /* non-symmetric macro-slip */
        double fn = fs * p->fs_ratio;
        f_fr = ml_slider_update(u, w[0], p->kf, fs, fn, &out.w_new, &k_fr,
                                &out.slipping);
        out.dissipated = (out.w_new > w[0] ? fs : fn) * fabs(out.w_new - w[0]);
        w_new[0] = out.w_new;
    } else {
        f_fr = ml_jenkins_update(u, w[0], p->kf, fs, &out.w_new, &k_fr,
                                 &out.slipping);
        out.dissipated = fs * fabs(out.w_new - w[0]);
        w_new[0] = out.w_new;
    }
    out.friction = f_fr;
    out.force = f_el + p->c * v + f_fr;
    out.tangent = k_el + k_fr;
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

int ml_axis_force_p(double u, double v, const double *w, const ml_axis_params *p,
                    double n, double *w_new, ml_axis_result *r, char *msg,
                    size_t size)
{
    return ml_axis_force_w(u, v, w, p, ml_slip_force(p, n), w_new, r, msg, size);
}

/* ------------------------------------------------------------------ messages */

void ml_repr_double(double x, char *buf, size_t size)
{
    char tmp[40], digits[24];
    int prec, exp10, nd = 0, i;
    const char *s;
    char *out = buf;
    size_t room = size;
    if (isnan(x)) {
        snprintf(buf, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(buf, size, x < 0 ? "-inf" : "inf");
        return;
    }
    for (prec = 1; prec <= 17; ++prec) {
        snprintf(tmp, sizeof tmp, "%.*e", prec - 1, x);
        if (strtod(tmp, NULL) == x)
            break;
    }
    s = tmp;
    if (*s == '-') {
        if (room > 1) {
            *out++ = '-';
            --room;
        }
        ++s;
    }
    for (; *s && *s != 'e'; ++s)
        if (*s != '.' && nd < (int)sizeof digits - 1)
            digits[nd++] = *s;
    exp10 = *s == 'e' ? atoi(s + 1) : 0;
    while (nd > 1 && digits[nd - 1] == '0')
        --nd;
    digits[nd] = '\0';
    if (exp10 < -4 || exp10 >= 16) {
        snprintf(out, room, "%c%s%s%se%c%02d", digits[0], nd > 1 ? "." : "",
                 digits + 1, "", exp10 < 0 ? '-' : '+', abs(exp10));
        return;
    }
    if (exp10 < 0) {
        char zeros[8] = "";
        for (i = 0; i < -exp10 - 1; ++i)
            zeros[i] = '0';
        zeros[-exp10 - 1] = '\0';
        snprintf(out, room, "0.%s%s", zeros, digits);
        return;
    }
    {
        char intpart[24], frac[24];
        for (i = 0; i <= exp10; ++i)
            intpart[i] = i < nd ? digits[i] : '0';
        intpart[exp10 + 1] = '\0';
        if (nd > exp10 + 1)
            snprintf(frac, sizeof frac, "%s", digits + exp10 + 1);
        else
            snprintf(frac, sizeof frac, "0");
        snprintf(out, room, "%s.%s", intpart, frac);
    }
}

void ml_append_problem(char *buf, size_t size, int *count, const char *text)
{
    size_t len = strlen(buf);
    if (len + 1 >= size)
        return;
    snprintf(buf + len, size - len, "%s%s", *count ? "; " : "", text);
    ++*count;
}

static int finite_and(double value, int strict)
{
    return isfinite(value) && (strict ? value > 0 : value >= 0);
}

/* mount_law._inclined_problems: the inclined element's checks on the axis's fields,
 * and micro-slip / non-symmetric friction belong to the Jenkins element. Appends to
 * buf (count problems there already); returns the number appended. */
static int inclined_problems(const ml_axis_params *p, const char *prefix, char *buf,
                             size_t size, int count)
{
    in_params q = ml_inclined_params(p);
    char text[2048], val[40];
    int added = in_problems(&q, prefix, text, sizeof text), n = count;
    if (added)
        ml_append_problem(buf, size, &n, text);  /* already "; "-separated */
    if (p->sliders != 1 || p->fs_ratio != 1.0) {
        ml_repr_double(p->fs_ratio, val, sizeof val);
        snprintf(text, sizeof text, "`%ssliders` = %d and `%sfs_ratio` = %s: micro-slip "
                 "and non-symmetric friction belong to the Jenkins element; the "
                 "inclined element needs sliders = 1 and fs_ratio = 1", prefix,
                 p->sliders, prefix, val);
        ml_append_problem(buf, size, &n, text);
        ++added;
    }
    return added;
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
        snprintf(text, sizeof text, "`%sfriction_kind` must be one of 0 = %s, 1 = %s, "
                 "got %d", prefix, KIND_NAMES[0], KIND_NAMES[1], p->friction_kind);
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
    if (kind_ok && ml_is_inclined(p))
        count += inclined_problems(p, prefix, buf, size, count);
    return count;
}
