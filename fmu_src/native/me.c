/* Model Exchange of the native FrictionMount (see me.h). */
#include "me.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "maxwell.h"
#include "friction_table.h"  /* the element names (generated) */

/* How an axis's element is treated in Model Exchange. */
enum { MX_NONE = 0, MX_BANK, MX_INCLINED, MX_PATH, MX_DAHL, MX_LUGRE, MX_BERG };

static const char *const MX_STATE_NAMES[5] = {
    "Instantiated", "InitializationMode", "EventMode", "ContinuousTimeMode",
    "Terminated"};

/* The element class of axis p: a Jenkins bank (macro-, micro-slip, non-symmetric),
 * the inclined element, Dahl, LuGre, Berg; any other (elements registered later) is
 * rate independent with a memory of its last reversal: committed at reversals. Berg
 * is such an element whose dissipated energy is a continuous state (berg_power). */
static int mx_kind(const ml_axis_params *p)
{
    const char *name;
    if (!p->friction || p->friction_kind < 0 || p->friction_kind >= ML_N_FRICTION_KINDS)
        return MX_NONE;
    name = ML_ELEMENTS[p->friction_kind]->name;
    if (strcmp(name, "jenkins") == 0)
        return MX_BANK;
    if (strcmp(name, "inclined") == 0)
        return MX_INCLINED;
    if (strcmp(name, "dahl") == 0)
        return MX_DAHL;
    if (strcmp(name, "lugre") == 0)
        return MX_LUGRE;
    if (strcmp(name, "berg") == 0)
        return MX_BERG;
    return MX_PATH;
}

static int mx_continuous(int kind) { return kind == MX_DAHL || kind == MX_LUGRE; }

double mx_normal(const md_instance *m, int j)
{
    return m->d.n_set[j] ? m->d.n[j] : m->d.p[j].n0;
}

static double mx_sign(double x) { return x > 0.0 ? 1.0 : x < 0.0 ? -1.0 : 0.0; }

/* Which of MX_STATE_NAMES the instance is in. */
static int mx_state(const md_instance *m)
{
    switch (m->d.mode) {
    case MD_INSTANTIATED: return 0;
    case MD_INIT: return 1;
    case MD_STEP: return m->d.me.phase == MX_PHASE_CONTINUOUS ? 3 : 2;
    default: return 4;
    }
}

md_status mx_check(md_instance *m, const char *call, unsigned allowed)
{
    char list[160] = "";
    int i, s = mx_state(m);
    if (!m->model_exchange) {
        md_log(m, MD_ERROR, "%s is a Model Exchange function; this instance was "
               "instantiated for Co-Simulation", call);
        return MD_ERROR;
    }
    if (allowed & (1u << s))
        return MD_OK;
    for (i = 0; i < 5; ++i) {
        if (!(allowed & (1u << i)))
            continue;
        if (list[0])
            strcat(list, ", ");
        strcat(list, MX_STATE_NAMES[i]);
    }
    md_log(m, MD_ERROR, "%s is not allowed in state %s (allowed in: %s)", call,
           MX_STATE_NAMES[s], list);
    return MD_ERROR;
}

md_status mx_refuse_in_me(md_instance *m, const char *call)
{
    if (!m->model_exchange)
        return MD_OK;
    md_log(m, MD_ERROR, "%s is a Co-Simulation function; this instance was "
           "instantiated for Model Exchange", call);
    return MD_ERROR;
}

static void mx_invalidate(md_instance *m)
{
    m->valid[0] = m->valid[1] = m->valid[2] = 0;
}

/* ------------------------------------------------------------ the inclined element */

/* The regime the inclined element of axis j continues in from its committed state
 * in the direction of v: the end regime of a probe increment of 1e-10 of the
 * deflection (inclined.c decides at the start which surfaces slip). */
