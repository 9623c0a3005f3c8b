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

#include "lib/delay_domains.h"
#include "lib/stability.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char stability_help[] =
    "usage: cellmap stability [--model microchaos-pd|microchaos-delay] [--param k=v[,k=v]]\n"
    "                         [--P LO:HI:N]\n"
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
    "  --quiet             no summary\n\n"
    "With --model microchaos-delay, the delay map's (a, b) plane (4.39, App. C.3,\n"
    "docs/models.md 5.4): the stable domain G (Fig. 4.8); the domains '01' and '012'\n"
    "where the attractor is whole basic branches on U_0, U_1 (and U_2) with their\n"
    "boundary curves (Fig. 4.10); where the partitions of App. C.3.2 are primitive\n"
    "(Fig. C.3). The --param point is marked and placed, with the lines U_k its orbit\n"
    "lands on as the check; --csv gives the curves against a.\n";

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


/* The delay map's parameter domains (lib/delay_domains.h). */
static int delay_domains(const cli *c, const stab_args *a, const cm_params *base)
{
    const delay_point pt = delay_point_at(cm_params_get(base, "a"), cm_params_get(base, "b"));
    if (a->out.json) {
        json j;
        json_begin(&j, stdout, "stability");
        param_base_json(&j, a->mo.name, base);
        delay_domains_json(&j, &pt);
        json_end(&j);
    } else if (!a->out.quiet) {
        delay_domains_report(report_stream(a->out.csv, a->out.png, NULL), &pt);
    }
    char msg[1024];
    const cm_status st = delay_domains_write(&a->out, a->mo.name, base, &pt, msg, sizeof msg);
    return analysis_said(c->cmd, st, msg);
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
    const bool delay = strcmp(a.mo.name, "microchaos-delay") == 0;
    if (delay && (a.has_P || a.has_alpha))
        return cli_usage_error(&c, "--P and --alpha are the PD map's axes; the delay map's "
                                   "charts span its whole (a, b) plane");
    const int verr = sweep_check(&c, &a.mo, "microchaos-pd or microchaos-delay", NULL, 0, &base);
    if (verr)
        return verr;
    char msg[1024];
    if (delay)
        return delay_domains(&c, &a, &base);
    stab_result r;
    cm_status st = stability_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json)
            stability_json(a.mo.name, &r.base, r.alpha, r.beta, r.P, r.D);
        else if (!a.out.quiet)
            stability_report(report_stream(a.out.csv, a.out.png, NULL), r.alpha, r.beta, r.P, r.D);
        st = stability_write(&a, &r, msg, sizeof msg);
    }
    stability_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
