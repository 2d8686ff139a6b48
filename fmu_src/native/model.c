/* The native FrictionMount instance (see model.h): life cycle, the law's evaluation,
 * the modes and steps; its variables' get/set are model_vars.c, its FMU state
 * model_state.c. */
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

/* ------------------------------------------------------------------ life cycle */

/* w_<axis> = value before the parameters are checked: one position, untagged;
 * conform_state makes it the element's state relaxed there (as the PythonFMU slave). */
void md_put_sliders(md_data *d, int j, double value)
{
    d->w[j][0] = value;
    d->nw[j] = 1;
    d->wkind[j] = 0;
}

/* mount_law.initial_sliders of the checked axis j at value: the element relaxed
 * there (its start), tagged with its kind if its state is a named one. */
void md_initial_state(md_data *d, int j, double value)
{
    ml_state_start(&d->p[j], value, d->w[j]);
    d->nw[j] = ml_state_size(&d->p[j]);
    d->wkind[j] = ml_state_tag(&d->p[j]);
}

/* mount_law.slider_position / mean_slider of axis j's committed state. */
double md_mean_state(const md_data *d, int j)
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
    md_initial_state(d, j, md_mean_state(d, j));
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
        case MD_PARAMETER:
            md_set_field(&m->d.p[var->axis], var->field, var->start);
            break;
        case MD_INPUT_U: m->d.u[var->axis] = var->start; break;
        case MD_INPUT_V: m->d.v[var->axis] = var->start; break;
        case MD_LOCAL_W: md_put_sliders(&m->d, var->axis, var->start); break;
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

double md_normal_force(const md_instance *m, int j)
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
                     md_normal_force(m, j)), &n1, &n2);
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
md_status md_evaluate(md_instance *m, const char *call, int j)
{
    double u = m->d.u[j], v = m->d.v[j], n = md_normal_force(m, j);
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

md_status md_energy_total(md_instance *m, const char *call, double *value)
{
    int j;
    md_status status;
    for (j = 0; j < 3; ++j) {
        status = md_evaluate(m, call, j);
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
        if (md_evaluate(m, call, j) != MD_OK)
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
        status = md_evaluate(m, call, j);
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
