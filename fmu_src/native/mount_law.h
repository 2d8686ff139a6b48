/* Force law of a friction-damped engine mount: a C99 port of fmu_src/mount_law.py.
 *
 * fmu_src/mount_law.py is the single source of truth; this file repeats its arithmetic
 * operation by operation (same order, so the same IEEE-754 results) and its parameter
 * checks with the same messages. tests/test_native_law.py holds the two to 1e-12 on
 * random trajectories. C standard library and libm only.
 */
#ifndef DRYMOUNT_MOUNT_LAW_H
#define DRYMOUNT_MOUNT_LAW_H

#include "internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#include <stddef.h>

#include "inclined.h"
#include "messages.h"

/* Elastic laws, codes as mount_law.LAWS. */
enum ml_law { ML_LINEAR = 0, ML_CUBIC = 1, ML_PIECEWISE = 2, ML_PIECEWISE_ASYM = 3 };
#define ML_N_LAWS 4
/* mount_law.MAX_SLIDERS */
#define ML_MAX_SLIDERS 64
/* linear_branches.MAX_MAXWELL: Maxwell branches per axis */
#define ML_MAX_MAXWELL 3
/* The largest axis state: the element's, then uc and the Maxwell strokes, then the
 * hydraulic fluid's 4 states (mount_law.MaxwellAxisState; hydraulic.h). */
#define ML_MAX_STATE (ML_MAX_SLIDERS + 1 + ML_MAX_MAXWELL + 4)

/* Parameters of one local axis (mount_law.AxisParameters), SI units. */
typedef struct {
    int law;          /* enum ml_law */
    double k1, kc, k2, delta, delta_neg, c;
    int friction;     /* 0 or 1 */
    double kf, mu, n0;
    int sliders;      /* Jenkins elements of the micro-slip (Iwan) element, 1..64 */
    double spread, fs_ratio;  /* slip-displacement spread; negative/positive Fs */
    int friction_kind;        /* code of the element in fmu_src.friction's registry */
    /* the inclined element (its inclined surface's stiffness is kf) */
    double theta_deg, k, kf2, mu1, mu2, preload;
    /* the LuGre element (its bristle stiffness sigma0 is kf) */
    double sigma1, sigma2, stribeck_ratio, v_stribeck;
    /* the Maxwell branches (k 0 or c 0: absent), maxwell.h */
    double maxwell_k1, maxwell_c1, maxwell_k2, maxwell_c2, maxwell_k3, maxwell_c3;
    /* the hydraulic fluid path (hyd_Ap 0: absent), hydraulic.h */
    double hyd_Ap, hyd_C1, hyd_C2, hyd_I_i, hyd_R_i, hyd_I_d, hyd_R_d;
} ml_axis_params;

/* Result of mount_law.axis_force. */
typedef struct {
    double force;       /* total force, N */
    double friction;    /* friction force, N */
    double w_new;       /* slider position after the increment, m (micro-slip: the
                           first slider's; all of them in the caller's array) */
    double tangent;     /* dF/du, N/m */
    int slipping;       /* 1 while the slider slips */
    double dissipated;  /* energy the sliders dissipate in the increment, J */
} ml_axis_result;

/* One increment of a friction element (fmu_src.friction.ElementStep without the
 * state, which goes to the caller's w_new array, and without dF/dv). */
typedef struct {
    double force;       /* friction force, N */
    double tangent;     /* dF/du, N/m */
    double dissipated;  /* J */
    int slipping;
} ml_friction_step;

/* The C contract of a friction element (fmu_src.friction.FrictionElement): one file
 * per element defines one of these (its c_port), the generated friction_table.h lists
 * them in registry order (ML_ELEMENTS, ML_N_FRICTION_KINDS). */
typedef struct {
    const char *name;
    int named_state;  /* its state is tagged with its kind (a named tuple in Python) */
    int (*state_size)(const ml_axis_params *p);
    void (*start)(const ml_axis_params *p, double w, double *state);
    double (*position)(const double *state, int n);
    /* returns 1 (message in msg) when the increment is impossible (lost contact) */
    int (*step)(double u, double v, const double *w, const ml_axis_params *p,
                double fs, double dt, double *w_new, ml_friction_step *out, char *msg,
                size_t size);
    void (*normal_forces)(const ml_axis_params *p, const double *w, double fs,
                          double *n1, double *n2);
    /* checks beyond one field (NULL: none); appends to buf (count there already),
     * returns the number appended */
    int (*problems)(const ml_axis_params *p, const char *prefix, char *buf,
                    size_t size, int count);
    /* FrictionElement.slider_slots: the index in the state of settable slider
     * `slot` (0, 1, ...), -1 if it has none (NULL: no settable sliders) */
    int (*slider_index)(const ml_axis_params *p, int slot);
} ml_element;

/* The thesis's defaults (mount_law.AxisParameters()). */
ML_DECL ml_axis_params ml_default_params(void);

/* mount_law.elastic_force: force into *f, tangent into *k. */
ML_DECL void ml_elastic_force(double u, int law, double k1, double kc, double k2,
                      double delta, double delta_neg, double *f, double *k);

