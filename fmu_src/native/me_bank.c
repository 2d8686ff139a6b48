/* Model Exchange of the native FrictionMount's Jenkins banks (macro-, micro-slip,
 * non-symmetric; see me.h): the stick/slip modes decided at an event, the event
 * indicators, the dissipated energy under a varying normal force and the estimate of
 * the slip force's rate. Split from me.c (the interface: states, events, values). */
#include "me.h"

#include <float.h>
#include <math.h>

#include "maxwell.h"

/* Slider i of axis p's bank with slip force fs (jenkins.c's arithmetic): stiffness,
 * slip forces towards +u and -u. */
static void bank_slider(const ml_axis_params *p, double fs, int i, double *k,
                        double *fp, double *fn)
{
    int n = p->sliders;
    if (n > 1) {
        double ri = 1.0 + p->spread * ((double)(2 * i + 1) / n - 1.0);
        *k = p->kf / n;
        *fp = fs * ri / n;
        *fn = fs * ri * p->fs_ratio / n;
    } else {
        *k = p->kf;
        *fp = fs;
        *fn = p->fs_ratio != 1.0 ? fs * p->fs_ratio : fs;
    }
}

/* The slack of a margin: relative 1e-9 of the slip forces plus the rounding of
 * k (u - w). Indicators carry it, so that a slider committed at its limit (a
 * reversal) starts with a positive margin. */
static double bank_slack(double k, double fp, double fn, double u, double w)
{
    return 1e-9 * (fp + fn) + 64.0 * DBL_EPSILON * k * (fabs(u) + fabs(w));
}

/* Which sliders of axis j's bank slip from the committed state on: a slider at its
 * limit slips on while its force, held, would pass the limit: k v > dFp/dt (towards
 * +u), k v < -dFn/dt (towards -u). At constant n that is the sign of v; under a
 * varying n a falling limit keeps a slider slipping after a reversal (fs_rate, the
 * estimate of mx_update). */
void mx_bank_modes(md_instance *m, int j)
{
    const ml_axis_params *p = &m->d.p[j];
    double fs = ml_slip_force(p, mx_normal(m, j)), u = m->d.u[j], v = m->d.v[j];
    double rate = m->d.me.n_varies[j] ? m->d.me.fs_rate[j] : 0.0;
    /* the sliders only: not uc and the Maxwell strokes after them (mode[j] holds
     * ML_MAX_SLIDERS entries) */
    int i, n = ml_inner_size(p, ml_state_size(p));
    for (i = 0; i < n; ++i) {
        double k, fp, fn, rp, rn, w = m->d.w[j][i], trial, tol;
        bank_slider(p, fs, i, &k, &fp, &fn);
        bank_slider(p, rate, i, &k, &rp, &rn);  /* the limits' rates (linear in fs) */
        trial = k * (u - w);
        tol = bank_slack(k, fp, fn, u, w);
        m->d.me.mode[j][i] = (signed char)(trial >= fp - tol && k * v > rp ? 1
                                           : trial <= -fn + tol && k * v < -rn ? -1
                                           : 0);
    }
}

/* Under a varying n: the least slip rate of the slipping sliders of axis j, in the
 * direction of their slip (v - dFp/dt / k towards +u, -v - dFn/dt / k towards -u,
 * with mx_update's estimate of dFs/dt) [m/s]; its sign change is where bank_modes
 * lets the slider stick. */
static double bank_slip_rate(const md_instance *m, int j)
{
    const ml_axis_params *p = &m->d.p[j];
    double least = 0.0, v = m->d.v[j];
    int i, n = ml_inner_size(p, ml_state_size(p)), any = 0;
    for (i = 0; i < n; ++i) {
        double k, rp, rn, g;
        if (m->d.me.mode[j][i] == 0)
            continue;
        bank_slider(p, m->d.me.fs_rate[j], i, &k, &rp, &rn);
        g = m->d.me.mode[j][i] > 0 ? v - rp / k : -v - rn / k;
        if (!any || g < least)
            least = g;
        any = 1;
    }
    return least;
}

