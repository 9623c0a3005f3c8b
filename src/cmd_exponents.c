/* cellmap exponents: the Lyapunov spectrum of one orbit of any model (a
 * flow by its variational equations, a map by the QR of its Jacobian),
 * the Kaplan-Yorke dimension, and for a flow's map the exponents per unit
 * of the flow's time (thesis 3.2, Fig. 3.7) over lib/exponents.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/embedding.h"
#include "lib/exponents.h"
#include "lib/parse.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/outfile.h"

static const char exponents_help[] =
    "usage: cellmap exponents [--model NAME] [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                         [--from X[,Y...]] [--of flow|map] [--count K]\n"
    "                         [--time T] [--transient T] [--renorm DT]\n"
    "                         [--iterations N] [--skip N] [--csv FILE|-] [--png FILE]\n"
    "                         [--size WxH] [--json] [--quiet]\n"
    "       cellmap exponents --model chip-bue [--param k=v[,k=v]] [--samples N] [--gs G]\n"
    "                         [--count K] [--time T] [--transient T] [--euler-tangent]\n"
    "                         [--csv FILE|-] [--png FILE] [--json] [--quiet]\n"
    "       cellmap exponents --model chip-bue --sync [--own-delay] [--q-max Q] [--time T]\n"
    "       cellmap exponents --series NAME [--input FILE|-] [--values max|min|all] [--dt DT]\n"
    "         [--dims M[:M2]] [--lag L] [--radius R[,R...]] [--steps K] [--theiler W]\n"
    "         [--fit K0:K1] [--fnn-dim M] [--time-unit S] [model and output options]\n\n"
    "The Lyapunov spectrum of one orbit (Benettin's method: K tangent vectors\n"
    "re-orthonormalised by Gram-Schmidt) and its Kaplan-Yorke dimension.\n"
    "A flow model (chip-4d, the default, duffing, a plugin's flow): by default the\n"
    "flow's spectrum from its variational equations, integrated with the state by\n"
    "the model's method and tolerances (one exponent is zero along the orbit).\n"
    "With --of map, or for a map model: the map's spectrum per iterate (the\n"
    "Jacobian by central differences at every iterate); for a flow's Poincare or\n"
    "stroboscopic map also the mean flight between iterates and the exponents per\n"
    "unit of the flow's time (lambda_map / mean return time, thesis 3.2).\n"
    "The delay model chip-bue (docs/models.md 12.3) by Farmer's method: the equation\n"
    "discretised on N samples per delay into a map of 4 (N + 1) coordinates whose\n"
    "steps are integrated, K exponents of its tangent map re-orthonormalised every G\n"
    "steps (thesis Table 3.2); or with --sync the synchronisation estimate of the\n"
    "largest (3.38)-(3.39): the least coupling q under which a copy started 1e-3\n"
    "away is pulled in by t = transient + time.\n"
    "`cellmap lyapunov` maps the largest exponent over a grid of parameters.\n\n";

static const char series_help[] =
    "With --series, the largest exponent from one series alone, as with TISEAN\n"
    "(thesis 3.3, Figs. 3.12, 3.15): the model's coordinate NAME sampled every dt\n"
    "after the transient, or the column NAME of a CSV file (a column t: the times),\n"
    "by default its maxima; false nearest neighbours per embedding dimension and\n"
    "Kantz's divergence curves S(k), whose slope where they rise is the exponent\n"
    "per value (per unit time, in 1/s given the unit). Check the fit on the figure.\n\n"
    "  --from X,Y,...      the start: the flow's coordinates (--of map: the map's);\n"
    "                      default the centre of the model's example region\n"
    "  --of flow|map       whose spectrum (default: flow for a flow model)\n"
    "  --count K           the K largest exponents (default all)\n"
    "  --time T, --transient T  flows: the time averaged over, and before it (100, 10)\n"
    "  --renorm DT         flows: the time between Gram-Schmidt steps (default 0.1)\n"
    "  --iterations N, --skip N  maps: iterates averaged over, of transient (10000, 100)\n"
    "  --samples N         chip-bue: samples per delay, 1..2000 (default 20)\n"
    "  --gs G              chip-bue: steps between Gram-Schmidt steps (default 10)\n"
    "  --euler-tangent     chip-bue: the thesis' variant, tangents by Euler steps\n"
    "  --sync              chip-bue: the synchronisation estimate instead\n"
    "  --own-delay, --q-max Q  with --sync: the copy reads its own delayed state; q is\n"
    "                      bisected in 0..Q (default 20)\n"
    "  --series NAME       the largest exponent of a series: a coordinate or column\n"
    "  --input FILE|-      the series from this CSV file, not from the model\n"
    "  --values max|min|all  its successive maxima (default), minima, or every value\n"
    "  --dims M[:M2]       the curves' dimensions (default: 3 from the least with < 1 %\n"
    "                      false neighbours); --fnn-dim M: those up to M (14)\n"
    "  --radius R,...      neighbourhoods as fractions of the range (0.005,0.01,0.02)\n"
    "  --lag L, --steps K, --theiler W  delay, curves' length, left out (1, 40, 0)\n"
    "  --fit K0:K1         the steps fitted (default each curve from 1 to half its rise)\n"
    "  --dt DT, --time-unit S  the model's sampling (0.01); seconds per unit of time\n"
    "  --png FILE          the 4 largest's estimates against t (--series: the curves)\n"
    "  --size WxH          its size (default 900x500; --series 900x900)\n"
    "  --csv FILE|-        the running estimates: t (time or iterates), lambda_1..K,\n"
    "                      kaplan_yorke (and flow_time for a flow's map); about\n"
    "                      10000 rows, the last the result (--series: dim,radius,k,S)\n"
    "  --json              the result as JSON on standard output\n"
    "  --quiet             no summary\n";

/* The options of --series. */
static bool take_series(cli *c, embed_args *e, int *err)
{
    if (cli_is(c, "--series", true, err)) {
        e->column = e->sim.of = c->value;
    } else if (cli_is(c, "--input", true, err)) {
        e->input = c->value;
    } else if (cli_is(c, "--values", true, err)) {
        if (c->value && !embedding_values(c->value, &e->extrema))
            *err = cli_usage_error(c, "--values: '%s' is not max, min or all", c->value);
    } else if (cli_is(c, "--dims", true, err) || cli_is(c, "--fit", true, err)) {
        const bool dims = strncmp(c->opt, "--dims", 6) == 0;
        if (c->value && !parse_int_span(c->value, dims ? &e->dim_lo : &e->fit_lo,
                                        dims ? &e->dim_hi : &e->fit_hi))
            *err = cli_usage_error(c, "%s: '%s' is not M or M:M2", dims ? "--dims" : "--fit",
                                   c->value);
    } else if (cli_is(c, "--radius", true, err)) {
        if (c->value && !parse_doubles(c->value, e->radius, &e->n_radius, EMBED_MAX_RADII))
            *err = cli_usage_error(c, "--radius: '%s' is not R[,R...] (at most %d)", c->value,
                                   EMBED_MAX_RADII);
    } else if (!cli_take_double(c, "--dt", 1e-9, 1e9, &e->sim.dt, err) &&
               !cli_take_int(c, "--lag", 1, 100000, &e->lag, err) &&
               !cli_take_int(c, "--steps", 2, 100000, &e->steps, err) &&
               !cli_take_int(c, "--theiler", 0, 100000000, &e->theiler, err) &&
               !cli_take_int(c, "--fnn-dim", 1, CM_EMBED_MAX_DIM, &e->fnn_dim, err) &&
               !cli_take_double(c, "--time-unit", 0, 1e9, &e->time_unit, err)) {
        return false;
    }
    return true;
}

