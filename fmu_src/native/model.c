/* The native FrictionMount instance (see model.h). */
#include "model.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "maxwell.h"
#include "model_variables.h"

static const char *const AXIS_NAMES[3] = {"axial", "radial1", "radial2"};

const char *md_axis_name(int j) { return AXIS_NAMES[j]; }
static const char *const TYPE_NAMES[3] = {"Real", "Integer", "Boolean"};
static const char *const MODE_NAMES[4] = {"Instantiated", "InitializationMode",
                                          "StepMode", "Terminated"};

/* The call-order rules of docs/fmu.md 4a, as fmu_src/fmi_state.py states them
 * (tests/test_native_fmu.py checks that the numbers agree): the largest
 * communication step [s] and the relative tolerance of a step's start time. */
#define MD_MAX_STEP_SIZE 1e6
#define MD_TIME_RTOL 1e-9

size_t md_n_variables(void) { return MD_N_VARIABLES; }

const char *md_instantiation_token(void) { return MD_INSTANTIATION_TOKEN; }

const md_variable *md_variable_at(size_t vr)
{
    return vr < MD_N_VARIABLES ? &MD_VARIABLES[vr] : NULL;
}

const char *md_mode_name(md_mode mode) { return MODE_NAMES[mode]; }

void md_log(md_instance *m, md_status status, const char *fmt, ...)
{
    char text[2048];
    va_list ap;
    static const char *const CATEGORY[5] = {"logAll", "logStatusWarning",
                                            "logStatusDiscard", "logStatusError",
                                            "logStatusFatal"};
    if (m->log == NULL || (status == MD_OK && !m->logging_on))
        return;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    m->log(m->env, m->name, status, CATEGORY[status], text);
}

md_status md_check_mode(md_instance *m, const char *call, unsigned allowed)
{
    char list[128] = "";
    int i;
    if (allowed & MD_IN(m->d.mode))
        return MD_OK;
    for (i = 0; i < 4; ++i) {
        if (!(allowed & MD_IN((md_mode)i)))
            continue;
        if (list[0])
            strcat(list, ", ");
        strcat(list, MODE_NAMES[i]);
    }
    md_log(m, MD_ERROR, "%s is not allowed in state %s (allowed in: %s)", call,
           MODE_NAMES[m->d.mode], list);
    return MD_ERROR;
}

/* FNV-1a of a message: which "outputs are 0" warning was logged last. */
static unsigned long text_hash(const char *text)
{
    unsigned long h = 2166136261UL;
    for (; *text; ++text)
        h = (h ^ (unsigned char)*text) * 16777619UL;
    return h ? h : 1UL;
}

/* 1 if variables of this role are outputs (everything not settable nor the time) */
static int is_output(md_role role)
{
    switch (role) {
    case MD_PARAMETER: case MD_INPUT_U: case MD_INPUT_V: case MD_INPUT_N:
    case MD_LOCAL_W: case MD_LOCAL_W1: case MD_LOCAL_W2: case MD_TIME:
        return 0;
    default:
        return 1;
    }
}

/* ------------------------------------------------------------------ life cycle */

static void set_field(ml_axis_params *p, md_field field, double value)
{
    switch (field) {
    case MD_P_LAW: p->law = (int)value; break;
    case MD_P_K1: p->k1 = value; break;
    case MD_P_KC: p->kc = value; break;
    case MD_P_K2: p->k2 = value; break;
    case MD_P_DELTA: p->delta = value; break;
    case MD_P_DELTA_NEG: p->delta_neg = value; break;
    case MD_P_C: p->c = value; break;
    case MD_P_FRICTION: p->friction = value != 0.0; break;
    case MD_P_KF: p->kf = value; break;
    case MD_P_MU: p->mu = value; break;
    case MD_P_N0: p->n0 = value; break;
    case MD_P_SLIDERS: p->sliders = (int)value; break;
    case MD_P_SPREAD: p->spread = value; break;
    case MD_P_FS_RATIO: p->fs_ratio = value; break;
    case MD_P_FRICTION_KIND: p->friction_kind = (int)value; break;
    case MD_P_THETA_DEG: p->theta_deg = value; break;
    case MD_P_K: p->k = value; break;
    case MD_P_KF2: p->kf2 = value; break;
    case MD_P_MU1: p->mu1 = value; break;
    case MD_P_MU2: p->mu2 = value; break;
    case MD_P_PRELOAD: p->preload = value; break;
    case MD_P_SIGMA1: p->sigma1 = value; break;
    case MD_P_SIGMA2: p->sigma2 = value; break;
    case MD_P_STRIBECK_RATIO: p->stribeck_ratio = value; break;
    case MD_P_V_STRIBECK: p->v_stribeck = value; break;
    case MD_P_MAXWELL_K1: p->maxwell_k1 = value; break;
    case MD_P_MAXWELL_C1: p->maxwell_c1 = value; break;
    case MD_P_MAXWELL_K2: p->maxwell_k2 = value; break;
    case MD_P_MAXWELL_C2: p->maxwell_c2 = value; break;
    case MD_P_MAXWELL_K3: p->maxwell_k3 = value; break;
    case MD_P_MAXWELL_C3: p->maxwell_c3 = value; break;
    case MD_P_HYD_AP: p->hyd_Ap = value; break;
    case MD_P_HYD_C1: p->hyd_C1 = value; break;
    case MD_P_HYD_C2: p->hyd_C2 = value; break;
    case MD_P_HYD_I_I: p->hyd_I_i = value; break;
    case MD_P_HYD_R_I: p->hyd_R_i = value; break;
    case MD_P_HYD_I_D: p->hyd_I_d = value; break;
    case MD_P_HYD_R_D: p->hyd_R_d = value; break;
    case MD_P_NONE: break;
    }
}