static void inclined_modes(md_instance *m, int j)
{
    in_params q = ml_inclined_params(&m->d.p[j]);
    double x = -m->d.u[j], *w = m->d.w[j];
    int dir = m->d.me.dir[j];
    in_step st;
    char msg[512];
    m->d.me.mode[j][0] = m->d.me.mode[j][1] = 0;
    if (dir == 0)
        return;
    if (in_update(x - dir * 1e-10 * (fabs(x) + 1e-3), x, w[0], w[1], &q, &st, msg,
                  sizeof msg) != IN_OK)
        return;  /* contact lost ahead: the outputs report it */
    m->d.me.mode[j][0] = (signed char)(st.slip1 ? (st.f1 >= 0 ? 1 : -1) : 0);
    m->d.me.mode[j][1] = (signed char)(st.slip2 ? (st.f2 >= 0 ? 1 : -1) : 0);
}

static void inclined_indicators(const md_instance *m, int j, double *zs, double *zr)
{
    in_params q = ml_inclined_params(&m->d.p[j]);
    const double *w = m->d.w[j];
    const signed char *mode = m->d.me.mode[j];
    double f[4], scale;
    int i, any_stuck = 0;
    in_forces(-m->d.u[j], w[0], w[1], &q, mode[0], mode[1], f);
    scale = fabs(f[0]) + fabs(f[1]) + q.preload;
    *zs = 1.0;
    for (i = 0; i < 2; ++i) {
        double mu = i == 0 ? q.mu1 : q.mu2, margin;
        if (mode[i] != 0 || isinf(mu))
            continue;
        margin = mu * f[2 + i] - fabs(f[i]) + 1e-9 * scale
                 + 64.0 * DBL_EPSILON * (i == 0 ? q.kf : q.kf2)
                   * (fabs(m->d.u[j]) + fabs(w[i]));
        if (!any_stuck || margin < *zs)
            *zs = margin;
        any_stuck = 1;
    }
    *zr = mode[0] || mode[1] ? m->d.me.dir[j] * m->d.v[j] : 1.0;
}

/* ------------------------------------------------------------ Berg's energy */

/* Berg's element of axis j from its committed state to the present u (the
 * Co-Simulation trial of berg.c): its force and tangent dF/du into *out. */
static void berg_trial(const md_instance *m, int j, ml_friction_step *out)
{
    const ml_axis_params *p = &m->d.p[j];
    double w_new[ML_MAX_STATE];
    char msg[8];
    if (ML_ELEMENTS[p->friction_kind]->step(m->d.u[j], m->d.v[j], m->d.w[j], p,
                                             ml_slip_force(p, mx_normal(m, j)), 0.0,
                                             w_new, out, msg, sizeof msg))
        out->force = out->tangent = 0.0;  /* not reached: Berg never refuses */
}

/* d Eb / dt of Berg's element (docs/fmu.md 7a): the positive part of its energy
 * rate at constant n, F v - F dF/dt / kf = F v (1 - kt / kf): the limit of
 * Co-Simulation's energy, whose increments berg.c clamps at 0. */
static double berg_power(const md_instance *m, int j)
{
    ml_friction_step st;
    double rate;
    berg_trial(m, j, &st);
    rate = st.force * m->d.v[j] * (1.0 - st.tangent / m->d.p[j].kf);
    return rate > 0.0 ? rate : 0.0;
}

/* ------------------------------------------------------------ Dahl and LuGre */

typedef struct {
    double ffr;      /* friction force, N */
    double dz;       /* dz/dt, m/s */
    double power;    /* dissipated power, W */
    double tangent;  /* dF/du along the motion, N/m */
} mx_rates;

