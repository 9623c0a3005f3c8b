/* lib/stick_map.c - the map of every k-th stick and its transient's
 * exponent (lib/stick_map.h). */
#include "lib/stick_map.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/clock.h"
#include "lib/bifurcation.h"
#include "lib/figure.h"
#include "lib/json.h"
#include "models/fo_stickmap.h"

enum { STICKS_PER_RUN = 4096 };
static const double DERIVATIVE_STEP = 1e-7;

/* One run's part: its points and its sums, added in run order. */
typedef struct run_part {
    size_t n, counted;
    double log_sum, time_sum;
} run_part;

/* Run `run`: its sticks, the map's points into x, y, kept (room for
 * STICKS_PER_RUN), the counted points' ln |f'| and step times summed. */
static void one_run(const lyap_args *a, const cm_fo *o, int run, double *x, double *y,
                    unsigned char *kept, cm_fo_stick *s, run_part *part)
{
    double u[3];
    bifurcation_random(a->seed, 0, run, 3, u); /* x, v in [-1, 1], t0 in [-T, T] as 2.6.1 */
    const int n = cm_fo_sticks(o, (2 * u[2] - 1) * o->T, 2 * u[0] - 1, 2 * u[1] - 1, a->periods, s,
                               STICKS_PER_RUN);
    const int k = a->every;
    memset(part, 0, sizeof *part);
    bool escaped = false;
    for (int i = 0; i + k < n; i++) {
        escaped = escaped || fabs(s[i + k].x - s[i].x) < a->escape;
        x[part->n] = s[i].x, y[part->n] = s[i + k].x;
        kept[part->n] = 0;
        cm_fo_stick up, down;
        /* the first step leaves the random start: not yet on the transient */
        if (!escaped && i >= k && cm_fo_stick_after(o, s[i].t, s[i].x + DERIVATIVE_STEP, k, 64, &up) &&
            cm_fo_stick_after(o, s[i].t, s[i].x - DERIVATIVE_STEP, k, 64, &down)) {
            part->log_sum += log(fabs(up.x - down.x) / (2 * DERIVATIVE_STEP));
            part->time_sum += s[i + k].t - s[i].t;
            part->counted++;
            kept[part->n] = 1;
        }
        part->n++;
    }
}

static cm_status setup(const lyap_args *a, stick_map_result *r, cm_fo *o, char *msg,
                       size_t msg_size)
{
    const cm_status st = lyapunov_fo_base(a, "stickmap", &r->base, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_fo_init(o, cm_params_get(&r->base, "S"), cm_params_get(&r->base, "S0"),
               cm_params_get(&r->base, "Omega"), 0);
    const size_t room = (size_t)a->runs * STICKS_PER_RUN;
    r->x = malloc(room * sizeof *r->x);
    r->y = malloc(room * sizeof *r->y);
    r->kept = malloc(room);
    if (!r->x || !r->y || !r->kept)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d runs' sticks", a->runs);
    return CM_OK;
}

cm_status stick_map_compute(const lyap_args *a, const work_hooks *h, stick_map_result *r,
                            char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    cm_fo o;
    run_part *parts = NULL;
    cm_status st = setup(a, r, &o, msg, msg_size);
    if (st == CM_OK && !(parts = calloc((size_t)a->runs, sizeof *parts)))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d runs", a->runs);
    if (st != CM_OK)
        return st;
    const double t0 = cm_seconds();
    int stop = 0, no_memory = 0;
    uint64_t done = 0;
#pragma omp parallel num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : stop, no_memory)
    {
        cm_fo_stick *s = malloc(STICKS_PER_RUN * sizeof *s);
        no_memory = !s;
#pragma omp for schedule(dynamic, 1)
        for (int run = 0; run < a->runs; run++) {
            if (no_memory || stop || (stop = work_stop(h) != NULL))
                continue;
            const size_t at = (size_t)run * STICKS_PER_RUN;
            one_run(a, &o, run, r->x + at, r->y + at, r->kept + at, s, &parts[run]);
            work_tick(h, &done);
        }
        free(s);
    }
    r->done = done;
    /* the runs' points packed together and their sums added in run order:
     * the same numbers on any thread count */
    double log_sum = 0, time_sum = 0;
    for (int run = 0; run < a->runs && !stop && !no_memory; run++) {
        const size_t at = (size_t)run * STICKS_PER_RUN, n = parts[run].n;
        memmove(r->x + r->n, r->x + at, n * sizeof *r->x);
        memmove(r->y + r->n, r->y + at, n * sizeof *r->y);
        memmove(r->kept + r->n, r->kept + at, n);
        r->n += n;
        r->counted += parts[run].counted;
        log_sum += parts[run].log_sum, time_sum += parts[run].time_sum;
    }
    free(parts);
    if (no_memory)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the sticks");
    if (stop)
        return work_canceled(h, msg, msg_size);
    r->seconds = cm_seconds() - t0;
    if (r->counted == 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "no orbit stuck %d times before it came within %g of a fixed point of "
                       "the map: no transient to measure (raise --periods or lower --escape)",
                       a->every + 1, a->escape);
    r->lambda_map = log_sum / (double)r->counted;
    r->step_time = time_sum / (double)r->counted;
    r->lambda_flow = log_sum / time_sum;
    return CM_OK;
}

static cm_status write_csv(const lyap_args *a, const stick_map_result *r, char *msg,
                           size_t msg_size)
{
    outfile o;
    cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "x,x_next,counted\n");
    for (size_t i = 0; i < r->n; i++)
        fprintf(o.f, "%.17g,%.17g,%d\n", r->x[i], r->y[i], r->kept[i]);
    return outfile_end(&o, true, msg, msg_size);
}

