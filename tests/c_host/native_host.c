/*
 * A plain FMI 2.0 Co-Simulation importer in C for the native FrictionMount FMU, used
 * by tests/test_native_fmu.py (started with an empty environment, `env -i`). It drives
 * TWO instances of the same binary side by side, step by step, each along its own
 * input trajectory, and records their outputs. Self-contained: the few FMI 2.0 types
 * it needs are declared below as in the standard's fmi2FunctionTypes.h.
 *
 * usage: native_host LIBRARY GUID CONFIG
 * CONFIG (text, whitespace separated):
 *   steps N  h H
 *   inputs K vr...        Real inputs set every step (K values per step)
 *   outputs L vr...       Real outputs read every step
 *   booleans B vr...      Boolean outputs read every step (written as 0.0 / 1.0)
 *   instance NAME TRAJECTORY OUTPUT   then its parameters until the next keyword:
 *     real VR VALUE | integer VR VALUE | boolean VR VALUE
 * TRAJECTORY: N*K doubles (native byte order); OUTPUT: N*(L+B) doubles are written.
 * Protocol per step k and instance: fmi2SetReal(inputs at t_k), fmi2GetReal(outputs),
 * fmi2GetBoolean(booleans), fmi2DoStep(t_k, H) with t_k = k H.
 * Builds for POSIX (dlopen) and Windows (LoadLibraryA; MinGW, run under wine).
 * Exit code: 0 ok, 2 usage / load error, 3 an FMI call failed (printed to stderr).
 */
#if defined(_WIN32)
/* the win64 DLL under wine (tests/test_native_platforms.py): LoadLibrary instead */
#include <windows.h>
#define dlopen(path, flags) ((void *)LoadLibraryA(path))
#define dlsym(lib, name) ((void *)GetProcAddress((HMODULE)(lib), name))
#define dlclose(lib) FreeLibrary((HMODULE)(lib))
#define dlerror() "LoadLibraryA failed"
#else
#include <dlfcn.h>
#endif
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status; /* 0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal */
typedef void (*fmi2CallbackLogger)(void *, const char *, fmi2Status, const char *,
                                   const char *, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*instantiate_t)(const char *, int, const char *, const char *,
                                       const fmi2CallbackFunctions *, int, int);
typedef void (*free_t)(fmi2Component);
typedef fmi2Status (*setup_t)(fmi2Component, int, double, double, int, double);
typedef fmi2Status (*void_t)(fmi2Component);
typedef fmi2Status (*real_t)(fmi2Component, const fmi2ValueReference *, size_t,
                             double *);
typedef fmi2Status (*int_t)(fmi2Component, const fmi2ValueReference *, size_t, int *);
typedef fmi2Status (*step_t)(fmi2Component, double, double, int);

#define MAXV 64
#define MAXP 128

typedef struct {
    char name[64];
    fmi2Component c;
    double *traj, *out;
    char out_path[4096];
    int np;
    char ptype[MAXP];
    fmi2ValueReference pvr[MAXP];
    double pval[MAXP];
} instance_t;