static void continuous_rates(const md_instance *m, int j, int kind, mx_rates *r)
{
    const ml_axis_params *p = &m->d.p[j];
    double fc = ml_slip_force(p, mx_normal(m, j)), v = m->d.v[j];
    double z = m->d.me.x[j][0], kf = p->kf, g = fc, s1 = 0.0, s2 = 0.0, a;
    int dir = m->d.me.dir[j];
    if (fc <= 0.0) {  /* lost contact: no friction (the bristle resets at the event) */
        r->ffr = r->dz = r->power = r->tangent = 0.0;
        return;
    }
    if (kind == MX_LUGRE) {  /* lugre._stribeck */
        double xs = v / p->v_stribeck, e = exp(-(xs * xs));
        if (e != 0.0)
            g = fc + (p->stribeck_ratio * fc - fc) * e;
        s1 = p->sigma1;
        s2 = p->sigma2;
    }
    /* |v|, continued smoothly past a reversal until its event */
    a = dir != 0 ? dir * v : fabs(v);
    r->dz = v - kf * a * z / g;
    r->ffr = kf * z + s1 * r->dz + s2 * v;
    r->power = r->ffr * v - kf * z * r->dz;
    r->tangent = (kf - s1 * kf * fabs(v) / g) * (1.0 - mx_sign(v) * kf * z / g);
}

/* The outputs of the continuous elements from the states (into the instance's
 * cached trial results, which md_get reads). */
static md_status refresh(md_instance *m, const char *call)
{
    int j;
    for (j = 0; j < 3; ++j) {
        const ml_axis_params *p = &m->d.p[j];
        int kind = mx_kind(p);
        double f_el, k_el, u = m->d.u[j], v = m->d.v[j], z = m->d.me.x[j][0];
        mx_rates r;
        ml_axis_result *res = &m->res[j];
        if (kind == MX_BERG || kind == MX_BANK) {  /* the trial, its energy from
                                                      the state */
            if (md_evaluate(m, call, j) != MD_OK)
                return MD_ERROR;
            res->dissipated = kind == MX_BERG ? m->d.me.x[j][1] - m->d.e[j]
                              : mx_bank_dissipated(m, j);
            continue;
        }
        if (!mx_continuous(kind))
            continue;
        ml_elastic_force(u, p->law, p->k1, p->kc, p->k2, p->delta, p->delta_neg,
                         &f_el, &k_el);
        continuous_rates(m, j, kind, &r);
        res->friction = r.ffr;
        res->force = f_el + p->c * v + r.ffr;
        res->tangent = k_el + r.tangent;
        res->slipping = v != 0.0;
        res->dissipated = m->d.me.x[j][1] - m->d.e[j];
        res->w_new = u;
        m->w_new[j][0] = kind == MX_DAHL ? p->kf * z : z;
        m->w_new[j][1] = u;
        if (!(isfinite(res->force) && isfinite(res->tangent)
              && isfinite(res->dissipated))) {
            md_log(m, MD_ERROR, "FrictionMount: outputs of axis %d are not finite at "
                   "the continuous state z=%g, E=%g (in %s)", j, z,
                   m->d.me.x[j][1], call);
            return MD_ERROR;
        }
        m->valid[j] = 1;
    }
    return MD_OK;
}

/* ------------------------------------------------------------ events */

static md_status commit(md_instance *m, const char *call, int j)
{
    ml_axis_result r;
    double w_new[ML_MAX_STATE];  /* sliders + uc + Maxwell strokes (ml_state_size) */
    char msg[512];
    int n = ml_state_size(&m->d.p[j]);
    if (ml_axis_force_p(m->d.u[j], m->d.v[j], 0.0, m->d.w[j], &m->d.p[j],
                        mx_normal(m, j), w_new, &r, msg, sizeof msg)) {
        md_log(m, MD_ERROR, "FrictionMount: axis %d at u=%g: %s (in %s)", j,
               m->d.u[j], msg, call);
        return MD_ERROR;
    }
    memcpy(m->d.w[j], w_new, n * sizeof(double));
    m->d.e[j] += r.dissipated;
    return MD_OK;
}

