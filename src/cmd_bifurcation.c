/* cellmap bifurcation: the Monte Carlo bifurcation diagram of the dry
 * friction oscillator (thesis 2.6.1, Fig. 2.22): for every value of one
 * parameter, several runs from random initial conditions, recorded after
 * their transients: the last sticking displacements, the Poincare points
 * and the asymmetry measure Psi. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/clock.h"
#include "models/friction_oscillator.h"
#include "models/params.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "lib/param_grid.h"
#include "src/progress.h"

static const char bifurcation_help[] =
    "usage: cellmap bifurcation [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                           --sweep NAME=LO:HI:N|NAME=V1,V2,... [--runs R] [--transient P]\n"
    "                           [--record n]\n"
    "                           [--seed K] [--csv FILE|-] [--runs-csv FILE|-] [--png FILE]\n"
    "                           [--json] [--quiet] [--size WxH] [--threads T]\n\n"
    "The Monte Carlo bifurcation diagram of the dry friction oscillator (thesis\n"
    "2.6.1, Fig. 2.22). Parameter NAME takes N values, the centres of N equal\n"
    "cells of LO..HI, or the listed ones. For each, R runs start from random x(t0) in [-1, 1],\n"
    "x'(t0) in [-1, 1], t0 in [-2 pi/Omega, 2 pi/Omega] (as the thesis), are\n"
    "followed exactly through P periods of transients, and are recorded for n\n"
    "periods: the Poincare points (phase phi), the last ten displacements where\n"
    "the block stuck, and Psi = |sum of x at the velocity zeros| over the n\n"
    "periods. Runs are spread over the threads; the results do not depend on the\n"
    "thread count, and the same seed gives the same initial conditions.\n\n"
    "  --sweep NAME=LO:HI:N the parameter and its values (N <= 2000), e.g. S=0.02:0.4:190,\n"
    "                      or NAME=V1,V2,... (increasing), e.g. S=0.32,0.4\n"
    "  --runs R            runs per value, 1..1000 (default 10)\n"
    "  --transient P       periods left out, 0..1000000 (default 1000)\n"
    "  --record n          periods recorded, 1..10000 (default 50)\n"
    "  --seed K            seed of the initial conditions (default 1)\n"
    "  --json              the summary as JSON on standard output (docs/cellmap.schema.json)\n"
    "  --quiet             no progress line and no summary\n"
    "  --csv FILE          NAME,run,kind,x,v: kind stick (the last ten sticking\n"
    "                      displacements, v = 0) or section (the Poincare points)\n"
    "  --runs-csv FILE     NAME,run,x0,v0,t0,psi,psi_per_period,sticks_per_period,status\n"
    "                      (status ok, or lost where the motion could not be followed)\n"
    "  --png FILE          sticking displacements (as Fig. 2.22, top), Poincare x and\n"
    "                      Psi per period against NAME\n"
    "  --size WxH          image size, all three panels (default 900x1200)\n"
    "  --threads T         OpenMP threads (default: all cores)\n";

enum { LAST_STOPS = 10 };

typedef struct bif_args {
    model_opts mo;
    param_axis sweep;
    int has_sweep, runs, transient, record, threads;
    long long seed;
    const char *runs_csv;
    chart_outputs out;
} bif_args;

static int parse_args(cli *c, bif_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(bifurcation_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--sweep", true, &err)) {
            if (c->value && !param_axis_parse(c->value, strlen(c->value), &a->sweep))
                err = cli_usage_error(c,
                                      "--sweep: '%s' is not NAME=LO:HI:N with LO < HI and "
                                      "1 <= N <= %d (e.g. S=0.02:0.4:190) nor NAME=V1,V2,... "
                                      "with increasing values",
                                      c->value, PARAM_AXIS_MAX);
            a->has_sweep = 1;
        } else if (cli_take_int(c, "--runs", 1, 1000, &a->runs, &err)) {
        } else if (cli_take_int(c, "--transient", 0, 1000000, &a->transient, &err)) {
        } else if (cli_take_int(c, "--record", 1, 10000, &a->record, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (cli_is(c, "--seed", true, &err)) {
            int64_t v = 0;
            if (c->value && (!parse_int64(c->value, &v) || v < 0))
                err = cli_usage_error(c, "--seed: '%s' must be a non-negative integer", c->value);
            a->seed = v;
        } else if (cli_is(c, "--runs-csv", true, &err)) {
            a->runs_csv = c->value;
        } else if (chart_outputs_take(c, &a->out, 300, 450, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !a->has_sweep)
        err = cli_usage_error(c, "--sweep NAME=LO:HI:N is required (e.g. --sweep S=0.02:0.4:190)");
    if (!err && !a->out.csv && !a->runs_csv && !a->out.png && !a->out.json)
        err = cli_usage_error(c,
                              "nothing to write: give --csv, --runs-csv and/or --png FILE, or --json");
    if (!err)
        err = chart_outputs_check(c, &a->out);
    if (!err && cm_output_names_stdout(a->runs_csv) &&
        (a->out.json || cm_output_names_stdout(a->out.csv) || cm_output_names_stdout(a->out.png)))
        err = cli_usage_error(c, "--runs-csv - and another output to standard output: choose one");
    if (!err && (double)a->sweep.n * a->runs * a->record > 1e7)
        err = cli_usage_error(c,
                              "%d values x %d runs x %d recorded periods is more than 1e7 "
                              "Poincare points; record fewer",
                              a->sweep.n, a->runs, a->record);
    return err;
}

/* ---- one run ---- */

