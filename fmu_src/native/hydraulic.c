/* The hydraulic mount's fluid path of a mount axis: see hydraulic.h. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "hydraulic.h"
#include "maxwell.h"

/* the augmented system (x, u, r): 4 + 2 */
#define AUG (ML_FLUID_STATE + 2)

int ml_has_hydraulic(const ml_axis_params *p)
{
    return p->hyd_Ap > 0.0;
}

int ml_has_branches(const ml_axis_params *p)
{
    return ml_has_maxwell(p) || ml_has_hydraulic(p);
}

/* linear_branches.fluid_matrices */
static void fluid_matrices(const ml_axis_params *p, double a[4][4], double b[4])
{
    double c1 = p->hyd_C1, c2 = p->hyd_C2, ii = p->hyd_I_i;
    memset(a, 0, 16 * sizeof(double));
    a[0][2] = a[0][3] = -1.0;
    a[1][2] = a[1][3] = 1.0 / c2;
    a[2][0] = 1.0 / (c1 * ii);
    a[2][1] = -1.0 / ii;
    a[2][2] = -p->hyd_R_i / ii;
    b[0] = b[1] = b[3] = 0.0;
    b[2] = p->hyd_Ap / (c1 * ii);
    if (p->hyd_I_d > 0.0) {
        double id = p->hyd_I_d;
        a[3][0] = 1.0 / (c1 * id);
        a[3][1] = -1.0 / id;
        a[3][2] = 0.0;
        a[3][3] = -p->hyd_R_d / id;
        b[3] = p->hyd_Ap / (c1 * id);
    } else {
        a[0][3] = a[1][3] = 0.0;
    }
}

/* linear_branches._matmul: out = x y, every entry an fsum of its n products */
static void matmul(int n, double x[AUG][AUG], double y[AUG][AUG], double out[AUG][AUG])
{
    double prod[AUG], tmp[AUG][AUG];
    int i, j, k;
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            for (k = 0; k < n; ++k)
                prod[k] = x[i][k] * y[k][j];
            tmp[i][j] = ml_fsum(prod, n);
        }
    memcpy(out, tmp, sizeof tmp);
}

/* The off-diagonal absolute sums of column i (col) and row i (row) of a. */
static void off_sums(int n, double a[AUG][AUG], int i, double *col, double *row)
{
    double cs[AUG], rs[AUG];
    int k, m = 0;
    for (k = 0; k < n; ++k) {
        if (k == i)
            continue;
        cs[m] = fabs(a[k][i]);
        rs[m++] = fabs(a[i][k]);
    }
    *col = ml_fsum(cs, m);
    *row = ml_fsum(rs, m);
}

/* _expm's Parlett-Reinsch balancing with powers of two: a = D^-1 m D, d = diag D */
static void balance(int n, double a[AUG][AUG], double d[AUG])
{
    int it, i, k, done;
    for (it = 0; it < 20; ++it) {
        done = 1;
        for (i = 0; i < n; ++i) {
            double c, r, f = 1.0;
            off_sums(n, a, i, &c, &r);
            if (c == 0.0 || r == 0.0)
                continue;
            while (c < r / 2.0) {
                c = c * 2.0;
                r = r / 2.0;
                f = f * 2.0;
            }
            while (c > r * 2.0) {
                c = c / 2.0;
                r = r * 2.0;
                f = f / 2.0;
            }
            if (f != 1.0) {
                done = 0;
                d[i] *= f;
                for (k = 0; k < n; ++k) {
                    a[i][k] /= f;
                    a[k][i] *= f;
                }
            }
        }
        if (done)
            break;
    }
}

/* linear_branches._expm: exp(m) into out */
static void expm(int n, double m[AUG][AUG], double out[AUG][AUG])
{
    double a[AUG][AUG], term[AUG][AUG], d[AUG], row[AUG], norm = 0.0, scale;
    int i, j, k, s = 0;
    memcpy(a, m, sizeof a);
    for (i = 0; i < n; ++i)
        d[i] = 1.0;
    balance(n, a, d);
    for (i = 0; i < n; ++i) {
        double x;
        for (j = 0; j < n; ++j)
            row[j] = fabs(a[i][j]);
        x = ml_fsum(row, n);
        if (i == 0 || x > norm)
            norm = x;
    }
    while (norm > 0.25) {
        norm /= 2.0;
        s += 1;
    }
    scale = ldexp(1.0, -s);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            a[i][j] = a[i][j] * scale;
            out[i][j] = term[i][j] = i == j ? 1.0 : 0.0;
        }
    for (k = 1; k < 19; ++k) {
        matmul(n, term, a, term);
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) {
                term[i][j] = term[i][j] / k;
                out[i][j] = out[i][j] + term[i][j];
            }
    }
    for (k = 0; k < s; ++k)
        matmul(n, out, out, out);
    for (i = 0; i < n; ++i)   /* undo the balancing */
        for (j = 0; j < n; ++j)
            out[i][j] = out[i][j] * d[i] / d[j];
}

