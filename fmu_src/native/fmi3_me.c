/* FMI 3.0 Model Exchange entry points of the native FrictionMount (me.h does the
 * work). The calls shared with Co-Simulation (instantiation, values, FMU states) are
 * those of fmi3_glue.c. */
#include <stddef.h>

#include "fmi3_api.h"
#include "me.h"

/* The instance: fmi3_glue.c's environment starts with the md_instance pointer. */
static md_instance *me3_model(fmi3Instance c) { return *(md_instance **)c; }

#define ME3_CHECK(c)              \
    do {                          \
        if ((c) == NULL)          \
            return fmi3Error;     \
    } while (0)

fmi3Status fmi3EnterEventMode(fmi3Instance c)
{
    md_instance *m;
    ME3_CHECK(c);
    m = me3_model(c);
    if (!m->model_exchange) {
        md_log(m, MD_ERROR, "fmi3EnterEventMode is not supported by this FMU in "
               "Co-Simulation (hasEventMode=false)");
        return fmi3Error;
    }
    return (fmi3Status)mx_enter_event_mode(m, "fmi3EnterEventMode");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *needUpdate,
                                    fmi3Boolean *terminate, fmi3Boolean *nominalsChanged,
                                    fmi3Boolean *valuesChanged,
                                    fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    int changed = 0;
    md_status status;
    ME3_CHECK(c);
    status = mx_update(me3_model(c), "fmi3UpdateDiscreteStates", &changed);
    if (needUpdate != NULL)
        *needUpdate = false;  /* one pass decides every mode */
    if (terminate != NULL)
        *terminate = false;
    if (nominalsChanged != NULL)
        *nominalsChanged = false;
    if (valuesChanged != NULL)
        *valuesChanged = changed != 0;
    if (nextEventTimeDefined != NULL)
        *nextEventTimeDefined = false;
    if (nextEventTime != NULL)
        *nextEventTime = 0.0;
    return (fmi3Status)status;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_enter_continuous_mode(me3_model(c),
                                                "fmi3EnterContinuousTimeMode");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSet,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation)
{
    int event = 0;
    md_status status;
    ME3_CHECK(c);
    (void)noSet;
    status = mx_completed_step(me3_model(c), "fmi3CompletedIntegratorStep", &event);
    if (enterEventMode != NULL)
        *enterEventMode = event != 0;
    if (terminateSimulation != NULL)
        *terminateSimulation = false;
    return (fmi3Status)status;
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_set_time(me3_model(c), "fmi3SetTime", time);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 x[], size_t n)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_set_states(me3_model(c), "fmi3SetContinuousStates", x, n);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 dx[], size_t n)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_derivatives(me3_model(c),
                                      "fmi3GetContinuousStateDerivatives", dx, n);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 z[], size_t n)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_indicators(me3_model(c), "fmi3GetEventIndicators", z, n);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 x[], size_t n)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_get_states(me3_model(c), "fmi3GetContinuousStates", x, n);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 x[], size_t n)
{
    ME3_CHECK(c);
    return (fmi3Status)mx_nominals(me3_model(c), "fmi3GetNominalsOfContinuousStates",
                                   x, n);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *n)
{
    ME3_CHECK(c);
    if (n == NULL || mx_check(me3_model(c), "fmi3GetNumberOfEventIndicators",
                              MX_AT_ANY) != MD_OK)
        return fmi3Error;
    *n = MX_N_INDICATORS;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *n)
{
    ME3_CHECK(c);
    if (n == NULL || mx_check(me3_model(c), "fmi3GetNumberOfContinuousStates",
                              MX_AT_ANY) != MD_OK)
        return fmi3Error;
    *n = MX_N_STATES;
    return fmi3OK;
}