void mx_bank_indicators(const md_instance *m, int j, double *zs, double *zr)
{
    const ml_axis_params *p = &m->d.p[j];
    double fs = ml_slip_force(p, mx_normal(m, j)), u = m->d.u[j];
    int i, n = ml_inner_size(p, ml_state_size(p)), any_stuck = 0, any_slip = 0;
    *zs = 1.0;
    for (i = 0; i < n; ++i) {
        double k, fp, fn, w = m->d.w[j][i], trial, margin;
        if (m->d.me.mode[j][i] != 0) {
            any_slip = 1;
            continue;
        }
        bank_slider(p, fs, i, &k, &fp, &fn);
        trial = k * (u - w);
        margin = fmin(fp - trial, trial + fn) + bank_slack(k, fp, fn, u, w);
        if (!any_stuck || margin < *zs)
            *zs = margin;
        any_stuck = 1;
    }
    *zr = any_slip ? m->d.me.dir[j] * m->d.v[j] : 1.0;
    if (any_slip && m->d.me.n_varies[j])
        *zr = bank_slip_rate(m, j);
}

/* The elastic energy sum k_i (u - w_i)^2 / 2 the sliders at w of axis j's bank
 * store at the present u. */
static double bank_stored(const md_instance *m, int j, const double *w)
{
    const ml_axis_params *p = &m->d.p[j];
    int i, n = p->sliders > 1 ? p->sliders : 1;
    double k = n > 1 ? p->kf / n : p->kf, u = m->d.u[j], sum = 0.0;
    for (i = 0; i < n; ++i)
        sum += k * (u - w[i]) * (u - w[i]) / 2.0;
    return sum;
}

/* The energy axis j's bank dissipated since the last event, at the cached trial
 * m->res[j] / m->w_new[j]: the integral of F dw over the slip. While n has not
 * varied, jenkins.c's slip force times the slip (Co-Simulation's increment, exact
 * at constant n; Eb stays 0, so fmpy's input table, whose derivatives see stale
 * inputs, is fine); once it has, the work of the friction force since (Eb,
 * integrated) less the change of the sliders' elastic energy, exact for any path
 * of u and n (Co-Simulation's increment takes the slip force at the step's end:
 * first order in the step). */
double mx_bank_dissipated(const md_instance *m, int j)
{
    const md_me *me = &m->d.me;
    if (!me->n_varies[j])
        return m->res[j].dissipated;
    return (me->x[j][1] - me->work_event[j])
           - (bank_stored(m, j, m->w_new[j]) - me->stored_event[j]);
}

/* An event of axis j's bank: the energy since the last one (bank_dissipated) added
 * to its committed energy e0; whether n varied since (n_last there; by more than
 * its rounding: fmpy's input table interpolates a constant column to 1 ulp); Eb and
 * the sliders' elastic energy of the committed state. */
void mx_bank_event_energy(md_instance *m, int j, double e0, double diss,
                              double n_last)
{
    md_me *me = &m->d.me;
    m->d.e[j] = e0 + diss;
    if (me->iterated && fabs(mx_normal(m, j) - n_last) > 1e-12 * fabs(n_last))
        me->n_varies[j] = 1;
    me->work_event[j] = me->x[j][1];
    me->stored_event[j] = bank_stored(m, j, m->d.w[j]);
}

/* The estimate of axis j's dFs/dt at an event: the change of the slip force since
 * the last event at an earlier time (n_last there) over the time between (kept
 * through an event iteration's repeated updates at one time). */
void mx_bank_rate(md_instance *m, int j, double n_last)
{
    md_me *me = &m->d.me;
    const ml_axis_params *p = &m->d.p[j];
    double t = m->d.time;
    if (!(t > me->t_event[j]))
        return;
    me->fs_rate[j] = (ml_slip_force(p, mx_normal(m, j)) - ml_slip_force(p, n_last))
                     / (t - me->t_event[j]);
    me->t_event[j] = t;
}
