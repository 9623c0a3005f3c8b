/* cellmap stability: the analytic charts of the PD-controlled micro-chaos
 * map (thesis 4.5, App. C.4; Figs. 4.12, 4.14, C.4): the stability domain
 * of the quantisation-free loop in the P-D plane with the eigen-structure
 * curves inside it, the number of regular fixed points against P with the
 * border collisions, the fewest fixed points a stable choice of gains
 * allows against alpha, and the bounds of the control error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/stability.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char stability_help[] =
    "usage: cellmap stability [--model microchaos-pd] [--param k=v[,k=v]] [--P LO:HI:N]\n"
    "                         [--alpha LO:HI:N] [--csv FILE|-] [--png FILE] [--size WxH]\n"
    "                         [--json] [--quiet]\n\n"
    "The analytic charts of the PD-controlled micro-chaos map (thesis 4.5, App. C.4,\n"
    "docs/models.md 6.5): the domain of gains P, D where x = 0 is asymptotically\n"
    "stable without quantisation, P_min = alpha^2 < P <= P_max and D_b1(P) < D <\n"
    "D_b0(P) (C.45)-(C.47); inside it the curves where trace S = 0 (D_1), det S = 0\n"
    "(D_0) and S has a double eigenvalue (D_c-, D_c+), and the deadbeat point P_quick\n"
    "(C.52)-(C.56); the regular fixed points m = -m_fix,max..m_fix,max (4.73)-(4.75)\n"
    "and their border collisions at P = m alpha^2/(m - 1) (4.72); the strange sets up\n"
    "to m_max (4.76) and the control error m_max/P (4.78), about 1/(P - alpha^2)\n"
    "(4.79)-(4.80). At the --param point it says which; over P it tabulates them.\n\n"
    "  --P LO:HI:N         the values of P for the CSV and the charts (default: N = 400\n"
    "                      from 1.0025 alpha^2 to 1.2 P_max)\n"
    "  --alpha LO:HI:N     alpha for the fewest fixed points (Fig. 4.14, right;\n"
    "                      default 0.05:3:300)\n"
    "  --csv FILE|-        per P: D_b1, D_b0, D_1, D_0, D_c-, D_c+, m_fix_max, the\n"
    "                      number of regular fixed points, m_max, m_max/P, 1/(P - alpha^2)\n"
    "  --png FILE          three charts: the stability domain with the curves and the\n"
    "                      --param point (Figs. 4.12, C.4); the regular fixed points\n"
    "                      against P with the border collisions (Fig. 4.14, left); the\n"
    "                      fewest at P_max against alpha (Fig. 4.14, right)\n"
    "  --size WxH          image size (default 900x1200)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n";

static int take_axis(cli *c, const char *opt, const char *name, param_axis *ax, int *has,
                     int *err)
{
    if (!cli_is(c, opt, true, err))
        return 0;
    char text[160];
    snprintf(text, sizeof text, "%s=%s", name, c->value ? c->value : "");
    if (c->value && (!param_axis_parse(text, strlen(text), ax) || ax->n > 100000 ||
                     !param_axis_even(ax) || ax->n < 2))
        *err = cli_usage_error(c, "%s: '%s' is not LO:HI:N with LO < HI and 2 <= N <= 100000",
                               opt, c->value);
    *has = 1;
    return 1;
}

static int parse_args(cli *c, stab_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(stability_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (take_axis(c, "--P", "P", &a->P, &a->has_P, &err)) {
        } else if (take_axis(c, "--alpha", "alpha", &a->alpha, &a->has_alpha, &err)) {
            if (!err && a->alpha.lo <= 0)
                err = cli_usage_error(c, "--alpha: alpha must be positive");
        } else if (chart_outputs_take(c, &a->out, 300, 450, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}


static void print_summary(FILE *f, double alpha, double beta, double P, double D)
{
    const double Pmax = cm_pd_P_max(alpha, beta), Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    fprintf(f, "alpha = %s, beta = %s: x = 0 is stable without quantisation for %.9g < P <= "
               "%.9g (P_max, where D = %.9g), D_b1(P) < D < D_b0(P) (C.45)-(C.47)\n",
            CM_NUM(alpha), CM_NUM(beta), alpha * alpha, Pmax, cm_pd_D_at_P_max(alpha, beta));
    fprintf(f, "  deadbeat (both eigenvalues of S zero): P_quick = %.9g, D = %.9g (C.56)\n", Pq,
            q.D_0);
    stab_row r;
    stability_row_at(alpha, beta, P, D, &r);
    fprintf(f, "at P = %s, D = %s: %s", CM_NUM(P), CM_NUM(D),
            r.st.stable ? "stable" : "not stable");
    if (P > alpha * alpha)
        fprintf(f, " (D_b1 = %.9g, D_b0 = %.9g)", r.st.D_b1, r.st.D_b0);
    fprintf(f, "\n");
    if (r.m_fix_max < 0) {
        fprintf(f, "  P <= alpha^2: the fixed points are unbounded (4.73 needs P > alpha^2)\n");
        return;
    }
    fprintf(f, "  regular fixed points m = -%lld..%lld: %lld (4.73)-(4.75); strange sets up to "
               "|m| = %lld at x = m/P (4.76)\n",
            (long long)r.m_fix_max, (long long)r.m_fix_max, (long long)(2 * r.m_fix_max + 1),
            (long long)r.m_max);
    fprintf(f, "  control error: m_max/P = %.9g (4.78), 1/(P - alpha^2) = %.9g (4.79)-(4.80)\n",
            r.x_max_sw, r.x_max);
}

static void print_json(const stab_args *a, const cm_params *p, double alpha, double beta,
                       double P, double D)
{
    stab_row r;
    stability_row_at(alpha, beta, P, D, &r);
    const double Pq = cm_pd_P_quick(alpha, beta);
    cm_pd_eigen_curves q;
    cm_pd_eigen_curves_at(alpha, beta, Pq, &q);
    json j;
    json_begin(&j, stdout, "stability");
    param_base_json(&j, a->mo.name, p);
    json_num(&j, "P_min", alpha * alpha);
    json_num(&j, "P_max", cm_pd_P_max(alpha, beta));
    json_num(&j, "D_at_P_max", cm_pd_D_at_P_max(alpha, beta));
    json_nums(&j, "quick", (const double[2]){Pq, q.D_0}, 2);
    json_bool(&j, "stable", r.st.stable);
    json_nums(&j, "D_range", (const double[2]){r.st.D_b1, r.st.D_b0}, 2);
    json_int(&j, "m_fix_max", r.m_fix_max);
    json_int(&j, "n_fixed", r.m_fix_max >= 0 ? 2 * r.m_fix_max + 1 : -1);
    json_int(&j, "m_max", r.m_max);
    json_num(&j, "x_max_sw", r.x_max_sw);
    json_num(&j, "x_max", r.x_max);
    json_end(&j);
}

int cmd_stability(int argc, char **argv)
{
    cli c = {"stability", argc, argv, 0, NULL, NULL};
    stab_args a = stability_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "microchaos-pd", NULL, 0, &base);
    if (verr)
        return verr;
    char msg[1024];
    stab_result r;
    cm_status st = stability_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json)
            print_json(&a, &r.base, r.alpha, r.beta, r.P, r.D);
        else if (!a.out.quiet)
            print_summary(report_stream(a.out.csv, a.out.png, NULL), r.alpha, r.beta, r.P, r.D);
        st = stability_write(&a, &r, msg, sizeof msg);
    }
    stability_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
