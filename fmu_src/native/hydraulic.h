/* The hydraulic mount's fluid path on a mount axis (piston Ap on two chambers C1,
 * C2 joined by an inertia track I_i, R_i and a decoupler I_d, R_d): a C99 port of
 * fmu_src/linear_branches.py's fluid_matrices, _expm, fluid_propagator,
 * fluid_relaxed and fluid_step, and of the fluid part of fmu_src/mount_law.py
 * (the four fluid states x1, p2, q_i, q_d after the Maxwell strokes), operation by
 * operation; math.fsum is ported as CPython computes it (exactly rounded), so
 * the results are Python's. C standard library and libm only. */
#ifndef DRYMOUNT_HYDRAULIC_H
#define DRYMOUNT_HYDRAULIC_H

#include "mount_law.h"

/* linear_branches.FLUID_STATE */
#define ML_FLUID_STATE 4

/* One step's propagator (linear_branches.fluid_propagator of dt for the fluid
 * fields in key): x = phi x0 + g0 uc + g1 r. */
typedef struct {
    int valid;
    double dt, key[7];
    double phi[ML_FLUID_STATE][ML_FLUID_STATE], g0[ML_FLUID_STATE],
        g1[ML_FLUID_STATE];
} ml_fluid_prop;

/* Whether axis p has the fluid path (hyd_Ap > 0; mount_law has_hydraulic). */
ML_DECL int ml_has_hydraulic(const ml_axis_params *p);

/* Whether axis p's state carries uc and the branch strokes (Maxwell branches or
 * the fluid path; mount_law has_branches). */
ML_DECL int ml_has_branches(const ml_axis_params *p);


/* linear_branches.fluid_propagator of axis p's fluid over dt > 0 seconds. */
ML_DECL void ml_fluid_propagator(const ml_axis_params *p, double dt, ml_fluid_prop *out);

/* The propagator of dt from cache (recomputed when dt or the fluid fields differ
 * from its key); cache NULL: computed into scratch. Returns the one to use. */
ML_DECL const ml_fluid_prop *ml_fluid_cached(const ml_axis_params *p, double dt,
                                             ml_fluid_prop *cache,
                                             ml_fluid_prop *scratch);

/* linear_branches.fluid_relaxed: the fluid at rest at deflection u into x[4]. */
ML_DECL void ml_fluid_relaxed(const ml_axis_params *p, double u, double *x);

/* linear_branches.fluid_step from the fluid state x0 (committed deflection uc) to
 * u over dt (prop NULL or dt <= 0: a jump, the fluid does not move): new state
 * into x, the force Ap p1 into *f and its tangent into *kt. */
ML_DECL void ml_fluid_step(const ml_axis_params *p, const ml_fluid_prop *prop,
                           const double *x0, double uc, double u, double dt,
                           double *x, double *f, double *kt);

/* ml_axis_force_dt (ml_axis_force_p: with the normal force n) with a cache of the
 * fluid's propagator (NULL: computed per call; the results are the same). */
ML_DECL
int ml_axis_force_dtc(double u, double v, double dt, const double *w,
                      const ml_axis_params *p, double fs, double *w_new,
                      ml_axis_result *r, char *msg, size_t size, ml_fluid_prop *cache);
ML_DECL
int ml_axis_force_pc(double u, double v, double dt, const double *w,
                     const ml_axis_params *p, double n, double *w_new,
                     ml_axis_result *r, char *msg, size_t size, ml_fluid_prop *cache);

/* The fluid fields' checks (after the Maxwell fields', as mount_law's problems);
 * appends to buf, returns the number appended. */
ML_DECL int ml_hydraulic_problems(const ml_axis_params *p, const char *prefix,
                                  char *buf, size_t size, int count);

#endif
