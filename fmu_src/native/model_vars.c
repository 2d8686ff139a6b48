/* The native FrictionMount's variables (model.h): md_get / md_set / md_check_set,
 * the value-reference dispatch of every role (parameters by field, inputs, the
 * committed state's w_<axis>, the outputs from the cached trial), the checks of a
 * value before it is set. Split from model.c (the instance: life cycle, the law's
 * evaluation, the modes and steps). */
#include "model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const TYPE_NAMES[3] = {"Real", "Integer", "Boolean"};

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

void md_set_field(ml_axis_params *p, md_field field, double value)
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

/* ------------------------------------------------------------------ values */

static md_status lookup(md_instance *m, const char *call, md_type type, unsigned vr,
                        const md_variable **var)
{
    if (vr >= md_n_variables()) {
        md_log(m, MD_ERROR, "%s: unknown value reference %u (the model has %u)", call,
               vr, (unsigned)md_n_variables());
        return MD_ERROR;
    }
    *var = md_variable_at(vr);
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
    case MD_INPUT_N: *value = md_normal_force(m, j); return MD_OK;
    case MD_LOCAL_W: *value = md_mean_state(&m->d, j); return MD_OK;
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
    case MD_OUTPUT_E_TOTAL: return md_energy_total(m, call, value);
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
    status = md_evaluate(m, call, j);
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
                         md_normal_force(m, j)), &n1, &n2);
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
               p->friction_kind, md_axis_name(j), n, slot + 1);
    else
        md_log(m, MD_ERROR, "%s: `%s` = %s: axis %s has no friction element; no "
               "slider %d to set", call, var->name, sv, md_axis_name(j), slot + 1);
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
    var = md_variable_at(vr);
    j = var->axis;
    switch (var->role) {
    case MD_PARAMETER:
        if (var->field == MD_P_LAW && value != floor(value))
            value = -1.0;  /* not a law code; reported by the parameter check */
        md_set_field(&m->d.p[j], var->field, value);
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
        if (value != md_normal_force(m, j))
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
            md_initial_state(&m->d, j, value);
        else
            md_put_sliders(&m->d, j, value);
        break;
    }
    m->valid[j] = 0;
    return MD_OK;
}
