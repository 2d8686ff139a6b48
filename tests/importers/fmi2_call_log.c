/* An FMI 2.0 call logger: a shared library exporting the FMI 2.0 functions (Model
 * Exchange and Co-Simulation) that forwards each call to the real FMU binary and writes
 * one line per call of interest to the file named by $FMI_CALL_LOG:
 *
 *   <instance> <call> <arguments>      e.g.  mount1 doStep t=0.0001 h=0.0001
 *
 * (reals as %.17g, which reads back exactly). Put it in the FMU's binaries/linux64/ as
 * <modelIdentifier>.so with the real binary beside it as <modelIdentifier>.real.so; an
 * importer then loads it like the FMU. Written for drymount's tests
 * (tests/test_ssp_omsimulator.py): which inputs an importer sets before which doStep,
 * at which time and step size. Build: gcc -shared -fPIC fmi2_call_log.c -ldl. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *C; /* fmi2Component, fmi2FMUstate, environment */
typedef unsigned int VR;
typedef int S; /* fmi2Status, fmi2Type, fmi2StatusKind, fmi2Boolean */

static void *real_lib;
static FILE *log_file;
static struct { C c; char name[64]; } names[64];

static void *real(const char *name)
{
    void *p;
    if (real_lib == NULL) {
        Dl_info info;
        char path[4096];
        size_t n;
        if (!dladdr((void *)real, &info) || strlen(info.dli_fname) + 16 > sizeof path)
            abort();
        strcpy(path, info.dli_fname);
        n = strlen(path);
        if (n > 3 && !strcmp(path + n - 3, ".so"))
            path[n - 3] = '\0';
        strcat(path, ".real.so");
        real_lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (real_lib == NULL) {
            fprintf(stderr, "fmi2_call_log: %s\n", dlerror());
            abort();
        }
        if (getenv("FMI_CALL_LOG"))
            log_file = fopen(getenv("FMI_CALL_LOG"), "a");
    }
    p = dlsym(real_lib, name);
    if (p == NULL) {
        fprintf(stderr, "fmi2_call_log: the real FMU lacks %s\n", name);
        abort();
    }
    return p;
}

static const char *who(C c)
{
    int i;
    for (i = 0; i < 64; ++i)
        if (names[i].c == c && c != NULL)
            return names[i].name;
    return "?";
}

#define LOG(...)                                                                  \
    do {                                                                          \
        if (log_file) {                                                           \
            fprintf(log_file, __VA_ARGS__);                                       \
            fputc('\n', log_file);                                                \
        }                                                                         \
    } while (0)
#define REAL(ret, name, params) ((ret(*) params)real(#name))

/* "<instance> <call> vr=value ...": reals from x, or integers from xi when x is NULL */
static void log_values(C c, const char *call, const VR *vr, size_t n, const double *x,
                       const int *xi)
{
    size_t i;
    if (!log_file)
        return;
    fprintf(log_file, "%s %s", who(c), call);
    for (i = 0; i < n; ++i) {
        if (x)
            fprintf(log_file, " %u=%.17g", vr[i], x[i]);
        else
            fprintf(log_file, " %u=%d", vr[i], xi[i]);
    }
    fputc('\n', log_file);
}

/* ---- logged calls ---- */
C fmi2Instantiate(const char *name, S type, const char *guid, const char *res,
                  const void *functions, S visible, S logging_on)
{
    C c = REAL(C, fmi2Instantiate, (const char *, S, const char *, const char *,
                                    const void *, S, S))(name, type, guid, res, functions,
                                                         visible, logging_on);
    int i;
    for (i = 0; i < 64; ++i)
        if (names[i].c == NULL) {
            names[i].c = c;
            snprintf(names[i].name, sizeof names[i].name, "%s", name);
            break;
        }
    LOG("%s instantiate type=%d", name, type);
    return c;
}

void fmi2FreeInstance(C c)
{
    int i;
    LOG("%s freeInstance", who(c));
    if (log_file)
        fflush(log_file);
    REAL(void, fmi2FreeInstance, (C))(c);
    for (i = 0; i < 64; ++i)
        if (names[i].c == c)
            names[i].c = NULL;
}