md_status mx_update(md_instance *m, const char *call, int *changed)
{
    int j;
    *changed = 0;
    if (mx_check(m, call, MX_AT_EVENT) != MD_OK)
        return MD_ERROR;
    if (!m->params_ok)  /* cannot happen after initialization; the guard of md_get */
        return MD_ERROR;
    for (j = 0; j < 3; ++j) {
        const ml_axis_params *p = &m->d.p[j];
        int kind = mx_kind(p);
        double n_last = m->d.me.n_event[j];
        m->d.me.dir[j] = (signed char)mx_sign(m->d.v[j]);
        m->d.me.n_event[j] = mx_normal(m, j);
        if (kind == MX_NONE)
            continue;
        if (mx_continuous(kind)) {
            double z = m->d.me.x[j][0];
            if (ml_slip_force(p, mx_normal(m, j)) <= 0.0 && z != 0.0) {
                /* lost contact: the bristle's stored energy is released */
                m->d.me.x[j][1] += p->kf * z * z / 2.0;
                m->d.me.x[j][0] = 0.0;
                *changed = 1;
            }
            m->d.w[j][0] = kind == MX_DAHL ? p->kf * m->d.me.x[j][0]
                                           : m->d.me.x[j][0];
            m->d.w[j][1] = m->d.u[j];
            continue;
        }
        if (kind == MX_BERG) {
            double e0 = m->d.e[j];
            if (commit(m, call, j) != MD_OK)
                return MD_ERROR;
            if (ml_slip_force(p, mx_normal(m, j)) <= 0.0 && m->d.e[j] != e0) {
                /* lost contact: the stored energy is released (berg.c) */
                m->d.me.x[j][1] += m->d.e[j] - e0;
                *changed = 1;
            }
            m->d.e[j] = m->d.me.x[j][1];
            continue;
        }
        if (kind == MX_BANK) {  /* the energy since the last event (bank_dissipated) */
            double e0 = m->d.e[j], diss;
            if (md_evaluate(m, call, j) != MD_OK)
                return MD_ERROR;
            diss = mx_bank_dissipated(m, j);
            if (commit(m, call, j) != MD_OK)
                return MD_ERROR;
            mx_bank_event_energy(m, j, e0, diss, n_last);
            mx_bank_rate(m, j, n_last);
            mx_bank_modes(m, j);
            continue;
        }
        if (commit(m, call, j) != MD_OK)
            return MD_ERROR;
        if (kind == MX_INCLINED)
            inclined_modes(m, j);
    }
    m->d.me.iterated = 1;
    mx_invalidate(m);
    return MD_OK;
}

md_status mx_indicators(md_instance *m, const char *call, double *z, size_t n)
{
    int j;
    if (mx_check(m, call, MX_AT_INIT | MX_AT_EVENT | MX_AT_CONTINUOUS
                 | MX_AT_TERMINATED) != MD_OK)
        return MD_ERROR;
    if (n != MX_N_INDICATORS) {
        md_log(m, MD_ERROR, "%s: the model has %d event indicators, got %u", call,
               MX_N_INDICATORS, (unsigned)n);
        return MD_ERROR;
    }
    for (j = 0; j < 3; ++j) {
        double *zs = &z[MX_INDICATORS_PER_AXIS * j], *zr = zs + 1;
        int kind = m->params_ok ? mx_kind(&m->d.p[j]) : MX_NONE;
        *zs = *zr = 1.0;
        if (kind == MX_BANK)
            mx_bank_indicators(m, j, zs, zr);
        else if (kind == MX_INCLINED)
            inclined_indicators(m, j, zs, zr);
        if (kind == MX_BERG && m->d.me.dir[j] != 0) {
            /* the sign of the energy rate: F against the motion after a reversal */
            ml_friction_step st;
            berg_trial(m, j, &st);
            *zs = m->d.me.dir[j] * st.force;
        }
        if (kind != MX_NONE && kind != MX_BANK && kind != MX_INCLINED)
            *zr = m->d.me.dir[j] != 0 ? m->d.me.dir[j] * m->d.v[j] : m->d.v[j];
    }
    return MD_OK;
}

