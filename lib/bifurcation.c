/* lib/bifurcation.c - runs of a sweep followed and written (lib/bifurcation.h). */
#include "lib/bifurcation.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/figure.h"
#include "models/params.h"

/* What a followed run recorded, one point at a time, value by value. */
enum point_kind { POINT_STICK, POINT_SECTION, POINT_PSI };
typedef void (*point_fn)(void *user, int kind, double p, int run, double x, double v);

typedef struct cloud {
    double *x, *y;
    size_t n;
    double lo, hi; /* the range of y */
} cloud;

/* splitmix64 (Steele, Lea, Flood 2014): a good 64-bit mix for seeding. */
static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

void bifurcation_random(long long seed, int value, int run, int n, double *u)
{
    uint64_t h = mix64(mix64((uint64_t)seed) ^ ((uint64_t)value << 32 | (uint64_t)run));
    for (int k = 0; k < n; k++) {
        h = mix64(h);
        u[k] = (double)(h >> 11) * 0x1p-52 - 1;
    }
}

static void on_event(void *user, const cm_fo_event *e)
{
    run_result *res = user;
    if (e->kind == CM_FO_EV_STICK)
        res->stops[res->sticks++ % LAST_STOPS] = e->x;
}

/* How many of the sticking displacements the ring holds. */
static int stops_kept(const run_result *res)
{
    return res->sticks < LAST_STOPS ? res->sticks : LAST_STOPS;
}

/* Runs from the random start; sections[2 k], [2 k + 1]: the k-th recorded Poincare point. */
static void bifurcation_run(const bif_args *a, const cm_fo *o, int value, int r, run_result *res,
                double *sections)
{
    double u[3];
    bifurcation_random(a->seed, value, r, 3, u);
    res->x0 = u[0];
    res->v0 = u[1];
    res->t0 = u[2] * o->T;
    cm_fo_run fr;
    cm_fo_run_start(o, res->t0, res->x0, res->v0, &fr);
    res->ok = true;
    for (int p = 0; p < a->transient && res->ok; p++)
        res->ok = cm_fo_run_period(o, &fr, NULL, NULL, NULL);
    double zero_sum = 0;
    for (int p = 0; p < a->record && res->ok; p++) {
        cm_fo_tally t;
        cm_fo_tally_start(&t, fr.st.x);
        res->ok = cm_fo_run_period(o, &fr, &t, on_event, res);
        zero_sum += t.x_zero_sum;
        sections[2 * p] = fr.st.x;
        sections[2 * p + 1] = fr.st.v;
    }
    res->psi = fabs(zero_sum);
}

const run_result *bifurcation_result_at(const sweep_results *s, int value, int r)
{
    return &s->res[(size_t)value * (size_t)s->runs + (size_t)r];
}

static const double *sections_at(const sweep_results *s, int value, int r)
{
    return s->sections + ((size_t)value * (size_t)s->runs + (size_t)r) * 2 * (size_t)s->record;
}

/* The recorded sticking displacements of a run in time order. */
static double stop_at(const run_result *res, int j)
{
    return res->stops[(res->sticks - stops_kept(res) + j) % LAST_STOPS];
}

static void visit_points(const bif_args *a, const sweep_results *s, point_fn fn, void *user)
{
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = bifurcation_result_at(s, i, r);
            if (!res->valid || !res->ok)
                continue;
            const double p = param_axis_value(&a->sweep, i), *z = sections_at(s, i, r);
            for (int j = 0; j < stops_kept(res); j++)
                fn(user, POINT_STICK, p, r, stop_at(res, j), 0);
            for (int k = 0; k < s->record; k++)
                fn(user, POINT_SECTION, p, r, z[2 * k], z[2 * k + 1]);
            fn(user, POINT_PSI, p, r, res->psi / s->record, 0);
        }
}

static void print_point(void *user, int kind, double p, int run, double x, double v)
{
    if (kind != POINT_PSI)
        fprintf(user, "%.17g,%d,%s,%.17g,%.17g\n", p, run,
                kind == POINT_STICK ? "stick" : "section", x, v);
}

static bool write_points_csv(const bif_args *a, const sweep_results *s, char *msg,
                                  size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->out.csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "%s,run,kind,x,v\n", a->sweep.name);
    visit_points(a, s, print_point, o.f);
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static bool write_runs_csv(const bif_args *a, const sweep_results *s, char *msg,
                                size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->runs_csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f, "%s,run,x0,v0,t0,psi,psi_per_period,sticks_per_period,status\n", a->sweep.name);
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = bifurcation_result_at(s, i, r);
            if (!res->valid)
                continue;
            fprintf(o.f, "%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s\n",
                    param_axis_value(&a->sweep, i), r, res->x0, res->v0, res->t0, res->psi,
                    res->psi / s->record, (double)res->sticks / s->record, res->ok ? "ok" : "lost");
        }
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

