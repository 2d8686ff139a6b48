/* FMI 2.0 entry points of the native FrictionMount shared by Co-Simulation and Model
 * Exchange (model.h does the work; this file converts types and names the calls;
 * the Model Exchange ones are in fmi2_me.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2_api.h"
#include "me.h"
#include "model.h"

typedef struct {
    md_instance *m;
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
} fmi2_env;

static void log_bridge(void *env, const char *instance, md_status status,
                       const char *category, const char *message)
{
    const fmi2_env *e = (const fmi2_env *)env;
    char text[4200];
    size_t i = 0;
    if (e->logger == NULL)
        return;
    /* The message is the logger's format string (importers that do not format it
     * show it as is): a literal '%' is written as "%%". */
    for (; *message && i + 2 < sizeof text; ++message) {
        if (*message == '%')
            text[i++] = '%';
        text[i++] = *message;
    }
    text[i] = '\0';
    e->logger(e->env, instance, (fmi2Status)status, category, text);
}

#define M(c) (((fmi2_env *)(c))->m)
#define CHECK(c, unused)                                                \
    do {                                                                \
        if ((c) == NULL)                                                \
            return fmi2Error;                                           \
        (void)(unused);                                                 \
    } while (0)

static fmi2Status worst(fmi2Status a, md_status b)
{
    return (fmi2Status)b > a ? (fmi2Status)b : a;
}

const char *fmi2GetTypesPlatform(void) { return "default"; }
const char *fmi2GetVersion(void) { return "2.0"; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t n,
                               const fmi2String categories[])
{
    size_t i;
    CHECK(c, 0);
    for (i = 0; i < n; ++i) {
        if (strcmp(categories[i], "logAll") && strcmp(categories[i], "logStatusWarning")
            && strcmp(categories[i], "logStatusDiscard")
            && strcmp(categories[i], "logStatusError")
            && strcmp(categories[i], "logStatusFatal")) {
            md_log(M(c), MD_ERROR, "fmi2SetDebugLogging: unknown log category '%s'",
                   categories[i]);
            return fmi2Error;
        }
    }
    M(c)->logging_on = loggingOn != fmi2False;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                              fmi2String fmuGUID, fmi2String resourceLocation,
                              const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    fmi2_env *e;
    fmi2CallbackAllocateMemory alloc = functions ? functions->allocateMemory : NULL;
    fmi2CallbackFreeMemory free_fn = functions ? functions->freeMemory : NULL;
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    const char *name = instanceName ? instanceName : "";
    (void)resourceLocation;
    (void)visible;
    if ((fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange)
        || fmuGUID == NULL || strcmp(fmuGUID, md_instantiation_token()) != 0) {
        if (logger != NULL)
            logger(env, name, fmi2Error, "logStatusError",
                   fmuType != fmi2CoSimulation && fmuType != fmi2ModelExchange
                       ? "fmi2Instantiate: fmuType must be 0 (Model Exchange) or 1 "
                         "(Co-Simulation)"
                       : "fmi2Instantiate: the GUID does not match the "
                         "modelDescription.xml of this FMU");
        return NULL;
    }
    if (alloc == NULL || free_fn == NULL) {
        alloc = NULL;
        free_fn = NULL;
    }
    e = (fmi2_env *)(alloc ? alloc(1, sizeof *e) : calloc(1, sizeof *e));
    if (e == NULL)
        return NULL;
    e->logger = logger;
    e->env = env;
    e->m = md_new(name, "fmi2", log_bridge, e, alloc, free_fn, loggingOn != fmi2False);
    if (e->m == NULL) {
        if (free_fn)
            free_fn(e);
        else
            free(e);
        return NULL;
    }
    e->m->model_exchange = fmuType == fmi2ModelExchange;
    return e;
}

