/* The native FrictionMount's FMU state (docs/fmu.md 4b): get/set/free a copy of the
 * instance data, and its serialization (STATE_MAGIC, the md_data bytes, a checksum),
 * every field range-checked before a state is accepted, so a corrupted state is
 * refused with a message and never reaches the law. Split from model.c (the
 * instance, its calls and variables). */
#include "model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char STATE_MAGIC[8] = {'D', 'M', 'N', 'T', 'S', 'T', '0', '7'};

/* ------------------------------------------------------------------ FMU state */

#define STATE_MODES (MD_IN(MD_INSTANTIATED) | MD_IN(MD_INIT) | MD_IN(MD_STEP) \
                     | MD_IN(MD_TERMINATED))

static int state_problem(const md_data *d, char *why, size_t size);

md_status md_get_state(md_instance *m, const char *call, void **state)
{
    md_data *copy;
    if (md_check_mode(m, call, STATE_MODES) != MD_OK)
        return MD_ERROR;
    copy = (md_data *)(*state != NULL ? *state : m->alloc(1, sizeof *copy));
    if (copy == NULL) {
        md_log(m, MD_ERROR, "%s: out of memory", call);
        return MD_ERROR;
    }
    *copy = m->d;
    *state = copy;
    return MD_OK;
}

md_status md_set_state(md_instance *m, const char *call, const void *state)
{
    if (md_check_mode(m, call, STATE_MODES) != MD_OK)
        return MD_ERROR;
    if (state == NULL) {
        md_log(m, MD_ERROR, "%s: the FMU state is NULL", call);
        return MD_ERROR;
    }
    {
        char why[1200];
        if (state_problem((const md_data *)state, why, sizeof why)) {
            md_log(m, MD_ERROR, "%s: not a valid FMU state (%s)", call, why);
            return MD_ERROR;
        }
    }
    m->d = *(const md_data *)state;
    m->params_ok = 0;
    m->last_time_ok = isnan(m->d.time) ? 0.0 : m->d.time;
    md_invalidate(m);
    /* after initialization the parameters are valid (state_problem): checked now, so
     * that the Model Exchange calls, which read them without checking, see them */
    if (m->d.mode == MD_STEP || m->d.mode == MD_TERMINATED)
        return md_check_parameters(m, call, MD_ERROR);
    return MD_OK;
}

void md_free_state(md_instance *m, void *state)
{
    if (state != NULL)
        m->free(state);
}

/* A serialized state: STATE_MAGIC, the md_data bytes, then STATE_SUM_SIZE bytes of
 * their FNV-1a 64-bit hash (little endian): any flipped byte is refused, and every
 * field is range-checked (state_problem) before a state is accepted. */
#define STATE_SUM_SIZE 8

size_t md_serialized_size(void)
{
    return sizeof STATE_MAGIC + sizeof(md_data) + STATE_SUM_SIZE;
}

static void state_sum(const unsigned char *bytes, size_t n, unsigned char out[8])
{
    unsigned long long h = 14695981039346656037ULL;
    size_t i;
    for (i = 0; i < n; ++i)
        h = (h ^ bytes[i]) * 1099511628211ULL;
    for (i = 0; i < 8; ++i)
        out[i] = (unsigned char)(h >> (8 * i));
}

md_status md_serialize(md_instance *m, const char *call, const void *state,
                       unsigned char *bytes, size_t size)
{
    if (state == NULL || bytes == NULL || size < md_serialized_size()) {
        md_log(m, MD_ERROR, "%s: need a state and %u bytes, got %u", call,
               (unsigned)md_serialized_size(), (unsigned)size);
        return MD_ERROR;
    }
    memcpy(bytes, STATE_MAGIC, sizeof STATE_MAGIC);
    memcpy(bytes + sizeof STATE_MAGIC, state, sizeof(md_data));
    state_sum(bytes + sizeof STATE_MAGIC, sizeof(md_data),
              bytes + sizeof STATE_MAGIC + sizeof(md_data));
    return MD_OK;
}

static int is_flag(int x) { return x == 0 || x == 1; }

/* Parameter fields that may hold +inf (fmi_state.INFINITE_ALLOWED). */
static int infinite_field(md_field f) { return f == MD_P_MU1 || f == MD_P_MU2; }

