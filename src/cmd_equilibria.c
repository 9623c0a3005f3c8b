/* cellmap equilibria: equilibria of a flow, their eigenvalues, the branch
 * in one parameter with its folds and Hopf points, and Hopf curves
 * (thesis 3.2, Figs. 3.5 and 3.8) over lib/equilibria.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/equilibria.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/outfile.h"

static const char equilibria_help[] =
    "usage: cellmap equilibria [--model NAME] [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                          --from X[,Y...] [--branch P=LO:HI [--direction up|down]\n"
    "                          [--ds-max D] [--max-points N] [--curve Q=V1,V2,...|Q=LO:HI:N]]\n"
    "                          [--csv FILE|-] [--json] [--quiet]\n\n"
    "Equilibria of a flow model's vector field (at its t0; for ODE models: chip-4d,\n"
    "the default, duffing, a plugin's flow), in the flow's coordinates. Newton from\n"
    "--from gives one equilibrium and its eigenvalues (stable when every real part\n"
    "is negative). With --branch the equilibrium is followed in parameter P over\n"
    "LO:HI (holding the model's value of P) by pseudo-arclength continuation, both\n"
    "ways, and its folds (a real eigenvalue through 0) and Hopf points (a complex\n"
    "pair through the imaginary axis) are located to 1e-10 in P (docs/models.md\n"
    "12.1: chip-4d's Hopf points at xi = 4.42808 and 11.8039). With --curve the\n"
    "Hopf points of the branch over LO:HI are found at each value of a second\n"
    "parameter Q: points of the Hopf curves in the (P, Q) plane.\n\n"
    "  --from X,Y,...      the start of Newton (the flow's dimension; `cellmap models`\n"
    "                      names the coordinates)\n"
    "  --branch P=LO:HI    follow the equilibrium in P over LO:HI\n"
    "  --direction up|down follow it only towards HI or LO (default: both)\n"
    "  --ds-max D          the longest arclength step (default (HI - LO)/50)\n"
    "  --max-points N      points each way, 10..1000000 (default 10000)\n"
    "  --curve Q=...       the Hopf points at these values of Q (up to 2000)\n"
    "  --csv FILE|-        rows kind (equilibrium, point, fold, hopf), P, Q, the\n"
    "                      state, re_k,im_k of the eigenvalues by decreasing real\n"
    "                      part, unstable (their count with re > 0), omega (Hopf)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

/* 0: go on; -1: --help was printed; else the usage error. */
static int parse_args(cli *c, eq_args *a, bool *json, bool *quiet)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(equilibria_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (branch_opts_take(c, &a->b, &err)) {
        } else if (cli_is(c, "--curve", true, &err)) {
            if (c->value && !param_axis_parse(c->value, strlen(c->value), &a->curve))
                err = cli_usage_error(c,
                                      "--curve: '%s' is not Q=V1,V2,... or Q=LO:HI:N "
                                      "(e.g. zeta=20,20.5,21)",
                                      c->value);
            a->has_curve = true;
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
    return err ? err : branch_opts_check(c, &a->b, a->has_curve, "--curve");
}

int cmd_equilibria(int argc, char **argv)
{
    cli c = {"equilibria", argc, argv, 0, NULL, NULL};
    eq_args a = equilibria_defaults();
    bool json = false, quiet = false;
    const int perr = parse_args(&c, &a, &json, &quiet);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    if (json && a.csv && strcmp(a.csv, "-") == 0)
        return cli_usage_error(&c, "--json and --csv -: both want standard output");
    const int werr = outfile_check("equilibria", a.csv, false);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    eq_result r;
    cm_status st = equilibria_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (json)
            equilibria_json(stdout, &a, &r);
        else if (!quiet)
            equilibria_report(report_stream(a.csv, NULL, NULL), &a, &r);
        st = equilibria_write(&a, &r, msg, sizeof msg);
    }
    equilibria_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
