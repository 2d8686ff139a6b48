/* Maxwell branches of a mount axis (a spring in series with a damper, in parallel
 * with the elastic law): a C99 port of fmu_src/linear_branches.py's maxwell_step and
 * of the Maxwell part of fmu_src/mount_law.py (MaxwellAxisState, _maxwell_axis_force),
 * operation by operation. C standard library and libm only. */
#ifndef DRYMOUNT_MAXWELL_H
#define DRYMOUNT_MAXWELL_H

#include "mount_law.h"

/* Whether axis p has a Maxwell branch (k > 0 and c > 0; mount_law has_maxwell). */
ML_DECL int ml_has_maxwell(const ml_axis_params *p);

/* linear_branches.maxwell_step: one increment of the branch (k, c) from the
 * committed deflection uc and stroke w0 to the deflection u over dt seconds (exact
 * for a linear path); force into *f, the new stroke into *w, dF/du into *kt. */
ML_DECL void ml_maxwell_step(double k, double c, double uc, double w0, double u,
                             double dt, double *f, double *w, double *kt);

/* The ML_MAX_MAXWELL branches of p from the committed uc and strokes: the new
 * strokes into strokes_new, the summed force and tangent into *f, *kt. */
ML_DECL void ml_maxwell_forces(const ml_axis_params *p, double uc,
                               const double *strokes, double u, double dt,
                               double *strokes_new, double *f, double *kt);

/* The friction element's part of axis p's state of n doubles (n minus uc and the
 * strokes when p has Maxwell branches and the state has their size). */
ML_DECL int ml_inner_size(const ml_axis_params *p, int n);

/* mount_law.slider_position of a state of n doubles with tag: the friction
 * element's position (the Maxwell part is not a position). */
ML_DECL double ml_state_position_p(const ml_axis_params *p, const double *state, int n,
                                   int tag);

/* The Maxwell fields' checks (after the element's, as mount_law's problems);
 * appends to buf, returns the number appended. */
ML_DECL int ml_maxwell_problems(const ml_axis_params *p, const char *prefix, char *buf,
                                size_t size, int count);

#endif
