/* The native FrictionMount instance: the co-simulation protocol of
 * fmu_src/friction_mount.py on top of the C law (mount_law.h), shared by the FMI 2.0
 * (fmi2_glue.c) and FMI 3.0 (fmi3_glue.c) entry points.
 *
 * Per communication step t_n -> t_n + h the master sets u, v (and n) at t_n and may read
 * the outputs at once: the trial return map at the current inputs and the committed
 * slider positions (direct feedthrough, nothing committed by a get). md_do_step commits
 * the sliders and adds the dissipated energy. Statuses use the FMI numbering (OK 0,
 * Warning 1, Discard 2, Error 3, Fatal 4) of both standards.
 *
 * The call-order rules of docs/fmu.md 4a: a refused call (out of order, unknown value
 * reference, a non-finite value, invalid parameters, a step size not in (0, 1e6] s, a
 * time that does not continue) returns MD_ERROR, logs a message naming the call and the
 * state or the value, and changes nothing.
 */
#ifndef DRYMOUNT_MODEL_H
#define DRYMOUNT_MODEL_H

#include "internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#include <stddef.h>

#include "mount_law.h"
#include "hydraulic.h"
#include "me_state.h"

typedef enum { MD_OK = 0, MD_WARNING = 1, MD_DISCARD = 2, MD_ERROR = 3,
               MD_FATAL = 4 } md_status;

typedef enum { MD_INSTANTIATED = 0, MD_INIT = 1, MD_STEP = 2,
               MD_TERMINATED = 3 } md_mode;

typedef enum { MD_REAL = 0, MD_INTEGER = 1, MD_BOOLEAN = 2 } md_type;

/* What a value reference means to the model (the builder maps the interface table's
 * names onto these roles; see fmu_build/native.py). */
typedef enum {
    MD_PARAMETER = 0, MD_INPUT_U, MD_INPUT_V, MD_INPUT_N, MD_OUTPUT_F,
    MD_OUTPUT_FFR, MD_OUTPUT_KT, MD_OUTPUT_SLIP, MD_OUTPUT_E_AXIS, MD_OUTPUT_E_TOTAL,
    MD_LOCAL_W, MD_TIME, MD_OUTPUT_N, MD_OUTPUT_N2,
    /* the record of the last step (fmu_src/step_record.py): slipped_, dE_fr_, ks_ */
    MD_OUTPUT_SLIPPED, MD_OUTPUT_DE_STEP, MD_OUTPUT_KS,
    MD_LOCAL_W1, MD_LOCAL_W2  /* w1_/w2_<axis>: one slider of the element */
} md_role;

/* Fields of a parameter variable, in mount_law.AxisParameters' order. */
typedef enum {
    MD_P_LAW = 0, MD_P_K1, MD_P_KC, MD_P_K2, MD_P_DELTA, MD_P_DELTA_NEG, MD_P_C,
    MD_P_FRICTION, MD_P_KF, MD_P_MU, MD_P_N0, MD_P_SLIDERS, MD_P_SPREAD,
    MD_P_FS_RATIO, MD_P_NONE, MD_P_FRICTION_KIND, MD_P_THETA_DEG, MD_P_K, MD_P_KF2,
    MD_P_MU1, MD_P_MU2, MD_P_PRELOAD, MD_P_SIGMA1, MD_P_SIGMA2, MD_P_STRIBECK_RATIO,
    MD_P_V_STRIBECK,
    MD_P_MAXWELL_K1, MD_P_MAXWELL_C1, MD_P_MAXWELL_K2, MD_P_MAXWELL_C2,
    MD_P_MAXWELL_K3, MD_P_MAXWELL_C3,
    MD_P_HYD_AP, MD_P_HYD_C1, MD_P_HYD_C2, MD_P_HYD_I_I, MD_P_HYD_R_I, MD_P_HYD_I_D,
    MD_P_HYD_R_D
} md_field;

typedef struct {
    const char *name;
    md_type type;
    md_role role;
    int axis;        /* 0 axial, 1 radial1, 2 radial2; -1 for E_fr */
    md_field field;  /* parameters only */
    double start;
} md_variable;

typedef void (*md_log_fn)(void *env, const char *instance, md_status status,
                          const char *category, const char *message);
typedef void *(*md_alloc_fn)(size_t count, size_t size);
typedef void (*md_free_fn)(void *ptr);

/* Everything an FMU state (get/set/serialize) holds. */
typedef struct {
    md_mode mode;
    ml_axis_params p[3];
    double u[3], v[3], n[3];
    int n_set[3];
    /* committed friction state per axis: nw[j] doubles in w[j] (the element's
     * state_size); wkind[j] its tag (ml_state_tag): 0 for a plain sequence (the
     * Jenkins sliders, or one position set before the parameters were checked),
     * kind + 1 for an element with a named state (the inclined (w1, w2, uc): 2) */
    double w[3][ML_MAX_STATE];   /* + uc and the Maxwell strokes (maxwell.h) */
    int nw[3], wkind[3];
    double e[3];
    double time;      /* end of the last step (= start time before the first) */
    double dt;        /* size of the last step (0 before the first): the increment
                         rate-dependent elements integrate over */
    int started;      /* a step was done since initialization */
    md_me me;         /* Model Exchange: continuous states, modes (me_state.h) */
    /* per axis, the record of the last step (fmu_src/step_record.py, the same
     * operations): post: no input of the axis changed since the last doStep (kt_ and
     * slip_ then read step_kt and slipped); the energy dissipated in it; its secant;
     * the deflection and the force less the damper it committed (at the end of
     * initialization before the first step) */
    int post[3], slipped[3];
    double step_kt[3], step_e[3], ks[3], step_u[3], step_r[3];
} md_data;

