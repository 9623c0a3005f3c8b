/* cellmap lyapunov: the largest Lyapunov exponent of the dry friction
 * oscillator over a grid of two parameters (thesis Figs. 2.20-2.21), by
 * the renormalised two-trajectory estimator of MODELS.md 9.8. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/friction_oscillator.h"
#include "models/params.h"
#include "models/registry.h"
#include "src/args.h"
#include "src/basin_png.h"
#include "src/commands.h"
#include "src/outfile.h"

static const char lyapunov_help[] =
    "usage: cellmap lyapunov [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                        --grid X=LO:HI:N,Y=LO:HI:M [--periods P] [--d0 D] [--from X,V]\n"
    "                        [--csv FILE] [--png FILE] [--size WxH] [--threads T]\n\n"
    "The largest Lyapunov exponent of the dry friction oscillator (thesis 2.5.3)\n"
    "at the centres of an N x M grid of parameters X and Y (e.g. Omega and S at\n"
    "fixed S0, as Figs. 2.20-2.21), by the renormalised two-trajectory\n"
    "estimator of MODELS.md 9.8: separation D in x, samples every T/32, P\n"
    "excitation periods. Grid points run in parallel; the results do not\n"
    "depend on the thread count. Points with S > S0 are not computed.\n\n"
    "  --grid X=LO:HI:N,Y=LO:HI:M  the two parameters and their ranges (N, M <= 2000)\n"
    "  --periods P         excitation periods per point (default 600, the thesis')\n"
    "  --d0 D              initial separation, >= 1e-9 (default 1e-8)\n"
    "  --from X,V          start at phase 0 (default the thesis': 1 + 0.9 S0, 0)\n"
    "  --csv FILE          X,Y,lambda per grid point (%.17g; nan: not computed)\n"
    "  --png FILE          heat map; only positive exponents are coloured\n"
    "  --size WxH          image size (default 900x700)\n"
    "  --threads T         OpenMP threads (default: all cores)\n";

typedef struct grid_axis {
    char name[32];
    double lo, hi;
    int n;
} grid_axis;

typedef struct lyap_args {
    model_opts mo;
    grid_axis ax[2];
    int has_grid, periods, threads, width, height, has_from;
    double d0, from[2];
    const char *csv, *png;
} lyap_args;

static double axis_value(const grid_axis *a, int i)
{
    return a->lo + (i + 0.5) * (a->hi - a->lo) / a->n;
}

/* "NAME=LO:HI:N" */
static bool parse_axis(const char *s, size_t len, grid_axis *a)
{
    char buf[128];
    if (len >= sizeof buf)
        return false;
    memcpy(buf, s, len);
    buf[len] = 0;
    char *eq = strchr(buf, '=');
    if (!eq || eq == buf || (size_t)(eq - buf) >= sizeof a->name)
        return false;
    *eq = 0;
    memcpy(a->name, buf, (size_t)(eq - buf) + 1);
    char *end;
    a->lo = strtod(eq + 1, &end);
    if (*end != ':')
        return false;
    a->hi = strtod(end + 1, &end);
    if (*end != ':')
        return false;
    const long n = strtol(end + 1, &end, 10);
    a->n = (int)n;
    return *end == 0 && n >= 1 && n <= 2000 && isfinite(a->lo) && isfinite(a->hi) && a->lo < a->hi;
}