/* Why axis j of d cannot be the content of a state, into why; 0 if it can. */
static int axis_problem(const md_data *d, int j, char *why, size_t size)
{
    const ml_axis_params *p = &d->p[j];
    const char *a = md_axis_name(j);
    static const md_field reals[] = {MD_P_K1, MD_P_KC, MD_P_K2, MD_P_DELTA,
        MD_P_DELTA_NEG, MD_P_C, MD_P_KF, MD_P_MU, MD_P_N0, MD_P_SPREAD, MD_P_FS_RATIO,
        MD_P_THETA_DEG, MD_P_K, MD_P_KF2, MD_P_MU1, MD_P_MU2, MD_P_PRELOAD,
        MD_P_SIGMA1, MD_P_SIGMA2, MD_P_STRIBECK_RATIO, MD_P_V_STRIBECK,
        MD_P_MAXWELL_K1, MD_P_MAXWELL_C1, MD_P_MAXWELL_K2, MD_P_MAXWELL_C2,
        MD_P_MAXWELL_K3, MD_P_MAXWELL_C3, MD_P_HYD_AP, MD_P_HYD_C1, MD_P_HYD_C2,
        MD_P_HYD_I_I, MD_P_HYD_R_I, MD_P_HYD_I_D, MD_P_HYD_R_D};
    size_t i;
    int k;
    for (i = 0; i < sizeof reals / sizeof reals[0]; ++i) {
        double x = md_get_field(p, reals[i]);
        if (!isfinite(x) && !(x == INFINITY && infinite_field(reals[i]))) {
            snprintf(why, size, "a parameter of axis %s is not finite", a);
            return 1;
        }
    }
    if (!is_flag(p->friction) || !is_flag(d->n_set[j])) {
        snprintf(why, size, "a flag of axis %s is neither 0 nor 1", a);
        return 1;
    }
    if (!(isfinite(d->u[j]) && isfinite(d->v[j]) && isfinite(d->n[j])
          && isfinite(d->e[j]))) {
        snprintf(why, size, "an input or the energy of axis %s is not finite", a);
        return 1;
    }
    if (!is_flag(d->post[j]) || !is_flag(d->slipped[j])
            || !(isfinite(d->step_kt[j]) && isfinite(d->step_e[j]) && isfinite(d->ks[j])
                 && isfinite(d->step_u[j]) && isfinite(d->step_r[j]))) {
        snprintf(why, size, "the record of the last step of axis %s is out of range", a);
        return 1;
    }
    /* wkind: 0 (a plain sequence) or an element's tag, friction kind + 1 */
    if (d->wkind[j] < 0 || d->wkind[j] > ml_friction_kinds() || d->nw[j] < 1
            || d->nw[j] > ML_MAX_STATE) {
        snprintf(why, size, "axis %s: slider count %d (kind %d) outside 1..%d", a,
                 d->nw[j], d->wkind[j], ML_MAX_STATE);
        return 1;
    }
    for (k = 0; k < d->nw[j]; ++k)
        if (!isfinite(d->w[j][k])) {
            snprintf(why, size, "a slider position of axis %s is not finite", a);
            return 1;
        }
    return 0;
}

/* Why d cannot be a state of this FMU (into why), 0 if it can: every field in its
 * range, and after initialization (step mode, terminated) valid parameters and a
 * friction state of the size the parameters ask for (what fmi2ExitInitialization
 * guarantees). */
static int state_problem(const md_data *d, char *why, size_t size)
{
    char text[4096];
    int j;
    if ((unsigned)d->mode > MD_TERMINATED || !is_flag(d->started)
            || !(isnan(d->time) || isfinite(d->time))
            || !(isfinite(d->dt) && d->dt >= 0.0)) {
        snprintf(why, size, "mode, time, step size or start flag out of range");
        return 1;
    }
    for (j = 0; j < 3; ++j) {
        if (axis_problem(d, j, why, size))
            return 1;
        if (d->mode < MD_STEP)
            continue;  /* parameters are checked at ExitInitializationMode */
        if (ml_axis_problems(&d->p[j], md_axis_name(j), text, sizeof text)) {
            snprintf(why, size, "invalid parameters after initialization: %.900s", text);
            return 1;
        }
        if (d->nw[j] != ml_state_size(&d->p[j]) || d->wkind[j] != ml_state_tag(&d->p[j])) {
            snprintf(why, size, "axis %s: %d slider positions for parameters that "
                     "need %d", md_axis_name(j), d->nw[j], ml_state_size(&d->p[j]));
            return 1;
        }
    }
    return 0;
}

md_status md_deserialize(md_instance *m, const char *call, const unsigned char *bytes,
                         size_t size, void **state)
{
    md_data data;
    unsigned char sum[8];
    char why[1200];
    if (bytes == NULL || size != md_serialized_size()
            || memcmp(bytes, STATE_MAGIC, sizeof STATE_MAGIC)) {
        md_log(m, MD_ERROR, "%s: not a state serialized by this FMU (%u bytes, a state "
               "has %u)", call, (unsigned)size, (unsigned)md_serialized_size());
        return MD_ERROR;
    }
    state_sum(bytes + sizeof STATE_MAGIC, sizeof data, sum);
    if (memcmp(sum, bytes + sizeof STATE_MAGIC + sizeof data, sizeof sum) != 0) {
        md_log(m, MD_ERROR, "%s: corrupt serialized state (checksum mismatch)", call);
        return MD_ERROR;
    }
    memcpy(&data, bytes + sizeof STATE_MAGIC, sizeof data);
    if (state_problem(&data, why, sizeof why)) {
        md_log(m, MD_ERROR, "%s: corrupt serialized state (%s)", call, why);
        return MD_ERROR;
    }
    if (state == NULL) {
        md_log(m, MD_ERROR, "%s: the FMU state pointer is NULL", call);
        return MD_ERROR;
    }
    if (*state == NULL)
        *state = m->alloc(1, sizeof data);
    if (*state == NULL) {
        md_log(m, MD_ERROR, "%s: out of memory", call);
        return MD_ERROR;
    }
    memcpy(*state, &data, sizeof data);
    return MD_OK;
}
