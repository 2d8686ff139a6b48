/*
 * A minimal FMI 2.0 Co-Simulation importer in C, used by tests/test_fmu.py to run
 * FrictionMount.fmu without fmpy (and without a Python host: libpython is loaded with
 * LD_PRELOAD, see docs/fmu.md). Self-contained: the few FMI 2.0 types it needs are
 * declared below as in fmi2FunctionTypes.h.
 *
 * usage: host UNZIPDIR STEPS H X FREQ VR_U VR_V VR_F VR_FFR VR_E [R<vr>=<real> |
 *             I<vr>=<int> | B<vr>=<0|1>]...
 *
 * Instantiates two instances, sets the parameters in initialization mode, drives
 * u = X sin(2 pi FREQ t_k), v = du/dt on both (protocol: set inputs at t_k, get
 * outputs, doStep(t_k, H)), saves the FMU state of instance 0 halfway, finishes,
 * restores it and replays the second half. Prints one line per step of instance 0:
 *   STEP k u v F Ffr E          (%.17g, so the floats round-trip exactly)
 * then "REPLAY identical" or "REPLAY differs", "TWIN identical" or "TWIN differs",
 * and "DONE". Log messages go to stdout as "LOG <status> <category> <message>".
 * Exit code: 0 ok, 2 usage/load error, 3 an FMI call failed (status printed).
 */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate_t)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions *, fmi2Boolean,
                                       fmi2Boolean);
typedef void (*FreeInstance_t)(fmi2Component);
typedef fmi2Status (*SetupExperiment_t)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real,
                                        fmi2Boolean, fmi2Real);
typedef fmi2Status (*Void_t)(fmi2Component);
typedef fmi2Status (*SetReal_t)(fmi2Component, const fmi2ValueReference *, size_t,
                                const fmi2Real *);
typedef fmi2Status (*GetReal_t)(fmi2Component, const fmi2ValueReference *, size_t,
                                fmi2Real *);
typedef fmi2Status (*SetInteger_t)(fmi2Component, const fmi2ValueReference *, size_t,
                                   const fmi2Integer *);
typedef fmi2Status (*DoStep_t)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*State_t)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SetState_t)(fmi2Component, fmi2FMUstate);

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env;
    printf("LOG %d %s %s: ", (int)status, category ? category : "-", instance);
    va_start(args, message);
    vprintf(message, args);
    va_end(args);
    printf("\n");
    fflush(stdout);
}

static void *sym(void *lib, const char *name)
{
    void *f = dlsym(lib, name);
    if (!f) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(2);
    }
    return f;
}

#define CHECK(call, what)                                                   \
    do {                                                                    \
        fmi2Status s_ = (call);                                             \
        if (s_ > fmi2Warning) {                                             \
            printf("FAILED %s status=%d\n", what, (int)s_);                 \
            fflush(stdout);                                                 \
            for (int i_ = 0; i_ < 2; i_++)                                  \
                if (inst[i_]) freeInstance(inst[i_]);                       \
            return 3;                                                       \
        }                                                                   \
    } while (0)

