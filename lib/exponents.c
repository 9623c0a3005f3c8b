/* lib/exponents.c - the Lyapunov spectrum of one orbit (lib/exponents.h). */
#include "lib/exponents.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/rows.h"
#include "models/chip_formation.h"
#include "models/dde_lyapunov.h"
#include "models/ode_flow.h"
#include "models/params.h"

/* The running estimates kept: about this many rows whatever the run's length. */
enum { EXP_ROWS = 10000 };

exp_args exponents_defaults(void)
{
    exp_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "chip-4d";
    a.o = (cm_spectrum_options){.transient = 10, .time = 100, .renorm = 0.1, .iterations = 10000,
                                .skip = 100};
    a.samples = 20, a.gs = 10, a.q_max = 20;
    return a;
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
    cm_sort_decreasing(row->lambda, count);
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

/* Keeps the result as the last row unless the trace gave it already. */
static cm_status last_row(exp_result *r, double t, char *msg, size_t msg_size)
{
    if (r->n_rows && r->rows[r->n_rows - 1].t == t)
        return CM_OK;
    if (!rows_room((void **)&r->rows, &r->cap_rows, r->n_rows, sizeof *r->rows))
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the running estimates");
    exp_row *last = &r->rows[r->n_rows++];
    last->t = t;
    memcpy(last->lambda, r->s.lambda, sizeof last->lambda);
    return CM_OK;
}

/* chip-bue's exponents: Farmer's map, or the synchronisation estimate. */
static cm_status delay_exponents(const exp_args *a, exp_result *r, char *msg, size_t msg_size)
{
    cm_params p;
    cm_status st = cm_chip_bue_params(a->mo.texts, a->mo.n_texts, &p, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_chip_bue_describe(&p, &r->m);
    r->delay = true;
    if (a->n_from || a->of_map)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "chip-bue starts from its start-up and has no map: leave out --from and "
                       "--of map");
    cm_chip_bue c;
    cm_dde d;
    cm_chip_bue_of(&p, &c, &d);
    if (a->sync) {
        const cm_sync_options so = {.t0 = 0, .t1 = a->o.transient + a->o.time, .offset = 1e-3,
                                    .lo = 0, .hi = a->q_max, .q_tol = 1e-3 * a->q_max,
                                    .own_delay = a->own_delay};
        st = cm_dde_sync_estimate(&d, &so, &r->sync_q, msg, msg_size);
        r->s.n = 4, r->s.count = 1, r->s.lambda[0] = r->sync_q, r->s.kaplan_yorke = NAN;
        return st == CM_OK ? last_row(r, so.t1, msg, msg_size) : st;
    }
    const cm_farmer_options fo = {.samples = a->samples, .gs = a->gs,
                                  .count = a->o.count ? a->o.count : 4,
                                  .transient = a->o.transient, .time = a->o.time,
                                  .euler_tangent = a->euler_tangent};
    if (fo.count > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "at most %d exponents", CM_MAX_DIM);
    r->stride = fo.time / (c.dt / fo.samples) / fo.gs > EXP_ROWS
                    ? (long)ceil(fo.time / (c.dt / fo.samples) / fo.gs / EXP_ROWS)
                    : 1;
    cm_farmer_result fr;
    st = cm_dde_farmer(&d, &fo, on_trace, r, &fr, msg, msg_size);
    if (st != CM_OK)
        return st == CM_ECANCELED
                   ? cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the running estimates")
                   : st;
    r->farmer_dim = fr.dim;
    r->s.n = 4, r->s.count = fr.count, r->s.time = fr.time, r->s.kaplan_yorke = fr.kaplan_yorke;
    memcpy(r->s.lambda, fr.lambda, (size_t)fr.count * sizeof *fr.lambda);
    return last_row(r, fr.time, msg, msg_size);
}

cm_status exponents_compute(const exp_args *a, exp_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    r->mean_flight = NAN;
    r->sync_q = NAN;
    r->stride = 1;
    if (a->mo.name && strcmp(a->mo.name, "chip-bue") == 0)
        return delay_exponents(a, r, msg, msg_size);
    if (a->sync || a->euler_tangent)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "--sync and --euler-tangent are for the delay model chip-bue");
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
    if (st == CM_OK) /* the last row is the result itself */
        st = last_row(r, r->of_map ? steps : r->s.time, msg, msg_size);
    return st;
}

