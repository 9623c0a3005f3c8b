/* cellmap escape: the transient chaos of the 1-D micro-chaos map with
 * Coulomb friction (thesis 4.3, Figs. 4.5, 4.7): its repeller, the bounds
 * on the escape rate and the mean escape number from the repeller's fractal
 * dimension, the exact mean escape number, an ensemble's and cell
 * mapping's, at one parameter point or along a sweep. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/escape.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char escape_help[] =
    "usage: cellmap escape [--model microchaos-1d-friction] [--param k=v[,k=v]] [--I0 W]\n"
    "                      [--sweep NAME=LO:HI:N] [--cells N] [--ensemble M] [--csv FILE|-]\n"
    "                      [--png FILE] [--size WxH] [--json] [--quiet] [--threads T]\n\n"
    "The transient chaos of the 1-D micro-chaos map with Coulomb friction (4.23)\n"
    "(thesis 4.3, docs/models.md 4.1), where it has one positive fixed point x0* in\n"
    "its repeller's interval I_rep = [x0*, a - c]. A point escapes when an iterate\n"
    "falls below x0*; its escape number is the steps that takes. The mean escape\n"
    "number over I_rep, four ways:\n"
    "  - bounds from the fractal dimension D0 of the repeller (4.28)-(4.32), the\n"
    "    escape rate kappa = (1 - D0) ln a (4.33) and N = 1/(1 - exp(-kappa)) (4.3);\n"
    "    in the border state (|F| <= 0, a <= a_crit) D0 = 0 and N = a/(a - 1) (4.35)\n"
    "  - exactly, on the Markov partition of I_rep cut by the orbit of a - c\n"
    "  - an ensemble of M points at random: its mean, and kappa from the decay of\n"
    "    the survivors\n"
    "  - cell mapping of I_rep in N cells: the mean step number of the cells that\n"
    "    leave it (the sink)\n\n"
    "  --I0 W              set c from |I0| = W (4.27), the thesis' parameter\n"
    "  --sweep NAME=LO:HI:N  a, b or I0 at the centres of N cells of LO:HI (Fig. 4.7:\n"
    "                      --param b=1.3 --I0 0.25 --sweep a=1.2:2.25:64); points\n"
    "                      outside the case of 4.3 are left out of the diagram\n"
    "  --cells N           cells of the cell mapping (default 100000; 0: none)\n"
    "  --ensemble M        points of the ensemble (default 1000000; 0: none)\n"
    "  --csv FILE|-        one line per point: the parameters, x0*, |I_rep|, |F|,\n"
    "                      a_crit, D0, kappa and N from C1 and from C2, the exact mean,\n"
    "                      the partition's intervals, the ensemble's kappa and mean,\n"
    "                      the cell mapping's mean and its cells that never leave\n"
    "  --png FILE          one point: the escape numbers over [0, 1.05 (a - c)] and\n"
    "                      I0, I_rep (Fig. 4.5); a sweep: the mean escape number\n"
    "                      against the swept parameter (Fig. 4.7): by (4.3) from the\n"
    "                      escape rates of the two dimensions and of the ensemble,\n"
    "                      exact, and by cell mapping\n"
    "  --size WxH          image size (default 1000x600)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n"
    "  --threads T         OpenMP threads over the sweep's points (default: all cores)\n";

static int parse_args(cli *c, esc_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(escape_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--I0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->I0) || !(a->I0 > 0 && a->I0 < 1e6)))
                err = cli_usage_error(c, "--I0: '%s' must be a number in (0, 1e6)", c->value);
            a->has_I0 = 1;
        } else if (cli_is(c, "--sweep", true, &err)) {
            if (c->value && (!param_axis_parse(c->value, strlen(c->value), &a->sweep) ||
                             a->sweep.n > 10000 || !param_axis_even(&a->sweep) ||
                             (strcmp(a->sweep.name, "a") != 0 && strcmp(a->sweep.name, "b") != 0 &&
                              strcmp(a->sweep.name, "I0") != 0)))
                err = cli_usage_error(c,
                                      "--sweep: '%s' is not NAME=LO:HI:N with NAME a, b or I0, "
                                      "LO < HI and 1 <= N <= 10000 (e.g. a=1.2:2.25:64)",
                                      c->value);
            a->has_sweep = 1;
        } else if (cli_is(c, "--cells", true, &err)) {
            int64_t v;
            if (c->value && (!parse_int64(c->value, &v) || v < 0 || v > 100000000))
                err = cli_usage_error(c, "--cells: '%s' must be 0..100000000", c->value);
            else if (c->value)
                a->cells = (long)v;
        } else if (cli_is(c, "--ensemble", true, &err)) {
            int64_t v;
            if (c->value && (!parse_int64(c->value, &v) || v < 0 || v > 1000000000))
                err = cli_usage_error(c, "--ensemble: '%s' must be 0..1000000000", c->value);
            else if (c->value)
                a->ensemble = (long)v;
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->has_sweep && strcmp(a->sweep.name, "I0") == 0 && a->has_I0)
        err = cli_usage_error(c, "--sweep I0=... and --I0: choose one");
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

static void json_point(json *j, const esc_point *p)
{
    const cm_te *t = &p->t;
    json_object(j, NULL);
    json_num(j, "a", t->a);
    json_num(j, "b", t->b);
    json_num(j, "c", t->c);
    json_bool(j, "valid", p->valid);
    if (!p->valid) {
        json_str(j, "why", p->why);
    } else {
        json_num(j, "I0", t->I0);
        json_nums(j, "I_rep", (const double[2]){t->x0, t->rep_hi}, 2);
        json_num(j, "F", t->F);
        json_num(j, "a_crit", t->a_crit);
        json_bool(j, "border", t->border);
        json_nums(j, "D0", t->D0, 2);
        json_nums(j, "kappa", t->kappa, 2);
        json_nums(j, "n_esc", t->n_esc, 2);
        json_num(j, "exact_mean", p->exact);
        json_int(j, "partition", (int)p->partition);
        json_num(j, "ensemble_kappa", p->ens.kappa);
        json_num(j, "ensemble_mean", p->ens.mean);
        json_num(j, "scm_mean", p->scm_mean);
        json_int(j, "scm_stay", (int)p->scm_stay);
    }
    json_object_end(j);
}

static void print_point(FILE *f, const esc_args *a, const esc_point *p)
{
    const cm_te *t = &p->t;
    fprintf(f, "a = %s, b = %s, c = %s (|I0| = %s): ", CM_NUM(t->a), CM_NUM(t->b), CM_NUM(t->c),
            CM_NUM(t->I0));
    if (!p->valid) {
        fprintf(f, "%s\n", p->why);
        return;
    }
    fprintf(f, "I_rep = [%.6g, %.6g], |F| = %.6g (4.28), a_crit = %.6g (4.34)\n", t->x0, t->rep_hi,
            t->F, t->a_crit);
    if (t->border)
        fprintf(f, "  border state: D0 = 0, kappa = ln a = %.6g, N = a/(a - 1) = %.9g (4.35)\n",
                t->kappa[0], t->n_esc[0]);
    else
        fprintf(f, "  D0 %.6g .. %.6g (4.32), kappa %.6g .. %.6g (4.33), N %.6g .. %.6g (4.3)\n",
                t->D0[1], t->D0[0], t->kappa[0], t->kappa[1], t->n_esc[1], t->n_esc[0]);
    if (isnan(p->exact))
        fprintf(f, "  exact mean escape number: the orbit of a - c stays in I_rep\n");
    else
        fprintf(f, "  exact mean escape number %.9g (Markov partition of %ld intervals)\n",
                p->exact, p->partition);
    if (a->ensemble > 0)
        fprintf(f, "  ensemble of %ld: mean %.6g, kappa %.6g (steps %d..%d)\n", p->ens.points,
                p->ens.mean, p->ens.kappa, p->ens.fit_from, p->ens.fit_to);
    if (a->cells > 0)
        fprintf(f, "  cell mapping on %ld cells: mean step number %.6g (%ld cells never leave)\n",
                a->cells, p->scm_mean, p->scm_stay);
}

int cmd_escape(int argc, char **argv)
{
    cli c = {"escape", argc, argv, 0, NULL, NULL};
    esc_args a = escape_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    param_axis none = {0};
    const bool sweeps_param = a.has_sweep && strcmp(a.sweep.name, "I0") != 0;
    const int verr = sweep_check(&c, &a.mo, "microchaos-1d-friction", sweeps_param ? &a.sweep : &none,
                                 sweeps_param ? 1 : 0, &base);
    if (verr)
        return verr;
    char msg[1024];
    esc_result r;
    cm_status st = escape_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json) {
            json j;
            json_begin(&j, stdout, "escape");
            param_base_json(&j, a.mo.name, &r.base);
            if (a.has_I0) /* c at each point from it */
                json_num(&j, "I0", a.I0);
            if (a.has_sweep)
                param_axes_json(&j, "sweep", &a.sweep, 1);
            json_int(&j, "cells", (int)a.cells);
            json_int(&j, "ensemble", (int)a.ensemble);
            json_array(&j, "points");
            for (int i = 0; i < r.n; i++)
                json_point(&j, &r.pts[i]);
            json_array_end(&j);
            json_end(&j);
        } else if (!a.out.quiet) {
            FILE *f = report_stream(a.out.csv, a.out.png, NULL);
            if (a.has_sweep)
                fprintf(f, "%d points, %d in the case of 4.3 (one positive fixed point in I_rep)\n",
                        r.n, r.valid);
            else
                print_point(f, &a, &r.pts[0]);
        }
        st = escape_write(&a, &r, msg, sizeof msg);
    }
    escape_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
