/* Model Exchange of the native FrictionMount (FMI 2.0 fmi2_me.c, FMI 3.0 fmi3_me.c):
 * the same law as Co-Simulation, as a hybrid ODE in the importer's time.
 *
 * Per axis the friction element's state is
 *  - discrete (Jenkins bank: the slider positions; inclined: (w1, w2, uc); Berg:
 *    its reversal memory): the committed state of model.h, updated at events only.
 *    Between events every output is the exact return map from the committed state to
 *    the present inputs (the Co-Simulation trial, rate independent), exact while u
 *    moves one way; an event commits it where u reverses and where a slider or
 *    surface starts to slip;
 *  - continuous (Dahl, LuGre): the bristle deflection z (Dahl's force / kf) with
 *    dz/dt = v - kf |v| z / g(v) (g = Fc for Dahl, the Stribeck curve for LuGre) and
 *    the dissipated energy E, integrated by the importer; the energy E is also
 *    continuous for Berg (the positive part of its rate) and for a bank once its
 *    normal force varies (the friction force's work; docs/fmu.md 7a).
 * Event indicators per axis: zs, the margin [N] of the stuck slider (surface) nearest
 * to its slip limit (negative: slipping; Berg: its force times the sign of v at the
 * last event, the sign of its energy rate), and zr = sign(v at the last event) * v
 * [m/s] while anything slips (or for Dahl, LuGre, Berg: always), negative once the
 * motion reverses. The importer supplies u and v = du/dt of the same motion: the
 * reversals are read from the sign of v.
 */
#ifndef DRYMOUNT_ME_H
#define DRYMOUNT_ME_H

#include "internal.h"

#ifdef __cplusplus
extern "C" {
#endif

#include <stddef.h>

#include "model.h"

#define MX_N_STATES (3 * MX_STATES_PER_AXIS)
#define MX_N_INDICATORS (3 * MX_INDICATORS_PER_AXIS)

/* Where an ME call may come (bitmask of these). */
#define MX_AT_INSTANTIATED 1u
#define MX_AT_INIT 2u
#define MX_AT_EVENT 4u
#define MX_AT_CONTINUOUS 8u
#define MX_AT_TERMINATED 16u
#define MX_AT_ANY 31u

/* MD_OK if the instance is a Model Exchange one and in one of the states `allowed`,
 * else logs why and returns MD_ERROR. */
ML_DECL md_status mx_check(md_instance *m, const char *call, unsigned allowed);
/* MD_ERROR (logged) if the instance is a Model Exchange one: `call` is
 * Co-Simulation only. */
ML_DECL md_status mx_refuse_in_me(md_instance *m, const char *call);

/* md_get plus the Model Exchange variables (states, derivatives, indicators); in a
 * Model Exchange instance the outputs of continuous elements from the states. */
ML_DECL md_status mx_get(md_instance *m, const char *call, md_type type, unsigned vr,
                         double *value);

ML_DECL md_status mx_set_time(md_instance *m, const char *call, double t);
ML_DECL md_status mx_set_states(md_instance *m, const char *call, const double *x,
                                size_t n);
ML_DECL md_status mx_get_states(md_instance *m, const char *call, double *x, size_t n);
ML_DECL md_status mx_derivatives(md_instance *m, const char *call, double *dx,
                                 size_t n);
ML_DECL md_status mx_indicators(md_instance *m, const char *call, double *z, size_t n);
ML_DECL md_status mx_nominals(md_instance *m, const char *call, double *x, size_t n);
ML_DECL md_status mx_enter_event_mode(md_instance *m, const char *call);
ML_DECL md_status mx_enter_continuous_mode(md_instance *m, const char *call);
/* The event iteration (fmi2NewDiscreteStates, fmi3UpdateDiscreteStates): commits
 * every discrete element's state, decides the stick/slip modes; *changed: the
 * continuous states changed (a Dahl/LuGre element that lost contact). */
ML_DECL md_status mx_update(md_instance *m, const char *call, int *changed);
/* *enter_event: a step event is needed (the normal force of a discrete element
 * changed since the last event: committing each step keeps its law the
 * Co-Simulation one with the integrator's steps). */
ML_DECL md_status mx_completed_step(md_instance *m, const char *call, int *enter_event);

/* Internal to me.c and me_bank.c. The normal force of axis j (n_<axis> once set,
 * else <axis>_n0). */
ML_DECL double mx_normal(const md_instance *m, int j);
/* The Jenkins bank of axis j (me_bank.c): its modes from the committed state, its
 * indicators zs and zr, the energy dissipated since the last event, the energies
 * kept at an event (e0: the committed energy, diss: mx_bank_dissipated's, n_last:
 * the normal force at the last event), the estimate of dFs/dt at an event. */
ML_DECL void mx_bank_modes(md_instance *m, int j);
ML_DECL void mx_bank_indicators(const md_instance *m, int j, double *zs, double *zr);
ML_DECL double mx_bank_dissipated(const md_instance *m, int j);
ML_DECL void mx_bank_event_energy(md_instance *m, int j, double e0, double diss,
                                  double n_last);
ML_DECL void mx_bank_rate(md_instance *m, int j, double n_last);

#ifdef __cplusplus
}
#endif

#endif
