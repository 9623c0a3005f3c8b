/* cellmap equilibria: equilibria of a flow, their eigenvalues, the branch
 * in one parameter with its folds and Hopf points, and Hopf curves
 * (thesis 3.2, Figs. 3.5 and 3.8) over lib/equilibria.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/equilibria.h"
#include "lib/json.h"
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

static void print_eigenvalues(FILE *f, const cm_equilibrium *e)
{
    for (int d = 0; d < e->dim; d++) {
        if (e->im[d] < 0)
            continue; /* a pair prints once, as re +- im i */
        fprintf(f, "%s%.6g", d ? ", " : "", e->re[d]);
        if (e->im[d] > 0)
            fprintf(f, " +- %.6gi", e->im[d]);
    }
}

static void print_state(FILE *f, const cm_model *m, const cm_equilibrium *e)
{
    for (int d = 0; d < e->dim; d++)
        fprintf(f, "%s%s = %.9g", d ? ", " : "", cm_flow_coord_name(m, d), e->x[d]);
}

static void print_summary(FILE *f, const eq_args *a, const eq_result *r)
{
    fprintf(f, "equilibrium: ");
    print_state(f, &r->m, &r->start);
    fprintf(f, "\neigenvalues: ");
    print_eigenvalues(f, &r->start);
    fprintf(f, "\n%s\n", r->start.unstable ? "unstable" : "stable");
    if (a->b.name[0]) {
        fprintf(f, "branch in %s over %g:%g: %zu points", a->b.name, a->b.lo, a->b.hi, r->n_pts);
        if (r->why[0])
            fprintf(f, "; down: %s", equilibria_why(r->why[0]));
        if (r->why[1])
            fprintf(f, "; up: %s", equilibria_why(r->why[1]));
        fprintf(f, "\n");
        for (size_t k = 0; !a->has_curve && k < r->n_events; k++) {
            const cm_eq_event *ev = &r->events[k].ev;
            fprintf(f, "%s at %s = %.9g", equilibria_event_name(ev->kind), a->b.name, ev->at.p);
            if (ev->kind == CM_EQ_HOPF)
                fprintf(f, ", omega %.6g", ev->omega);
            fprintf(f, " (");
            print_state(f, &r->m, &ev->at);
            fprintf(f, ")\n");
        }
    }
    for (size_t k = 0; k < r->n_hopf; k++)
        fprintf(f, "hopf at %s = %.9g, %s = %.9g, omega %.6g\n", a->curve.name, r->hopf[k].q,
                a->b.name, r->hopf[k].ev.at.p, r->hopf[k].ev.omega);
}

static void print_json(const eq_args *a, const eq_result *r)
{
    json j;
    json_begin(&j, stdout, "equilibria");
    json_model(&j, &r->m);
    json_nums(&j, "from", a->b.from, a->b.n_from);
    json_nums(&j, "equilibrium", r->start.x, r->start.dim);
    json_nums(&j, "re", r->start.re, r->start.dim);
    json_nums(&j, "im", r->start.im, r->start.dim);
    json_int(&j, "unstable", r->start.unstable);
    if (a->b.name[0]) {
        json_str(&j, "branch", a->b.name);
        json_int(&j, "points", (long long)r->n_pts);
        json_array(&j, "events");
        for (size_t k = 0; k < r->n_events; k++) {
            const cm_eq_event *ev = &r->events[k].ev;
            json_object(&j, NULL);
            json_str(&j, "kind", equilibria_event_name(ev->kind));
            json_num(&j, "p", ev->at.p);
            json_nums(&j, "x", ev->at.x, ev->at.dim);
            if (ev->kind == CM_EQ_HOPF)
                json_num(&j, "omega", ev->omega);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    if (a->has_curve) {
        json_array(&j, "hopf_curve");
        for (size_t k = 0; k < r->n_hopf; k++) {
            json_object(&j, NULL);
            json_num(&j, "q", r->hopf[k].q);
            json_num(&j, "p", r->hopf[k].ev.at.p);
            json_num(&j, "omega", r->hopf[k].ev.omega);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    json_end(&j);
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
            print_json(&a, &r);
        else if (!quiet)
            print_summary(report_stream(a.csv, NULL, NULL), &a, &r);
        st = equilibria_write(&a, &r, msg, sizeof msg);
    }
    equilibria_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
