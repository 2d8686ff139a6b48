/* C99 port of fmu_src/inclined.py (see inclined.h). */
#include "inclined.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <float.h>
#include "messages.h"

#define IN_MAX_EVENTS 64
#define IN_REL_TOL 1e-12
#define IN_RES_ULPS 64.0  /* at-limit slack in units of kf ulp(x) */
#define IN_PI 3.14159265358979323846  /* Py_MATH_PI */

in_params in_default_params(void)
{
    in_params p;
    p.theta_deg = 60.0;
    p.k = 20000.0;
    p.kf = 60000.0;
    p.kf2 = 60000.0;
    p.mu1 = 0.3;
    p.mu2 = 0.3;
    p.preload = 200.0;
    return p;
}

void in_sc(const in_params *p, double *s, double *c)
{
    double t;
    if (p->theta_deg == 90.0) {
        *s = 1.0;
        *c = 0.0;
        return;
    }
    t = p->theta_deg * (IN_PI / 180.0);  /* math.radians */
    *s = sin(t);
    *c = cos(t);
}

double in_self_locking_margin(const in_params *p)
{
    double s, c, m1, m2, best = 0.0;
    int sig1, sig2, first = 1, i;
    in_sc(p, &s, &c);
    m1 = isinf(p->mu1) ? 0.0 : p->mu1;  /* a bonded surface never slips */
    m2 = isinf(p->mu2) ? 0.0 : p->mu2;
    for (sig1 = 1; sig1 >= -1; sig1 -= 2) {
        for (sig2 = 1; sig2 >= -1; sig2 -= 2) {
            double d1 = s - sig1 * m1 * c, d2 = s - sig2 * m2 * c, dets[3];
            dets[0] = d1;
            dets[1] = d2;
            dets[2] = d1 * d2 - (double)(sig1 * sig2) * m1 * m2;
            for (i = 0; i < 3; ++i) {  /* Python's min(): the first smallest */
                if (first || dets[i] < best)
                    best = dets[i];
                first = 0;
            }
        }
    }
    return best;
}

/* Python's format(x, ".<prec>g") (C's %g but "nan" for every NaN). */
static void py_g(double x, int prec, char *buf, size_t size)
{
    if (isnan(x))
        snprintf(buf, size, "nan");
    else
        snprintf(buf, size, "%.*g", prec, x);
}

int in_problems(const in_params *p, const char *prefix, char *buf, size_t size)
{
    struct { const char *name; double v; int ok; const char *rule; } r[7];
    char text[512], val[40], m1[40], m2[40], worst[40];
    int count = 0, i;
    if (size)
        buf[0] = '\0';
    r[0].name = "theta_deg"; r[0].v = p->theta_deg;
    r[0].ok = 0 < r[0].v && r[0].v <= 90; r[0].rule = "in (0, 90] degrees";
    r[1].name = "k"; r[1].v = p->k;
    r[1].ok = 0 <= r[1].v && r[1].v < INFINITY; r[1].rule = "finite and >= 0";
    r[2].name = "kf"; r[2].v = p->kf;
    r[2].ok = 0 < r[2].v && r[2].v < INFINITY; r[2].rule = "finite and > 0";
    r[3].name = "kf2"; r[3].v = p->kf2;
    r[3].ok = 0 < r[3].v && r[3].v < INFINITY; r[3].rule = "finite and > 0";
    r[4].name = "mu1"; r[4].v = p->mu1; r[4].ok = r[4].v >= 0;
    r[4].rule = ">= 0 (inf = bonded)";
    r[5].name = "mu2"; r[5].v = p->mu2; r[5].ok = r[5].v >= 0;
    r[5].rule = ">= 0 (inf = bonded)";
    r[6].name = "preload"; r[6].v = p->preload;
    r[6].ok = 0 <= r[6].v && r[6].v < INFINITY; r[6].rule = "finite and >= 0";
    for (i = 0; i < 7; ++i) {
        if (!isnan(r[i].v) && r[i].ok)
            continue;
        ml_repr_double(r[i].v, val, sizeof val);
        snprintf(text, sizeof text, "`%s%s` must be %s, got %s", prefix, r[i].name,
                 r[i].rule, val);
        ml_append_problem(buf, size, &count, text);
    }
    if (count == 0) {
        double margin = in_self_locking_margin(p);
        if (margin <= 1e-9) {
            ml_repr_double(p->theta_deg, val, sizeof val);
            ml_repr_double(p->mu1, m1, sizeof m1);
            ml_repr_double(p->mu2, m2, sizeof m2);
            py_g(margin, 3, worst, sizeof worst);
            snprintf(text, sizeof text, "`%stheta_deg` = %s self-locks the wedge with "
                     "mu1 = %s, mu2 = %s (the normal force of a slipping regime has "
                     "determinant %s <= 0): increase theta or lower mu1/mu2", prefix,
                     val, m1, m2, worst);
            ml_append_problem(buf, size, &count, text);
        }
    }
    return count;
}