void fmi2FreeInstance(fmi2Component c)
{
    fmi2_env *e = (fmi2_env *)c;
    md_free_fn free_fn;
    if (e == NULL)
        return;
    free_fn = e->m->free;
    md_delete(e->m);
    free_fn(e);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    md_instance *m;
    CHECK(c, 0);
    m = M(c);
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    if (md_check_mode(m, "fmi2SetupExperiment", MD_IN(MD_INSTANTIATED)) != MD_OK)
        return fmi2Error;
    if (!isfinite(startTime)) {
        md_log(m, MD_ERROR, "fmi2SetupExperiment: startTime must be finite, got %g",
               startTime);
        return fmi2Error;
    }
    m->start_time = startTime;
    m->d.time = startTime;  /* part of the FMU state from here on */
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    CHECK(c, 0);
    return (fmi2Status)md_enter_initialization(M(c), "fmi2EnterInitializationMode",
                                               M(c)->d.time, !isnan(M(c)->d.time));
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    CHECK(c, 0);
    return (fmi2Status)md_exit_initialization(M(c), "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    CHECK(c, 0);
    return (fmi2Status)md_terminate(M(c), "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component c)
{
    CHECK(c, 0);
    md_reset(M(c));
    return fmi2OK;
}

/* ------------------------------------------------------------------ values */

#define GET_LOOP(call, mdtype, ctype)                                           \
    size_t i;                                                                   \
    fmi2Status status = fmi2OK;                                                 \
    double x;                                                                   \
    CHECK(c, 0);                                                                \
    for (i = 0; i < nvr; ++i) {                                                 \
        status = worst(status, mx_get(M(c), call, mdtype, vr[i], &x));          \
        if (status >= fmi2Error) { /* a refused call returns zeros */           \
            memset(value, 0, nvr * sizeof value[0]);                            \
            return status;                                                      \
        }                                                                       \
        value[i] = (ctype)x;                                                    \
    }                                                                           \
    return status

#define SET_LOOP(call, mdtype)                                                  \
    size_t i;                                                                   \
    CHECK(c, 0);                                                                \
    for (i = 0; i < nvr; ++i) /* every value checked before any is set */     \
        if (md_check_set(M(c), call, mdtype, vr[i], (double)value[i]) != MD_OK) \
            return fmi2Error;                                                   \
    for (i = 0; i < nvr; ++i)                                                   \
        md_set(M(c), call, mdtype, vr[i], (double)value[i]);                    \
    return fmi2OK

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[])
{
    GET_LOOP("fmi2GetReal", MD_REAL, fmi2Real);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[])
{
    GET_LOOP("fmi2GetInteger", MD_INTEGER, fmi2Integer);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[])
{
    GET_LOOP("fmi2GetBoolean", MD_BOOLEAN, fmi2Boolean);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    CHECK(c, 0);
    (void)value;
    if (nvr == 0)
        return fmi2OK;
    md_log(M(c), MD_ERROR, "fmi2GetString: the model has no String variables "
           "(value reference %u)", vr[0]);
    return fmi2Error;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    SET_LOOP("fmi2SetReal", MD_REAL);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[])
{
    SET_LOOP("fmi2SetInteger", MD_INTEGER);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[])
{
    SET_LOOP("fmi2SetBoolean", MD_BOOLEAN);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    CHECK(c, 0);
    (void)value;
    if (nvr == 0)
        return fmi2OK;
    md_log(M(c), MD_ERROR, "fmi2SetString: the model has no String variables "
           "(value reference %u)", vr[0]);
    return fmi2Error;
}

/* ------------------------------------------------------------------ FMU state */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    CHECK(c, 0);
    return (fmi2Status)md_get_state(M(c), "fmi2GetFMUstate", state);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state)
{
    CHECK(c, 0);
    return (fmi2Status)md_set_state(M(c), "fmi2SetFMUstate", state);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state)
{
    CHECK(c, 0);
    if (state != NULL) {
        md_free_state(M(c), *state);
        *state = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    CHECK(c, 0);
    (void)state;
    if (size == NULL)
        return fmi2Error;
    *size = md_serialized_size();
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state,
                                 fmi2Byte bytes[], size_t size)
{
    CHECK(c, 0);
    return (fmi2Status)md_serialize(M(c), "fmi2SerializeFMUstate", state,
                                    (unsigned char *)bytes, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[],
                                   size_t size, fmi2FMUstate *state)
{
    CHECK(c, 0);
    return (fmi2Status)md_deserialize(M(c), "fmi2DeSerializeFMUstate",
                                      (const unsigned char *)bytes, size, state);
}

/* ------------------------------------------------------------------ not provided */

static fmi2Status unsupported(fmi2Component c, const char *call, const char *why)
{
    CHECK(c, 0);
    md_log(M(c), MD_ERROR, "%s is not supported by this FMU (%s)", call, why);
    return fmi2Error;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c,
                                        const fmi2ValueReference vUnknown[],
                                        size_t nUnknown,
                                        const fmi2ValueReference vKnown[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    (void)vUnknown; (void)nUnknown; (void)vKnown; (void)nKnown; (void)dvKnown;
    (void)dvUnknown;
    return unsupported(c, "fmi2GetDirectionalDerivative",
                       "providesDirectionalDerivative=false; read kt_<axis>");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives",
                       "canInterpolateInputs=false");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives",
                       "maxOutputDerivativeOrder=0");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    CHECK(c, 0);
    (void)noSetFMUStatePriorToCurrentPoint;
    if (mx_refuse_in_me(M(c), "fmi2DoStep") != MD_OK)
        return fmi2Error;
    return (fmi2Status)md_do_step(M(c), "fmi2DoStep", currentCommunicationPoint,
                                  communicationStepSize);
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return unsupported(c, "fmi2CancelStep", "fmi2DoStep never returns fmi2Pending");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s; (void)value;
    return unsupported(c, "fmi2GetStatus", "fmi2DoStep never returns fmi2Pending");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    CHECK(c, 0);
    if (s != fmi2LastSuccessfulTime)
        return unsupported(c, "fmi2GetRealStatus", "only fmi2LastSuccessfulTime");
    *value = M(c)->last_time_ok;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s,
                                fmi2Integer *value)
{
    (void)s; (void)value;
    return unsupported(c, "fmi2GetIntegerStatus", "no integer status");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s,
                                fmi2Boolean *value)
{
    CHECK(c, 0);
    if (s != fmi2Terminated)
        return unsupported(c, "fmi2GetBooleanStatus", "only fmi2Terminated");
    *value = fmi2False;  /* the FMU never asks to end the simulation */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s,
                               fmi2String *value)
{
    (void)s; (void)value;
    return unsupported(c, "fmi2GetStringStatus", "no string status");
}