/* splitmix64 (Steele, Lea, Flood 2014): a good 64-bit mix for seeding. */
static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* Three numbers in [-1, 1) that depend only on the seed, the value and the run. */
static void random_start(long long seed, int value, int run, double u[3])
{
    uint64_t h = mix64(mix64((uint64_t)seed) ^ ((uint64_t)value << 32 | (uint64_t)run));
    for (int k = 0; k < 3; k++) {
        h = mix64(h);
        u[k] = (double)(h >> 11) * 0x1p-52 - 1;
    }
}

typedef struct run_result {
    double x0, v0, t0, psi;
    double stops[LAST_STOPS]; /* a ring: the last sticking displacements */
    int sticks;               /* in all of the recorded periods */
    bool ok, valid;           /* valid: the parameter value admits the model */
} run_result;

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
static void run(const bif_args *a, const cm_fo *o, int value, int r, run_result *res,
                double *sections)
{
    double u[3];
    random_start(a->seed, value, r, u);
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

/* ---- output ---- */

typedef struct sweep_results {
    int n_values, runs, record;
    run_result *res;  /* res[value * runs + run] */
    double *sections; /* record * 2 per run, in the same order */
} sweep_results;

static const run_result *result_at(const sweep_results *s, int value, int r)
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

/* What a followed run recorded, one point at a time, value by value. */
enum point_kind { POINT_STICK, POINT_SECTION, POINT_PSI };
typedef void (*point_fn)(void *user, int kind, double p, int run, double x, double v);

static void visit_points(const bif_args *a, const sweep_results *s, point_fn fn, void *user)
{
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = result_at(s, i, r);
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

static bool write_points_csv(const bif_args *a, const sweep_results *s)
{
    outfile o;
    if (!outfile_open("bifurcation", a->out.csv, &o))
        return false;
    fprintf(o.f, "%s,run,kind,x,v\n", a->sweep.name);
    visit_points(a, s, print_point, o.f);
    return outfile_close("bifurcation", &o, true);
}

static bool write_runs_csv(const bif_args *a, const sweep_results *s)
{
    outfile o;
    if (!outfile_open("bifurcation", a->runs_csv, &o))
        return false;
    fprintf(o.f, "%s,run,x0,v0,t0,psi,psi_per_period,sticks_per_period,status\n", a->sweep.name);
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = result_at(s, i, r);
            if (!res->valid)
                continue;
            fprintf(o.f, "%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s\n",
                    param_axis_value(&a->sweep, i), r, res->x0, res->v0, res->t0, res->psi,
                    res->psi / s->record, (double)res->sticks / s->record, res->ok ? "ok" : "lost");
        }
    return outfile_close("bifurcation", &o, true);
}

typedef struct cloud {
    double *x, *y;
    size_t n;
    double lo, hi; /* the range of y */
} cloud;

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

static bool write_png(const bif_args *a, const cm_params *base, const sweep_results *s)
{
    cloud c[3];
    bool ok = collect_clouds(a, s, c);
    if (!ok)
        fprintf(stderr, "cellmap bifurcation: out of memory for the picture\n");
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
        ok = write_chart_png("bifurcation", a->out.png, charts, 3, texts, 4);
    for (int k = 0; k < 3; k++) {
        free(c[k].x);
        free(c[k].y);
    }
    return ok;
}

static void print_summary(const bif_args *a, const cm_params *base, const sweep_results *s,
                          double secs)
{
    int valid = 0, lost = 0;
    double psi_lo = INFINITY, psi_hi = -INFINITY;
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = result_at(s, i, r);
            valid += res->valid;
            lost += res->valid && !res->ok;
            if (res->valid && res->ok) {
                psi_lo = fmin(psi_lo, res->psi / s->record);
                psi_hi = fmax(psi_hi, res->psi / s->record);
            }
        }
    if (a->out.json) {
        json j;
        json_begin(&j, stdout, "bifurcation");
        param_base_json(&j, a->mo.name, base);
        param_axes_json(&j, "sweep", &a->sweep, 1);
        json_int(&j, "runs", s->runs);
        json_int(&j, "transient", a->transient);
        json_int(&j, "record", a->record);
        json_int(&j, "seed", a->seed);
        json_int(&j, "followed", valid - lost);
        json_int(&j, "lost", lost);
        json_int(&j, "not_computed", s->n_values * s->runs - valid);
        if (psi_lo <= psi_hi)
            json_nums(&j, "psi_per_period", (const double[2]){psi_lo, psi_hi}, 2);
        json_seconds(&j, "seconds", secs);
        json_end(&j);
        return;
    }
    FILE *out = report_stream(a->out.csv, a->runs_csv, a->out.png);
    fprintf(out, "%d values of %s x %d runs in %.2f s: %d runs followed, %d lost", s->n_values,
           a->sweep.name, s->runs, secs, valid - lost, lost);
    if (psi_lo <= psi_hi)
        fprintf(out, "; Psi per period %.6g..%.6g", psi_lo, psi_hi);
    fprintf(out, "\n");
    if (valid < s->n_values * s->runs)
        fprintf(out, "values where the model cannot be built (S > S0) are not computed\n");
}

