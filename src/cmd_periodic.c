/* cellmap periodic: periodic orbits of any map model (a flow's section
 * map included), their branches in a parameter and period-doubling
 * cascades (thesis 3.2, Table 3.1) over lib/periodic.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/periodic.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/outfile.h"

static const char periodic_help[] =
    "usage: cellmap periodic [--model NAME] [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                        --from X[,Y...] [--settle N] [--period K]\n"
    "                        [--branch P=LO:HI [--direction up|down] [--ds-max D]\n"
    "                        [--max-points N] [--cascade N]] [--csv FILE|-] [--json] [--quiet]\n"
    "       cellmap periodic [--model FLOW] --hopf --from X,Y,... --branch P=LO:HI\n"
    "                        [--direction up|down] [--ds-max D] [--max-points N]\n\n"
    "Periodic orbits of a model's map (chip-4d, the default, or any other; a flow's\n"
    "Poincare or stroboscopic map included): a point of period K by Newton's method on\n"
    "P^K(x) - x from --from (after N iterates of the map with --settle, to start\n"
    "from where a simulated orbit settles), and its multipliers (the eigenvalues of\n"
    "DP^K by central differences; stable when all lie inside the unit circle).\n"
    "For a flow the integrator's tolerances become 1e-12 unless --param sets them.\n"
    "With --branch the orbit is followed in parameter P over LO:HI by\n"
    "pseudo-arclength continuation and its folds (a multiplier through +1), period\n"
    "doublings (through -1) and Neimark-Sacker points (a pair through the circle)\n"
    "are located. With --cascade N (and a direction) the branch is followed to its\n"
    "first period doubling, the branch of twice the period is started there, and so\n"
    "on N times; the doublings, the Feigenbaum ratios of their spacings and the\n"
    "accumulation point they give are printed (docs/models.md 12.1: chip-4d's\n"
    "cascades at zeta = 21, PD1 from 3.11285 and PD2 from 10.6639).\n\n"
    "  --from X,Y,...      the start, in the map's coordinates\n"
    "  --settle N          iterate the map N times first (0..1e7, default 0)\n"
    "  --period K          the period, 1..4096 (default 1)\n"
    "  --branch P=LO:HI    follow the orbit in P over LO:HI\n"
    "  --direction up|down only towards HI or LO (default: both; a cascade needs one)\n"
    "  --ds-max D          the longest arclength step (default (HI - LO)/50)\n"
    "  --max-points N      points each way, 10..1000000 (default 10000)\n"
    "  --cascade N         follow N period doublings, 1..12\n"
    "  --hopf              start from the first Hopf point of the flow's equilibrium\n"
    "                      near --from (the flow's coordinates) on its branch in P\n"
    "                      (--direction's way, default up): the orbit born there, on\n"
    "                      the section plane through the equilibrium (level set so),\n"
    "                      followed over LO:HI\n"
    "  --csv FILE|-        rows kind (point, fold, pd, ns), period, P, the state,\n"
    "                      re_k,im_k of the multipliers by decreasing modulus,\n"
    "                      outside (how many lie outside the unit circle)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

/* 0: go on; -1: --help was printed; else the usage error. */
static int parse_args(cli *c, po_args *a, bool *json, bool *quiet)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(periodic_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (branch_opts_take(c, &a->b, &err)) {
        } else if (cli_take_int(c, "--settle", 0, 10000000, &a->settle, &err)) {
        } else if (cli_take_int(c, "--period", 1, 4096, &a->period, &err)) {
        } else if (cli_take_int(c, "--cascade", 1, PERIODIC_MAX_CASCADE, &a->cascade, &err)) {
        } else if (cli_is(c, "--hopf", false, &err)) {
            a->hopf = true;
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            *json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            *quiet = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = branch_opts_check(c, &a->b, a->cascade != 0, "--cascade");
    if (!err && a->hopf && !a->b.name[0])
        err = cli_usage_error(c, "--hopf needs --branch P=LO:HI: where to look for the Hopf point");
    if (!err && a->cascade && !a->b.direction)
        err = cli_usage_error(c, "--cascade needs --direction up or down: the way it goes");
    return err;
}

int cmd_periodic(int argc, char **argv)
{
    cli c = {"periodic", argc, argv, 0, NULL, NULL};
    po_args a = periodic_defaults();
    bool json = false, quiet = false;
    const int perr = parse_args(&c, &a, &json, &quiet);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    if (json && a.csv && strcmp(a.csv, "-") == 0)
        return cli_usage_error(&c, "--json and --csv -: both want standard output");
    const int werr = outfile_check("periodic", a.csv, false);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    po_result r;
    cm_status st = periodic_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (json)
            periodic_json(stdout, &a, &r);
        else if (!quiet)
            periodic_report(report_stream(a.csv, NULL, NULL), &a, &r);
        st = periodic_write(&a, &r, msg, sizeof msg);
    }
    periodic_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