md_status mx_completed_step(md_instance *m, const char *call, int *enter_event)
{
    int j;
    *enter_event = 0;
    if (mx_check(m, call, MX_AT_CONTINUOUS) != MD_OK)
        return MD_ERROR;
    for (j = 0; j < 3; ++j) {
        int kind = mx_kind(&m->d.p[j]);
        if (kind != MX_NONE && !mx_continuous(kind)
                && mx_normal(m, j) != m->d.me.n_event[j])
            *enter_event = 1;
    }
    return MD_OK;
}

md_status mx_enter_event_mode(md_instance *m, const char *call)
{
    if (mx_check(m, call, MX_AT_EVENT | MX_AT_CONTINUOUS) != MD_OK)
        return MD_ERROR;
    m->d.me.phase = MX_PHASE_EVENT;
    return MD_OK;
}

md_status mx_enter_continuous_mode(md_instance *m, const char *call)
{
    if (mx_check(m, call, MX_AT_EVENT) != MD_OK)
        return MD_ERROR;
    m->d.me.phase = MX_PHASE_CONTINUOUS;
    return MD_OK;
}

/* ------------------------------------------------------------ states */

md_status mx_set_time(md_instance *m, const char *call, double t)
{
    if (mx_check(m, call, MX_AT_EVENT | MX_AT_CONTINUOUS) != MD_OK)
        return MD_ERROR;
    if (!isfinite(t)) {
        md_log(m, MD_ERROR, "%s: time must be finite, got %g", call, t);
        return MD_ERROR;
    }
    m->d.time = t;
    m->last_time_ok = t;
    return MD_OK;
}

static md_status count_ok(md_instance *m, const char *call, size_t n)
{
    if (n == MX_N_STATES)
        return MD_OK;
    md_log(m, MD_ERROR, "%s: the model has %d continuous states, got %u", call,
           MX_N_STATES, (unsigned)n);
    return MD_ERROR;
}

md_status mx_set_states(md_instance *m, const char *call, const double *x, size_t n)
{
    size_t i;
    if (mx_check(m, call, MX_AT_CONTINUOUS) != MD_OK || count_ok(m, call, n) != MD_OK)
        return MD_ERROR;
    for (i = 0; i < n; ++i)
        if (!isfinite(x[i])) {
            md_log(m, MD_ERROR, "%s: continuous state %u must be finite, got %g", call,
                   (unsigned)i, x[i]);
            return MD_ERROR;
        }
    memcpy(m->d.me.x, x, n * sizeof(double));
    mx_invalidate(m);
    return MD_OK;
}

md_status mx_get_states(md_instance *m, const char *call, double *x, size_t n)
{
    if (mx_check(m, call, MX_AT_ANY) != MD_OK || count_ok(m, call, n) != MD_OK)
        return MD_ERROR;
    memcpy(x, m->d.me.x, n * sizeof(double));
    return MD_OK;
}

md_status mx_derivatives(md_instance *m, const char *call, double *dx, size_t n)
{
    int j;
    if (mx_check(m, call, MX_AT_INIT | MX_AT_EVENT | MX_AT_CONTINUOUS
                 | MX_AT_TERMINATED) != MD_OK || count_ok(m, call, n) != MD_OK)
        return MD_ERROR;
    for (j = 0; j < 3; ++j) {
        int kind = m->params_ok ? mx_kind(&m->d.p[j]) : MX_NONE;
        mx_rates r;
        dx[2 * j] = dx[2 * j + 1] = 0.0;
        if (kind == MX_BERG)
            dx[2 * j + 1] = berg_power(m, j);
        if (kind == MX_BANK && m->d.me.n_varies[j]) {  /* its friction's power */
            if (md_evaluate(m, call, j) != MD_OK)
                return MD_ERROR;
            dx[2 * j + 1] = m->res[j].friction * m->d.v[j];
        }
        if (!mx_continuous(kind))
            continue;
        continuous_rates(m, j, kind, &r);
        dx[2 * j] = r.dz;
        dx[2 * j + 1] = r.power;
    }
    return MD_OK;
}

