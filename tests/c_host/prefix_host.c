/*
 * Two copies of the native FMU's sources in one program (tests/test_native_sources.py):
 * sources/drymount_fmu.c compiled twice, with FMI2_FUNCTION_PREFIX=A_ and =B_, linked
 * with this file. Each copy drives one instance along its own sine on the axial axis
 * (amplitudes 10 and 20 mm, 7 Hz, friction on), protocol: set u, v at t_k, get F,
 * doStep(t_k, H). Prints "k uA vA FA uB vB FB" per step (%.17g), then "DONE".
 *
 * usage: prefix_host GUID STEPS VR_U VR_V VR_F VR_FRICTION VR_N0 N0
 * Exit code: 0 ok, 2 usage, 3 an FMI call failed.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *comp;
typedef unsigned int vref;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void (*step_finished)(void *, int);
    void *env;
} callbacks;

#define DECLARE(P)                                                                  \
    comp P##fmi2Instantiate(const char *, int, const char *, const char *,          \
                            const callbacks *, int, int);                           \
    int P##fmi2SetupExperiment(comp, int, double, double, int, double);             \
    int P##fmi2EnterInitializationMode(comp);                                       \
    int P##fmi2ExitInitializationMode(comp);                                        \
    int P##fmi2SetReal(comp, const vref *, size_t, const double *);                 \
    int P##fmi2SetBoolean(comp, const vref *, size_t, const int *);                 \
    int P##fmi2GetReal(comp, const vref *, size_t, double *);                       \
    int P##fmi2DoStep(comp, double, double, int);                                   \
    void P##fmi2FreeInstance(comp);
DECLARE(A_)
DECLARE(B_)

static void logger(void *env, const char *name, int status, const char *category,
                   const char *fmt, ...)
{
    va_list ap;
    (void)env;
    fprintf(stderr, "LOG %s [%d] %s: ", name, status, category);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

#define CHECK(call)                                                                 \
    do {                                                                            \
        if ((call) != 0) {                                                          \
            fprintf(stderr, "failed: %s\n", #call);                                 \
            return 3;                                                               \
        }                                                                           \
    } while (0)

#define SETUP(P, c, name)                                                           \
    do {                                                                            \
        c = P##fmi2Instantiate(name, 1, argv[1], "", &cb, 0, 0);                   \
        if (c == NULL)                                                              \
            return 3;                                                               \
        CHECK(P##fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0));                      \
        CHECK(P##fmi2EnterInitializationMode(c));                                   \
        CHECK(P##fmi2SetBoolean(c, &vr_fr, 1, &on));                                \
        CHECK(P##fmi2SetReal(c, &vr_n0, 1, &n0));                                   \
        CHECK(P##fmi2ExitInitializationMode(c));                                    \
    } while (0)

#define STEP(P, c, x)                                                               \
    do {                                                                            \
        uv[0] = (x) * sin(w * t);                                                   \
        uv[1] = (x) * w * cos(w * t);                                               \
        CHECK(P##fmi2SetReal(c, vr_uv, 2, uv));                                     \
        CHECK(P##fmi2GetReal(c, &vr_f, 1, &f));                                     \
        CHECK(P##fmi2DoStep(c, t, h, 1));                                           \
        printf(" %.17g %.17g %.17g", uv[0], uv[1], f);                              \
    } while (0)

int main(int argc, char **argv)
{
    callbacks cb = {logger, calloc, free, NULL, NULL};
    comp a, b;
    vref vr_uv[2], vr_f, vr_fr, vr_n0;
    double n0, uv[2], f, t, h = 1e-4, w = 2.0 * 3.141592653589793 * 7.0;
    int on = 1;
    long k, steps;
    if (argc != 9)
        return 2;
    steps = atol(argv[2]);
    vr_uv[0] = (vref)atoi(argv[3]);
    vr_uv[1] = (vref)atoi(argv[4]);
    vr_f = (vref)atoi(argv[5]);
    vr_fr = (vref)atoi(argv[6]);
    vr_n0 = (vref)atoi(argv[7]);
    n0 = atof(argv[8]);
    SETUP(A_, a, "copyA");
    SETUP(B_, b, "copyB");
    for (k = 0; k < steps; ++k) {
        t = (double)k * h;
        printf("%ld", k);
        STEP(A_, a, 0.01);
        STEP(B_, b, 0.02);
        printf("\n");
    }
    A_fmi2FreeInstance(a);
    B_fmi2FreeInstance(b);
    printf("DONE\n");
    return 0;
}