static void cloud_add(cloud *c, double x, double y)
{
    c->x[c->n] = x;
    c->y[c->n++] = y;
    if (c->n == 1 || y < c->lo)
        c->lo = y;
    if (c->n == 1 || y > c->hi)
        c->hi = y;
}

/* A panel's point: panels 0, 1 and 2 are the point kinds. */
static void add_to_cloud(void *user, int kind, double p, int run, double x, double v)
{
    (void)run;
    (void)v;
    cloud_add(&((cloud *)user)[kind], p, x);
}

/* The three panels' points: sticking displacements, Poincare x, Psi per period. */
static bool collect_clouds(const bif_args *a, const sweep_results *s, cloud c[3])
{
    const size_t runs = (size_t)s->n_values * (size_t)s->runs,
                 cap[3] = {runs * LAST_STOPS, runs * (size_t)s->record, runs};
    bool ok = true;
    for (int k = 0; k < 3; k++) {
        c[k] = (cloud){malloc(cap[k] * sizeof(double)), malloc(cap[k] * sizeof(double)), 0, 0, 0};
        ok = ok && c[k].x && c[k].y;
    }
    if (ok)
        visit_points(a, s, add_to_cloud, c);
    return ok;
}

static bool write_png(const bif_args *a, const cm_params *base, const sweep_results *s,
                           char *msg, size_t msg_size)
{
    cloud c[3];
    bool ok = collect_clouds(a, s, c);
    if (!ok)
        snprintf(msg, msg_size, "out of memory for the picture");
    static const cm_rgb colours[3] = {{0, 0, 0}, {30, 60, 200}, {200, 30, 30}};
    static const float sizes[3] = {2, 1, 3};
    static const char *const y_names[3] = {"x stick", "x", "Psi/n"};
    char params[400], sweep[200], runs[160], titles[3][600];
    const char *const swept[] = {a->sweep.name, NULL};
    cm_params_format_with(base, swept, params, sizeof params);
    param_axes_format(&a->sweep, 1, sweep, sizeof sweep);
    snprintf(titles[0], sizeof titles[0], "sticking displacements (last %d per run), %s %s",
             LAST_STOPS, a->mo.name, params);
    snprintf(titles[1], sizeof titles[1], "Poincare points (phase phi), %d periods per run",
             a->record);
    snprintf(titles[2], sizeof titles[2], "asymmetry Psi per period (thesis 2.6.1)");
    cm_series series[3];
    cm_chart charts[3];
    const int h = a->out.height / 3;
    for (int k = 0; k < 3; k++) {
        double lo = c[k].n ? c[k].lo : -1, hi = c[k].n ? c[k].hi : 1;
        const double pad = hi > lo ? 0.05 * (hi - lo) : 0.5;
        if (k == 2)
            lo = 0; /* Psi >= 0: its zero is the point of the panel */
        series[k] = (cm_series){CM_SERIES_POINTS, c[k].x, c[k].y, c[k].n, colours[k], sizes[k]};
        charts[k] = (cm_chart){a->out.width,
                               k < 2 ? h : a->out.height - 2 * h,
                               {a->sweep.lo, lo - pad},
                               {a->sweep.hi, hi + pad},
                               a->sweep.name,
                               y_names[k],
                               titles[k],
                               NULL,
                               &series[k],
                               1,
                               figure_font(),
                               0,
                               NULL,
                               0};
    }
    snprintf(runs, sizeof runs,
             "%d runs per value, seed %lld; %d transient and %d recorded periods", a->runs, a->seed,
             a->transient, a->record);
    const cm_png_text texts[] = {
        {"Model", a->mo.name}, {"Parameters", params}, {"Sweep", sweep}, {"Runs", runs}};
    if (ok)
        ok = (outfile_charts(a->out.png, charts, 3, texts, 4, msg, msg_size) == CM_OK);
    for (int k = 0; k < 3; k++) {
        free(c[k].x);
        free(c[k].y);
    }
    return ok;
}

static void free_runs(sweep_results *s, cm_model *models)
{
    for (int i = 0; i < s->n_values && models; i++)
        if (cm_fo_of_model(&models[i]))
            cm_model_release(&models[i]);
    free(models);
    free(s->res);
    free(s->sections);
}

