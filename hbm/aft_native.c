/* The harmonic-form AFT's two compiled kernels (hbm/aft_native.py) in C: the
 * sampled elastic remainders, the Jenkins march and the tangent's sums
 * (dm_aft_samples), and the slip memory's rank-one terms (dm_slip_memory).
 *
 * The same floating-point operations in the same order as the numba kernels of
 * hbm/friction_march_numba.py (_column, _aft_samples, _slip_memory), which are those
 * of the NumPy code (hbm.laws, hbm.aft): the same numbers bit for bit
 * (tests/test_hbm_aft_native.py). Compiled with -ffp-contract=off (no fused
 * multiply-adds) and without -ffast-math; at -O3 GCC vectorises only the
 * elementwise loops (the same operations per element).
 *
 * Arrays are C-ordered: u, f, kt (nb, N, n_ax); stuck (bytes 0/1), last (nb, N, C);
 * dF (nb, n_ax, m, m); cum (N + 1, m); E (N, m). */
#include <stdint.h>

typedef int64_t i64;

/* hbm.friction_march_numba._column: the periodic Jenkins march of one column */
static void column(const double *restrict u, i64 n, double kf, double fs,
                   double w_start, double *restrict force,
                   unsigned char *restrict stuck, i64 *restrict last_slip)
{
    double eps = fs / kf;
    i64 i_max = 0, i_min = 0, start, last;
    double w;
    for (i64 i = 1; i < n; i++) {
        if (u[i] > u[i_max]) i_max = i;
        if (u[i] < u[i_min]) i_min = i;
    }
    if (u[i_max] - u[i_min] > 2.0 * eps) {
        start = i_max;
        w = u[i_max] - eps;
        last = i_max;
    } else {
        start = 0;
        w = w_start;
        last = -1;
        for (i64 i = 0; i < n; i++) {
            double trial = kf * (u[i] - w);
            if (trial > fs) {
                w = u[i] - fs / kf;
                last = i;
            } else if (trial < -fs) {
                w = u[i] + fs / kf;
                last = i;
            }
        }
    }
    for (i64 j = 0; j < n; j++) {
        i64 i = start + j;
        if (i >= n) i -= n;
        double trial = kf * (u[i] - w);
        if (trial > fs) {
            force[i] = fs;
            w = u[i] - fs / kf;
            last = i;
            stuck[i] = 0;
        } else if (trial < -fs) {
            force[i] = -fs;
            w = u[i] + fs / kf;
            last = i;
            stuck[i] = 0;
        } else {
            force[i] = trial;
            stuck[i] = 1;
        }
        last_slip[i] = last;
    }
}

/* hbm.friction_march_numba._aft_samples; scratch: force, col (N doubles), cstuck (N
 * bytes), clast (N i64) */
void dm_aft_samples(i64 nb, i64 N, i64 n_ax, const double *restrict u,
                    const i64 *restrict code, const double *restrict p1,
                    const double *restrict p2, const double *restrict p3, i64 C,
                    const i64 *restrict fr, const double *restrict kf,
                    const double *restrict fs, const double *restrict w_start,
                    double *restrict f, double *restrict kt,
                    unsigned char *restrict stuck, i64 *restrict last,
                    double *restrict force, unsigned char *restrict cstuck,
                    i64 *restrict clast, double *restrict col)
{
    for (i64 b = 0; b < nb; b++) {
        const double *ub = u + b * N * n_ax;
        double *fb = f + b * N * n_ax, *kb = kt + b * N * n_ax;
        for (i64 a = 0; a < n_ax; a++) {
            i64 c = code[a];
            if (c == 1) {  /* hbm.laws._gap_remainder: dk, delta, delta_neg */
                double dk = p1[a], dl = p2[a], dn = p3[a];
                for (i64 n = 0; n < N; n++) {
                    double x = ub[n * n_ax + a];
                    int hi = x > dl, lo = x < -dn;
                    double s1 = hi ? x - dl : 0.0;
                    double s2 = lo ? x + dn : 0.0;
                    fb[n * n_ax + a] = dk * (s1 + s2);
                    kb[n * n_ax + a] = dk * ((hi || lo) ? 1.0 : 0.0);
                }
            } else if (c == 2) {  /* hbm.laws._cubic_remainder: kc */
                double kc = p1[a];
                double k3 = 3.0 * kc;
                for (i64 n = 0; n < N; n++) {
                    double x = ub[n * n_ax + a];
                    fb[n * n_ax + a] = kc * x * x * x;
                    kb[n * n_ax + a] = k3 * x * x;
                }
            } else {
                for (i64 n = 0; n < N; n++) {
                    fb[n * n_ax + a] = 0.0;
                    kb[n * n_ax + a] = 0.0;
                }
            }
        }
        for (i64 j = 0; j < C; j++) {
            i64 a = fr[j];
            for (i64 n = 0; n < N; n++) col[n] = ub[n * n_ax + a];
            column(col, N, kf[j], fs[j], w_start[j], force, cstuck, clast);
            double k = kf[j];
            for (i64 n = 0; n < N; n++) {
                fb[n * n_ax + a] += force[n];
                kb[n * n_ax + a] += cstuck[n] ? k : 0.0;
                stuck[(b * N + n) * C + j] = cstuck[n];
                last[(b * N + n) * C + j] = clast[n];
            }
        }
    }
}

