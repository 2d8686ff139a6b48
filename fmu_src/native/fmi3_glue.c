/* FMI 3.0 entry points of the native FrictionMount shared by Co-Simulation and Model
 * Exchange (model.h does the work; this file converts types and names the calls; the
 * Model Exchange ones are in fmi3_me.c). Scheduled Execution is not provided: its
 * functions log an error and return fmi3Error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3_api.h"
#include "me.h"
#include "model.h"

typedef struct {
    md_instance *m;
    fmi3LogMessageCallback logger;
    fmi3InstanceEnvironment env;
} fmi3_env;

#define M(c) (((fmi3_env *)(c))->m)
#define CHECK(c)                      \
    do {                              \
        if ((c) == NULL)              \
            return fmi3Error;         \
    } while (0)
#define UNUSED(x) (void)(x)

static void log_bridge(void *env, const char *instance, md_status status,
                       const char *category, const char *message)
{
    const fmi3_env *e = (const fmi3_env *)env;
    char text[2300];
    (void)category;
    if (e->logger == NULL)
        return;
    /* FMI 3.0 passes no instance name: prefix it */
    snprintf(text, sizeof text, "%s: %s", instance, message);
    e->logger(e->env, (fmi3Status)status, category, text);
}

static fmi3Status unsupported(fmi3Instance c, const char *call, const char *why)
{
    CHECK(c);
    md_log(M(c), MD_ERROR, "%s is not supported by this FMU (%s)", call, why);
    return fmi3Error;
}

