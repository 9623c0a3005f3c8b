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

#include "lib/work.h"
#include "lib/bifurcation.h"
#include "lib/map_bifurcation.h"
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
    "  --threads T         OpenMP threads (default: all cores)\n\n"
    "Any other model (a map, or a flow's section or stroboscopic map: chip-4d,\n"
    "Fig. 3.5): R runs a value from random starts in the model's example region,\n"
    "P iterates of transient and n recorded (--transient, --record count iterates),\n"
    "one coordinate of each recorded iterate kept.\n"
    "  --of NAME           the coordinate recorded (default the map's first)\n"
    "  --branches FILE     a table of `cellmap equilibria` or `cellmap periodic` --csv\n"
    "                      over the same parameter, drawn over the points (stable\n"
    "                      black, unstable red); repeat it for more (up to 8)\n"
    "  --csv FILE          NAME,run,COORD per recorded iterate\n";

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
        } else if (cli_is(c, "--of", true, &err)) {
            a->of = c->value;
        } else if (cli_is(c, "--branches", true, &err)) {
            if (c->value && a->n_branches == 8)
                err = cli_usage_error(c, "--branches: at most 8 tables");
            else if (c->value)
                a->branches[a->n_branches++] = c->value;
        } else if (chart_outputs_take(c, &a->out, 300, 450, &err)) {
            a->has_size |= strcmp(c->opt, "--size") == 0;
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

/* ---- output ---- */

static void print_summary(const bif_args *a, const cm_params *base, const sweep_results *s,
                          double secs)
{
    int valid = 0, lost = 0;
    double psi_lo = INFINITY, psi_hi = -INFINITY;
    for (int i = 0; i < s->n_values; i++)
        for (int r = 0; r < s->runs; r++) {
            const run_result *res = bifurcation_result_at(s, i, r);
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

/* A map model's diagram (lib/map_bifurcation.h). */
static int run_map(cli *c, bif_args *a)
{
    if (a->runs_csv)
        return cli_usage_error(c, "--runs-csv is friction-oscillator's: a map's runs are in --csv");
    const int werr = chart_outputs_writable(c, &a->out);
    if (werr != EXIT_OK)
        return werr;
    const uint64_t n_runs = (uint64_t)a->sweep.n * (uint64_t)a->runs;
    progress pr;
    progress_start(&pr, "bifurcation", "runs", n_runs, a->out.quiet);
    const work_hooks hooks = progress_hooks(&pr);
    interrupt_catch();
    char msg[1024];
    map_bif_result r;
    cm_status st = map_bifurcation_compute(a, &hooks, &r, msg, sizeof msg);
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        map_bifurcation_free(&r);
        return interrupt_stopped("bifurcation", r.done, n_runs, "runs");
    }
    if (st == CM_OK) {
        if (!a->out.quiet || a->out.json)
            map_bifurcation_report(
                a->out.json ? stdout : report_stream(a->out.csv, a->out.png, NULL), a, &r);
        st = map_bifurcation_write(a, &r, msg, sizeof msg);
    }
    map_bifurcation_free(&r);
    return analysis_said(c->cmd, st, msg);
}

int cmd_bifurcation(int argc, char **argv)
{
    cli c = {"bifurcation", argc, argv, 0, NULL, NULL};
    bif_args a = bifurcation_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    if (map_bifurcation_model(&a.mo)) {
        if (!a.has_size) /* one panel, not friction-oscillator's three */
            a.out.width = 900, a.out.height = 600;
        return run_map(&c, &a);
    }
    if (a.of || a.n_branches)
        return cli_usage_error(&c, "--of and --branches are for map models (chip-4d, ...)");
    int werr = chart_outputs_writable(&c, &a.out);
    if (werr == EXIT_OK)
        werr = outfile_check("bifurcation", a.runs_csv, false);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "friction-oscillator", &a.sweep, 1, &base);
    if (verr)
        return verr;
    const uint64_t n_runs = (uint64_t)a.sweep.n * (uint64_t)a.runs;
    progress pr;
    progress_start(&pr, "bifurcation", "runs", n_runs, a.out.quiet);
    const work_hooks hooks = progress_hooks(&pr);
    interrupt_catch();
    char msg[1024];
    bif_result r;
    cm_status st = bifurcation_compute(&a, &hooks, &r, msg, sizeof msg);
    progress_end(&pr);
    if (st == CM_ECANCELED) {
        bifurcation_result_free(&r);
        return interrupt_stopped("bifurcation", r.done, n_runs, "runs");
    }
    if (st == CM_OK) {
        if (!a.out.quiet || a.out.json)
            print_summary(&a, &r.base, &r.s, r.seconds);
        st = bifurcation_write(&a, &r, msg, sizeof msg);
    }
    bifurcation_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