/* ------------------------------------------------------------------ return map */

/* _solve: forces (f1, f2, N, N2) at x in regime (sig1, sig2); sig 0 = stuck. */
static void solve(double x, double w1, double w2, int sig1, int sig2,
                  const in_params *p, double s, double c, double out[4])
{
    double q = p->k * x * c / s + p->preload;
    double a11, a12, b1, a21, a22, b2, m, det, f1, f2;
    if (sig1 == 0) {
        a11 = 1.0;
        a12 = 0.0;
        b1 = p->kf * (x / s - w1);
    } else {
        m = sig1 * p->mu1;
        a11 = s - m * c;
        a12 = -m;
        b1 = m * q;
    }
    if (sig2 == 0) {
        a21 = 0.0;
        a22 = 1.0;
        b2 = p->kf2 * (x * c / s - w2);
    } else {
        m = sig2 * p->mu2;
        a21 = -m;
        a22 = s - m * c;
        b2 = m * c * q;
    }
    det = a11 * a22 - a12 * a21;
    f1 = (b1 * a22 - a12 * b2) / det;
    f2 = (a11 * b2 - a21 * b1) / det;
    out[0] = f1;
    out[1] = f2;
    out[2] = (c * f1 + f2 + q) / s;
    out[3] = (f1 + c * f2 + c * q) / s;
}

void in_forces(double x, double w1, double w2, const in_params *p, int sig1, int sig2,
               double out[4])
{
    double s, c;
    in_sc(p, &s, &c);
    solve(x, w1, w2, sig1, sig2, p, s, c, out);
}

/* _affine: values at x and slopes d/dx of (f1, f2, N, N2) in the regime. */
static void affine(double x, double w1, double w2, const int reg[2],
                   const in_params *p, double s, double c, double vals[4],
                   double slopes[4])
{
    double v0z[4], v1z[4];
    int i;
    solve(x, w1, w2, reg[0], reg[1], p, s, c, vals);
    solve(0.0, 0.0, 0.0, reg[0], reg[1], p, s, c, v0z);
    solve(1.0, 0.0, 0.0, reg[0], reg[1], p, s, c, v1z);
    for (i = 0; i < 4; ++i)
        slopes[i] = v1z[i] - v0z[i];
}

/* _consistent: whether the regime can continue from vals in direction d. */
static int consistent(const double vals[4], const double slopes[4], const int reg[2],
                      const int at_limit[2], double d, const in_params *p, double s,
                      double c)
{
    int i;
    for (i = 0; i < 2; ++i) {
        double f = vals[i], df = slopes[i], dn = slopes[2 + i];
        double mu = i == 0 ? p->mu1 : p->mu2, kfi = i == 0 ? p->kf : p->kf2;
        double da = i == 0 ? 1.0 / s : c / s;
        int sig = reg[i];
        if (sig == 0) {
            if (at_limit[i]) {
                double g = f >= 0 ? 1.0 : -1.0;
                if (d * (g * df - mu * dn)
                        > 1e-9 * (fabs(df) + mu * fabs(dn) + 1e-30))
                    return 0;
            }
        } else {
            double dw = da - df / kfi;
            if (d * sig * dw < -1e-12 * (fabs(da) + fabs(df) / kfi))
                return 0;
        }
    }
    return 1;
}

/* Python's max(a, b, c, e): the first largest (a NaN after the first is skipped). */
static double py_max4(double a, double b, double c, double e)
{
    double m = a;
    if (b > m)
        m = b;
    if (c > m)
        m = c;
    if (e > m)
        m = e;
    return m;
}

/* _choose: the regime that continues from x in direction d; 0 or ContactLost. */
static int choose(double x, double w1, double w2, double d, const in_params *p,
                  double s, double c, int reg[2], char *msg, size_t size)
{
    double vals[4], slopes[4], lim[2], dummy[4], scale;
    int at_limit[2], options[2][2], n_opt[2], i, a, b;
    char sx[40], sn1[40], sn2[40];
    solve(x, w1, w2, 0, 0, p, s, c, vals);
    lim[0] = p->mu1 * vals[2];
    lim[1] = p->mu2 * vals[3];
    /* within rounding of the element's force scale (a normal force near 0 makes the
     * limit tiny, not exact) */
    scale = fabs(vals[0]) + fabs(vals[1]) + p->preload;
    for (i = 0; i < 2; ++i) {
        double f = vals[i], L = lim[i];
        /* ... and within a contact force's rounding kf ulp(x) (stiff contacts) */
        double res = i == 0 ? p->kf * (fabs(x / s) + fabs(w1))
                            : p->kf2 * (fabs(x * c / s) + fabs(w2));
        double tol = IN_REL_TOL * py_max4(fabs(f), fabs(L), scale, 1e-9);
        if (IN_RES_ULPS * DBL_EPSILON * res > tol)
            tol = IN_RES_ULPS * DBL_EPSILON * res;
        at_limit[i] = !isinf(L) && fabs(f) >= L - tol;
        options[i][0] = 0;
        options[i][1] = f >= 0 ? 1 : -1;
        n_opt[i] = at_limit[i] ? 2 : 1;
    }
    for (a = 0; a < n_opt[0]; ++a) {
        for (b = 0; b < n_opt[1]; ++b) {
            reg[0] = options[0][a];
            reg[1] = options[1][b];
            affine(x, w1, w2, reg, p, s, c, dummy, slopes);
            if (consistent(vals, slopes, reg, at_limit, d, p, s, c))
                return 0;
        }
    }
    ml_repr_double(x, sx, sizeof sx);
    py_g(vals[2], 6, sn1, sizeof sn1);
    py_g(vals[3], 6, sn2, sizeof sn2);
    snprintf(msg, size, "no consistent stick/slip state at x = %s m (N = %s N, N2 = "
             "%s N)", sx, sn1, sn2);
    return 1;
}