/* Fig. 2.26 (a): the map's graph over the counted points' range, the
 * other points red (a run's first step from its random start, and after
 * the escape: the stable fixed points and the way to them), the counted
 * ones black over them, the diagonal grey. */
static cm_status write_png(const lyap_args *a, const stick_map_result *r, char *msg,
                           size_t msg_size)
{
    double *px = malloc(2 * r->n * sizeof *px), lo = INFINITY, hi = -INFINITY;
    if (!px)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the graph");
    double *py = px + r->n;
    size_t n_kept = 0, n_rest = r->n;
    for (size_t i = 0; i < r->n; i++) { /* counted points first, the rest from the end */
        const size_t at = r->kept[i] ? n_kept++ : --n_rest;
        px[at] = r->x[i], py[at] = r->y[i];
        if (r->kept[i])
            lo = fmin(lo, fmin(r->x[i], r->y[i])), hi = fmax(hi, fmax(r->x[i], r->y[i]));
    }
    const double pad = 0.03 * (hi - lo), diagonal[4] = {lo - pad, hi + pad, lo - pad, hi + pad};
    const cm_series series[3] = {
        {CM_SERIES_LINE, diagonal, diagonal + 2, 2, (cm_rgb){150, 150, 150}, 1},
        {CM_SERIES_POINTS, px + n_kept, py + n_kept, r->n - n_kept, (cm_rgb){215, 48, 39}, 3},
        {CM_SERIES_POINTS, px, py, n_kept, (cm_rgb){0, 0, 0}, 2}};
    char title[600], params[400], yname[32];
    cm_params_format_with(&r->base, NULL, params, sizeof params);
    snprintf(title, sizeof title,
             "every %d%s stick: lambda_map %.4g, lambda_flow %.4g (black: counted); %s",
             a->every, a->every == 1 ? "st" : a->every == 2 ? "nd" : a->every == 3 ? "rd" : "th",
             r->lambda_map, r->lambda_flow, params);
    snprintf(yname, sizeof yname, "x_n+%d", a->every);
    const cm_chart chart = {a->width, a->height, {lo - pad, lo - pad}, {hi + pad, hi + pad},
                            "x_n", yname, title, NULL, series, 3, figure_font(), 0, NULL, 0};
    const cm_png_text texts[] = {{"Model", a->mo.name}, {"Parameters", params}};
    const cm_status st = outfile_charts(a->png, &chart, 1, texts, 2, msg, msg_size);
    free(px);
    return st;
}

cm_status stick_map_write(const lyap_args *a, const stick_map_result *r, char *msg,
                          size_t msg_size)
{
    cm_status st = a->csv ? write_csv(a, r, msg, msg_size) : CM_OK;
    if (st == CM_OK && a->png)
        st = write_png(a, r, msg, msg_size);
    return st;
}

void stick_map_report(FILE *out, const lyap_args *a, const stick_map_result *r)
{
    if (!a->json) {
        fprintf(out,
                "%d runs in %.2f s: %zu map steps counted before escape; lambda_map = %.6g per "
                "step of %.6g time units: lambda_flow = %.6g\n",
                a->runs, r->seconds, r->counted, r->lambda_map, r->step_time, r->lambda_flow);
        return;
    }
    json j;
    json_begin(&j, out, "lyapunov_stickmap");
    param_base_json(&j, a->mo.name, &r->base);
    json_int(&j, "every", a->every);
    json_int(&j, "runs", a->runs);
    json_uint(&j, "counted", r->counted);
    json_num(&j, "lambda_map", r->lambda_map);
    json_num(&j, "step_time", r->step_time);
    json_num(&j, "lambda_flow", r->lambda_flow);
    json_seconds(&j, "seconds", r->seconds);
    json_end(&j);
}

void stick_map_free(stick_map_result *r)
{
    free(r->x);
    free(r->y);
    free(r->kept);
    memset(r, 0, sizeof *r);
}