double md_get_field(const ml_axis_params *p, md_field field)
{
    switch (field) {
    case MD_P_LAW: return p->law;
    case MD_P_K1: return p->k1;
    case MD_P_KC: return p->kc;
    case MD_P_K2: return p->k2;
    case MD_P_DELTA: return p->delta;
    case MD_P_DELTA_NEG: return p->delta_neg;
    case MD_P_C: return p->c;
    case MD_P_FRICTION: return p->friction;
    case MD_P_KF: return p->kf;
    case MD_P_MU: return p->mu;
    case MD_P_N0: return p->n0;
    case MD_P_SLIDERS: return p->sliders;
    case MD_P_SPREAD: return p->spread;
    case MD_P_FS_RATIO: return p->fs_ratio;
    case MD_P_FRICTION_KIND: return p->friction_kind;
    case MD_P_THETA_DEG: return p->theta_deg;
    case MD_P_K: return p->k;
    case MD_P_KF2: return p->kf2;
    case MD_P_MU1: return p->mu1;
    case MD_P_MU2: return p->mu2;
    case MD_P_PRELOAD: return p->preload;
    case MD_P_SIGMA1: return p->sigma1;
    case MD_P_SIGMA2: return p->sigma2;
    case MD_P_STRIBECK_RATIO: return p->stribeck_ratio;
    case MD_P_V_STRIBECK: return p->v_stribeck;
    case MD_P_MAXWELL_K1: return p->maxwell_k1;
    case MD_P_MAXWELL_C1: return p->maxwell_c1;
    case MD_P_MAXWELL_K2: return p->maxwell_k2;
    case MD_P_MAXWELL_C2: return p->maxwell_c2;
    case MD_P_MAXWELL_K3: return p->maxwell_k3;
    case MD_P_MAXWELL_C3: return p->maxwell_c3;
    case MD_P_HYD_AP: return p->hyd_Ap;
    case MD_P_HYD_C1: return p->hyd_C1;
    case MD_P_HYD_C2: return p->hyd_C2;
    case MD_P_HYD_I_I: return p->hyd_I_i;
    case MD_P_HYD_R_I: return p->hyd_R_i;
    case MD_P_HYD_I_D: return p->hyd_I_d;
    case MD_P_HYD_R_D: return p->hyd_R_d;
    case MD_P_NONE: break;
    }
    return 0.0;
}

/* w_<axis> = value before the parameters are checked: one position, untagged;
 * conform_state makes it the element's state relaxed there (as the PythonFMU slave). */
static void put_sliders(md_data *d, int j, double value)
{
    d->w[j][0] = value;
    d->nw[j] = 1;
    d->wkind[j] = 0;
}

/* mount_law.initial_sliders of the checked axis j at value: the element relaxed
 * there (its start), tagged with its kind if its state is a named one. */
static void initial_state(md_data *d, int j, double value)
{
    ml_state_start(&d->p[j], value, d->w[j]);
    d->nw[j] = ml_state_size(&d->p[j]);
    d->wkind[j] = ml_state_tag(&d->p[j]);
}

/* mount_law.slider_position / mean_slider of axis j's committed state. */
static double mean_state(const md_data *d, int j)
{
    return ml_state_position_p(&d->p[j], d->w[j], d->nw[j], d->wkind[j]);
}