static cm_status write_csv(const exp_args *a, const exp_result *r, char *msg, size_t msg_size)
{
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

/* The running estimates of the (at most 4) largest exponents against t,
 * as Figs. 3.7 and 3.18 show their convergence; the others are far below. */
static cm_status write_png(const exp_args *a, const exp_result *r, char *msg, size_t msg_size)
{
    enum { SHOWN = 4 };
    static const cm_rgb ink[SHOWN] = {{20, 60, 160}, {200, 40, 30}, {0, 140, 60}, {120, 60, 160}};
    const int k = r->s.count < SHOWN ? r->s.count : SHOWN;
    const size_t n = r->n_rows;
    double *t = malloc((size_t)(k + 1) * (n ? n : 1) * sizeof *t);
    if (!t || n == 0) {
        free(t);
        return t ? cm_fail(CM_EINVAL, msg, msg_size, "no estimates to draw")
                 : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    }
    cm_series series[SHOWN];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++)
        t[i] = r->rows[i].t;
    for (int j = 0; j < k; j++) {
        double *y = t + (size_t)(j + 1) * n;
        for (size_t i = 0; i < n; i++) {
            y[i] = r->rows[i].lambda[j];
            /* the first tenth is the estimates' own transient: not in the range */
            if (i >= n / 10 && isfinite(y[i]))
                lo = fmin(lo, y[i]), hi = fmax(hi, y[i]);
        }
        series[j] = (cm_series){CM_SERIES_LINE, t, y, n, ink[j], 1.5f};
    }
    const double pad = hi > lo ? 0.1 * (hi - lo) : 0.5;
    char title[256], params[512];
    cm_params_format(&r->m.values, params, sizeof params);
    snprintf(title, sizeof title, "running Lyapunov exponents of %s (%s)%s", r->m.name,
             r->of_map ? "its map, per iterate" : "per unit time",
             k > 1 ? ": lambda_1 blue, lambda_2 red, lambda_3 green, lambda_4 violet" : "");
    /* 0: the default size, so that a caller can tell whether one was given */
    const int width = a->width ? a->width : 900, height = a->width ? a->height : 500;
    const cm_chart chart = {width, height, {t[0], lo - pad}, {t[n - 1], hi + pad},
                            r->of_map ? "iterates" : "t", "lambda", title, NULL, series, k,
                            figure_font(), 0, NULL, 0};
    const cm_png_text texts[] = {{"Model", r->m.name}, {"Parameters", params}};
    const cm_status st = outfile_charts(a->png, &chart, 1, texts, 2, msg, msg_size);
    free(t);
    return st;
}

cm_status exponents_write(const exp_args *a, const exp_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->csv)
        st = write_csv(a, r, msg, msg_size);
    if (st == CM_OK && a->png)
        st = write_png(a, r, msg, msg_size);
    return st;
}

void exponents_report(FILE *f, const exp_result *r)
{
    const cm_spectrum *s = &r->s;
    if (!isnan(r->sync_q)) {
        fprintf(f, "synchronisation estimate of %s's largest exponent: q = %.4g\n", r->m.name,
                r->sync_q);
        return;
    }
    double sum = 0;
    if (r->farmer_dim)
        fprintf(f, "Farmer's map of %s (%ld coordinates; %d exponents, per unit time):",
                r->m.name, r->farmer_dim, s->count);
    else
        fprintf(f, "%s spectrum of %s (%d of %d exponents%s):", r->of_map ? "map" : "flow",
                r->m.name, s->count, s->n, r->of_map ? ", per iterate" : ", per unit time");
    for (int j = 0; j < s->count; j++) {
        fprintf(f, " %.6g", s->lambda[j]);
        sum += s->lambda[j];
    }
    fprintf(f, "\nsum %.6g; Kaplan-Yorke dimension ", sum);
    if (isnan(s->kaplan_yorke))
        fprintf(f, "above %d (more exponents needed)\n", s->count);
    else
        fprintf(f, "%.4f\n", s->kaplan_yorke);
    if (!isnan(r->mean_flight)) {
        fprintf(f, "mean flight between iterates %.6g; per unit of the flow's time:",
                r->mean_flight);
        for (int j = 0; j < s->count; j++)
            fprintf(f, " %.6g", s->lambda[j] / r->mean_flight);
        fprintf(f, "\n");
    }
}

void exponents_json(FILE *f, const exp_result *r)
{
    const cm_spectrum *s = &r->s;
    json j;
    json_begin(&j, f, "exponents");
    json_model(&j, &r->m);
    json_str(&j, "of",
             !isnan(r->sync_q) ? "sync" : r->farmer_dim ? "farmer" : r->of_map ? "map" : "flow");
    json_nums(&j, "lambda", s->lambda, s->count);
    json_num(&j, "kaplan_yorke", s->kaplan_yorke);
    if (!isnan(r->mean_flight)) {
        double per_time[CM_MAX_DIM];
        for (int k = 0; k < s->count; k++)
            per_time[k] = s->lambda[k] / r->mean_flight;
        json_num(&j, "mean_flight", r->mean_flight);
        json_nums(&j, "lambda_per_time", per_time, s->count);
    }
    if (r->farmer_dim)
        json_int(&j, "farmer_dim", r->farmer_dim);
    if (!r->delay)
        json_nums(&j, "end", s->x, s->n);
    json_end(&j);
}

void exponents_result_free(exp_result *r)
{
    cm_model_release(&r->m);
    free(r->rows);
    memset(r, 0, sizeof *r);
}