S fmi2SetupExperiment(C c, S tol_defined, double tol, double start, S stop_defined,
                      double stop)
{
    LOG("%s setupExperiment tol_defined=%d tol=%.17g start=%.17g stop_defined=%d "
        "stop=%.17g", who(c), tol_defined, tol, start, stop_defined, stop);
    return REAL(S, fmi2SetupExperiment, (C, S, double, double, S, double))(
        c, tol_defined, tol, start, stop_defined, stop);
}

/* the calls that take only the instance: logged as "<instance> <label>" */
#define LOGGED_CALL(name, label)                                                  \
    S name(C c)                                                                   \
    {                                                                             \
        LOG("%s " label, who(c));                                                 \
        return REAL(S, name, (C))(c);                                             \
    }
LOGGED_CALL(fmi2EnterInitializationMode, "enterInitializationMode")
LOGGED_CALL(fmi2ExitInitializationMode, "exitInitializationMode")
LOGGED_CALL(fmi2Terminate, "terminate")
LOGGED_CALL(fmi2Reset, "reset")

S fmi2SetReal(C c, const VR vr[], size_t n, const double x[])
{
    log_values(c, "setReal", vr, n, x, NULL);
    return REAL(S, fmi2SetReal, (C, const VR *, size_t, const double *))(c, vr, n, x);
}

S fmi2GetReal(C c, const VR vr[], size_t n, double x[])
{
    S s = REAL(S, fmi2GetReal, (C, const VR *, size_t, double *))(c, vr, n, x);
    log_values(c, "getReal", vr, n, x, NULL);
    return s;
}

S fmi2SetInteger(C c, const VR vr[], size_t n, const int x[])
{
    log_values(c, "setInteger", vr, n, NULL, x);
    return REAL(S, fmi2SetInteger, (C, const VR *, size_t, const int *))(c, vr, n, x);
}

S fmi2SetBoolean(C c, const VR vr[], size_t n, const int x[])
{
    log_values(c, "setBoolean", vr, n, NULL, x);
    return REAL(S, fmi2SetBoolean, (C, const VR *, size_t, const int *))(c, vr, n, x);
}

S fmi2DoStep(C c, double t, double h, S no_set_prior)
{
    LOG("%s doStep t=%.17g h=%.17g", who(c), t, h);
    return REAL(S, fmi2DoStep, (C, double, double, S))(c, t, h, no_set_prior);
}

S fmi2GetFMUstate(C c, C *state)
{
    LOG("%s getFMUstate", who(c));
    return REAL(S, fmi2GetFMUstate, (C, C *))(c, state);
}

S fmi2SetFMUstate(C c, C state)
{
    LOG("%s setFMUstate", who(c));
    return REAL(S, fmi2SetFMUstate, (C, C))(c, state);
}

S fmi2SetRealInputDerivatives(C c, const VR vr[], size_t n, const int order[],
                              const double x[])
{
    LOG("%s setRealInputDerivatives n=%zu", who(c), n);
    return REAL(S, fmi2SetRealInputDerivatives,
                (C, const VR *, size_t, const int *, const double *))(c, vr, n, order, x);
}

S fmi2SetTime(C c, double t)
{
    LOG("%s setTime t=%.17g", who(c), t);
    return REAL(S, fmi2SetTime, (C, double))(c, t);
}