const char *fmi3GetVersion(void) { return "3.0"; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t n,
                               const fmi3String categories[])
{
    size_t i;
    CHECK(c);
    for (i = 0; i < n; ++i) {
        if (strcmp(categories[i], "logAll") && strcmp(categories[i], "logStatusWarning")
            && strcmp(categories[i], "logStatusDiscard")
            && strcmp(categories[i], "logStatusError")
            && strcmp(categories[i], "logStatusFatal")) {
            md_log(M(c), MD_ERROR, "fmi3SetDebugLogging: unknown log category '%s'",
                   categories[i]);
            return fmi3Error;
        }
    }
    M(c)->logging_on = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediate[],
    size_t nRequiredIntermediate, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediate)
{
    fmi3_env *e;
    const char *name = instanceName ? instanceName : "";
    const char *why = NULL;
    char text[256];
    UNUSED(resourcePath); UNUSED(visible); UNUSED(earlyReturnAllowed);
    UNUSED(requiredIntermediate); UNUSED(intermediate);
    if (instantiationToken == NULL
        || strcmp(instantiationToken, md_instantiation_token()) != 0)
        why = "the instantiationToken does not match the modelDescription.xml of "
              "this FMU";
    else if (eventModeUsed)
        why = "eventModeUsed: this FMU has no event mode (hasEventMode=false)";
    else if (nRequiredIntermediate > 0)
        why = "no intermediate variables are provided";
    if (why != NULL) {
        if (logMessage != NULL) {
            snprintf(text, sizeof text, "%s: fmi3InstantiateCoSimulation: %s", name, why);
            logMessage(instanceEnvironment, fmi3Error, "logStatusError", text);
        }
        return NULL;
    }
    e = (fmi3_env *)calloc(1, sizeof *e);
    if (e == NULL)
        return NULL;
    e->logger = logMessage;
    e->env = instanceEnvironment;
    e->m = md_new(name, "fmi3", log_bridge, e, NULL, NULL, loggingOn);
    if (e->m == NULL) {
        free(e);
        return NULL;
    }
    return e;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String token,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment env,
                                          fmi3LogMessageCallback logMessage)
{
    fmi3_env *e;
    const char *name = instanceName ? instanceName : "";
    char text[256];
    UNUSED(resourcePath); UNUSED(visible);
    if (token == NULL || strcmp(token, md_instantiation_token()) != 0) {
        if (logMessage != NULL) {
            snprintf(text, sizeof text, "%s: fmi3InstantiateModelExchange: the "
                     "instantiationToken does not match the modelDescription.xml of "
                     "this FMU", name);
            logMessage(env, fmi3Error, "logStatusError", text);
        }
        return NULL;
    }
    e = (fmi3_env *)calloc(1, sizeof *e);
    if (e == NULL)
        return NULL;
    e->logger = logMessage;
    e->env = env;
    e->m = md_new(name, "fmi3", log_bridge, e, NULL, NULL, loggingOn);
    if (e->m == NULL) {
        free(e);
        return NULL;
    }
    e->m->model_exchange = 1;
    return e;
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock)
{
    UNUSED(instanceName); UNUSED(token); UNUSED(resourcePath); UNUSED(visible);
    UNUSED(loggingOn); UNUSED(clockUpdate); UNUSED(lock); UNUSED(unlock);
    if (logMessage != NULL)
        logMessage(env, fmi3Error, "logStatusError",
                   "fmi3InstantiateScheduledExecution: this FMU supports "
                   "Co-Simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance c)
{
    if (c == NULL)
        return;
    md_delete(M(c));
    free(c);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    CHECK(c);
    UNUSED(toleranceDefined); UNUSED(tolerance); UNUSED(stopTimeDefined);
    UNUSED(stopTime);
    return (fmi3Status)md_enter_initialization(M(c), "fmi3EnterInitializationMode",
                                               startTime, 1);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
{
    CHECK(c);
    return (fmi3Status)md_exit_initialization(M(c), "fmi3ExitInitializationMode");
}

fmi3Status fmi3Terminate(fmi3Instance c)
{
    CHECK(c);
    return (fmi3Status)md_terminate(M(c), "fmi3Terminate");
}

fmi3Status fmi3Reset(fmi3Instance c)
{
    CHECK(c);
    md_reset(M(c));
    return fmi3OK;
}

/* ------------------------------------------------------------------ values */

static fmi3Status count_check(fmi3Instance c, const char *call, size_t nvr,
                              size_t nValues)
{
    if (nvr == nValues)
        return fmi3OK;
    md_log(M(c), MD_ERROR, "%s: nValues (%u) must equal nValueReferences (%u): the "
           "model has no array variables", call, (unsigned)nValues, (unsigned)nvr);
    return fmi3Error;
}

#define GET_LOOP(call, mdtype, ctype)                                              \
    size_t i;                                                                      \
    md_status status = MD_OK, s;                                                   \
    double x;                                                                      \
    CHECK(c);                                                                      \
    if (count_check(c, call, nvr, nValues) != fmi3OK)                              \
        return fmi3Error;                                                          \
    for (i = 0; i < nvr; ++i) {                                                    \
        s = mx_get(M(c), call, mdtype, vr[i], &x);                                 \
        if (s > status)                                                            \
            status = s;                                                            \
        if (status >= MD_ERROR) { /* a refused call returns zeros */              \
            memset(value, 0, nvr * sizeof value[0]);                               \
            return (fmi3Status)status;                                             \
        }                                                                          \
        value[i] = (ctype)x;                                                       \
    }                                                                              \
    return (fmi3Status)status

#define SET_LOOP(call, mdtype)                                                     \
    size_t i;                                                                      \
    CHECK(c);                                                                      \
    if (count_check(c, call, nvr, nValues) != fmi3OK)                              \
        return fmi3Error;                                                          \
    for (i = 0; i < nvr; ++i) /* every value checked before any is set */        \
        if (md_check_set(M(c), call, mdtype, vr[i], (double)value[i]) != MD_OK)    \
            return fmi3Error;                                                      \
    for (i = 0; i < nvr; ++i)                                                      \
        md_set(M(c), call, mdtype, vr[i], (double)value[i]);                       \
    return fmi3OK

fmi3Status fmi3GetFloat64(fmi3Instance c, VR_IN, fmi3Float64 value[], size_t nValues)
{
    GET_LOOP("fmi3GetFloat64", MD_REAL, fmi3Float64);
}

fmi3Status fmi3SetFloat64(fmi3Instance c, VR_IN, const fmi3Float64 value[],
                          size_t nValues)
{
    SET_LOOP("fmi3SetFloat64", MD_REAL);
}

fmi3Status fmi3GetInt32(fmi3Instance c, VR_IN, fmi3Int32 value[], size_t nValues)
{
    GET_LOOP("fmi3GetInt32", MD_INTEGER, fmi3Int32);
}

fmi3Status fmi3SetInt32(fmi3Instance c, VR_IN, const fmi3Int32 value[], size_t nValues)
{
    SET_LOOP("fmi3SetInt32", MD_INTEGER);
}

fmi3Status fmi3GetBoolean(fmi3Instance c, VR_IN, fmi3Boolean value[], size_t nValues)
{
    GET_LOOP("fmi3GetBoolean", MD_BOOLEAN, fmi3Boolean);
}

fmi3Status fmi3SetBoolean(fmi3Instance c, VR_IN, const fmi3Boolean value[],
                          size_t nValues)
{
    SET_LOOP("fmi3SetBoolean", MD_BOOLEAN);
}

/* Types the model has no variables of: any value reference is unknown. */
static fmi3Status no_such_type(fmi3Instance c, const char *call, VR_IN)
{
    CHECK(c);
    if (nvr == 0)
        return fmi3OK;
    md_log(M(c), MD_ERROR, "%s: the model has no variable of this type (value "
           "reference %u)", call, (unsigned)vr[0]);
    return fmi3Error;
}

#define NO_SUCH_TYPE(T)                                                            \
    fmi3Status fmi3Get##T(fmi3Instance c, VR_IN, fmi3##T value[], size_t nValues)  \
    {                                                                              \
        UNUSED(value); UNUSED(nValues);                                            \
        return no_such_type(c, "fmi3Get" #T, vr, nvr);                             \
    }                                                                              \
    fmi3Status fmi3Set##T(fmi3Instance c, VR_IN, const fmi3##T value[],            \
                          size_t nValues)                                          \
    {                                                                              \
        UNUSED(value); UNUSED(nValues);                                            \
        return no_such_type(c, "fmi3Set" #T, vr, nvr);                             \
    }
NO_SUCH_TYPE(Float32)
NO_SUCH_TYPE(Int8)
NO_SUCH_TYPE(UInt8)
NO_SUCH_TYPE(Int16)
NO_SUCH_TYPE(UInt16)
NO_SUCH_TYPE(UInt32)
NO_SUCH_TYPE(Int64)
NO_SUCH_TYPE(UInt64)
NO_SUCH_TYPE(String)

fmi3Status fmi3GetBinary(fmi3Instance c, VR_IN, size_t valueSizes[],
                         fmi3Binary value[], size_t nValues)
{
    UNUSED(valueSizes); UNUSED(value); UNUSED(nValues);
    return no_such_type(c, "fmi3GetBinary", vr, nvr);
}

fmi3Status fmi3SetBinary(fmi3Instance c, VR_IN, const size_t valueSizes[],
                         const fmi3Binary value[], size_t nValues)
{
    UNUSED(valueSizes); UNUSED(value); UNUSED(nValues);
    return no_such_type(c, "fmi3SetBinary", vr, nvr);
}

fmi3Status fmi3GetClock(fmi3Instance c, VR_IN, fmi3Clock value[])
{
    UNUSED(value);
    return no_such_type(c, "fmi3GetClock", vr, nvr);
}

fmi3Status fmi3SetClock(fmi3Instance c, VR_IN, const fmi3Clock value[])
{
    UNUSED(value);
    return no_such_type(c, "fmi3SetClock", vr, nvr);
}

/* ------------------------------------------------------------------ FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *state)
{
    CHECK(c);
    return (fmi3Status)md_get_state(M(c), "fmi3GetFMUState", state);
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState state)
{
    CHECK(c);
    return (fmi3Status)md_set_state(M(c), "fmi3SetFMUState", state);
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *state)
{
    CHECK(c);
    if (state != NULL) {
        md_free_state(M(c), *state);
        *state = NULL;
    }
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState state, size_t *size)
{
    CHECK(c);
    UNUSED(state);
    if (size == NULL)
        return fmi3Error;
    *size = md_serialized_size();
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState state,
                                 fmi3Byte bytes[], size_t size)
{
    CHECK(c);
    return (fmi3Status)md_serialize(M(c), "fmi3SerializeFMUState", state, bytes, size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte bytes[], size_t size,
                                   fmi3FMUState *state)
{
    CHECK(c);
    return (fmi3Status)md_deserialize(M(c), "fmi3DeserializeFMUState", bytes, size,
                                      state);
}

/* ------------------------------------------------------------------ stepping */

fmi3Status fmi3EnterStepMode(fmi3Instance c)
{
    return unsupported(c, "fmi3EnterStepMode", "hasEventMode=false: the FMU is in "
                       "step mode after fmi3ExitInitializationMode");
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    md_status status;
    CHECK(c);
    UNUSED(noSetFMUStatePriorToCurrentPoint);
    if (mx_refuse_in_me(M(c), "fmi3DoStep") != MD_OK)
        return fmi3Error;
    status = md_do_step(M(c), "fmi3DoStep", currentCommunicationPoint,
                        communicationStepSize);
    if (eventHandlingNeeded != NULL)
        *eventHandlingNeeded = false;
    if (terminateSimulation != NULL)
        *terminateSimulation = false;
    if (earlyReturn != NULL)
        *earlyReturn = false;
    if (lastSuccessfulTime != NULL)
        *lastSuccessfulTime = M(c)->last_time_ok;
    return (fmi3Status)status;
}

/* ------------------------------------------------------------------ not provided */

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference vr,
                                               size_t *n)
{
    UNUSED(vr); UNUSED(n);
    return unsupported(c, "fmi3GetNumberOfVariableDependencies",
                       "see ModelStructure in modelDescription.xml");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                       size_t elementIndices[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind kinds[], size_t n)
{
    UNUSED(dependent); UNUSED(elementIndices); UNUSED(independents);
    UNUSED(elementIndicesOfIndependents); UNUSED(kinds); UNUSED(n);
    return unsupported(c, "fmi3GetVariableDependencies",
                       "see ModelStructure in modelDescription.xml");
}

#define DERIVATIVE_ARGS                                                            \
    fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,         \
        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], \
        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity
#define DERIVATIVE_UNUSED                                                          \
    UNUSED(unknowns); UNUSED(nUnknowns); UNUSED(knowns); UNUSED(nKnowns);          \
    UNUSED(seed); UNUSED(nSeed); UNUSED(sensitivity); UNUSED(nSensitivity)

fmi3Status fmi3GetDirectionalDerivative(DERIVATIVE_ARGS)
{
    DERIVATIVE_UNUSED;
    return unsupported(c, "fmi3GetDirectionalDerivative",
                       "providesDirectionalDerivative=false; read kt_<axis>");
}

fmi3Status fmi3GetAdjointDerivative(DERIVATIVE_ARGS)
{
    DERIVATIVE_UNUSED;
    return unsupported(c, "fmi3GetAdjointDerivative", "providesAdjointDerivatives=false");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c)
{
    return unsupported(c, "fmi3EnterConfigurationMode", "no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c)
{
    return unsupported(c, "fmi3ExitConfigurationMode", "no structural parameters");
}

#define NO_CLOCKS(call) return unsupported(c, call, "the model has no clocks")

fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, VR_IN, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(intervals); UNUSED(qualifiers);
    NO_CLOCKS("fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance c, VR_IN, fmi3UInt64 counters[],
                                   fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(counters); UNUSED(resolutions); UNUSED(qualifiers);
    NO_CLOCKS("fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance c, VR_IN, fmi3Float64 shifts[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(shifts);
    NO_CLOCKS("fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance c, VR_IN, fmi3UInt64 counters[],
                                fmi3UInt64 resolutions[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(counters); UNUSED(resolutions);
    NO_CLOCKS("fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, VR_IN, const fmi3Float64 intervals[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(intervals);
    NO_CLOCKS("fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance c, VR_IN, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(counters); UNUSED(resolutions);
    NO_CLOCKS("fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance c, VR_IN, const fmi3Float64 shifts[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(shifts);
    NO_CLOCKS("fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance c, VR_IN, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[])
{
    UNUSED(vr); UNUSED(nvr); UNUSED(counters); UNUSED(resolutions);
    NO_CLOCKS("fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c)
{
    return unsupported(c, "fmi3EvaluateDiscreteStates", "hasEventMode=false");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, VR_IN, const fmi3Int32 orders[],
                                    fmi3Float64 values[], size_t nValues)
{
    UNUSED(vr); UNUSED(nvr); UNUSED(orders); UNUSED(values); UNUSED(nValues);
    return unsupported(c, "fmi3GetOutputDerivatives", "maxOutputDerivativeOrder=0");
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clock,
                                      fmi3Float64 activationTime)
{
    UNUSED(clock); UNUSED(activationTime);
    return unsupported(c, "fmi3ActivateModelPartition", "Co-Simulation only");
}
