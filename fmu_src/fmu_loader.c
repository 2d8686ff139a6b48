/*
 * FrictionMount.fmu, binaries/linux64/FrictionMount.so: a loader in front of
 * pythonfmu's binary, so that importers which are not Python programs (C/C++ tools
 * such as OMSimulator, fmusim, the FMU Compliance Checker, libcosim's `cosim`) can
 * run the FMU without LD_PRELOAD.
 *
 * pythonfmu's binary (shipped next to this one as FrictionMount.pythonfmu.so) calls
 * the Python C API but does not link libpython: in a Python process (fmpy,
 * libcosimpy, PyFMI) the interpreter's symbols are already there; in any other process
 * loading it fails with an undefined symbol. At the first fmi2Instantiate this loader
 *
 *   1. checks whether the process already has Python (Py_IsInitialized visible);
 *   2. if not, loads libpython with RTLD_GLOBAL, trying in order $DRYMOUNT_LIBPYTHON,
 *      the path of the Python that built the FMU (DRYMOUNT_LIBPYTHON_PATH below) and
 *      its soname on the loader's search path, and sets PYTHONHOME to that Python's
 *      prefix unless PYTHONHOME is already set (the interpreter must find its
 *      standard library; $DRYMOUNT_PYTHONHOME overrides);
 *   3. loads FrictionMount.pythonfmu.so from its own directory and forwards every
 *      FMI call to it.
 *
 * Failures are reported through the importer's logger (category "drymount") and
 * make fmi2Instantiate return NULL. The build (fmu_build/builder.py) compiles this
 * file with the paths of the building Python:
 *   cc -shared -fPIC -O2 -fvisibility=hidden -DDRYMOUNT_LIBPYTHON_PATH=... \
 *      -DDRYMOUNT_LIBPYTHON_SONAME=... -DDRYMOUNT_PYTHONHOME=... -ldl -lpthread
 * Self-contained: the FMI 2.0 types are declared as in fmi2TypesPlatform.h and
 * fmi2FunctionTypes.h.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef DRYMOUNT_LIBPYTHON_PATH
#define DRYMOUNT_LIBPYTHON_PATH ""
#endif
#ifndef DRYMOUNT_LIBPYTHON_SONAME
#define DRYMOUNT_LIBPYTHON_SONAME ""
#endif
#ifndef DRYMOUNT_PYTHONHOME
#define DRYMOUNT_PYTHONHOME ""
#endif
#define REAL_BINARY "FrictionMount.pythonfmu.so"
#define EXPORT __attribute__((visibility("default")))

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum {
    fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated
} fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef const fmi2ValueReference *VRs;

/* one X(name, return type, parameter list, argument list) per forwarded function */
#define FMI2_FORWARDED(X) \
    X(fmi2SetDebugLogging, fmi2Status, (fmi2Component c, fmi2Boolean on, size_t n, \
      const fmi2String cat[]), (c, on, n, cat)) \
    X(fmi2SetupExperiment, fmi2Status, (fmi2Component c, fmi2Boolean tol_def, \
      fmi2Real tol, fmi2Real t0, fmi2Boolean stop_def, fmi2Real t1), \
      (c, tol_def, tol, t0, stop_def, t1)) \
    X(fmi2EnterInitializationMode, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2ExitInitializationMode, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2Terminate, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2Reset, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2GetReal, fmi2Status, (fmi2Component c, VRs vr, size_t n, fmi2Real v[]), \
      (c, vr, n, v)) \
    X(fmi2GetInteger, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2Integer v[]), (c, vr, n, v)) \
    X(fmi2GetBoolean, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2Boolean v[]), (c, vr, n, v)) \
    X(fmi2GetString, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      fmi2String v[]), (c, vr, n, v)) \
    X(fmi2SetReal, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Real v[]), (c, vr, n, v)) \
    X(fmi2SetInteger, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer v[]), (c, vr, n, v)) \
    X(fmi2SetBoolean, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Boolean v[]), (c, vr, n, v)) \
    X(fmi2SetString, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2String v[]), (c, vr, n, v)) \
    X(fmi2GetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(fmi2SetFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate s), (c, s)) \
    X(fmi2FreeFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate *s), (c, s)) \
    X(fmi2SerializedFMUstateSize, fmi2Status, (fmi2Component c, fmi2FMUstate s, \
      size_t *size), (c, s, size)) \
    X(fmi2SerializeFMUstate, fmi2Status, (fmi2Component c, fmi2FMUstate s, \
      fmi2Byte b[], size_t size), (c, s, b, size)) \
    X(fmi2DeSerializeFMUstate, fmi2Status, (fmi2Component c, const fmi2Byte b[], \
      size_t size, fmi2FMUstate *s), (c, b, size, s)) \
    X(fmi2GetDirectionalDerivative, fmi2Status, (fmi2Component c, VRs unk, size_t nu, \
      VRs known, size_t nk, const fmi2Real dv_known[], fmi2Real dv_unknown[]), \
      (c, unk, nu, known, nk, dv_known, dv_unknown)) \
    X(fmi2SetRealInputDerivatives, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer order[], const fmi2Real v[]), (c, vr, n, order, v)) \
    X(fmi2GetRealOutputDerivatives, fmi2Status, (fmi2Component c, VRs vr, size_t n, \
      const fmi2Integer order[], fmi2Real v[]), (c, vr, n, order, v)) \
    X(fmi2DoStep, fmi2Status, (fmi2Component c, fmi2Real t, fmi2Real h, \
      fmi2Boolean no_prior), (c, t, h, no_prior)) \
    X(fmi2CancelStep, fmi2Status, (fmi2Component c), (c)) \
    X(fmi2GetStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Status *v), (c, k, v)) \
    X(fmi2GetRealStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Real *v), (c, k, v)) \
    X(fmi2GetIntegerStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Integer *v), (c, k, v)) \
    X(fmi2GetBooleanStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2Boolean *v), (c, k, v)) \
    X(fmi2GetStringStatus, fmi2Status, (fmi2Component c, const fmi2StatusKind k, \
      fmi2String *v), (c, k, v))

