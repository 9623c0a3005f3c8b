/* cellmap lyapunov: the largest Lyapunov exponent over a grid of two
 * parameters: the dry friction oscillator's (thesis Figs. 2.20-2.21) by the
 * renormalised two-trajectory estimator of docs/models.md 9.8, any other
 * model's by finite differences on its map (docs/models.md 11.3). */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/work.h"
#include "lib/lyapunov.h"
#include "lib/lyapunov_method.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "src/interrupt.h"
#include "src/outfile.h"
#include "lib/param_grid.h"
#include "src/progress.h"

static const char lyapunov_help[] =
    "usage: cellmap lyapunov [--model NAME] [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                        --grid X=LO:HI:N,Y=LO:HI:M [--periods P] [--d0 D] [--from X[,Y...]]\n"
    "                        [--csv FILE|-] [--png FILE] [--json] [--quiet] [--size WxH]\n"
    "                        [--threads T]\n"
    "       cellmap lyapunov --method sync --q LO:HI:N | --method stickmap [--every K]\n"
    "                        [--runs N] [--escape E]; --param, --periods and the outputs\n\n"
    "The largest Lyapunov exponent at the centres of an N x M grid of parameters\n"
    "X and Y. For the dry friction oscillator (the default model; thesis 2.5.3,\n"
    "e.g. Omega and S at fixed S0 as Figs. 2.20-2.21) by the renormalised\n"
    "two-trajectory estimator of docs/models.md 9.8: separation D in x, samples\n"
    "every T/32, P excitation periods; points with S > S0 are not computed. For\n"
    "any other model (ODE flows such as duffing, maps, plugins) by finite\n"
    "differences on its map (docs/models.md 11.3): a second orbit D away,\n"
    "renormalised after every iterate, P iterates after P/10 of transient; the\n"
    "exponent is per unit of the flow's time for a flow, per iterate for a map.\n"
    "Grid points run in parallel; the results do not depend on the thread count.\n\n"
    "  --grid X=LO:HI:N,Y=LO:HI:M  the two parameters and their ranges (N, M <= 2000);\n"
    "                      evenly spaced lists X=V1,V2,...,Y=V1,V2,... also do\n"
    "  --periods P         excitation periods (friction-oscillator) or iterates of the\n"
    "                      map per point (default 600, the thesis')\n"
    "  --d0 D              initial separation, >= 1e-9 (default 1e-8)\n"
    "  --from X[,Y...]     the start (default: friction-oscillator 1 + 0.9 S0, 0 at\n"
    "                      phase 0, as the thesis; other models the centre of their\n"
    "                      default region)\n"
    "  --csv FILE|-        X,Y,lambda per grid point (%.17g; nan: not computed)\n"
    "  --json              the summary as JSON on standard output (docs/cellmap.schema.json)\n"
    "  --quiet             no progress line and no summary\n"
    "  --png FILE          heat map; only positive exponents are coloured\n"
    "  --curves FILE       draw the curves of `cellmap continue --curves` (bifurcation\n"
    "                      curves in the grid's two parameters) over the heat map;\n"
    "                      repeat it (up to 8) for the curves of several runs\n"
    "  --size WxH          image size (default 900x700)\n"
    "  --threads T         OpenMP threads (default: all cores)\n\n"
    "--method sync: the exponent bounded by synchronisation (thesis 2.6.1, Fig. 2.23): a\n"
    "copy 1e-6 away coupled one way with strength q at the N couplings of LO:HI; the\n"
    "smallest q from which every larger one pulls it on (--periods 2000, the last 100\n"
    "watched). --method stickmap: the map of every K-th (3) stick from N (200) random\n"
    "starts over --periods (1500), and its chaotic transient's exponent until an orbit\n"
    "comes within E (0.01) of a fixed point (2.6.2, Fig. 2.26). docs/models.md 9.8.\n";