static int parse_args(cli *c, exp_args *a, embed_args *e, bool *json, bool *quiet)
{
    int err = 0, iterations = (int)a->o.iterations, skip = (int)a->o.skip;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(exponents_help, stdout);
            fputs(series_help, stdout);
            return -1;
        } else if (take_series(c, e, &err)) {
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && !parse_doubles(c->value, a->from, &a->n_from, CM_MAX_DIM))
                err = cli_usage_error(c, "--from: '%s' is not X[,Y...] (numbers)", c->value);
        } else if (cli_is(c, "--of", true, &err)) {
            if (c->value && strcmp(c->value, "flow") && strcmp(c->value, "map"))
                err = cli_usage_error(c, "--of: '%s' is neither flow nor map", c->value);
            a->of_map = c->value && strcmp(c->value, "map") == 0;
        } else if (cli_take_int(c, "--count", 1, CM_MAX_DIM, &a->o.count, &err)) {
        } else if (cli_take_double(c, "--time", 1e-9, 1e9, &a->o.time, &err)) {
        } else if (cli_take_double(c, "--transient", 0, 1e9, &a->o.transient, &err)) {
        } else if (cli_take_double(c, "--renorm", 1e-9, 1e9, &a->o.renorm, &err)) {
        } else if (cli_take_int(c, "--iterations", 1, 100000000, &iterations, &err)) {
        } else if (cli_take_int(c, "--skip", 0, 100000000, &skip, &err)) {
        } else if (cli_take_int(c, "--samples", 1, 2000, &a->samples, &err)) {
        } else if (cli_take_int(c, "--gs", 1, 1000000, &a->gs, &err)) {
        } else if (cli_is(c, "--euler-tangent", false, &err)) {
            a->euler_tangent = true;
        } else if (cli_is(c, "--sync", false, &err)) {
            a->sync = true;
        } else if (cli_is(c, "--own-delay", false, &err)) {
            a->own_delay = true;
        } else if (cli_take_double(c, "--q-max", 1e-6, 1e6, &a->q_max, &err)) {
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_take_size(c, 300, 200, 4096, &a->width, &a->height, &err)) {
        } else if (cli_is(c, "--json", false, &err)) {
            *json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            *quiet = true;
        } else {
            err = cli_stray(c);
        }
    }
    a->o.iterations = iterations, a->o.skip = skip;
    if (!err && (e->input || e->fit_hi || e->dim_lo) && !e->column)
        err = cli_usage_error(c, "--input, --dims and --fit go with --series NAME");
    if (!err && a->o.renorm > a->o.time)
        err = cli_usage_error(c, "--renorm %g is longer than --time %g", a->o.renorm, a->o.time);
    if (!err && a->o.time / a->o.renorm > 1e8)
        err = cli_usage_error(c,
                              "--time / --renorm is over 1e8 renormalisations: renorm less often");
    if (!err && *json && (cm_output_names_stdout(a->csv) || cm_output_names_stdout(a->png)))
        err = cli_usage_error(c, "--json and an output to standard output: choose one");
    if (!err && a->own_delay && !a->sync)
        err = cli_usage_error(c, "--own-delay goes with --sync");
    return err;
}