bif_args bifurcation_defaults(void)
{
    return (bif_args){.mo = {.name = "friction-oscillator"}, .runs = 10, .transient = 1000,
                      .record = 50, .seed = 1, .out = {.width = 900, .height = 1200}};
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(const bif_args *a, char *msg, size_t msg_size)
{
    if (!a->has_sweep || a->sweep.n < 1)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a sweep NAME=LO:HI:N is required (e.g. S=0.02:0.4:190)");
    if (a->runs < 1 || a->runs > 1000 || a->transient < 0 || a->transient > 1000000 ||
        a->record < 1 || a->record > 10000 || a->seed < 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "runs %d, transient %d, record %d, seed %lld: need 1..1000 runs, a "
                       "transient of 0..10^6 periods, 1..10000 recorded and a seed >= 0",
                       a->runs, a->transient, a->record, a->seed);
    if ((double)a->sweep.n * a->runs * a->record > 1e7)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d values x %d runs x %d recorded periods is more than 1e7 Poincare "
                       "points; record fewer",
                       a->sweep.n, a->runs, a->record);
    return CM_OK;
}

/* The models of the values, and which runs are to be followed. */
static cm_status prepare(const bif_args *a, bif_result *r, char *msg, size_t msg_size)
{
    const int n_values = a->sweep.n;
    const size_t n_runs = (size_t)n_values * (size_t)a->runs;
    r->s = (sweep_results){n_values, a->runs, a->record, calloc(n_runs, sizeof(run_result)),
                           malloc(n_runs * 2 * (size_t)a->record * sizeof(double))};
    r->models = calloc((size_t)n_values, sizeof *r->models);
    if (!r->s.res || !r->s.sections || !r->models)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu runs", n_runs);
    for (size_t k = 0; k < n_runs * 2 * (size_t)a->record; k++)
        r->s.sections[k] = NAN;
    for (int i = 0; i < n_values; i++) {
        if (!model_at_point(&a->mo, &a->sweep, &i, 1, &r->models[i]))
            continue;
        r->n_valid++;
        for (int k = 0; k < a->runs; k++)
            r->s.res[(size_t)i * (size_t)a->runs + (size_t)k].valid = true;
    }
    return CM_OK;
}

cm_status bifurcation_compute(const bif_args *a, const work_hooks *h, bif_result *r, char *msg,
                              size_t msg_size)
{
    *r = (bif_result){0};
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK)
        st = param_sweep_base(&a->mo, "friction-oscillator", &a->sweep, 1, &r->base, msg,
                              msg_size);
    if (st == CM_OK)
        st = prepare(a, r, msg, msg_size);
    if (st != CM_OK)
        return st;
    const size_t n_runs = (size_t)a->sweep.n * (size_t)a->runs;
    const double t0 = cm_seconds();
    uint64_t done = 0;
    int stopped = 0;
    sweep_results *s = &r->s;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads ? a->threads : omp_get_max_threads()) reduction(| : stopped)
    for (size_t k = 0; k < n_runs; k++) {
        const int i = (int)(k / (size_t)a->runs), run = (int)(k % (size_t)a->runs);
        if (!s->res[k].valid || stopped || (stopped = work_stop(h) != NULL))
            continue; /* stopped: the runs left are skipped */
        bifurcation_run(a, cm_fo_of_model(&r->models[i]), i, run, &s->res[k],
                        s->sections + k * 2 * (size_t)a->record);
        work_tick(h, &done);
    }
    r->done = done;
    r->seconds = cm_seconds() - t0;
    return stopped ? work_canceled(h, msg, msg_size) : CM_OK;
}

cm_status bifurcation_write(const bif_args *a, const bif_result *r, char *msg, size_t msg_size)
{
    if (r->n_valid == 0)
        return cm_fail(CM_ERANGE, msg, msg_size,
                       "no value of %s admits the model (is S <= S0 anywhere?)", a->sweep.name);
    const bool ok = (!a->out.csv || write_points_csv(a, &r->s, msg, msg_size)) &&
                    (!a->runs_csv || write_runs_csv(a, &r->s, msg, msg_size)) &&
                    (!a->out.png || write_png(a, &r->base, &r->s, msg, msg_size));
    return ok ? CM_OK : CM_EIO;
}

void bifurcation_result_free(bif_result *r)
{
    free_runs(&r->s, r->models);
    r->s = (sweep_results){0};
    r->models = NULL;
}