typedef struct {
    char *name;
    const char *api;  /* "fmi2" or "fmi3", for the messages */
    md_log_fn log;
    void *env;
    md_alloc_fn alloc;
    md_free_fn free;
    int logging_on;
    md_data d;
    int params_ok;         /* parameters checked since the last parameter change */
    int valid[3];          /* cached trial results per axis */
    ml_axis_result res[3];
    double w_new[3][ML_MAX_STATE];  /* slider positions of the cached results */
    char lost[512];                   /* message of the inclined element's ContactLost */
    double start_time;     /* from fmi2SetupExperiment / fmi3EnterInitializationMode */
    double last_time_ok;   /* last successful communication point */
    unsigned long warned;  /* hash of the last "outputs are 0" warning's problems */
    int model_exchange;    /* instantiated for Model Exchange (me.h) */
    ml_fluid_prop fluid[3];  /* per axis: the fluid's propagator of the last dt (a
                                cache, keyed by dt and the fields: not state) */
} md_instance;

/* Number of variables, the variable table and the instantiation token (GUID), all
 * generated from fmu_src/interface.py into model_variables.h. */
ML_DECL size_t md_n_variables(void);
ML_DECL const char *md_instantiation_token(void);
ML_DECL const md_variable *md_variable_at(size_t vr);

ML_DECL md_instance *md_new(const char *name, const char *api, md_log_fn log, void *env,
                    md_alloc_fn alloc, md_free_fn free_fn, int logging_on);
ML_DECL void md_delete(md_instance *m);
ML_DECL const char *md_mode_name(md_mode mode);

/* Log (always for status >= Warning, for OK only with logging on). */
ML_DECL void md_log(md_instance *m, md_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* MD_OK if `call` is allowed in the current mode (bitmask of 1 << md_mode), else logs
 * "<call> is not allowed in state <mode> (allowed: ...)" and returns MD_ERROR. */
ML_DECL md_status md_check_mode(md_instance *m, const char *call, unsigned allowed);
#define MD_IN(mode) (1u << (mode))

ML_DECL void md_reset(md_instance *m);
/* start_defined 0: FMI 2.0 without fmi2SetupExperiment, the first step starts anywhere
 * (md_data.time is NAN until the first step) */
ML_DECL
md_status md_enter_initialization(md_instance *m, const char *call, double start,
                                  int start_defined);
ML_DECL md_status md_exit_initialization(md_instance *m, const char *call);
ML_DECL md_status md_terminate(md_instance *m, const char *call);
ML_DECL md_status md_do_step(md_instance *m, const char *call, double t, double h);

/* Values, one value reference at a time; `call` names the FMI function. */
ML_DECL md_status md_get(md_instance *m, const char *call, md_type type, unsigned vr,
                 double *value);
ML_DECL md_status md_set(md_instance *m, const char *call, md_type type, unsigned vr,
                 double value);
/* MD_OK if md_set would accept the value (nothing changed; refusals are logged): the
 * glue checks every value of a call before setting any (docs/fmu.md 4a). */
ML_DECL
md_status md_check_set(md_instance *m, const char *call, md_type type, unsigned vr,
                       double value);

/* FMU state: a heap copy of md_data, serialized as magic + size + bytes. */
/* Shared by model.c and model_state.c: an axis's name, a parameter field's value,
 * dropping the cached evaluations, the parameter check (MD_OK or a logged error). */
ML_DECL const char *md_axis_name(int j);
ML_DECL double md_get_field(const ml_axis_params *p, md_field field);
ML_DECL void md_invalidate(md_instance *m);
ML_DECL md_status md_check_parameters(md_instance *m, const char *call, md_status level);

/* Shared by model.c and model_vars.c (the variables' get/set): a parameter field
 * set; w_<axis> before the parameters are checked (one untagged position) and after
 * (the element relaxed there); the committed state's position; the normal force in
 * use (n_<axis> once set, else <axis>_n0); the trial return map of axis j at the
 * current inputs (cached in m->res, commits nothing); E_fr, the axes' sum. */
ML_DECL void md_set_field(ml_axis_params *p, md_field field, double value);
ML_DECL void md_put_sliders(md_data *d, int j, double value);
ML_DECL void md_initial_state(md_data *d, int j, double value);
ML_DECL double md_mean_state(const md_data *d, int j);
ML_DECL double md_normal_force(const md_instance *m, int j);
ML_DECL md_status md_evaluate(md_instance *m, const char *call, int j);
ML_DECL md_status md_energy_total(md_instance *m, const char *call, double *value);

ML_DECL md_status md_get_state(md_instance *m, const char *call, void **state);
ML_DECL md_status md_set_state(md_instance *m, const char *call, const void *state);
ML_DECL void md_free_state(md_instance *m, void *state);
ML_DECL size_t md_serialized_size(void);
ML_DECL md_status md_serialize(md_instance *m, const char *call, const void *state,
                       unsigned char *bytes, size_t size);
ML_DECL
md_status md_deserialize(md_instance *m, const char *call, const unsigned char *bytes,
                         size_t size, void **state);

#ifdef __cplusplus
}
#endif

#endif