int main(int argc, char **argv)
{
    if (argc < 11) {
        fprintf(stderr, "usage: see the comment at the top of host.c\n");
        return 2;
    }
    const char *dir = argv[1];
    int steps = atoi(argv[2]);
    double h = atof(argv[3]), X = atof(argv[4]), freq = atof(argv[5]);
    fmi2ValueReference vr_in[2] = {(fmi2ValueReference)atoi(argv[6]),
                                   (fmi2ValueReference)atoi(argv[7])};
    fmi2ValueReference vr_out[3] = {(fmi2ValueReference)atoi(argv[8]),
                                    (fmi2ValueReference)atoi(argv[9]),
                                    (fmi2ValueReference)atoi(argv[10])};
    char path[4096], uri[4200];
    snprintf(path, sizeof path, "%s/binaries/linux64/FrictionMount.so", dir);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    Instantiate_t instantiate = (Instantiate_t)sym(lib, "fmi2Instantiate");
    FreeInstance_t freeInstance = (FreeInstance_t)sym(lib, "fmi2FreeInstance");
    SetupExperiment_t setup = (SetupExperiment_t)sym(lib, "fmi2SetupExperiment");
    Void_t enterInit = (Void_t)sym(lib, "fmi2EnterInitializationMode");
    Void_t exitInit = (Void_t)sym(lib, "fmi2ExitInitializationMode");
    Void_t terminate = (Void_t)sym(lib, "fmi2Terminate");
    SetReal_t setReal = (SetReal_t)sym(lib, "fmi2SetReal");
    GetReal_t getReal = (GetReal_t)sym(lib, "fmi2GetReal");
    SetInteger_t setInteger = (SetInteger_t)sym(lib, "fmi2SetInteger");
    SetInteger_t setBoolean = (SetInteger_t)sym(lib, "fmi2SetBoolean");
    DoStep_t doStep = (DoStep_t)sym(lib, "fmi2DoStep");
    State_t getState = (State_t)sym(lib, "fmi2GetFMUstate");
    SetState_t setState = (SetState_t)sym(lib, "fmi2SetFMUstate");
    State_t freeState = (State_t)sym(lib, "fmi2FreeFMUstate");

    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component inst[2] = {NULL, NULL};
    for (int i = 0; i < 2; i++) {
        char name[32];
        snprintf(name, sizeof name, "mount%d", i);
        /* the GUID of modelDescription.xml, passed by the test ($FMU_GUID) */
        const char *guid = getenv("FMU_GUID") ? getenv("FMU_GUID") : "";
        inst[i] = instantiate(name, fmi2CoSimulation, guid, uri, &cb, 0, 1);
        if (!inst[i]) {
            printf("FAILED fmi2Instantiate\n");
            return 3;
        }
        CHECK(setup(inst[i], 0, 0.0, 0.0, 0, 0.0), "fmi2SetupExperiment");
        CHECK(enterInit(inst[i]), "fmi2EnterInitializationMode");
        for (int a = 11; a < argc; a++) {
            char kind = argv[a][0];
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(argv[a] + 1, NULL, 10);
            const char *value = strchr(argv[a], '=') + 1;
            if (kind == 'R') {
                double r = strtod(value, NULL);
                CHECK(setReal(inst[i], &vr, 1, &r), "fmi2SetReal");
            } else {
                int n = atoi(value);
                CHECK((kind == 'I' ? setInteger : setBoolean)(inst[i], &vr, 1, &n),
                      kind == 'I' ? "fmi2SetInteger" : "fmi2SetBoolean");
            }
        }
        CHECK(exitInit(inst[i]), "fmi2ExitInitializationMode");
    }
    double *out = calloc((size_t)steps * 3, sizeof(double));
    double *twin = calloc((size_t)steps * 3, sizeof(double));
    fmi2FMUstate saved = NULL;
    int half = steps / 2, replay_same = 1;
    for (int pass = 0; pass < 2; pass++) {
        int k0 = pass == 0 ? 0 : half;
        if (pass == 1) CHECK(setState(inst[0], saved), "fmi2SetFMUstate");
        for (int k = k0; k < steps; k++) {
            double t = k * h, u[2], y[3];
            u[0] = X * sin(2.0 * M_PI * freq * t);
            u[1] = X * 2.0 * M_PI * freq * cos(2.0 * M_PI * freq * t);
            if (pass == 0 && k == half) CHECK(getState(inst[0], &saved), "fmi2GetFMUstate");
            for (int i = 0; i < (pass == 0 ? 2 : 1); i++) {
                CHECK(setReal(inst[i], vr_in, 2, u), "fmi2SetReal");
                CHECK(getReal(inst[i], vr_out, 3, y), "fmi2GetReal");
                CHECK(doStep(inst[i], t, h, 1), "fmi2DoStep");
                if (pass == 0 && i == 0) {
                    memcpy(out + 3 * k, y, sizeof y);
                    printf("STEP %d %.17g %.17g %.17g %.17g %.17g\n", k, u[0], u[1], y[0],
                           y[1], y[2]);
                } else if (pass == 0) {
                    memcpy(twin + 3 * k, y, sizeof y);
                } else if (memcmp(out + 3 * k, y, sizeof y) != 0) {
                    replay_same = 0;
                }
            }
        }
    }
    printf("REPLAY %s\n", replay_same ? "identical" : "differs");
    printf("TWIN %s\n", memcmp(out, twin, (size_t)steps * 3 * sizeof(double)) == 0
                            ? "identical" : "differs");
    CHECK(freeState(inst[0], &saved), "fmi2FreeFMUstate");
    for (int i = 0; i < 2; i++) {
        CHECK(terminate(inst[i]), "fmi2Terminate");
        freeInstance(inst[i]);
        inst[i] = NULL;
    }
    free(out);
    free(twin);
    printf("DONE\n");
    return 0;
}