/* --series: the exponent of one series over lib/embedding.h. */
static int series_exponent(const cli *c, const exp_args *a, embed_args *e, bool json, bool quiet)
{
    embedding_take_run(e, a);
    char msg[1024];
    embed_result r;
    cm_status st = embedding_compute(e, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (json)
            embedding_json(stdout, e, &r);
        else if (!quiet)
            embedding_report(report_stream(e->csv, e->png, NULL), e, &r);
        st = embedding_write(e, &r, msg, sizeof msg);
    }
    embedding_result_free(&r);
    return analysis_said(c->cmd, st, msg);
}

int cmd_exponents(int argc, char **argv)
{
    cli c = {"exponents", argc, argv, 0, NULL, NULL};
    exp_args a = exponents_defaults();
    embed_args e = embedding_defaults();
    bool json = false, quiet = false;
    const int perr = parse_args(&c, &a, &e, &json, &quiet);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    int werr = outfile_check("exponents", a.csv, false);
    if (werr == EXIT_OK)
        werr = chart_png_check("exponents", a.png);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    if (e.column)
        return series_exponent(&c, &a, &e, json, quiet);
    exp_result r;
    cm_status st = exponents_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (json)
            exponents_json(stdout, &r);
        else if (!quiet)
            exponents_report(report_stream(a.csv, a.png, NULL), &r);
        st = exponents_write(&a, &r, msg, sizeof msg);
    }
    exponents_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
