/* Inclined two-surface friction element of thesis Chapter 5 (Fig. 5.4, eq. 5.1-5.10):
 * a C99 port of fmu_src/inclined.py.
 *
 * fmu_src/inclined.py is the source of truth (the derivation is in docs/physics.md,
 * "Inclined two-surface friction element"); this file repeats its exact return map
 * operation by operation (same order, so the same IEEE-754 results), its parameter
 * checks and its ContactLost messages. tests/test_native_inclined.py holds the two to
 * 1e-12 on random trajectories. C standard library and libm only.
 */
#ifndef DRYMOUNT_INCLINED_H
#define DRYMOUNT_INCLINED_H

#include "internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#include <stddef.h>

/* inclined.InclinedParameters (SI units, theta_deg in degrees; mu = inf: bonded). */
typedef struct {
    double theta_deg, k, kf, kf2, mu1, mu2, preload;
} in_params;

/* inclined.InclinedStep: the state after a deflection increment. */
typedef struct {
    double force;        /* force along the mount axis, N (= n2) */
    double f1, f2;       /* friction forces of the inclined and the flat surface, N */
    double n1, n2;       /* normal forces N and N2, N */
    double w1, w2;       /* slider positions, m */
    int slip1, slip2;    /* whether each surface slips at the end */
    double tangent;      /* dF/dx at the end, N/m */
    double dissipated;   /* friction energy of the increment, J */
} in_step;

/* in_update's outcome: IN_CONTACT_LOST is inclined.ContactLost (message written). */
typedef enum { IN_OK = 0, IN_CONTACT_LOST = 1 } in_status;

/* The thesis's example values (inclined.InclinedParameters()). */
ML_DECL in_params in_default_params(void);

/* InclinedParameters.sc: sin and cos of theta (exactly 1, 0 at 90 degrees). */
ML_DECL void in_sc(const in_params *p, double *s, double *c);

/* InclinedParameters.self_locking_margin. */
ML_DECL double in_self_locking_margin(const in_params *p);

/* InclinedParameters.problems(prefix) as "; "-separated text in buf (always
 * NUL-terminated); returns the number of problems. */
ML_DECL int in_problems(const in_params *p, const char *prefix, char *buf, size_t size);

/* inclined.inclined_forces: (f1, f2, N, N2) at x in regime (sig1, sig2), each -1, 0
 * (stuck) or +1, into out[4]. */
ML_DECL
void in_forces(double x, double w1, double w2, const in_params *p, int sig1, int sig2,
               double out[4]);

/* inclined.inclined_update: the exact return map from x_old to x (monotonic inside)
 * with the committed sliders w1, w2. IN_OK: *out is the step. IN_CONTACT_LOST: the
 * motion needs a negative normal force on a surface that can slip (or more than 64
 * stick/slip events); msg receives ContactLost's message, *out is untouched. */
ML_DECL
in_status in_update(double x, double x_old, double w1, double w2, const in_params *p,
                    in_step *out, char *msg, size_t size);

#ifdef __cplusplus
}
#endif

#endif
