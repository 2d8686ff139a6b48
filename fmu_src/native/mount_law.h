/* Force law of a friction-damped engine mount: a C99 port of fmu_src/mount_law.py.
 *
 * fmu_src/mount_law.py is the single source of truth; this file repeats its arithmetic
 * operation by operation (same order, so the same IEEE-754 results) and its parameter
 * checks with the same messages. tests/test_native_law.py holds the two to 1e-12 on
 * random trajectories. C standard library and libm only.
 */
#ifndef DRYMOUNT_MOUNT_LAW_H
#define DRYMOUNT_MOUNT_LAW_H

#include <stddef.h>

/* Elastic laws, codes as mount_law.LAWS. */
enum ml_law { ML_LINEAR = 0, ML_CUBIC = 1, ML_PIECEWISE = 2, ML_PIECEWISE_ASYM = 3 };
#define ML_N_LAWS 4
/* mount_law.MAX_SLIDERS */
#define ML_MAX_SLIDERS 64

/* Parameters of one local axis (mount_law.AxisParameters), SI units. */
typedef struct {
    int law;          /* enum ml_law */
    double k1, kc, k2, delta, delta_neg, c;
    int friction;     /* 0 or 1 */
    double kf, mu, n0;
    int sliders;      /* micro-slip sliders; the C port runs only 1 (see model.c) */
    double spread, fs_ratio;  /* checked; fs_ratio != 1 is not ported either */
} ml_axis_params;

/* Result of mount_law.axis_force. */
typedef struct {
    double force;       /* total force, N */
    double friction;    /* friction force, N */
    double w_new;       /* slider position after the increment, m */
    double tangent;     /* dF/du, N/m */
    int slipping;       /* 1 while the slider slips */
    double dissipated;  /* fs * |w_new - w|, J */
} ml_axis_result;

/* The thesis's defaults (mount_law.AxisParameters()). */
ml_axis_params ml_default_params(void);

/* mount_law.elastic_force: force into *f, tangent into *k. */
void ml_elastic_force(double u, int law, double k1, double kc, double k2,
                      double delta, double delta_neg, double *f, double *k);

/* mount_law.jenkins_update; returns the friction force. */
double ml_jenkins_update(double u, double w, double kf, double fs, double *w_new,
                         double *tangent, int *slipping);

/* mount_law.axis_force (kf <= 0: no friction element). */
ml_axis_result ml_axis_force(double u, double v, double w, int law, double k1,
                             double kc, double k2, double delta, double delta_neg,
                             double c, double kf, double fs);

/* Slip force from the normal-force input: mu * max(n, 0) with friction, else 0. */
double ml_slip_force(const ml_axis_params *p, double n);

/* mount_law.axis_force with the parameters of an axis and normal force n. */
ml_axis_result ml_axis_force_p(double u, double v, double w, const ml_axis_params *p,
                               double n);

/* Append the problems of p (AxisParameters.problems(prefix), plus the law-code check
 * of the FMU) to buf as "; "-separated text. Returns the number of problems found.
 * buf is always NUL-terminated (truncated if too small). */
int ml_axis_problems(const ml_axis_params *p, const char *prefix, char *buf,
                     size_t size);

/* Python's repr() of a float (shortest round-trip text), for the messages. */
void ml_repr_double(double x, char *buf, size_t size);

#endif