static int parse_args(cli *c, lyap_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(lyapunov_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--grid", true, &err)) {
            const char *comma = c->value ? strchr(c->value, ',') : NULL;
            if (c->value &&
                (!comma || !parse_axis(c->value, (size_t)(comma - c->value), &a->ax[0]) ||
                 !parse_axis(comma + 1, strlen(comma + 1), &a->ax[1])))
                err = cli_usage_error(c,
                                      "--grid: '%s' is not X=LO:HI:N,Y=LO:HI:M with LO < HI and "
                                      "1 <= N, M <= 2000 (e.g. Omega=0.3:0.7:100,S=0.02:0.4:100)",
                                      c->value);
            a->has_grid = 1;
        } else if (cli_take_int(c, "--periods", 1, 1000000, &a->periods, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (cli_is(c, "--d0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->d0) || !(a->d0 >= 1e-9 && a->d0 <= 1e-3)))
                err = cli_usage_error(
                    c, "--d0: '%s' must be a number in 1e-9..1e-3 (MODELS.md 9.8)", c->value);
        } else if (cli_is(c, "--from", true, &err)) {
            int n = 0;
            if (c->value && (!parse_doubles(c->value, a->from, &n, 2) || n != 2))
                err = cli_usage_error(c, "--from: '%s' is not X,V", c->value);
            a->has_from = 1;
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_is(c, "--size", true, &err)) {
            int64_t wh[2];
            int n = 0;
            if (c->value && (!parse_counts(c->value, wh, &n, 2) || n != 2 || wh[0] < 200 ||
                             wh[1] < 150 || wh[0] > 4096 || wh[1] > 4096))
                err = cli_usage_error(c, "--size: '%s' must be WxH within 200x150..4096x4096",
                                      c->value);
            else if (c->value) {
                a->width = (int)wh[0];
                a->height = (int)wh[1];
            }
        } else {
            err = cli_usage_error(c, "unknown option '%s'", c->opt);
        }
    }
    if (!err && !a->has_grid)
        err = cli_usage_error(c, "--grid X=LO:HI:N,Y=LO:HI:M is required");
    if (!err && !a->csv && !a->png)
        err = cli_usage_error(c, "nothing to write: give --csv FILE and/or --png FILE");
    return err;
}

/* The exponent at grid point (i, j); NaN where the model cannot be built
 * (S > S0) or no sample was accepted. */
static double point_exponent(const lyap_args *a, int i, int j, int *invalid)
{
    const char *texts[MAX_PARAM_TEXTS + 1];
    char grid_text[160];
    int n = 0;
    for (int k = 0; k < a->mo.n_texts; k++)
        texts[n++] = a->mo.texts[k];
    snprintf(grid_text, sizeof grid_text, "%s=%.17g,%s=%.17g", a->ax[0].name,
             axis_value(&a->ax[0], i), a->ax[1].name, axis_value(&a->ax[1], j));
    texts[n++] = grid_text;
    cm_model m;
    char msg[256];
    if (cm_model_create(a->mo.name, texts, n, &m, msg, sizeof msg) != CM_OK) {
        *invalid = 1;
        return NAN;
    }
    const cm_fo *o = cm_fo_of_model(&m);
    const double x0 = a->has_from ? a->from[0] : 1 + 0.9 * o->S0, v0 = a->has_from ? a->from[1] : 0;
    double lambda = NAN;
    if (!cm_fo_lyapunov(o, x0, v0, a->d0, a->periods, &lambda))
        lambda = NAN;
    cm_model_release(&m);
    return lambda;
}

static bool write_csv(const lyap_args *a, const double *v)
{
    outfile o;
    if (!outfile_open("lyapunov", a->csv, &o))
        return false;
    fprintf(o.f, "%s,%s,lambda\n", a->ax[0].name, a->ax[1].name);
    for (int j = 0; j < a->ax[1].n; j++)
        for (int i = 0; i < a->ax[0].n; i++)
            fprintf(o.f, "%.17g,%.17g,%.17g\n", axis_value(&a->ax[0], i), axis_value(&a->ax[1], j),
                    v[(size_t)j * (size_t)a->ax[0].n + (size_t)i]);
    return outfile_close("lyapunov", &o, true);
}

static bool write_png(const lyap_args *a, const char *model, const cm_params *p, const double *v)
{
    char title[512], params[400], grid[200];
    cm_params_format(p, params, sizeof params);
    snprintf(grid, sizeof grid, "%s=%.17g:%.17g:%d,%s=%.17g:%.17g:%d", a->ax[0].name, a->ax[0].lo,
             a->ax[0].hi, a->ax[0].n, a->ax[1].name, a->ax[1].lo, a->ax[1].hi, a->ax[1].n);
    snprintf(title, sizeof title, "largest Lyapunov exponent, %s, %d periods", model, a->periods);
    const cm_heat heat = {a->ax[0].n, a->ax[1].n, v, 0, "lambda > 0"};
    const cm_chart chart = {a->width,
                            a->height,
                            {a->ax[0].lo, a->ax[1].lo},
                            {a->ax[0].hi, a->ax[1].hi},
                            a->ax[0].name,
                            a->ax[1].name,
                            title,
                            &heat,
                            NULL,
                            0,
                            figure_font()};
    char periods[32];
    snprintf(periods, sizeof periods, "%d", a->periods);
    const cm_png_text texts[] = {{"Model", model},
                                 {"Parameters", params},
                                 {"Grid", grid},
                                 {"Periods", periods},
                                 {"Estimator", "MODELS.md 9.8 (renormalised two trajectories)"}};
    return write_chart_png("lyapunov", a->png, &chart, texts, 5);
}

int cmd_lyapunov(int argc, char **argv)
{
    cli c = {"lyapunov", argc, argv, 0, NULL, NULL};
    lyap_args a = {.mo = {"friction-oscillator", {0}, 0},
                   .periods = 600,
                   .d0 = 1e-8,
                   .width = 900,
                   .height = 700};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    /* the parameters without the grid's; S0 >= S is checked per point */
    const cm_model_entry *e = cm_model_find(a.mo.name);
    if (!e || strcmp(e->name, "friction-oscillator") != 0)
        return cli_usage_error(&c,
                               "model %s: the Lyapunov estimator is implemented for "
                               "friction-oscillator only",
                               a.mo.name);
    cm_params base;
    char msg[256];
    cm_status st = cm_params_defaults(e->params, &base, msg, sizeof msg);
    for (int k = 0; k < a.mo.n_texts && st == CM_OK; k++)
        st = cm_params_set(&base, a.mo.texts[k], msg, sizeof msg);
    if (st != CM_OK)
        return cli_usage_error(&c, "%s", msg);
    for (int k = 0; k < 2; k++)
        if (cm_params_find(&base, a.ax[k].name) < 0)
            return cli_usage_error(&c, "--grid: '%s' is not a parameter of %s (`cellmap models`)",
                                   a.ax[k].name, e->name);
    const size_t nx = (size_t)a.ax[0].n, n = nx * (size_t)a.ax[1].n;
    double *v = malloc(n * sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap lyapunov: out of memory for %zu grid points\n", n);
        return EXIT_FAIL;
    }
    int invalid = 0;
    const double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 1)                                                      \
    num_threads(a.threads ? a.threads : omp_get_max_threads()) reduction(|                         \
                                                                         : invalid)
    for (size_t k = 0; k < n; k++)
        v[k] = point_exponent(&a, (int)(k % nx), (int)(k / nx), &invalid);
    const double secs = omp_get_wtime() - t0;
    size_t positive = 0, computed = 0, best = 0;
    for (size_t k = 0; k < n; k++) {
        computed += !isnan(v[k]);
        positive += v[k] > 0;
        if (!(v[best] >= v[k]))
            best = k;
    }
    printf("%zu grid points in %.2f s: %zu computed, %zu with lambda > 0", n, secs, computed,
           positive);
    if (!isnan(v[best]))
        printf("; largest %.6g at %s = %.6g, %s = %.6g", v[best], a.ax[0].name,
               axis_value(&a.ax[0], (int)(best % nx)), a.ax[1].name,
               axis_value(&a.ax[1], (int)(best / nx)));
    printf("\n");
    if (invalid)
        printf("points where the model cannot be built (S > S0) are not computed\n");
    bool ok = computed > 0;
    if (!ok)
        fprintf(stderr,
                "cellmap lyapunov: no grid point could be computed (is S <= S0 anywhere?)\n");
    if (ok && a.csv)
        ok = write_csv(&a, v);
    if (ok && a.png)
        ok = write_png(&a, e->name, &base, v);
    free(v);
    return ok ? EXIT_OK : EXIT_FAIL;
}
