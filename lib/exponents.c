/* lib/exponents.c - the Lyapunov spectrum of one orbit (lib/exponents.h). */
#include "lib/exponents.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/outfile.h"
#include "lib/rows.h"
#include "models/ode_flow.h"

/* The running estimates kept: about this many rows whatever the run's length. */
enum { EXP_ROWS = 10000 };

exp_args exponents_defaults(void)
{
    exp_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "chip-4d";
    a.o = (cm_spectrum_options){.transient = 10, .time = 100, .renorm = 0.1, .iterations = 10000,
                                .skip = 100};
    return a;
}

static void sort_decreasing(double *v, int k)
{
    for (int i = 1; i < k; i++)
        for (int j = i; j > 0 && v[j] > v[j - 1]; j--) {
            const double t = v[j];
            v[j] = v[j - 1];
            v[j - 1] = t;
        }
}

static int on_trace(void *user, double t, const double *lambda, int count)
{
    exp_result *r = user;
    if (r->seen++ % r->stride)
        return 0;
    if (!rows_room((void **)&r->rows, &r->cap_rows, r->n_rows, sizeof *r->rows))
        return 1;
    exp_row *row = &r->rows[r->n_rows++];
    row->t = t;
    memcpy(row->lambda, lambda, (size_t)count * sizeof *lambda);
    sort_decreasing(row->lambda, count);
    return 0;
}

static cm_status check_start(const exp_args *a, const cm_model *m, int n, char *msg,
                             size_t msg_size)
{
    if (a->n_from == 0 || a->n_from == n)
        return CM_OK;
    char names[256] = "";
    for (int d = 0; d < n; d++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", d ? ", " : "",
                 a->of_map ? cm_model_coord_name(m, d) : cm_flow_coord_name(m, d));
    return cm_fail(CM_EINVAL, msg, msg_size,
                   "the start has %d value(s) but the %s of model %s has %d coordinates (%s)",
                   a->n_from, a->of_map ? "map" : "flow", m->name, n, names);
}

/* The start: the user's, or the centre of the example region (lifted
 * onto a flow's section plane). */
static cm_status start_of(const exp_args *a, const cm_model *m, double *x, char *msg,
                          size_t msg_size)
{
    if (a->n_from) {
        memcpy(x, a->from, (size_t)a->n_from * sizeof *x);
        return CM_OK;
    }
    double centre[CM_MAX_DIM];
    const cm_status st = model_spec_centre(&a->mo, m->dim, centre, msg, msg_size);
    if (st == CM_OK && !a->of_map && cm_model_is_flow(m))
        cm_flow_lift(m, centre, x);
    else
        memcpy(x, centre, (size_t)m->dim * sizeof *x);
    return st;
}

cm_status exponents_compute(const exp_args *a, exp_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->mean_flight = NAN;
    cm_status st = model_spec_build(&a->mo, &r->m, msg, msg_size);
    if (st != CM_OK)
        return st;
    const cm_model *m = &r->m;
    r->of_map = a->of_map || !cm_model_is_flow(m);
    const int n = r->of_map ? m->dim : cm_flow_dim(m);
    st = check_start(a, m, n, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double steps = r->of_map ? (double)a->o.iterations : a->o.time / a->o.renorm;
    r->stride = steps > EXP_ROWS ? (long)ceil(steps / EXP_ROWS) : 1;
    double x[CM_MAX_DIM];
    st = start_of(a, m, x, msg, msg_size);
    if (st != CM_OK)
        return st;
    st = r->of_map ? cm_map_spectrum(m, x, &a->o, on_trace, r, &r->s, msg, msg_size)
                   : cm_flow_spectrum(m, x, &a->o, on_trace, r, &r->s, msg, msg_size);
    if (st == CM_ECANCELED)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the running estimates");
    if (st == CM_OK && r->of_map && cm_model_is_flow(m))
        r->mean_flight = r->s.time / (double)a->o.iterations;
    /* the last row is the result itself */
    if (st == CM_OK && r->n_rows && r->rows[r->n_rows - 1].t != (r->of_map ? steps : r->s.time)) {
        if (!rows_room((void **)&r->rows, &r->cap_rows, r->n_rows, sizeof *r->rows))
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the running estimates");
        exp_row *last = &r->rows[r->n_rows++];
        last->t = r->of_map ? steps : r->s.time;
        memcpy(last->lambda, r->s.lambda, sizeof last->lambda);
    }
    return st;
}

cm_status exponents_write(const exp_args *a, const exp_result *r, char *msg, size_t msg_size)
{
    if (!a->csv)
        return CM_OK;
    outfile o;
    cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int k = r->s.count;
    const bool flight = !isnan(r->mean_flight);
    fprintf(o.f, "t");
    for (int j = 1; j <= k; j++)
        fprintf(o.f, ",lambda_%d", j);
    fprintf(o.f, ",kaplan_yorke%s\n", flight ? ",flow_time" : "");
    for (size_t i = 0; i < r->n_rows; i++) {
        const exp_row *row = &r->rows[i];
        fprintf(o.f, "%.17g", row->t);
        for (int j = 0; j < k; j++)
            fprintf(o.f, ",%.17g", row->lambda[j]);
        fprintf(o.f, ",%.17g", cm_kaplan_yorke(row->lambda, k));
        if (flight)
            fprintf(o.f, ",%.17g", row->t * r->mean_flight);
        fprintf(o.f, "\n");
    }
    return outfile_end(&o, true, msg, msg_size);
}

void exponents_result_free(exp_result *r)
{
    cm_model_release(&r->m);
    free(r->rows);
    memset(r, 0, sizeof *r);
}
