/* The inclined element of thesis Ch. 5 on a mount axis (fmu_src/inclined_element.py):
 * its law is inclined.c; element deflection x = -u, axis force -N2. */
#include "mount_law.h"

#include <stdio.h>

#include "messages.h"

in_params ml_inclined_params(const ml_axis_params *p)
{
    in_params q;
    q.theta_deg = p->theta_deg;
    q.k = p->k;
    q.kf = p->kf;
    q.kf2 = p->kf2;
    q.mu1 = p->mu1;
    q.mu2 = p->mu2;
    q.preload = p->preload;
    return q;
}

void ml_relaxed_state(const ml_axis_params *p, double u, double *w)
{
    in_params q = ml_inclined_params(p);
    double s, c;
    in_sc(&q, &s, &c);
    w[0] = -u / s;
    w[1] = -u * c / s;
    w[2] = u;
}

/* The inclined element on an axis (mount_law._friction, inclined.axis_step): element
 * deflection x = -u from the committed -uc, friction force -N2. */
static int inclined_step(double u, double v, const double *w, const ml_axis_params *p,
                         double fs, double dt, double *w_new, ml_friction_step *r,
                         char *msg, size_t size)
{
    in_params q = ml_inclined_params(p);
    in_step st;
    (void)v;
    (void)fs;
    (void)dt;
    if (in_update(-u, -w[2], w[0], w[1], &q, &st, msg, size) != IN_OK)
        return 1;
    r->force = -st.force;
    r->tangent = st.tangent;
    r->slipping = st.slip1 || st.slip2;
    r->dissipated = st.dissipated;
    w_new[0] = st.w1;
    w_new[1] = st.w2;
    w_new[2] = u;
    return 0;
}

/* inclined.axis_normal_forces */
static void inclined_normal_forces(const ml_axis_params *p, const double *w, double fs,
                                   double *n1, double *n2)
{
    in_params q = ml_inclined_params(p);
    double f[4];
    (void)fs;
    in_forces(-w[2], w[0], w[1], &q, 0, 0, f);
    *n1 = f[2];
    *n2 = f[3];
}

static int inclined_state_size(const ml_axis_params *p)
{
    (void)p;
    return 3;
}

static double inclined_position(const double *state, int n)
{
    (void)n;
    return state[2];
}

/* mount_law._inclined_problems: the inclined element's checks on the axis's fields,
 * and micro-slip / non-symmetric friction belong to the Jenkins element. Appends to
 * buf (count problems there already); returns the number appended. */
static int inclined_problems(const ml_axis_params *p, const char *prefix, char *buf,
                             size_t size, int count)
{
    in_params q = ml_inclined_params(p);
    char text[2048], val[40];
    int added = in_problems(&q, prefix, text, sizeof text), n = count;
    if (added)
        ml_append_problem(buf, size, &n, text);  /* already "; "-separated */
    if (p->sliders != 1 || p->fs_ratio != 1.0) {
        ml_repr_double(p->fs_ratio, val, sizeof val);
        snprintf(text, sizeof text, "`%ssliders` = %d and `%sfs_ratio` = %s: micro-slip "
                 "and non-symmetric friction belong to the Jenkins element; the "
                 "inclined element needs sliders = 1 and fs_ratio = 1", prefix,
                 p->sliders, prefix, val);
        ml_append_problem(buf, size, &n, text);
        ++added;
    }
    return added;
}

/* the sliders w1 (inclined surface) and w2 (flat surface) of the state (w1, w2, uc):
 * inclined_element.py slider_slots */
static int inclined_slider_index(const ml_axis_params *p, int slot)
{
    (void)p;
    return slot == 0 || slot == 1 ? slot : -1;
}

ML_ELEMENT_DEF const ml_element ml_inclined = {
    "inclined", 1, inclined_state_size, ml_relaxed_state, inclined_position,
    inclined_step, inclined_normal_forces, inclined_problems, inclined_slider_index};