/* _next_event: the first deflection between x and x1 where a stuck surface reaches
 * its limit. */
static double next_event(double x, double x1, double d, const double vals[4],
                         const double slopes[4], const int reg[2], const in_params *p)
{
    double best = x1;
    int i, gi;
    for (i = 0; i < 2; ++i) {
        double mu = i == 0 ? p->mu1 : p->mu2;
        double f = vals[i], df = slopes[i], n = vals[2 + i], dn = slopes[2 + i];
        if (reg[i] || isinf(mu))
            continue;
        for (gi = 0; gi < 2; ++gi) {
            double g = gi == 0 ? 1.0 : -1.0;
            double phi = g * f - mu * n, dphi = g * df - mu * dn;
            if (d * dphi > 0) {
                double xe = x - phi / dphi;
                if ((xe - best) * d < 0)
                    best = (xe - x) * d > 0 ? xe : x;
            }
        }
    }
    return best;
}

/* _check_contact: 0, or 1 with ContactLost's message. */
static int check_contact(double x, const double vals[4], const in_params *p,
                         char *msg, size_t size)
{
    static const char *const NAMES[2] = {"N", "N2"};
    int i;
    for (i = 0; i < 2; ++i) {
        double n = vals[2 + i], mu = i == 0 ? p->mu1 : p->mu2;
        double scale = fabs(vals[0]) + fabs(vals[1]) + p->preload + 1e-9;
        if (n < -IN_REL_TOL * scale && !isinf(mu)) {
            char sx[40], sn[40];
            ml_repr_double(x, sx, sizeof sx);
            py_g(n, 6, sn, sizeof sn);
            snprintf(msg, size, "the inclined element loses contact at x = %s m: %s "
                     "= %s N < 0 (raise the preload or k)", sx, NAMES[i], sn);
            return 1;
        }
    }
    return 0;
}

in_status in_update(double x, double x_old, double w1, double w2, const in_params *p,
                    in_step *out, char *msg, size_t size)
{
    double s, c, d, xc = x_old, diss = 0.0, vals[4], slopes[4], end[4];
    int reg[2] = {0, 0}, event;
    in_sc(p, &s, &c);
    d = x >= x_old ? 1.0 : -1.0;
    for (event = 0; event < IN_MAX_EVENTS; ++event) {
        double xe, nw1, nw2;
        if (choose(xc, w1, w2, d, p, s, c, reg, msg, size))
            return IN_CONTACT_LOST;
        affine(xc, w1, w2, reg, p, s, c, vals, slopes);
        xe = next_event(xc, x, d, vals, slopes, reg, p);
        solve(xe, w1, w2, reg[0], reg[1], p, s, c, end);
        if (check_contact(xe, end, p, msg, size))
            return IN_CONTACT_LOST;
        /* _sliders: a slipping surface's slider follows */
        nw1 = reg[0] ? xe / s - end[0] / p->kf : w1;
        nw2 = reg[1] ? xe * c / s - end[1] / p->kf2 : w2;
        /* slip energy: f affine and w linear in x on the segment -> trapezoid exact */
        diss += 0.5 * ((vals[0] + end[0]) * (nw1 - w1)
                       + (vals[1] + end[1]) * (nw2 - w2));
        w1 = nw1;
        w2 = nw2;
        xc = xe;
        if (xe == x)
            break;
    }
    if (event == IN_MAX_EVENTS) {
        char s_old[40], s_x[40];
        ml_repr_double(x_old, s_old, sizeof s_old);
        ml_repr_double(x, s_x, sizeof s_x);
        snprintf(msg, size, "more than %d stick/slip events between %s and %s m",
                 IN_MAX_EVENTS, s_old, s_x);
        return IN_CONTACT_LOST;
    }
    out->force = end[3];
    out->f1 = end[0];
    out->f2 = end[1];
    out->n1 = end[2];
    out->n2 = end[3];
    out->w1 = w1;
    out->w2 = w2;
    out->slip1 = reg[0] != 0;
    out->slip2 = reg[1] != 0;
    out->tangent = slopes[3];
    out->dissipated = diss;
    return IN_OK;
}