static void fluid_key(const ml_axis_params *p, double key[7])
{
    key[0] = p->hyd_Ap;
    key[1] = p->hyd_C1;
    key[2] = p->hyd_C2;
    key[3] = p->hyd_I_i;
    key[4] = p->hyd_R_i;
    key[5] = p->hyd_I_d;
    key[6] = p->hyd_R_d;
}

void ml_fluid_propagator(const ml_axis_params *p, double dt, ml_fluid_prop *out)
{
    double a[4][4], b[4], m[AUG][AUG], e[AUG][AUG];
    int i, j, n = ML_FLUID_STATE;
    fluid_matrices(p, a, b);
    memset(m, 0, sizeof m);
    for (i = 0; i < n; ++i) {
        for (j = 0; j < n; ++j)
            m[i][j] = a[i][j] * dt;
        m[i][n] = b[i] * dt;
    }
    m[n][n + 1] = dt;
    expm(AUG, m, e);
    for (i = 0; i < n; ++i) {
        for (j = 0; j < n; ++j)
            out->phi[i][j] = e[i][j];
        out->g0[i] = e[i][n];
        out->g1[i] = e[i][n + 1];   /* the coefficient of the rate r */
    }
    out->dt = dt;
    fluid_key(p, out->key);
    out->valid = 1;
}

const ml_fluid_prop *ml_fluid_cached(const ml_axis_params *p, double dt,
                                     ml_fluid_prop *cache, ml_fluid_prop *scratch)
{
    double key[7];
    if (cache == NULL) {
        ml_fluid_propagator(p, dt, scratch);
        return scratch;
    }
    fluid_key(p, key);
    if (!(cache->valid == 1 && cache->dt == dt
          && memcmp(cache->key, key, sizeof key) == 0))
        ml_fluid_propagator(p, dt, cache);
    return cache;
}

void ml_fluid_relaxed(const ml_axis_params *p, double u, double *x)
{
    double pr = p->hyd_Ap * u / (p->hyd_C1 + p->hyd_C2);
    x[0] = p->hyd_C1 * pr - p->hyd_Ap * u;
    x[1] = pr;
    x[2] = x[3] = 0.0;
}

void ml_fluid_step(const ml_axis_params *p, const ml_fluid_prop *prop,
                   const double *x0, double uc, double u, double dt, double *x,
                   double *f, double *kt)
{
    double ap = p->hyd_Ap, c1 = p->hyd_C1, r, terms[6], out[ML_FLUID_STATE];
    int i;
    if (prop == NULL || dt <= 0.0) {
        for (i = 0; i < ML_FLUID_STATE; ++i)
            out[i] = x0[i];
        *f = ap * (out[0] + ap * u) / c1;
        *kt = ap * ap / c1;
        memcpy(x, out, sizeof out);
        return;
    }
    r = (u - uc) / dt;
    for (i = 0; i < ML_FLUID_STATE; ++i) {
        terms[0] = prop->phi[i][0] * x0[0];
        terms[1] = prop->phi[i][1] * x0[1];
        terms[2] = prop->phi[i][2] * x0[2];
        terms[3] = prop->phi[i][3] * x0[3];
        terms[4] = prop->g0[i] * uc;
        terms[5] = prop->g1[i] * r;
        out[i] = ml_fsum(terms, 6);
    }
    *f = ap * (out[0] + ap * u) / c1;
    *kt = ap * (ap + prop->g1[0] / dt) / c1;
    memcpy(x, out, sizeof out);   /* x may be x0 */
}

int ml_hydraulic_problems(const ml_axis_params *p, const char *prefix, char *buf,
                          size_t size, int count)
{
    static const char *const names[7] = {"hyd_Ap", "hyd_C1", "hyd_C2", "hyd_I_i",
                                         "hyd_R_i", "hyd_I_d", "hyd_R_d"};
    double values[7];
    char text[320], val[40];
    int i, added = 0, on = isfinite(p->hyd_Ap) && p->hyd_Ap > 0.0;
    fluid_key(p, values);
    for (i = 0; i < 7; ++i) {
        int positive = i >= 1 && i <= 3;   /* C1, C2, I_i */
        ml_repr_double(values[i], val, sizeof val);
        if (!(isfinite(values[i]) && values[i] >= 0.0))
            snprintf(text, sizeof text, "`%s%s` must be finite and >= 0 (the "
                     "hydraulic fluid path; hyd_Ap = 0: absent), got %s", prefix,
                     names[i], val);
        else if (on && positive && values[i] == 0.0)
            snprintf(text, sizeof text, "`%s%s` must be > 0 when `%shyd_Ap` > 0 (a "
                     "fluid mount needs two compliant chambers and an inertia "
                     "track), got %s", prefix, names[i], prefix, val);
        else
            continue;
        ml_append_problem(buf, size, &count, text);
        ++added;
    }
    return added;
}