md_status mx_nominals(md_instance *m, const char *call, double *x, size_t n)
{
    int j;
    if (mx_check(m, call, MX_AT_ANY) != MD_OK || count_ok(m, call, n) != MD_OK)
        return MD_ERROR;
    for (j = 0; j < 3; ++j) {
        /* the slip displacement Fs / kf and the energy Fs^2 / kf of the start
         * normal force n0 (1e-4 m and 1e-3 J without one) */
        const ml_axis_params *p = &m->d.p[j];
        double fs = p->mu * p->n0;
        int scaled = isfinite(fs) && fs > 0.0 && p->kf > 0.0
                     && isfinite(fs * fs / p->kf) && fs * fs / p->kf > 0.0;
        x[2 * j] = scaled ? fs / p->kf : 1e-4;
        x[2 * j + 1] = scaled ? fs * fs / p->kf : 1e-3;
    }
    return MD_OK;
}

/* ------------------------------------------------------------ values */

static int is_me_role(md_role role)
{
    return role == MX_ROLE_Z || role == MX_ROLE_E || role == MX_ROLE_DZ
           || role == MX_ROLE_DE || role == MX_ROLE_STICK || role == MX_ROLE_REVERSE;
}

static int reads_law(md_role role)
{
    switch (role) {
    case MD_PARAMETER: case MD_INPUT_U: case MD_INPUT_V: case MD_INPUT_N:
    case MD_LOCAL_W: case MD_TIME:
        return 0;
    default:
        return 1;
    }
}

md_status mx_get(md_instance *m, const char *call, md_type type, unsigned vr,
                 double *value)
{
    const md_variable *var = md_variable_at(vr);
    md_status status;
    if (var == NULL || var->type != type)
        return md_get(m, call, type, vr, value);  /* its messages */
    if (is_me_role(var->role)) {
        double buf[MX_N_INDICATORS > MX_N_STATES ? MX_N_INDICATORS : MX_N_STATES];
        int j = var->axis, saved = m->model_exchange;
        *value = 0.0;
        if (var->role == MX_ROLE_Z || var->role == MX_ROLE_E) {
            *value = m->d.me.x[j][var->role == MX_ROLE_E];
            return MD_OK;
        }
        m->model_exchange = 1;  /* readable also in a Co-Simulation instance */
        if (var->role == MX_ROLE_DZ || var->role == MX_ROLE_DE) {
            status = m->d.mode == MD_INSTANTIATED ? MD_OK
                     : mx_derivatives(m, call, buf, MX_N_STATES);
            if (status == MD_OK && m->d.mode != MD_INSTANTIATED)
                *value = buf[2 * j + (var->role == MX_ROLE_DE)];
        } else {
            status = m->d.mode == MD_INSTANTIATED ? MD_OK
                     : mx_indicators(m, call, buf, MX_N_INDICATORS);
            *value = 1.0;
            if (status == MD_OK && m->d.mode != MD_INSTANTIATED)
                *value = buf[MX_INDICATORS_PER_AXIS * j
                             + (var->role == MX_ROLE_REVERSE)];
        }
        m->model_exchange = saved;
        return status;
    }
    if (m->model_exchange && reads_law(var->role)) {
        if (!m->params_ok) {  /* md_get checks them (and warns before the end of
                                 initialization) */
            status = md_get(m, call, type, vr, value);
            if (status != MD_OK || !m->params_ok)
                return status;
        }
        if (refresh(m, call) != MD_OK) {
            *value = 0.0;
            return MD_ERROR;
        }
    }
    return md_get(m, call, type, vr, value);
}
