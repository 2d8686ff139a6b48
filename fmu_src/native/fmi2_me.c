/* FMI 2.0 Model Exchange entry points of the native FrictionMount (me.h does the
 * work). The calls shared with Co-Simulation (instantiation, values, FMU states) are
 * those of fmi2_glue.c. */
#include <stddef.h>

#include "fmi2_api.h"
#include "me.h"

#ifdef FMI2_FUNCTION_PREFIX
#define fmi2CompletedIntegratorStep fmi2FullName(fmi2CompletedIntegratorStep)
#define fmi2EnterContinuousTimeMode fmi2FullName(fmi2EnterContinuousTimeMode)
#define fmi2EnterEventMode fmi2FullName(fmi2EnterEventMode)
#define fmi2GetContinuousStates fmi2FullName(fmi2GetContinuousStates)
#define fmi2GetDerivatives fmi2FullName(fmi2GetDerivatives)
#define fmi2GetEventIndicators fmi2FullName(fmi2GetEventIndicators)
#define fmi2GetNominalsOfContinuousStates fmi2FullName(fmi2GetNominalsOfContinuousStates)
#define fmi2NewDiscreteStates fmi2FullName(fmi2NewDiscreteStates)
#define fmi2SetContinuousStates fmi2FullName(fmi2SetContinuousStates)
#define fmi2SetTime fmi2FullName(fmi2SetTime)
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* fmi2FunctionTypes.h of the standard */
typedef struct {
    fmi2Boolean newDiscreteStatesNeeded;
    fmi2Boolean terminateSimulation;
    fmi2Boolean nominalsOfContinuousStatesChanged;
    fmi2Boolean valuesOfContinuousStatesChanged;
    fmi2Boolean nextEventTimeDefined;
    fmi2Real nextEventTime;
} fmi2EventInfo;

FMI2_API fmi2Status fmi2EnterEventMode(fmi2Component);
FMI2_API fmi2Status fmi2NewDiscreteStates(fmi2Component, fmi2EventInfo *);
FMI2_API fmi2Status fmi2EnterContinuousTimeMode(fmi2Component);
FMI2_API fmi2Status fmi2CompletedIntegratorStep(fmi2Component, fmi2Boolean,
                                                fmi2Boolean *, fmi2Boolean *);
FMI2_API fmi2Status fmi2SetTime(fmi2Component, fmi2Real);
FMI2_API fmi2Status fmi2SetContinuousStates(fmi2Component, const fmi2Real[], size_t);
FMI2_API fmi2Status fmi2GetDerivatives(fmi2Component, fmi2Real[], size_t);
FMI2_API fmi2Status fmi2GetEventIndicators(fmi2Component, fmi2Real[], size_t);
FMI2_API fmi2Status fmi2GetContinuousStates(fmi2Component, fmi2Real[], size_t);
FMI2_API fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component, fmi2Real[],
                                                      size_t);

#ifdef __cplusplus
}
#endif

/* The instance: fmi2_glue.c's environment starts with the md_instance pointer. */
static md_instance *me2_model(fmi2Component c) { return *(md_instance **)c; }

#define ME2_CHECK(c)              \
    do {                          \
        if ((c) == NULL)          \
            return fmi2Error;     \
    } while (0)

fmi2Status fmi2EnterEventMode(fmi2Component c)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_enter_event_mode(me2_model(c), "fmi2EnterEventMode");
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info)
{
    int changed = 0;
    md_status status;
    ME2_CHECK(c);
    if (info == NULL)
        return fmi2Error;
    status = mx_update(me2_model(c), "fmi2NewDiscreteStates", &changed);
    info->newDiscreteStatesNeeded = fmi2False;  /* one pass decides every mode */
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return (fmi2Status)status;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_enter_continuous_mode(me2_model(c),
                                                "fmi2EnterContinuousTimeMode");
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetPrior,
                                       fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation)
{
    int event = 0;
    md_status status;
    ME2_CHECK(c);
    (void)noSetPrior;
    status = mx_completed_step(me2_model(c), "fmi2CompletedIntegratorStep", &event);
    if (enterEventMode != NULL)
        *enterEventMode = event ? fmi2True : fmi2False;
    if (terminateSimulation != NULL)
        *terminateSimulation = fmi2False;
    return (fmi2Status)status;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_set_time(me2_model(c), "fmi2SetTime", time);
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_set_states(me2_model(c), "fmi2SetContinuousStates", x, nx);
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_derivatives(me2_model(c), "fmi2GetDerivatives", derivatives,
                                      nx);
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t ni)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_indicators(me2_model(c), "fmi2GetEventIndicators", z, ni);
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_get_states(me2_model(c), "fmi2GetContinuousStates", x, nx);
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    ME2_CHECK(c);
    return (fmi2Status)mx_nominals(me2_model(c), "fmi2GetNominalsOfContinuousStates",
                                   x, nx);
}