/* mount_law.jenkins_update; returns the friction force. */
ML_DECL
double ml_jenkins_update(double u, double w, double kf, double fs, double *w_new,
                         double *tangent, int *slipping);

/* mount_law.slider_update (non-symmetric slip forces fs_pos, fs_neg); returns the
 * friction force. */
ML_DECL
double ml_slider_update(double u, double w, double kf, double fs_pos, double fs_neg,
                        double *w_new, double *tangent, int *slipping);

/* mount_law.iwan_update with the bank mount_law.slider_bank(p, fs): the micro-slip
 * element of axis p alone (force = friction). w holds the p->sliders committed
 * positions, w_new receives them after the increment. */
ML_DECL
ml_axis_result ml_iwan_update(double u, const double *w, const ml_axis_params *p,
                              double fs, double *w_new);

/* Number of doubles in the friction state of axis p (its element's state_size; 1
 * without friction). */
ML_DECL int ml_state_size(const ml_axis_params *p);

/* mount_law.initial_sliders: the state of axis p relaxed at w, into state. */
ML_DECL void ml_state_start(const ml_axis_params *p, double w, double *state);

/* The tag of a state of axis p's element: its kind + 1 for an element with a named
 * state (mount_law.conform_state keeps only a state of its own kind), else 0. */
ML_DECL int ml_state_tag(const ml_axis_params *p);
/* The number of friction elements of the table (the largest state tag). */
ML_DECL int ml_friction_kinds(void);

/* The index in axis p's friction state of its settable slider `slot` (the FMU's
 * w1_/w2_<axis>: FrictionElement.slider_slots), -1 if it has none. */
ML_DECL int ml_slider_index(const ml_axis_params *p, int slot);

/* mount_law.slider_position / mean_slider of the n doubles of a state with tag. */
ML_DECL double ml_state_position(const double *state, int n, int tag);

/* The inclined element's parameters of axis p (kf: the axis's). */
ML_DECL in_params ml_inclined_params(const ml_axis_params *p);

/* inclined.relaxed_state: the inclined element of axis p relaxed at deflection u, as
 * the state (w1, w2, uc) in w[0..2]. */
ML_DECL void ml_relaxed_state(const ml_axis_params *p, double u, double *w);

/* mount_law.normal_forces (N, N2) of axis p's friction element in state w (after an
 * increment) with slip force fs (its element's normal_forces; (0, 0) without
 * friction). */
ML_DECL
void ml_normal_forces(const ml_axis_params *p, const double *w, double fs, double *n1,
                      double *n2);

/* jenkins.contact_normal_forces: the contact's normal force Fs / mu (n0 if mu = 0)
 * and 0 (w unused). */
ML_DECL
void ml_contact_normal_forces(const ml_axis_params *p, const double *w, double fs,
                              double *n1, double *n2);

/* mount_law.mean_slider of the n positions w: the common position when all are
 * equal, else their exactly rounded sum (math.fsum) / n. */
/* math.fsum of x[0..n-1] (CPython's algorithm: exactly rounded; mount_law.c). */
ML_DECL double ml_fsum(const double *x, int n);

ML_DECL double ml_mean_slider(const double *w, int n);

/* mount_law.axis_force for every friction element of p (macro-slip, non-symmetric,
 * micro-slip, inclined) with slip force fs: w holds the ml_state_size(p) doubles of
 * the committed state, w_new receives them after the increment. Returns 0 with the
 * result in *r, or 1 when the inclined element loses contact (inclined.ContactLost:
 * its message in msg, nothing else written). */
ML_DECL
int ml_axis_force_w(double u, double v, const double *w, const ml_axis_params *p,
                    double fs, double *w_new, ml_axis_result *r, char *msg,
                    size_t size);

/* ml_axis_force_w over an increment of dt seconds (mount_law.axis_force's dt: read by
 * rate-dependent elements only; ml_axis_force_w is dt = 0). */
ML_DECL
int ml_axis_force_dt(double u, double v, double dt, const double *w,
                     const ml_axis_params *p, double fs, double *w_new,
                     ml_axis_result *r, char *msg, size_t size);

/* mount_law.axis_force of the symmetric macro-slip element (kf <= 0: no friction
 * element). */
ML_DECL ml_axis_result ml_axis_force(double u, double v, double w, int law, double k1,
                             double kc, double k2, double delta, double delta_neg,
                             double c, double kf, double fs);

/* Slip force from the normal-force input: mu * max(n, 0) with friction, else 0. */
ML_DECL double ml_slip_force(const ml_axis_params *p, double n);

/* ml_axis_force_dt with the parameters of an axis and normal force n. */
ML_DECL
int ml_axis_force_p(double u, double v, double dt, const double *w,
                    const ml_axis_params *p, double n, double *w_new,
                    ml_axis_result *r, char *msg, size_t size);

/* Append the problems of p (AxisParameters.problems(prefix), plus the law-code and
 * friction-kind-code checks of the FMU) to buf as "; "-separated text. Returns the number of problems found.
 * buf is always NUL-terminated (truncated if too small). */
ML_DECL int ml_axis_problems(const ml_axis_params *p, const char *prefix, char *buf,
                     size_t size);


#ifdef __cplusplus
}
#endif

#endif
