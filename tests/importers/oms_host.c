/* A host on OMSimulator's C API (OMSimulator.h, libOMSimulator) that runs an SSP
 * archive exported by `drymount export-ssp` under prescribed inputs: per step k it
 * sets u_, v_, n_<axis> of every mount component to row k of the input file, advances
 * the system by one step of h and reads F_<axis> and E_fr of every mount.
 *
 *   oms_host SSP TEMPDIR IN OUT STEPS H MODE MOUNT...
 *
 * IN: STEPS rows of (mounts x 3 axes x (u, v, n)) little-endian doubles; OUT: STEPS rows
 * of (mounts x (F_axial, F_radial1, F_radial2, E_fr)). MODE says how the host advances:
 *   dostep      oms_doStep: one step of the master (time += h inside OMSimulator);
 *   until-acc   oms_stepUntil(t) with t accumulated by the host as t += h, the sum
 *               OMSimulator's fixed-step master forms itself;
 *   until-mul   oms_stepUntil((k + 1) * h), the communication points computed by product.
 * Written for drymount's tests (tests/test_ssp_omsimulator.py); exit 0 on success,
 * 1 with a message on stderr otherwise. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "OMSimulator/OMSimulator.h"

static const char *AXES[3] = {"axial", "radial1", "radial2"};

static int fail(const char *what, const char *cref)
{
    fprintf(stderr, "oms_host: %s failed%s%s\n", what, cref ? " for " : "", cref ? cref : "");
    return 1;
}

static void logger(oms_message_type_enu_t type, const char *message)
{
    if (type != oms_message_info || getenv("OMS_HOST_VERBOSE"))
        fprintf(stderr, "[oms %d] %s\n", (int)type, message);
}

int main(int argc, char **argv)
{
    const char *ssp, *tmp, *in_path, *out_path, *mode;
    long steps, k;
    double h, t = 0.0, *in, *out;
    int mounts, m, a;
    char *model = NULL, cref[512];
    FILE *f;

    if (argc < 9) {
        fprintf(stderr, "usage: oms_host SSP TEMPDIR IN OUT STEPS H MODE MOUNT...\n");
        return 2;
    }
    ssp = argv[1], tmp = argv[2], in_path = argv[3], out_path = argv[4];
    steps = strtol(argv[5], NULL, 10), h = strtod(argv[6], NULL), mode = argv[7];
    mounts = argc - 8;
    if (strcmp(mode, "dostep") && strcmp(mode, "until-acc") && strcmp(mode, "until-mul")) {
        fprintf(stderr, "oms_host: MODE must be dostep, until-acc or until-mul, got %s\n",
                mode);
        return 2;
    }
    in = malloc(sizeof(double) * (size_t)(steps * mounts * 9));
    out = malloc(sizeof(double) * (size_t)(steps * mounts * 4));
    f = fopen(in_path, "rb");
    if (!in || !out || !f
        || fread(in, sizeof(double), (size_t)(steps * mounts * 9), f)
               != (size_t)(steps * mounts * 9)) {
        fprintf(stderr, "oms_host: cannot read %ld rows from %s\n", steps, in_path);
        return 1;
    }
    fclose(f);

    oms_setLoggingCallback(logger);
    if (getenv("OMS_HOST_LOGLEVEL"))
        oms_setLoggingLevel(atoi(getenv("OMS_HOST_LOGLEVEL")));
    if (oms_setTempDirectory(tmp) != oms_status_ok)
        return fail("oms_setTempDirectory", tmp);
    if (oms_importFile(ssp, &model) != oms_status_ok || model == NULL)
        return fail("oms_importFile", ssp);
    if (oms_setResultFile(model, "", 0) != oms_status_ok)
        return fail("oms_setResultFile", model);
    /* stop time beyond the run: no step is clipped by it */
    if (oms_setStopTime(model, 2.0 * (double)steps * h) != oms_status_ok)
        return fail("oms_setStopTime", model);
    if (oms_instantiate(model) != oms_status_ok)
        return fail("oms_instantiate", model);
    if (oms_initialize(model) != oms_status_ok)
        return fail("oms_initialize", model);

    for (k = 0; k < steps; ++k) {
        const double *row = in + k * mounts * 9;
        oms_status_enu_t st;
        for (m = 0; m < mounts; ++m)
            for (a = 0; a < 3; ++a) {
                static const char *Q[3] = {"u", "v", "n"};
                int q;
                for (q = 0; q < 3; ++q) {
                    snprintf(cref, sizeof cref, "%s.%s.%s.%s_%s", model, model,
                             argv[8 + m], Q[q], AXES[a]);
                    if (oms_setReal(cref, row[m * 9 + a * 3 + q]) != oms_status_ok)
                        return fail("oms_setReal", cref);
                }
            }
        if (!strcmp(mode, "dostep"))
            st = oms_doStep(model);
        else if (!strcmp(mode, "until-acc"))
            st = oms_stepUntil(model, t += h);
        else
            st = oms_stepUntil(model, (double)(k + 1) * h);
        if (st != oms_status_ok)
            return fail(!strcmp(mode, "dostep") ? "oms_doStep" : "oms_stepUntil", model);
        for (m = 0; m < mounts; ++m) {
            double *o = out + (k * mounts + m) * 4;
            for (a = 0; a < 4; ++a) {
                if (a < 3)
                    snprintf(cref, sizeof cref, "%s.%s.%s.F_%s", model, model, argv[8 + m],
                             AXES[a]);
                else
                    snprintf(cref, sizeof cref, "%s.%s.%s.E_fr", model, model, argv[8 + m]);
                if (oms_getReal(cref, &o[a]) != oms_status_ok)
                    return fail("oms_getReal", cref);
            }
        }
    }
    if (oms_terminate(model) != oms_status_ok)
        return fail("oms_terminate", model);
    if (oms_delete(model) != oms_status_ok)
        return fail("oms_delete", model);
    f = fopen(out_path, "wb");
    if (!f || fwrite(out, sizeof(double), (size_t)(steps * mounts * 4), f)
                  != (size_t)(steps * mounts * 4))
        return fail("writing", out_path);
    fclose(f);
    free(in);
    free(out);
    return 0;
}
