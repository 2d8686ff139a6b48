/* The Jenkins friction element (fmu_src/jenkins.py): macro-slip, non-symmetric and
 * micro-slip (Iwan), operation by operation as the Python element. */
#include "mount_law.h"

#include <math.h>

double ml_slider_update(double u, double w, double kf, double fs_pos, double fs_neg,
                        double *w_new, double *tangent, int *slipping)
{
    double trial = kf * (u - w);
    if (trial > fs_pos) {
        *w_new = u - fs_pos / kf;
        *tangent = 0.0;
        *slipping = 1;
        return fs_pos;
    }
    if (trial < -fs_neg) {
        *w_new = u + fs_neg / kf;
        *tangent = 0.0;
        *slipping = 1;
        return -fs_neg;
    }
    *w_new = w;
    *tangent = kf;
    *slipping = 0;
    return trial;
}

/* The symmetric element: ml_slider_update with fs_pos = fs_neg = fs (the same
 * arithmetic as the Python jenkins_update). */
double ml_jenkins_update(double u, double w, double kf, double fs, double *w_new,
                         double *tangent, int *slipping)
{
    return ml_slider_update(u, w, kf, fs, fs, w_new, tangent, slipping);
}

ml_axis_result ml_iwan_update(double u, const double *w, const ml_axis_params *p,
                              double fs, double *w_new)
{
    /* slider_bank: k_i = kf / S, r_i = 1 + spread ((2 i + 1) / S - 1),
     * fs_pos_i = Fs r_i / S, fs_neg_i = Fs r_i fs_ratio / S (same operation order) */
    ml_axis_result r;
    int n = p->sliders, i;
    double k = p->kf / n, f = 0.0, kt = 0.0, diss = 0.0;
    int slipping = 0;
    for (i = 0; i < n; ++i) {
        double ri = 1.0 + p->spread * ((double)(2 * i + 1) / n - 1.0);
        double fp = fs * ri / n, fn = fs * ri * p->fs_ratio / n;
        double wi = w[i], trial = k * (u - wi), wn;
        if (trial > fp) {
            wn = u - fp / k;
            f += fp;
            diss += fp * (wn - wi);
            slipping = 1;
        } else if (trial < -fn) {
            wn = u + fn / k;
            f -= fn;
            diss += fn * (wi - wn);
            slipping = 1;
        } else {
            wn = wi;
            f += trial;
            kt += k;
        }
        w_new[i] = wn;
    }
    r.force = f;
    r.friction = f;
    r.w_new = w_new[0];
    r.tangent = kt;
    r.slipping = slipping;
    r.dissipated = diss;
    return r;
}

double ml_mean_slider(const double *w, int n)
{
    int i;
    if (n <= 1)
        return w[0];
    for (i = 1; i < n; ++i)
        if (!(w[i] == w[0]))
            return ml_fsum(w, n) / n;
    return w[0];
}

/* JENKINS.bind: the variant its fields choose (micro-slip, non-symmetric, macro). */
static int jenkins_step(double u, double v, const double *w, const ml_axis_params *p,
                        double fs, double dt, double *w_new, ml_friction_step *out,
                        char *msg, size_t size)
{
    (void)v;
    (void)dt;
    (void)msg;
    (void)size;
    if (p->sliders > 1) {  /* micro-slip (jenkins._iwan) */
        ml_axis_result fr = ml_iwan_update(u, w, p, fs, w_new);
        out->force = fr.force;
        out->tangent = fr.tangent;
        out->slipping = fr.slipping;
        out->dissipated = fr.dissipated;
    } else if (p->fs_ratio != 1.0) {  /* non-symmetric macro-slip */
        double fn = fs * p->fs_ratio;
        out->force = ml_slider_update(u, w[0], p->kf, fs, fn, &w_new[0], &out->tangent,
                                      &out->slipping);
        out->dissipated = (w_new[0] > w[0] ? fs : fn) * fabs(w_new[0] - w[0]);
    } else {
        out->force = ml_jenkins_update(u, w[0], p->kf, fs, &w_new[0], &out->tangent,
                                       &out->slipping);
        out->dissipated = fs * fabs(w_new[0] - w[0]);
    }
    return 0;
}

static int jenkins_state_size(const ml_axis_params *p)
{
    return p->sliders > 1 ? p->sliders : 1;
}

static void jenkins_start(const ml_axis_params *p, double w, double *state)
{
    int i, n = jenkins_state_size(p);
    for (i = 0; i < n; ++i)
        state[i] = w;
}

void ml_contact_normal_forces(const ml_axis_params *p, const double *w, double fs,
                              double *n1, double *n2)
{
    (void)w;
    *n1 = p->mu > 0 ? fs / p->mu : p->n0;
    *n2 = 0.0;
}

/* every slider of the state may be set (jenkins.py slider_slots) */
static int jenkins_slider_index(const ml_axis_params *p, int slot)
{
    return slot < jenkins_state_size(p) ? slot : -1;
}

ML_ELEMENT_DEF const ml_element ml_jenkins = {
    "jenkins", 0, jenkins_state_size, jenkins_start, ml_mean_slider, jenkins_step,
    ml_contact_normal_forces, NULL, jenkins_slider_index};