/* hbm.friction_march_numba._slip_memory: subtract, in place, per stick run after the
 * same last slip, (sum_run P[:, n]) kf E[last] from dF of its axis */
void dm_slip_memory(i64 nb, i64 N, i64 C, i64 n_ax, i64 m, double *restrict dF,
                    const unsigned char *restrict stuck, const i64 *restrict last,
                    const i64 *restrict fr, const double *restrict kf,
                    const double *restrict cum, const double *restrict E)
{
    for (i64 b = 0; b < nb; b++) {
        for (i64 j = 0; j < C; j++) {
            i64 a = fr[j];
            double k = kf[j];
            double *d = dF + (b * n_ax + a) * m * m;
            i64 n = 0;
            while (n < N) {
                i64 at = (b * N + n) * C + j;
                if (!(stuck[at] && last[at] >= 0)) {
                    n++;
                    continue;
                }
                i64 lst = last[at], n0 = n;
                n++;
                while (n < N && stuck[(b * N + n) * C + j]
                       && last[(b * N + n) * C + j] == lst)
                    n++;
                i64 n1 = n - 1;
                for (i64 h = 0; h < m; h++) {
                    double p = (cum[(n1 + 1) * m + h] - cum[n0 * m + h]) * k;
                    for (i64 g = 0; g < m; g++)
                        d[h * m + g] -= p * E[lst * m + g];
                }
            }
        }
    }
}

/* hbm.friction_march_numba._march: every column c of every motion b of u (nb, N, C)
 * marched (through contiguous copies: the same operations) */
void dm_march(i64 nb, i64 N, i64 C, const double *restrict u,
              const double *restrict kf, const double *restrict fs,
              const double *restrict w_start, double *restrict force,
              unsigned char *restrict stuck, i64 *restrict last,
              double *restrict col, double *restrict cforce,
              unsigned char *restrict cstuck, i64 *restrict clast)
{
    for (i64 b = 0; b < nb; b++) {
        for (i64 c = 0; c < C; c++) {
            i64 o = b * N * C + c;
            for (i64 n = 0; n < N; n++) col[n] = u[o + n * C];
            column(col, N, kf[c], fs[c], w_start[c], cforce, cstuck, clast);
            for (i64 n = 0; n < N; n++) {
                force[o + n * C] = cforce[n];
                stuck[o + n * C] = cstuck[n];
                last[o + n * C] = clast[n];
            }
        }
    }
}

/* hbm.friction_march_numba._samples: Z (nb, C, N, m) with dF = P Z */
void dm_samples(i64 nb, i64 N, i64 C, i64 m, const double *restrict E,
                const double *restrict kf, const unsigned char *restrict stuck,
                const i64 *restrict last, double *restrict Z)
{
    for (i64 b = 0; b < nb; b++) {
        for (i64 c = 0; c < C; c++) {
            double k = kf[c];
            for (i64 n = 0; n < N; n++) {
                double *z = Z + ((b * C + c) * N + n) * m;
                i64 at = (b * N + n) * C + c;
                if (stuck[at]) {
                    for (i64 g = 0; g < m; g++) z[g] = k * E[n * m + g];
                    i64 j = last[at];
                    if (j >= 0)
                        for (i64 g = 0; g < m; g++) z[g] -= k * E[j * m + g];
                } else {
                    for (i64 g = 0; g < m; g++) z[g] = 0.0;
                }
            }
        }
    }
}