static int parse_args(cli *c, lyap_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(lyapunov_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--grid", true, &err)) {
            if (c->value && !param_axes_parse2(c->value, a->ax))
                err = cli_usage_error(c,
                                      "--grid: '%s' is not X=LO:HI:N,Y=LO:HI:M with LO < HI and "
                                      "1 <= N, M <= 2000 (e.g. Omega=0.3:0.7:100,S=0.02:0.4:100), "
                                      "nor lists X=V1,V2,...,Y=V1,V2,...",
                                      c->value);
            for (int k = 0; k < 2 && c->value && !err; k++)
                if (!param_axis_even(&a->ax[k]))
                    err = cli_usage_error(c,
                                          "--grid: the values of %s are not evenly spaced, and "
                                          "the heat map's cells would not sit on them; give "
                                          "%s=LO:HI:N",
                                          a->ax[k].name, a->ax[k].name);
            a->has_grid = 1;
        } else if (cli_is(c, "--method", true, &err)) {
            if (c->value && (a->method = lyapunov_method_of(c->value)) < 0)
                err = cli_usage_error(c, "--method: '%s' must be direct, sync or stickmap",
                                      c->value);
        } else if (cli_take_int(c, "--every", 1, 64, &a->every, &err) ||
                   cli_take_int(c, "--runs", 1, 10000, &a->runs, &err) ||
                   cli_take_double(c, "--escape", 1e-9, 1, &a->escape, &err)) {
        } else if (cli_is(c, "--q", true, &err)) {
            char text[128];
            snprintf(text, sizeof text, "q=%s", c->value ? c->value : "");
            if (c->value && (!param_axis_parse(text, strlen(text), &a->q) || a->q.listed))
                err = cli_usage_error(c, "--q: '%s' is not LO:HI:N (0 <= LO < HI, N <= 2000)",
                                      c->value);
        } else if (cli_take_int(c, "--periods", 1, 1000000, &a->periods, &err)) {
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (cli_is(c, "--d0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->d0) || !(a->d0 >= 1e-9 && a->d0 <= 1e-3)))
                err = cli_usage_error(
                    c, "--d0: '%s' must be a number in 1e-9..1e-3 (docs/models.md 9.8)", c->value);
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && !parse_doubles(c->value, a->from, &a->n_from, CM_MAX_DIM))
                err = cli_usage_error(c, "--from: '%s' is not X[,Y...] (numbers)", c->value);
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_is(c, "--curves", true, &err)) {
            if (c->value && a->n_curves == MAX_CURVE_FILES)
                err = cli_usage_error(c, "--curves: at most %d files", MAX_CURVE_FILES);
            else if (c->value)
                a->curves[a->n_curves++] = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else if (cli_take_size(c, 200, 150, 4096, &a->width, &a->height, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->method == LYAP_STICKMAP && (a->q.n || a->has_grid || a->n_curves))
        err = cli_usage_error(c, "--method stickmap takes no --grid, --q or --curves");
    if (!err && a->method == LYAP_SYNC && (!a->q.n || a->has_grid || a->n_curves || a->q.lo < 0))
        err = cli_usage_error(c, "--method sync takes --q LO:HI:N (0 <= LO) instead of --grid "
                                 "and --curves");
    if (!err && a->method == LYAP_DIRECT && (!a->has_grid || a->q.n))
        err = cli_usage_error(c, "--grid X=LO:HI:N,Y=LO:HI:M is required (--q goes with "
                                 "--method sync)");
    if (!err && a->n_curves && !a->png)
        err = cli_usage_error(c, "--curves draws over the heat map: give --png FILE too");
    if (!err && !a->csv && !a->png && !a->json)
        err = cli_usage_error(c, "nothing to write: give --csv FILE, --png FILE and/or --json");
    if (!err && a->json && (cm_output_names_stdout(a->csv) || cm_output_names_stdout(a->png)))
        err = cli_usage_error(c, "--json and an output to standard output: choose one");
    return err;
}

static void print_text(const lyap_args *a, const lyap_result *s)
{
    FILE *out = report_stream(a->csv, a->png, NULL);
    const size_t nx = (size_t)a->ax[0].n;
    fprintf(out, "%zu grid points in %.2f s: %zu computed, %zu with lambda > 0", s->points,
            s->seconds, s->computed, s->positive);
    if (!isnan(s->v[s->best]))
        fprintf(out, "; largest %.6g at %s = %s, %s = %s", s->v[s->best], a->ax[0].name,
                CM_NUM(param_axis_value(&a->ax[0], (int)(s->best % nx))), a->ax[1].name,
                CM_NUM(param_axis_value(&a->ax[1], (int)(s->best / nx))));
    fprintf(out, "\n");
    if (s->invalid)
        fprintf(out, "points where the model cannot be built (S > S0) are not computed\n");
}

static void print_json(const lyap_args *a, const lyap_result *s)
{
    const size_t nx = (size_t)a->ax[0].n;
    json j;
    json_begin(&j, stdout, "lyapunov");
    param_base_json(&j, a->mo.name, &s->base);
    param_axes_json(&j, "grid", a->ax, 2);
    json_int(&j, "periods", a->periods);
    json_uint(&j, "points", s->points);
    json_uint(&j, "computed", s->computed);
    json_uint(&j, "positive", s->positive);
    if (!isnan(s->v[s->best])) {
        json_object(&j, "largest");
        json_num(&j, "lambda", s->v[s->best]);
        json_num(&j, a->ax[0].name, param_axis_value(&a->ax[0], (int)(s->best % nx)));
        json_num(&j, a->ax[1].name, param_axis_value(&a->ax[1], (int)(s->best / nx)));
        json_object_end(&j);
    }
    json_seconds(&j, "seconds", s->seconds);
    json_end(&j);
}

/* --method sync or stickmap: the estimate computed, said and written. */
static int run_method(const cli *c, lyap_args *a)
{
    const bool sync = a->method == LYAP_SYNC;
    if (a->periods == lyapunov_defaults().periods)
        a->periods = sync ? 2000 : 1500;
    const uint64_t units = sync ? (uint64_t)a->q.n : (uint64_t)a->runs;
    const char *unit = sync ? "couplings" : "runs";
    progress pr;
    progress_start(&pr, "lyapunov", unit, units, a->quiet);
    const work_hooks hooks = progress_hooks(&pr);
    interrupt_catch();
    char msg[1024];
    lyap_method_result r;
    cm_status st = lyapunov_method_compute(a, &hooks, &r, msg, sizeof msg);
    progress_end(&pr);
    if (st == CM_OK && (a->json || !a->quiet))
        lyapunov_method_report(a->json ? stdout : report_stream(a->csv, a->png, NULL), a, &r);
    if (st == CM_OK)
        st = lyapunov_method_write(a, &r, msg, sizeof msg);
    lyapunov_method_free(&r);
    return st == CM_ECANCELED ? interrupt_stopped("lyapunov", r.done, units, unit)
                              : analysis_said(c->cmd, st, msg);
}

int cmd_lyapunov(int argc, char **argv)
{
    cli c = {"lyapunov", argc, argv, 0, NULL, NULL};
    lyap_args a = lyapunov_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    int werr = outfile_check("lyapunov", a.csv, false);
    if (werr == EXIT_OK)
        werr = chart_png_check("lyapunov", a.png);
    if (werr != EXIT_OK)
        return werr;
    if (a.method != LYAP_DIRECT)
        return run_method(&c, &a);
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, NULL, a.ax, 2, &base);
    if (verr)
        return verr;
    const uint64_t n = (uint64_t)a.ax[0].n * (uint64_t)a.ax[1].n;
    progress pr;
    progress_start(&pr, "lyapunov", "grid points", n, a.quiet);
    const work_hooks hooks = progress_hooks(&pr);
    interrupt_catch();
    char msg[1024];
    lyap_result r;
    cm_status st = lyapunov_compute(&a, &hooks, &r, msg, sizeof msg);
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        lyapunov_result_free(&r);
        return interrupt_stopped("lyapunov", r.done, n, "grid points");
    }
    if (st == CM_OK) {
        if (a.json)
            print_json(&a, &r);
        else if (!a.quiet)
            print_text(&a, &r);
        st = lyapunov_write(&a, &r, msg, sizeof msg);
    }
    lyapunov_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
