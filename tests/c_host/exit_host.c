/*
 * An FMI 2.0 importer that leaves its instance alive until the process exits, as
 * OMSimulator does: the instance is freed by an exit handler the host registered
 * before it loaded the FMU (so the handler runs after any the FMU registered), or
 * not at all. Used by tests/test_fmu_loader.py.
 *
 * Built with the FMI 2.0 headers fmpy ships (fmpy/c-code).
 *
 * usage: exit_host UNZIPDIR GUID VR_U VR_F MODE      MODE: free-at-exit | leak
 *
 * Instantiates one instance, initialises it, drives u = 1e-3 * k for 10 steps of
 * 1e-3 s, prints "F <force>" (%.17g) after the last step and "MAIN DONE", then
 * returns from main. In free-at-exit mode the exit handler frees the instance and
 * prints "FREED AT EXIT". Exit code: 0 ok, 2 usage/load error, 3 an FMI call failed.
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h" /* the standard's header (fmpy ships it: c-code/) */

typedef fmi2InstantiateTYPE *Instantiate_t;
typedef fmi2FreeInstanceTYPE *FreeInstance_t;

static FreeInstance_t free_instance;
static fmi2Component instance;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    printf("LOG %d %s %s: ", (int)status, category ? category : "-", name);
    va_start(args, message);
    vprintf(message, args);
    va_end(args);
    printf("\n");
    fflush(stdout);
}

static void free_at_exit(void) {
    if (instance != NULL) {
        free_instance(instance);
        printf("FREED AT EXIT\n");
        fflush(stdout);
    }
}

static void *sym(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (f == NULL) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(2);
    }
    return f;
}

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: see the comment at the top of exit_host.c\n");
        return 2;
    }
    fmi2ValueReference vr_u = (fmi2ValueReference)atoi(argv[3]);
    fmi2ValueReference vr_f = (fmi2ValueReference)atoi(argv[4]);
    if (strcmp(argv[5], "free-at-exit") == 0)
        atexit(free_at_exit); /* before the FMU is loaded: runs after its handlers */
    char path[4096], uri[4200];
    snprintf(path, sizeof path, "%s/binaries/linux64/FrictionMount.so", argv[1]);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (lib == NULL) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    Instantiate_t instantiate = (Instantiate_t)sym(lib, "fmi2Instantiate");
    free_instance = (FreeInstance_t)sym(lib, "fmi2FreeInstance");
    fmi2SetupExperimentTYPE *setup = sym(lib, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter = sym(lib, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *leave = sym(lib, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *set_real = sym(lib, "fmi2SetReal");
    fmi2GetRealTYPE *get_real = sym(lib, "fmi2GetReal");
    fmi2DoStepTYPE *do_step = sym(lib, "fmi2DoStep");
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    snprintf(uri, sizeof uri, "file://%s/resources", argv[1]);
    instance = instantiate("mount", fmi2CoSimulation, argv[2], uri, &cb, 0, 0);
    if (instance == NULL) {
        printf("FAILED fmi2Instantiate\n");
        return 3;
    }
    double f = 0.0;
    if (setup(instance, 0, 0.0, 0.0, 0, 0.0) > fmi2Warning || enter(instance) > fmi2Warning ||
        leave(instance) > fmi2Warning) {
        printf("FAILED initialisation\n");
        return 3;
    }
    for (int k = 1; k <= 10; k++) {
        double u = 1e-3 * k;
        if (set_real(instance, &vr_u, 1, &u) > fmi2Warning ||
            do_step(instance, 1e-3 * (k - 1), 1e-3, 1) > fmi2Warning) {
            printf("FAILED step %d\n", k);
            return 3;
        }
    }
    if (get_real(instance, &vr_f, 1, &f) > fmi2Warning) {
        printf("FAILED fmi2GetReal\n");
        return 3;
    }
    printf("F %.17g\nMAIN DONE\n", f);
    fflush(stdout);
    return 0; /* the instance is still alive */
}
