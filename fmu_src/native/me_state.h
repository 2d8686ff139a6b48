/* What a Model Exchange instance of the native FrictionMount keeps beyond the
 * Co-Simulation state (part of md_data, so FMU states save and restore it): see me.h. */
#ifndef DRYMOUNT_ME_STATE_H
#define DRYMOUNT_ME_STATE_H

#include "mount_law.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Continuous states per axis: the bristle deflection z [m] and the energy E [J] the
 * Dahl, LuGre or Berg element dissipated (a Jenkins bank: its friction force's work;
 * both constant 0 for the other elements). */
#define MX_STATES_PER_AXIS 2
/* Event indicators per axis: the margin of the stuck slider (or surface) nearest to
 * slipping [N], and the velocity reversal of the slipping ones [m/s]. */
#define MX_INDICATORS_PER_AXIS 2

/* Roles of the Model Exchange variables in the variable table (beyond md_role). */
#define MX_ROLE_Z ((md_role)100)        /* state zb_<axis> */
#define MX_ROLE_E ((md_role)101)        /* state Eb_<axis> */
#define MX_ROLE_DZ ((md_role)102)       /* der(zb_<axis>) */
#define MX_ROLE_DE ((md_role)103)       /* der(Eb_<axis>) */
#define MX_ROLE_STICK ((md_role)104)    /* event indicator zs_<axis> */
#define MX_ROLE_REVERSE ((md_role)105)  /* event indicator zr_<axis> */

typedef enum { MX_PHASE_NONE = 0, MX_PHASE_EVENT = 1, MX_PHASE_CONTINUOUS = 2 } mx_phase;

typedef struct {
    int phase;            /* mx_phase (after initialization) */
    double x[3][MX_STATES_PER_AXIS];
    /* per slider (Jenkins bank) or surface (inclined): 0 stuck, +1 / -1 slipping
     * in the direction of +u / -u, as decided at the last event */
    signed char mode[3][ML_MAX_SLIDERS];
    signed char dir[3];   /* sign of v at the last event (0: at rest) */
    double n_event[3];    /* normal force at the last event */
    /* once n varies: the slip force's rate dFs/dt [N/s] from the last two events at
     * different times (t_event: the time of the last), which decides whether a
     * slider at its limit slips on against the motion (a falling Fs) or sticks */
    double fs_rate[3], t_event[3];
    /* the Jenkins bank's energy under a varying normal force (docs/fmu.md 7a): once
     * n_varies (n changed between two events), Eb_<axis> integrates the work of its
     * friction force and E_fr_<axis> adds to the energy at the last event the work
     * since less the change of the sliders' elastic energy; at the last event: Eb and
     * that elastic energy; iterated: an event iteration was done since
     * initialization */
    double work_event[3], stored_event[3];
    int n_varies[3], iterated;
} md_me;

#ifdef __cplusplus
}
#endif

#endif