static void logger(void *env, const char *name, fmi2Status status,
                   const char *category, const char *fmt, ...)
{
    va_list ap;
    (void)env;
    fprintf(stderr, "LOG %s [%d] %s: ", name, status, category);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static void *sym(void *lib, const char *name)
{
    void *f = dlsym(lib, name);
    if (f == NULL) {
        fprintf(stderr, "missing symbol %s\n", name);
        exit(2);
    }
    return f;
}

#define CALL(expr, what)                                                   \
    do {                                                                   \
        fmi2Status s_ = (expr);                                            \
        if (s_ > 1) {                                                      \
            fprintf(stderr, "FAILED %s: status %d\n", what, s_);           \
            exit(3);                                                       \
        }                                                                  \
    } while (0)

static double *read_doubles(const char *path, size_t n)
{
    FILE *f = fopen(path, "rb");
    double *buf = malloc(n * sizeof *buf);
    if (f == NULL || buf == NULL || fread(buf, sizeof *buf, n, f) != n) {
        fprintf(stderr, "cannot read %zu doubles from %s\n", n, path);
        exit(2);
    }
    fclose(f);
    return buf;
}

int main(int argc, char **argv)
{
    FILE *cfg;
    char key[64];
    long steps = 0, k;
    double h = 0.0;
    int nin = 0, nout = 0, nbool = 0, ninst = 0, i, j;
    fmi2ValueReference vin[MAXV], vout[MAXV], vbool[MAXV];
    instance_t inst[2];
    void *lib;
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    if (argc != 4) {
        fprintf(stderr, "usage: native_host LIBRARY GUID CONFIG\n");
        return 2;
    }
    cfg = fopen(argv[3], "r");
    if (cfg == NULL)
        return 2;
    memset(inst, 0, sizeof inst);
    while (fscanf(cfg, "%63s", key) == 1) {
        instance_t *cur = ninst ? &inst[ninst - 1] : NULL;
        if (!strcmp(key, "steps")) {
            if (fscanf(cfg, "%ld", &steps) != 1) return 2;
        } else if (!strcmp(key, "h")) {
            if (fscanf(cfg, "%lf", &h) != 1) return 2;
        } else if (!strcmp(key, "inputs") || !strcmp(key, "outputs")
                   || !strcmp(key, "booleans")) {
            int *n = key[0] == 'i' ? &nin : key[0] == 'o' ? &nout : &nbool;
            fmi2ValueReference *v = key[0] == 'i' ? vin : key[0] == 'o' ? vout : vbool;
            if (fscanf(cfg, "%d", n) != 1 || *n > MAXV) return 2;
            for (i = 0; i < *n; ++i)
                if (fscanf(cfg, "%u", &v[i]) != 1) return 2;
        } else if (!strcmp(key, "instance")) {
            if (ninst == 2) return 2;
            cur = &inst[ninst++];
            if (fscanf(cfg, "%63s %4095s", cur->name, cur->out_path) != 2) return 2;
            cur->traj = read_doubles(cur->out_path, (size_t)(steps * nin));
            if (fscanf(cfg, "%4095s", cur->out_path) != 1) return 2;
        } else if (cur && (!strcmp(key, "real") || !strcmp(key, "integer")
                           || !strcmp(key, "boolean"))) {
            if (cur->np == MAXP) return 2;
            cur->ptype[cur->np] = key[0];
            if (fscanf(cfg, "%u %lf", &cur->pvr[cur->np], &cur->pval[cur->np]) != 2)
                return 2;
            cur->np++;
        } else {
            fprintf(stderr, "bad config keyword %s\n", key);
            return 2;
        }
    }
    fclose(cfg);
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (lib == NULL) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    {
        instantiate_t instantiate = (instantiate_t)sym(lib, "fmi2Instantiate");
        setup_t setup = (setup_t)sym(lib, "fmi2SetupExperiment");
        void_t enter = (void_t)sym(lib, "fmi2EnterInitializationMode");
        void_t exit_init = (void_t)sym(lib, "fmi2ExitInitializationMode");
        void_t terminate = (void_t)sym(lib, "fmi2Terminate");
        free_t free_inst = (free_t)sym(lib, "fmi2FreeInstance");
        real_t set_real = (real_t)sym(lib, "fmi2SetReal");
        real_t get_real = (real_t)sym(lib, "fmi2GetReal");
        int_t set_int = (int_t)sym(lib, "fmi2SetInteger");
        int_t set_bool = (int_t)sym(lib, "fmi2SetBoolean");
        int_t get_bool = (int_t)sym(lib, "fmi2GetBoolean");
        step_t do_step = (step_t)sym(lib, "fmi2DoStep");
        for (i = 0; i < ninst; ++i) {
            instance_t *p = &inst[i];
            p->c = instantiate(p->name, 1, argv[2], "", &cb, 0, 0);
            if (p->c == NULL) {
                fprintf(stderr, "FAILED fmi2Instantiate\n");
                return 3;
            }
            p->out = malloc((size_t)(steps * (nout + nbool)) * sizeof(double));
            for (j = 0; j < p->np; ++j) {
                double x = p->pval[j];
                int n = (int)x;
                if (p->ptype[j] == 'r')
                    CALL(set_real(p->c, &p->pvr[j], 1, &x), "fmi2SetReal");
                else if (p->ptype[j] == 'i')
                    CALL(set_int(p->c, &p->pvr[j], 1, &n), "fmi2SetInteger");
                else
                    CALL(set_bool(p->c, &p->pvr[j], 1, &n), "fmi2SetBoolean");
            }
            CALL(setup(p->c, 0, 0.0, 0.0, 0, 0.0), "fmi2SetupExperiment");
            CALL(enter(p->c), "fmi2EnterInitializationMode");
            CALL(exit_init(p->c), "fmi2ExitInitializationMode");
        }
        for (k = 0; k < steps; ++k) {
            for (i = 0; i < ninst; ++i) {
                instance_t *p = &inst[i];
                double *row = p->out + k * (nout + nbool);
                int b[MAXV];
                CALL(set_real(p->c, vin, (size_t)nin, p->traj + k * nin), "fmi2SetReal");
                CALL(get_real(p->c, vout, (size_t)nout, row), "fmi2GetReal");
                CALL(get_bool(p->c, vbool, (size_t)nbool, b), "fmi2GetBoolean");
                for (j = 0; j < nbool; ++j)
                    row[nout + j] = b[j] ? 1.0 : 0.0;
                CALL(do_step(p->c, (double)k * h, h, 1), "fmi2DoStep");
            }
        }
        for (i = 0; i < ninst; ++i) {
            FILE *f = fopen(inst[i].out_path, "wb");
            size_t n = (size_t)(steps * (nout + nbool));
            if (f == NULL || fwrite(inst[i].out, sizeof(double), n, f) != n)
                return 2;
            fclose(f);
            CALL(terminate(inst[i].c), "fmi2Terminate");
            free_inst(inst[i].c);
        }
    }
    dlclose(lib);
    printf("DONE %ld steps, %d instances\n", steps, ninst);
    return 0;
}