typedef fmi2Component (*Instantiate_t)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions *, fmi2Boolean,
                                       fmi2Boolean);
typedef void (*FreeInstance_t)(fmi2Component);
static Instantiate_t real_Instantiate;
static FreeInstance_t real_FreeInstance;

#define DECLARE_POINTER(name, ret, params, args) static ret(*real_##name) params;
FMI2_FORWARDED(DECLARE_POINTER)

static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;
static int loaded;            /* 1: every real_* pointer is set */
static char load_error[8192]; /* why loading failed (kept for later instances) */

static int load_libpython(void) {
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized") != NULL)
        return 0; /* a Python process (or LD_PRELOAD): nothing to do */
    const char *candidates[3] = {getenv("DRYMOUNT_LIBPYTHON"), DRYMOUNT_LIBPYTHON_PATH,
                                 DRYMOUNT_LIBPYTHON_SONAME};
    char tried[600] = "";
    for (int i = 0; i < 3; ++i) {
        const char *lib = candidates[i];
        if (lib == NULL || lib[0] == '\0')
            continue;
        if (dlopen(lib, RTLD_NOW | RTLD_GLOBAL) != NULL) {
            const char *home = getenv("DRYMOUNT_PYTHONHOME");
            struct stat st;
            if ((home == NULL || home[0] == '\0') && lib != candidates[0])
                home = DRYMOUNT_PYTHONHOME;
            if (getenv("PYTHONHOME") == NULL && home != NULL && home[0] != '\0' &&
                stat(home, &st) == 0)
                setenv("PYTHONHOME", home, 0);
            return 0;
        }
        size_t used = strlen(tried);
        snprintf(tried + used, sizeof tried - used, "%s%s", used ? ", " : "", lib);
    }
    const char *why = tried[0] ? dlerror() : NULL;
    snprintf(load_error, sizeof load_error,
             "cannot load libpython (tried: %s; last error: %s). Set DRYMOUNT_LIBPYTHON "
             "to the libpython3.X.so of a CPython >= 3.10 built with --enable-shared, "
             "or LD_PRELOAD it (documentation/externalDependencies.txt)",
             tried[0] ? tried : "nothing", why ? why : "none");
    return -1;
}

static int load_real_binary(void) {
    Dl_info info;
    if (dladdr((void *)&load_real_binary, &info) == 0 || info.dli_fname == NULL) {
        snprintf(load_error, sizeof load_error, "cannot locate the FMU's binary directory");
        return -1;
    }
    char path[4096];
    const char *slash = strrchr(info.dli_fname, '/');
    int dir_len = slash ? (int)(slash - info.dli_fname) : 1;
    const char *dir = slash ? info.dli_fname : ".";
    snprintf(path, sizeof path, "%.*s/%s", dir_len, dir, REAL_BINARY);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (h == NULL) {
        snprintf(load_error, sizeof load_error, "cannot load %s: %s", path, dlerror());
        return -1;
    }
    real_Instantiate = (Instantiate_t)dlsym(h, "fmi2Instantiate");
    real_FreeInstance = (FreeInstance_t)dlsym(h, "fmi2FreeInstance");
    int missing = real_Instantiate == NULL || real_FreeInstance == NULL;
#define RESOLVE(name, ret, params, args) \
    *(void **)(&real_##name) = dlsym(h, #name); \
    missing |= real_##name == NULL;
    FMI2_FORWARDED(RESOLVE)
    if (missing) {
        snprintf(load_error, sizeof load_error, "%s lacks FMI 2.0 functions", path);
        return -1;
    }
    return 0;
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String resources,
                                     const fmi2CallbackFunctions *cb, fmi2Boolean visible,
                                     fmi2Boolean logging) {
    pthread_mutex_lock(&load_lock);
    if (!loaded && load_error[0] == '\0' && load_libpython() == 0 &&
        load_real_binary() == 0)
        loaded = 1;
    pthread_mutex_unlock(&load_lock);
    if (!loaded) {
        if (cb != NULL && cb->logger != NULL)
            cb->logger(cb->componentEnvironment, name, fmi2Fatal, "drymount", "%s",
                       load_error);
        else
            fprintf(stderr, "FrictionMount: %s\n", load_error);
        return NULL;
    }
    return real_Instantiate(name, type, guid, resources, cb, visible, logging);
}

EXPORT void fmi2FreeInstance(fmi2Component c) {
    if (loaded && c != NULL)
        real_FreeInstance(c);
}

/* Every other function: forward (only reachable with an instance, i.e. after a
 * successful load). */
#define DEFINE_FORWARD(name, ret, params, args) \
    EXPORT ret name params { return loaded ? real_##name args : fmi2Error; }
FMI2_FORWARDED(DEFINE_FORWARD)