/* mount_law.conform_state once the parameters are checked: the state of the axis's
 * element, kept if it is one already (an untagged sequence of its size, or one
 * tagged with its kind), else the element relaxed at the state's position. */
static void conform_state(md_data *d, int j)
{
    const ml_axis_params *p = &d->p[j];
    int tag = ml_state_tag(p);
    if ((d->wkind[j] == 0 || d->wkind[j] == tag) && d->nw[j] == ml_state_size(p)) {
        d->wkind[j] = tag;
        return;
    }
    initial_state(d, j, mean_state(d, j));
}

void md_invalidate(md_instance *m)
{
    m->valid[0] = m->valid[1] = m->valid[2] = 0;
}

void md_reset(md_instance *m)
{
    size_t i;
    int j;
    memset(&m->d, 0, sizeof m->d);
    for (j = 0; j < 3; ++j)
        m->d.p[j] = ml_default_params();
    for (i = 0; i < MD_N_VARIABLES; ++i) {
        const md_variable *var = &MD_VARIABLES[i];
        switch (var->role) {
        case MD_PARAMETER: set_field(&m->d.p[var->axis], var->field, var->start); break;
        case MD_INPUT_U: m->d.u[var->axis] = var->start; break;
        case MD_INPUT_V: m->d.v[var->axis] = var->start; break;
        case MD_LOCAL_W: put_sliders(&m->d, var->axis, var->start); break;
        default: break;  /* n follows <axis>_n0 until set; outputs are computed */
        }
    }
    m->d.mode = MD_INSTANTIATED;
    m->params_ok = 0;
    m->start_time = NAN;  /* no fmi2SetupExperiment yet: the first step starts anywhere */
    m->d.time = NAN;      /* (in the FMU state, as the PythonFMU build's _t_next) */
    m->last_time_ok = 0.0;
    md_invalidate(m);
}

md_instance *md_new(const char *name, const char *api, md_log_fn log, void *env,
                    md_alloc_fn alloc, md_free_fn free_fn, int logging_on)
{
    md_instance *m;
    size_t len = strlen(name ? name : "") + 1;
    if (alloc == NULL || free_fn == NULL) {
        alloc = calloc;
        free_fn = free;
    }
    m = (md_instance *)alloc(1, sizeof *m);
    if (m == NULL)
        return NULL;
    memset(m, 0, sizeof *m);
    m->name = (char *)alloc(len, 1);
    if (m->name == NULL) {
        free_fn(m);
        return NULL;
    }
    memcpy(m->name, name ? name : "", len);
    m->api = api;
    m->log = log;
    m->env = env;
    m->alloc = alloc;
    m->free = free_fn;
    m->logging_on = logging_on;
    md_reset(m);
    return m;
}

void md_delete(md_instance *m)
{
    md_free_fn free_fn;
    if (m == NULL)
        return;
    free_fn = m->free;
    free_fn(m->name);
    free_fn(m);
}

/* ------------------------------------------------------------------ the law */

/* Model Exchange does not carry the hydraulic fluid path (docs/fmu.md 7a): 1 with
 * the message naming the parameter when axis j of an ME instance has it. */
static int me_refuses_fluid(const md_instance *m, int j, char *why, size_t size)
{
    char val[40];
    if (!m->model_exchange || !ml_has_hydraulic(&m->d.p[j]))
        return 0;
    ml_repr_double(m->d.p[j].hyd_Ap, val, sizeof val);
    snprintf(why, size, "`%s_hyd_Ap` = %s: the hydraulic fluid path is Co-Simulation "
             "only (Model Exchange does not carry its fluid states); set it to 0 or "
             "instantiate for Co-Simulation", AXIS_NAMES[j], val);
    return 1;
}

