/* lib/lyapunov_sync.c - the synchronisation estimate over couplings
 * (lib/lyapunov_sync.h). */
#include "lib/lyapunov_sync.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/clock.h"
#include "lib/json.h"
#include "lib/figure.h"
#include "models/fo_sync.h"

/* Steps of RK4 per excitation period between events: the estimate moves
 * by less than the couplings' spacing from 200 to 400. */
enum { SYNC_STEPS = 200 };

static cm_status sync_setup(const lyap_args *a, sync_result *r, cm_fo_sync *c, char *msg,
                            size_t msg_size)
{
    if (a->periods < SYNC_RECORD + 100)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "--method sync watches the last %d periods after a transient of 100 or "
                       "more: give --periods %d or more",
                       SYNC_RECORD, SYNC_RECORD + 100);
    const cm_status st = lyapunov_fo_base(a, "sync", &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double S = cm_params_get(&r->base, "S"), S0 = cm_params_get(&r->base, "S0");
    /* the thesis' start, the copy 1e-6 away: a copy started far off can
     * settle on the mirror-image attractor and needs a stronger coupling
     * than the exponent to be pulled over (docs/models.md 9.8) */
    *c = (cm_fo_sync){S, S0, cm_params_get(&r->base, "Omega"), SYNC_STEPS,
                      a->periods - SYNC_RECORD, SYNC_RECORD, {1 + 0.9 * S0, 0}, {1e-6, 0}};
    r->n = a->q.n;
    r->largest = malloc((size_t)r->n * sizeof *r->largest);
    r->gaps = malloc((size_t)r->n * SYNC_RECORD * sizeof *r->gaps);
    if (!r->largest || !r->gaps)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d couplings", r->n);
    return CM_OK;
}

cm_status lyapunov_sync(const lyap_args *a, const work_hooks *h, sync_result *r, char *msg,
                        size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->first = -1;
    cm_fo_sync c;
    cm_status st = sync_setup(a, r, &c, msg, msg_size);
    if (st != CM_OK)
        return st;
    const double t0 = cm_seconds();
    int stop = 0;
    uint64_t done = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : stop)
    for (int k = 0; k < r->n; k++) {
        if (stop || (stop = work_stop(h) != NULL)) /* the couplings left are skipped */
            continue;
        r->largest[k] =
            cm_fo_sync_run(&c, param_axis_value(&a->q, k), r->gaps + (size_t)k * SYNC_RECORD);
        work_tick(h, &done);
    }
    r->done = done;
    if (stop)
        return work_canceled(h, msg, msg_size);
    r->seconds = cm_seconds() - t0;
    for (int k = r->n - 1; k >= 0 && r->largest[k] < CM_FO_SYNC_TOL; k--)
        r->first = k;
    return CM_OK;
}

static cm_status write_csv(const lyap_args *a, const sync_result *r, char *msg, size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "q,largest_difference,synchronised\n");
    for (int k = 0; k < r->n; k++)
        fprintf(o.f, "%.17g,%.17g,%d\n", param_axis_value(&a->q, k), r->largest[k],
                r->largest[k] < CM_FO_SYNC_TOL);
    return outfile_end(&o, true, msg, msg_size);
}

/* Fig. 2.23: x1 - x3 at the watched section instants against q, and the
 * estimate marked. */
static cm_status write_png(const lyap_args *a, const sync_result *r, char *msg, size_t msg_size)
{
    const size_t n = (size_t)r->n * SYNC_RECORD;
    double *q = malloc(n * sizeof *q);
    if (!q)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the diagram");
    double lo = -0.1, hi = 0.1;
    for (size_t i = 0; i < n; i++) {
        q[i] = param_axis_value(&a->q, (int)(i / SYNC_RECORD));
        lo = fmin(lo, r->gaps[i]), hi = fmax(hi, r->gaps[i]);
    }
    const double pad = 0.05 * (hi - lo);
    const cm_series points = {CM_SERIES_POINTS, q, r->gaps, n, (cm_rgb){0, 0, 0}, 3};
    char title[512], params[400], label[64];
    cm_params_format_with(&r->base, NULL, params, sizeof params);
    snprintf(title, sizeof title,
             "synchronisation: x1 - x3 at the last %d sections against the coupling q; %s",
             SYNC_RECORD, params);
    snprintf(label, sizeof label, "q* = %.4g", r->first >= 0 ? param_axis_value(&a->q, r->first)
                                                               : NAN);
    const cm_chart_label mark = {r->first >= 0 ? param_axis_value(&a->q, r->first) : 0, 0, label};
    const cm_chart chart = {a->width, a->height, {a->q.lo, lo - pad}, {a->q.hi, hi + pad},
                            "q", "x1 - x3", title, NULL, &points, 1, figure_font(), 0,
                            r->first >= 0 ? &mark : NULL, r->first >= 0};
    char range[96];
    param_axes_format(&a->q, 1, range, sizeof range);
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}, {"Sweep", range}};
    const cm_status st = outfile_charts(a->png, &chart, 1, texts, 3, msg, msg_size);
    free(q);
    return st;
}

cm_status lyapunov_sync_write(const lyap_args *a, const sync_result *r, char *msg,
                              size_t msg_size)
{
    cm_status st = a->csv ? write_csv(a, r, msg, msg_size) : CM_OK;
    if (st == CM_OK && a->png)
        st = write_png(a, r, msg, msg_size);
    return st;
}

void lyapunov_sync_report(FILE *out, const lyap_args *a, const sync_result *r)
{
    const double q = r->first >= 0 ? param_axis_value(&a->q, r->first) : NAN;
    const double below = r->first > 0 ? param_axis_value(&a->q, r->first - 1) : NAN;
    if (!a->json) {
        fprintf(out,
                "%d couplings in %.2f s: synchronised from q = %.6g (not at %.6g): the largest "
                "Lyapunov exponent is at most that\n",
                r->n, r->seconds, q, below);
        return;
    }
    json j;
    json_begin(&j, out, "lyapunov_sync");
    param_base_json(&j, a->mo.name, &r->base);
    json_num(&j, "q_sync", q);
    json_num(&j, "q_below", below);
    json_seconds(&j, "seconds", r->seconds);
    json_end(&j);
}

void lyapunov_sync_free(sync_result *r)
{
    free(r->largest);
    free(r->gaps);
    memset(r, 0, sizeof *r);
}