/* ---- forwarded silently ---- */
const char *fmi2GetTypesPlatform(void)
{
    return REAL(const char *, fmi2GetTypesPlatform, (void))();
}
const char *fmi2GetVersion(void) { return REAL(const char *, fmi2GetVersion, (void))(); }
S fmi2SetDebugLogging(C c, S on, size_t n, const char *const cat[])
{
    return REAL(S, fmi2SetDebugLogging, (C, S, size_t, const char *const *))(c, on, n, cat);
}
S fmi2GetInteger(C c, const VR vr[], size_t n, int x[])
{
    return REAL(S, fmi2GetInteger, (C, const VR *, size_t, int *))(c, vr, n, x);
}
S fmi2GetBoolean(C c, const VR vr[], size_t n, int x[])
{
    return REAL(S, fmi2GetBoolean, (C, const VR *, size_t, int *))(c, vr, n, x);
}
S fmi2GetString(C c, const VR vr[], size_t n, const char *x[])
{
    return REAL(S, fmi2GetString, (C, const VR *, size_t, const char **))(c, vr, n, x);
}
S fmi2SetString(C c, const VR vr[], size_t n, const char *const x[])
{
    return REAL(S, fmi2SetString, (C, const VR *, size_t, const char *const *))(c, vr, n,
                                                                                  x);
}
S fmi2FreeFMUstate(C c, C *state)
{
    return REAL(S, fmi2FreeFMUstate, (C, C *))(c, state);
}
S fmi2SerializedFMUstateSize(C c, C state, size_t *size)
{
    return REAL(S, fmi2SerializedFMUstateSize, (C, C, size_t *))(c, state, size);
}
S fmi2SerializeFMUstate(C c, C state, char data[], size_t size)
{
    return REAL(S, fmi2SerializeFMUstate, (C, C, char *, size_t))(c, state, data, size);
}
S fmi2DeSerializeFMUstate(C c, const char data[], size_t size, C *state)
{
    return REAL(S, fmi2DeSerializeFMUstate, (C, const char *, size_t, C *))(c, data, size,
                                                                             state);
}
S fmi2GetDirectionalDerivative(C c, const VR u[], size_t nu, const VR z[], size_t nz,
                               const double dv[], double dz[])
{
    return REAL(S, fmi2GetDirectionalDerivative,
                (C, const VR *, size_t, const VR *, size_t, const double *, double *))(
        c, u, nu, z, nz, dv, dz);
}
S fmi2GetRealOutputDerivatives(C c, const VR vr[], size_t n, const int order[], double x[])
{
    return REAL(S, fmi2GetRealOutputDerivatives,
                (C, const VR *, size_t, const int *, double *))(c, vr, n, order, x);
}
S fmi2CancelStep(C c) { return REAL(S, fmi2CancelStep, (C))(c); }
S fmi2GetStatus(C c, S kind, S *value)
{
    return REAL(S, fmi2GetStatus, (C, S, S *))(c, kind, value);
}
S fmi2GetRealStatus(C c, S kind, double *value)
{
    return REAL(S, fmi2GetRealStatus, (C, S, double *))(c, kind, value);
}
S fmi2GetIntegerStatus(C c, S kind, int *value)
{
    return REAL(S, fmi2GetIntegerStatus, (C, S, int *))(c, kind, value);
}
S fmi2GetBooleanStatus(C c, S kind, S *value)
{
    return REAL(S, fmi2GetBooleanStatus, (C, S, S *))(c, kind, value);
}
S fmi2GetStringStatus(C c, S kind, const char **value)
{
    return REAL(S, fmi2GetStringStatus, (C, S, const char **))(c, kind, value);
}
/* Model Exchange */
S fmi2EnterEventMode(C c) { return REAL(S, fmi2EnterEventMode, (C))(c); }
S fmi2NewDiscreteStates(C c, void *info)
{
    return REAL(S, fmi2NewDiscreteStates, (C, void *))(c, info);
}
S fmi2EnterContinuousTimeMode(C c) { return REAL(S, fmi2EnterContinuousTimeMode, (C))(c); }
S fmi2CompletedIntegratorStep(C c, S no_set_prior, S *enter_event, S *terminate)
{
    return REAL(S, fmi2CompletedIntegratorStep, (C, S, S *, S *))(c, no_set_prior,
                                                                   enter_event, terminate);
}
S fmi2SetContinuousStates(C c, const double x[], size_t n)
{
    return REAL(S, fmi2SetContinuousStates, (C, const double *, size_t))(c, x, n);
}
S fmi2GetDerivatives(C c, double x[], size_t n)
{
    return REAL(S, fmi2GetDerivatives, (C, double *, size_t))(c, x, n);
}
S fmi2GetEventIndicators(C c, double x[], size_t n)
{
    return REAL(S, fmi2GetEventIndicators, (C, double *, size_t))(c, x, n);
}
S fmi2GetContinuousStates(C c, double x[], size_t n)
{
    return REAL(S, fmi2GetContinuousStates, (C, double *, size_t))(c, x, n);
}
S fmi2GetNominalsOfContinuousStates(C c, double x[], size_t n)
{
    return REAL(S, fmi2GetNominalsOfContinuousStates, (C, double *, size_t))(c, x, n);
}