/* ---- the command ---- */

static void sweep_free(sweep_results *s, cm_model *models)
{
    for (int i = 0; i < s->n_values && models; i++)
        if (cm_fo_of_model(&models[i]))
            cm_model_release(&models[i]);
    free(models);
    free(s->res);
    free(s->sections);
}

int cmd_bifurcation(int argc, char **argv)
{
    cli c = {"bifurcation", argc, argv, 0, NULL, NULL};
    bif_args a = {.mo = {.name = "friction-oscillator"},
                  .runs = 10,
                  .transient = 1000,
                  .record = 50,
                  .seed = 1,
                  .out = {.width = 900, .height = 1200}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    int werr = chart_outputs_writable(&c, &a.out);
    if (werr == EXIT_OK)
        werr = outfile_check("bifurcation", a.runs_csv, false);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "friction-oscillator", &a.sweep, 1, &base);
    if (verr)
        return verr;
    const int n_values = a.sweep.n;
    const size_t n_runs = (size_t)n_values * (size_t)a.runs;
    sweep_results s = {n_values, a.runs, a.record, calloc(n_runs, sizeof(run_result)),
                       malloc(n_runs * 2 * (size_t)a.record * sizeof(double))};
    cm_model *models = calloc((size_t)n_values, sizeof *models);
    if (!s.res || !s.sections || !models) {
        fprintf(stderr, "cellmap bifurcation: out of memory for %zu runs\n", n_runs);
        sweep_free(&s, models);
        return EXIT_FAIL;
    }
    for (size_t k = 0; k < n_runs * 2 * (size_t)a.record; k++)
        s.sections[k] = NAN;
    int n_valid = 0;
    for (int i = 0; i < n_values; i++) {
        if (!model_at_point(&a.mo, &a.sweep, &i, 1, &models[i]))
            continue;
        n_valid++;
        for (int r = 0; r < a.runs; r++)
            s.res[(size_t)i * (size_t)a.runs + (size_t)r].valid = true;
    }
    const double t0 = cm_seconds();
    progress pr;
    progress_start(&pr, "bifurcation", "runs", n_runs, a.out.quiet);
    interrupt_catch();
    uint64_t done = 0;
#pragma omp parallel for schedule(dynamic, 1)                                                      \
    num_threads(a.threads ? a.threads : omp_get_max_threads())
    for (size_t k = 0; k < n_runs; k++) {
        const int i = (int)(k / (size_t)a.runs), r = (int)(k % (size_t)a.runs);
        if (!s.res[k].valid || interrupt_requested()) /* Ctrl-C: the runs left are skipped */
            continue;
        run(&a, cm_fo_of_model(&models[i]), i, r, &s.res[k], s.sections + k * 2 * (size_t)a.record);
        progress_tick(&pr, &done);
    }
    progress_end(&pr);
    if (interrupt_requested()) {
        sweep_free(&s, models);
        return interrupt_stopped("bifurcation", done, n_runs, "runs");
    }
    if (!a.out.quiet || a.out.json)
        print_summary(&a, &base, &s, cm_seconds() - t0);
    bool ok = n_valid > 0;
    if (!ok)
        fprintf(stderr,
                "cellmap bifurcation: no value of %s admits the model (is S <= S0 "
                "anywhere?)\n",
                a.sweep.name);
    if (ok && a.out.csv)
        ok = write_points_csv(&a, &s);
    if (ok && a.runs_csv)
        ok = write_runs_csv(&a, &s);
    if (ok && a.out.png)
        ok = write_png(&a, &base, &s);
    sweep_free(&s, models);
    return ok ? EXIT_OK : EXIT_FAIL;
}
