/* cellmap exponents: the Lyapunov spectrum of one orbit of any model (a
 * flow by its variational equations, a map by the QR of its Jacobian),
 * the Kaplan-Yorke dimension, and for a flow's map the exponents per unit
 * of the flow's time (thesis 3.2, Fig. 3.7) over lib/exponents.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    "       cellmap exponents --model chip-bue --sync [--own-delay] [--q-max Q] [--time T]\n\n"
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
    "`cellmap lyapunov` maps the largest exponent over a grid of parameters.\n\n"
    "  --from X,Y,...      the start: the flow's coordinates (--of map: the map's);\n"
    "                      default the centre of the model's example region\n"
    "  --of flow|map       whose spectrum (default: flow for a flow model)\n"
    "  --count K           the K largest exponents (default all)\n"
    "  --time T            flows: the time averaged over (default 100)\n"
    "  --transient T       flows: the time before averaging starts (default 10)\n"
    "  --renorm DT         flows: the time between Gram-Schmidt steps (default 0.1)\n"
    "  --iterations N      maps: the iterates averaged over (default 10000)\n"
    "  --skip N            maps: the iterates of transient (default 100)\n"
    "  --samples N         chip-bue: samples per delay, 1..2000 (default 20)\n"
    "  --gs G              chip-bue: steps between Gram-Schmidt steps (default 10)\n"
    "  --euler-tangent     chip-bue: the thesis' variant, tangents by Euler steps\n"
    "  --sync              chip-bue: the synchronisation estimate instead\n"
    "  --own-delay         with --sync: the copy reads its own delayed state\n"
    "  --q-max Q           with --sync: q is bisected in 0..Q (default 20)\n"
    "  --png FILE          the running estimates of the 4 largest against t\n"
    "  --size WxH          its size (default 900x500)\n"
    "  --csv FILE|-        the running estimates: t (time or iterates), lambda_1..K,\n"
    "                      kaplan_yorke (and flow_time for a flow's map); about\n"
    "                      10000 rows, the last the result\n"
    "  --json              the result as JSON on standard output\n"
    "  --quiet             no summary\n";

static int parse_args(cli *c, exp_args *a, bool *json, bool *quiet)
{
    int err = 0, iterations = (int)a->o.iterations, skip = (int)a->o.skip;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(exponents_help, stdout);
            return -1;
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

int cmd_exponents(int argc, char **argv)
{
    cli c = {"exponents", argc, argv, 0, NULL, NULL};
    exp_args a = exponents_defaults();
    bool json = false, quiet = false;
    const int perr = parse_args(&c, &a, &json, &quiet);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    int werr = outfile_check("exponents", a.csv, false);
    if (werr == EXIT_OK)
        werr = chart_png_check("exponents", a.png);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
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