/* Check every parameter once (FrictionMount._prepare): MD_OK or a logged MD_ERROR. */
md_status md_check_parameters(md_instance *m, const char *call, md_status level)
{
    /* logged at `level`: MD_ERROR (the call fails) or MD_WARNING (an output read before
     * the end of initialization reads 0; one warning per distinct problem) */
    char all[2048] = "", one[1024], prefix[16];
    int j, count = 0;
    if (m->params_ok)
        return MD_OK;
    for (j = 0; j < 3; ++j) {
        snprintf(prefix, sizeof prefix, "%s_", AXIS_NAMES[j]);
        if (ml_axis_problems(&m->d.p[j], prefix, one, sizeof one) == 0
                && !me_refuses_fluid(m, j, one, sizeof one))
            continue;
        if (count++)
            strncat(all, "; ", sizeof all - strlen(all) - 1);
        strncat(all, one, sizeof all - strlen(all) - 1);
    }
    if (count) {
        if (level == MD_ERROR)
            md_log(m, MD_ERROR, "FrictionMount: invalid parameters: %s (in %s)", all,
                   call);
        else if (text_hash(all) != m->warned) {
            m->warned = text_hash(all);
            md_log(m, MD_WARNING, "FrictionMount: outputs are 0 until the parameters "
                   "are valid (invalid parameters: %s)", all);
        }
        return MD_ERROR;
    }
    /* a micro-slip axis keeps one position per slider, an inclined one its (w1, w2,
     * uc) (FrictionMount._prepare) */
    for (j = 0; j < 3; ++j)
        conform_state(&m->d, j);
    m->params_ok = 1;
    return MD_OK;
}

static double normal_force(const md_instance *m, int j)
{
    return m->d.n_set[j] ? m->d.n[j] : m->d.p[j].n0;
}

#ifndef DRYMOUNT_NULL_MODEL
/* MD_ERROR (logged, naming the output and its value) if an output of axis j other
 * than F and kt would not be finite at the trial result m->res[j] (parameters at
 * their extremes: mu n overflowing, fs_ratio near DBL_MAX, energies past DBL_MAX);
 * docs/fmu.md: no NaN or infinity reaches an output. */
static md_status nonfinite_output(md_instance *m, const char *call, int j)
{
    const char *a = AXIS_NAMES[j], *name = NULL;
    double n1, n2, value = 0.0;
    char sv[40], su[40];
    ml_normal_forces(&m->d.p[j], m->w_new[j], ml_slip_force(&m->d.p[j],
                     normal_force(m, j)), &n1, &n2);
    if (!isfinite(m->res[j].friction))
        name = "Ffr", value = m->res[j].friction;
    else if (!isfinite(m->d.e[j] + m->res[j].dissipated))
        name = "E_fr", value = m->d.e[j] + m->res[j].dissipated;
    else if (!isfinite(n1))
        name = "N", value = n1;
    else if (!isfinite(n2))
        name = "N2", value = n2;
    else {
        int i, n = ml_state_size(&m->d.p[j]);
        for (i = 0; i < n && isfinite(m->w_new[j][i]); ++i)
            ;
        if (i == n)
            return MD_OK;
        name = "w", value = m->w_new[j][i];
    }
    ml_repr_double(value, sv, sizeof sv);
    ml_repr_double(m->d.u[j], su, sizeof su);
    md_log(m, MD_ERROR, "FrictionMount: output %s_%s would be %s at u_%s=%s (a "
           "parameter or input too large for a finite result; nothing committed) "
           "(in %s)", name, a, sv, a, su, call);
    return MD_ERROR;
}
#endif

/* The trial return map of axis j at the current inputs (cached; commits nothing). */
static md_status evaluate(md_instance *m, const char *call, int j)
{
    double u = m->d.u[j], v = m->d.v[j], n = normal_force(m, j);
    char su[40], sv[40], sn[40];
    md_status status;
    if (m->valid[j])
        return MD_OK;
    status = md_check_parameters(m, call, MD_ERROR);
    if (status != MD_OK)
        return status;
    if (!(isfinite(u) && isfinite(v) && isfinite(n))) {
        const char *a = AXIS_NAMES[j];
        ml_repr_double(u, su, sizeof su);
        ml_repr_double(v, sv, sizeof sv);
        ml_repr_double(n, sn, sizeof sn);
        /* a guard: md_check_set refuses non-finite values (docs/fmu.md 4a) */
        md_log(m, MD_ERROR, "FrictionMount: inputs of axis %s must be finite, got "
               "u_%s=%s, v_%s=%s, n_%s=%s (in %s)", a, a, su, a, sv, a, sn, call);
        return MD_ERROR;
    }
#ifdef DRYMOUNT_NULL_MODEL
    /* The null FMU of the benchmark: the same interface and bookkeeping, no law. */
    memset(&m->res[j], 0, sizeof m->res[j]);
    m->res[j].w_new = m->d.w[j][0];
    memcpy(m->w_new[j], m->d.w[j], ml_state_size(&m->d.p[j]) * sizeof(double));
#else
    if (ml_axis_force_pc(u, v, m->d.dt, m->d.w[j], &m->d.p[j], n, m->w_new[j],
                         &m->res[j], m->lost, sizeof m->lost, &m->fluid[j])) {  /* inclined: ContactLost */
        const char *a = AXIS_NAMES[j];
        ml_repr_double(u, su, sizeof su);
        md_log(m, MD_ERROR, "FrictionMount: axis %s at u_%s=%s: %s (in %s)", a, a, su,
               m->lost, call);
        return MD_ERROR;
    }
    if (!(isfinite(m->res[j].force) && isfinite(m->res[j].tangent))) {
        const char *a = AXIS_NAMES[j];
        char sf[40];
        ml_repr_double(u, su, sizeof su);
        ml_repr_double(v, sv, sizeof sv);
        ml_repr_double(m->res[j].force, sf, sizeof sf);
        md_log(m, MD_ERROR, "FrictionMount: force of axis %s overflowed at u_%s=%s, "
               "v_%s=%s: F=%s (in %s)", a, a, su, a, sv, sf, call);
        return MD_ERROR;
    }
    if (nonfinite_output(m, call, j) != MD_OK)
        return MD_ERROR;
#endif
    m->valid[j] = 1;
    return MD_OK;
}

static md_status energy_total(md_instance *m, const char *call, double *value)
{
    int j;
    md_status status;
    for (j = 0; j < 3; ++j) {
        status = evaluate(m, call, j);
        if (status != MD_OK)
            return status;
    }
    /* the same summation order as FrictionMount._energy_total */
    *value = m->d.e[0] + m->res[0].dissipated + m->d.e[1] + m->res[1].dissipated
             + m->d.e[2] + m->res[2].dissipated;
    if (!isfinite(*value)) {
        char sv[40];
        ml_repr_double(*value, sv, sizeof sv);
        md_log(m, MD_ERROR, "FrictionMount: output E_fr would be %s (the sum of the "
               "axes' energies overflows) (in %s)", sv, call);
        *value = 0.0;
        return MD_ERROR;
    }
    return MD_OK;
}

/* ------------------------------------------------------------------ modes */

/* step_record.start_record: the record at the end of initialization. */
static void start_record(md_data *d, int j, const ml_axis_result *r)
{
    d->post[j] = 0;
    d->slipped[j] = 0;
    d->step_kt[j] = r->tangent;
    d->step_e[j] = 0.0;
    d->ks[j] = r->tangent;
    d->step_u[j] = d->u[j];
    d->step_r[j] = r->force - d->p[j].c * d->v[j];
}

/* step_record.step_record: the record after a step committed with result r. */
static void record_step(md_data *d, int j, const ml_axis_result *r)
{
    double force = r->force - d->p[j].c * d->v[j];
    double du = d->u[j] - d->step_u[j];
    double ks = du != 0.0 ? (force - d->step_r[j]) / du : d->step_kt[j];
    if (!isfinite(ks))  /* a step below the resolution of the forces */
        ks = d->step_kt[j];
    d->post[j] = 1;
    d->slipped[j] = r->slipping != 0;
    d->step_kt[j] = r->tangent;
    d->step_e[j] = r->dissipated;
    d->ks[j] = ks;
    d->step_u[j] = d->u[j];
    d->step_r[j] = force;
}

md_status md_enter_initialization(md_instance *m, const char *call, double start,
                                  int start_defined)
{
    if (md_check_mode(m, call, MD_IN(MD_INSTANTIATED)) != MD_OK)
        return MD_ERROR;
    if (start_defined && !isfinite(start)) {
        md_log(m, MD_ERROR, "%s: startTime must be finite, got %g", call, start);
        return MD_ERROR;
    }
    m->start_time = start;
    m->d.time = start_defined ? start : NAN;  /* NAN: the first step starts anywhere */
    m->last_time_ok = start_defined ? start : 0.0;
    m->d.started = 0;
    m->d.mode = MD_INIT;
    return MD_OK;
}

md_status md_exit_initialization(md_instance *m, const char *call)
{
    int j;
    if (md_check_mode(m, call, MD_IN(MD_INIT)) != MD_OK)
        return MD_ERROR;
    if (md_check_parameters(m, call, MD_ERROR) != MD_OK)
        return MD_ERROR;
    for (j = 0; j < 3; ++j)  /* the start outputs must exist too (lost contact) */
        if (evaluate(m, call, j) != MD_OK)
            return MD_ERROR;  /* still initializationMode, as for parameters */
    for (j = 0; j < 3; ++j)  /* where the first step's secant starts */
        start_record(&m->d, j, &m->res[j]);
    m->d.mode = MD_STEP;
    return MD_OK;
}

md_status md_terminate(md_instance *m, const char *call)
{
    if (md_check_mode(m, call, MD_IN(MD_STEP)) != MD_OK)
        return MD_ERROR;
    m->d.mode = MD_TERMINATED;
    return MD_OK;
}

/* The step checks of docs/fmu.md 4a in fmu_src/fmi_state.step_error's order: 1 (and
 * logged) if doStep(t, h) is refused. */
static int step_refused(md_instance *m, const char *call, double t, double h)
{
    double expected = m->d.time;  /* NAN: no start time, the first step starts anywhere */
    char st[40], sh[40], se[40];
    int refused = 1;
    if (isfinite(h) && h > 0.0 && h <= MD_MAX_STEP_SIZE && isfinite(t) && t + h > t
            && !(!isnan(expected) && fabs(t - expected)
                 > MD_TIME_RTOL * fmax(1.0, fmax(fabs(expected), h))))
        return 0;  /* accepted: nothing formatted (three reprs cost ~6 us a step) */
    ml_repr_double(t, st, sizeof st);
    ml_repr_double(h, sh, sizeof sh);
    ml_repr_double(expected, se, sizeof se);
    if (!(isfinite(h) && h > 0.0))
        md_log(m, MD_ERROR, "%s: communicationStepSize must be finite and > 0, got %s",
               call, sh);
    else if (h > MD_MAX_STEP_SIZE)
        md_log(m, MD_ERROR, "%s: communicationStepSize must be <= %g s, got %s", call,
               MD_MAX_STEP_SIZE, sh);
    else if (!isfinite(t))
        md_log(m, MD_ERROR, "%s: currentCommunicationPoint must be finite, got %s",
               call, st);
    else if (!(t + h > t))
        md_log(m, MD_ERROR, "%s: communicationStepSize = %s does not advance "
               "currentCommunicationPoint = %s (below its resolution)", call, sh, st);
    else if (!isnan(expected) && fabs(t - expected)
             > MD_TIME_RTOL * fmax(1.0, fmax(fabs(expected), h)))
        md_log(m, MD_ERROR, "%s: currentCommunicationPoint must continue from the end "
               "of the last step, %s, got %s", call, se, st);
    else
        refused = 0;  /* not reached: the test above accepted the same cases */
    return refused;
}

md_status md_do_step(md_instance *m, const char *call, double t, double h)
{
    int j;
    md_status status;
    if (md_check_mode(m, call, MD_IN(MD_STEP)) != MD_OK)
        return MD_ERROR;
    if (step_refused(m, call, t, h))
        return MD_ERROR;
    for (j = 0; j < 3; ++j) {
        status = evaluate(m, call, j);
        if (status != MD_OK)
            return status;  /* error: nothing committed */
    }
    for (j = 0; j < 3; ++j) {
        memcpy(m->d.w[j], m->w_new[j], ml_state_size(&m->d.p[j]) * sizeof(double));
        m->d.e[j] += m->res[j].dissipated;
        record_step(&m->d, j, &m->res[j]);
    }
    m->d.time = t + h;
    m->d.dt = h;
    m->d.started = 1;
    m->last_time_ok = m->d.time;
    md_invalidate(m);  /* outputs now follow the committed state */
    return MD_OK;
}

/* ------------------------------------------------------------------ values */

static md_status lookup(md_instance *m, const char *call, md_type type, unsigned vr,
                        const md_variable **var)
{
    if (vr >= MD_N_VARIABLES) {
        md_log(m, MD_ERROR, "%s: unknown value reference %u (the model has %u)", call,
               vr, (unsigned)MD_N_VARIABLES);
        return MD_ERROR;
    }
    *var = &MD_VARIABLES[vr];
    if ((*var)->type != type) {
        md_log(m, MD_ERROR, "%s: value reference %u (%s) is a %s variable, not %s",
               call, vr, (*var)->name, TYPE_NAMES[(*var)->type], TYPE_NAMES[type]);
        return MD_ERROR;
    }
    return MD_OK;
}

md_status md_get(md_instance *m, const char *call, md_type type, unsigned vr,
                 double *value)
{
    const md_variable *var;
    md_status status;
    int j;
    if (lookup(m, call, type, vr, &var) != MD_OK)
        return MD_ERROR;  /* getters are allowed in every state (docs/fmu.md 4a) */
    j = var->axis;
    if (is_output(var->role) && m->d.mode <= MD_INIT
            && md_check_parameters(m, call, MD_WARNING) != MD_OK) {
        *value = 0.0;  /* the error comes from ExitInitializationMode */
        return MD_OK;
    }
    if (var->role == MD_TIME && isnan(m->d.time)) {
        *value = 0.0;  /* no start time yet (FMI 2.0 without fmi2SetupExperiment) */
        return MD_OK;
    }
    switch (var->role) {
    case MD_PARAMETER: *value = md_get_field(&m->d.p[j], var->field); return MD_OK;
    case MD_INPUT_U: *value = m->d.u[j]; return MD_OK;
    case MD_INPUT_V: *value = m->d.v[j]; return MD_OK;
    case MD_INPUT_N: *value = normal_force(m, j); return MD_OK;
    case MD_LOCAL_W: *value = mean_state(&m->d, j); return MD_OK;
    case MD_LOCAL_W1: case MD_LOCAL_W2: {  /* FrictionMount._slider */
        int idx;
        *value = 0.0;  /* no such slider, or invalid parameters */
        if (!m->params_ok && md_check_parameters(m, call, MD_WARNING) != MD_OK)
            return MD_OK;
        idx = ml_slider_index(&m->d.p[j], var->role == MD_LOCAL_W1 ? 0 : 1);
        if (idx >= 0)
            *value = m->d.w[j][idx];
        return MD_OK;
    }
    case MD_TIME: *value = m->d.time; return MD_OK;
    case MD_OUTPUT_E_TOTAL: return energy_total(m, call, value);
    case MD_OUTPUT_SLIPPED: *value = m->d.slipped[j]; return MD_OK;
    case MD_OUTPUT_DE_STEP: *value = m->d.step_e[j]; return MD_OK;
    case MD_OUTPUT_KS:
        if (m->d.mode > MD_INIT) {
            *value = m->d.ks[j];
            return MD_OK;
        }
        break;  /* before the first step: the tangent */
    case MD_OUTPUT_KT:
        if (m->d.post[j]) {  /* after doStep: the tangent the step ended with */
            *value = m->d.step_kt[j];
            return MD_OK;
        }
        break;
    case MD_OUTPUT_SLIP:
        if (m->d.post[j]) {  /* after doStep: whether the step slipped */
            *value = m->d.slipped[j];
            return MD_OK;
        }
        break;
    default: break;
    }
    status = evaluate(m, call, j);
    if (status != MD_OK) {
        *value = 0.0;  /* never a NaN, also in a refused get */
        return status;
    }
    switch (var->role) {
    case MD_OUTPUT_F: *value = m->res[j].force; break;
    case MD_OUTPUT_FFR: *value = m->res[j].friction; break;
    case MD_OUTPUT_KT: case MD_OUTPUT_KS: *value = m->res[j].tangent; break;
    case MD_OUTPUT_SLIP: *value = m->res[j].slipping; break;
    case MD_OUTPUT_N: case MD_OUTPUT_N2: {
        double n1, n2;
        ml_normal_forces(&m->d.p[j], m->w_new[j], ml_slip_force(&m->d.p[j],
                         normal_force(m, j)), &n1, &n2);
        *value = var->role == MD_OUTPUT_N ? n1 : n2;
        break;
    }
    default: *value = m->d.e[j] + m->res[j].dissipated; break;  /* E_fr_<axis> */
    }
    return MD_OK;
}

/* Whether Real variable `name` also takes +inf (fmu_src/fmi_state.py
 * INFINITE_ALLOWED): the inclined element's <axis>_mu1, <axis>_mu2 (a bonded surface). */
static int infinite_allowed(const char *name)
{
    static const char *const suffixes[] = {"_mu1", "_mu2"};
    size_t len = strlen(name), i;
    for (i = 0; i < sizeof suffixes / sizeof suffixes[0]; ++i) {
        size_t n = strlen(suffixes[i]);
        if (len >= n && strcmp(name + len - n, suffixes[i]) == 0)
            return 1;
    }
    return 0;
}

/* FrictionMount._slot_problem: w1_/w2_<axis> need valid parameters (set in an
 * earlier call) and an element with that slider. */
static md_status check_slider(md_instance *m, const char *call, const md_variable *var,
                              double value)
{
    int j = var->axis, slot = var->role == MD_LOCAL_W1 ? 0 : 1, n = 0;
    const ml_axis_params *p = &m->d.p[j];
    char sv[40];
    ml_repr_double(value, sv, sizeof sv);
    if (!m->params_ok && md_check_parameters(m, call, MD_ERROR) != MD_OK) {
        md_log(m, MD_ERROR, "%s: `%s` = %s sets a slider of the axis's friction "
               "element, which needs valid parameters first", call, var->name, sv);
        return MD_ERROR;
    }
    if (ml_slider_index(p, slot) >= 0)
        return MD_OK;
    while (ml_slider_index(p, n) >= 0)
        ++n;
    if (p->friction)
        md_log(m, MD_ERROR, "%s: `%s` = %s: the friction element (kind %d) of axis %s "
               "has %d settable slider(s); no slider %d to set", call, var->name, sv,
               p->friction_kind, AXIS_NAMES[j], n, slot + 1);
    else
        md_log(m, MD_ERROR, "%s: `%s` = %s: axis %s has no friction element; no "
               "slider %d to set", call, var->name, sv, AXIS_NAMES[j], slot + 1);
    return MD_ERROR;
}

md_status md_check_set(md_instance *m, const char *call, md_type type, unsigned vr,
                       double value)
{
    const md_variable *var;
    unsigned allowed;
    char sv[40];
    if (lookup(m, call, type, vr, &var) != MD_OK)
        return MD_ERROR;
    switch (var->role) {
    case MD_PARAMETER:  /* fixed parameters: before the end of initialization */
        allowed = MD_IN(MD_INSTANTIATED) | MD_IN(MD_INIT);
        break;
    case MD_INPUT_U: case MD_INPUT_V: case MD_INPUT_N:
    case MD_LOCAL_W:  /* w also in step mode, as the PythonFMU build (docs/fmu.md) */
    case MD_LOCAL_W1: case MD_LOCAL_W2:
        allowed = MD_IN(MD_INSTANTIATED) | MD_IN(MD_INIT) | MD_IN(MD_STEP);
        break;
    default:
        md_log(m, MD_ERROR, "%s: %s is %s and cannot be set", call, var->name,
               var->role == MD_TIME ? "the independent variable" : "an output");
        return MD_ERROR;
    }
    if (!(allowed & MD_IN(m->d.mode))) {
        char what[96];
        snprintf(what, sizeof what, "%s of %s", call, var->name);
        return md_check_mode(m, what, allowed);
    }
    if (type == MD_REAL && !isfinite(value)
            && !(value == INFINITY && infinite_allowed(var->name))) {
        ml_repr_double(value, sv, sizeof sv);
        md_log(m, MD_ERROR, "%s: `%s` must be finite, got %s", call, var->name, sv);
        return MD_ERROR;
    }
    if (var->role == MD_LOCAL_W1 || var->role == MD_LOCAL_W2)
        return check_slider(m, call, var, value);
    return MD_OK;
}

md_status md_set(md_instance *m, const char *call, md_type type, unsigned vr,
                 double value)
{
    const md_variable *var;
    int j;
    if (md_check_set(m, call, type, vr, value) != MD_OK)
        return MD_ERROR;
    var = &MD_VARIABLES[vr];
    j = var->axis;
    switch (var->role) {
    case MD_PARAMETER:
        if (var->field == MD_P_LAW && value != floor(value))
            value = -1.0;  /* not a law code; reported by the parameter check */
        set_field(&m->d.p[j], var->field, value);
        m->params_ok = 0;
        m->d.post[0] = m->d.post[1] = m->d.post[2] = 0;
        md_invalidate(m);
        return MD_OK;
    case MD_INPUT_U:
        if (value != m->d.u[j])
            m->d.post[j] = 0;
        m->d.u[j] = value;
        break;
    case MD_INPUT_V:
        if (value != m->d.v[j])
            m->d.post[j] = 0;
        m->d.v[j] = value;
        break;
    case MD_INPUT_N:
        /* an importer writing the declared start before the end of initialization:
         * n keeps following <axis>_n0 (FrictionMount._set_normal_force) */
        if (!m->d.n_set[j] && value == var->start && m->d.mode <= MD_INIT)
            return MD_OK;
        if (value != normal_force(m, j))
            m->d.post[j] = 0;
        m->d.n[j] = value;
        m->d.n_set[j] = 1;
        break;
    case MD_LOCAL_W1: case MD_LOCAL_W2:  /* FrictionMount._set_slider (checked) */
        m->d.post[j] = 0;
        m->d.w[j][ml_slider_index(&m->d.p[j], var->role == MD_LOCAL_W1 ? 0 : 1)] =
            value;
        break;
    default:  /* w_<axis>: FrictionMount._set_sliders */
        m->d.post[j] = 0;
        if (m->params_ok)
            initial_state(&m->d, j, value);
        else
            put_sliders(&m->d, j, value);
        break;
    }
    m->valid[j] = 0;
    return MD_OK;
}
