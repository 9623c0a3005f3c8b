/* cellmap simulate: one trajectory of the dry friction oscillator, followed
 * exactly (docs/models.md 9), as a CSV of its events and as the thesis' pictures
 * of it: x(t) over the sticking region and the phase portrait (Figs. 2.3,
 * 2.9, 2.16). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/simulate.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"

static const char simulate_help[] =
    "usage: cellmap simulate [--model friction-oscillator] [--param k=v[,k=v]] [--from X,V]\n"
    "                        [--t0 T0] [--periods N] [--skip P] [--csv FILE|-] [--png FILE]\n"
    "                        [--json] [--quiet] [--size WxH]\n\n"
    "A trajectory of the dry friction oscillator x'' + x = cos(Omega t) - S f(x')\n"
    "(thesis eq. (2.3)) from (x, x') = (X, V) at time T0, followed exactly\n"
    "(docs/models.md 9) up to the N-th section instant (forcing phase phi) after T0.\n"
    "Prints what the last period did, its Poincare point and Psi.\n\n"
    "  --from X,V          the initial state (default 0,0)\n"
    "  --t0 T0             the initial time (default phi/Omega, a section instant)\n"
    "  --periods N         periods to follow, 1..100000 (default 20)\n"
    "  --skip P            periods left out of the CSV, the PNG and Psi (transients)\n"
    "  --json              the summary as JSON on standard output (docs/cellmap.schema.json)\n"
    "  --quiet             no summary\n"
    "  --csv FILE          t,x,v,kind: the start, every stick, breakaway and turn, and\n"
    "                      the section point ending each period (%.17g)\n"
    "  --png FILE          top: x(t) with the sticking region |x - cos(Omega t)| < S0\n"
    "                      (blue); bottom: the phase portrait with the sticking\n"
    "                      segment and the section points (black). Slip red, stick green\n"
    "  --size WxH          image size, both panels (default 900x1000)\n";

static int parse_args(cli *c, sim_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        int n = 0;
        if (strcmp(c->opt, "--help") == 0) {
            fputs(simulate_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && (!parse_doubles(c->value, a->from, &n, 2) || n != 2 ||
                             !isfinite(a->from[0]) || !isfinite(a->from[1])))
                err = cli_usage_error(c, "--from: '%s' is not X,V (two finite numbers)", c->value);
        } else if (cli_is(c, "--t0", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->t0) || !(fabs(a->t0) <= 1e9)))
                err = cli_usage_error(c, "--t0: '%s' must be a time within +-1e9", c->value);
            a->has_t0 = 1;
        } else if (cli_take_int(c, "--periods", 1, 100000, &a->periods, &err)) {
        } else if (cli_take_int(c, "--skip", 0, 100000, &a->skip, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 400, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err)
        err = chart_outputs_check(c, &a->out);
    if (!err && a->skip >= a->periods)
        err = cli_usage_error(c, "--skip %d leaves nothing of %d periods to show", a->skip,
                              a->periods);
    return err;
}

static void print_json(const sim_args *a, const cm_model *m, const cm_fo_run *r,
                       const cm_fo_tally *last, const double z_prev[2], double psi)
{
    json j;
    json_begin(&j, stdout, "simulate");
    json_model(&j, m);
    json_nums(&j, "from", a->from, 2);
    json_num(&j, "t0", a->t0);
    json_int(&j, "periods", a->periods);
    json_int(&j, "skip", a->skip);
    json_num(&j, "t_end", r->t_section);
    json_object(&j, "last_period");
    json_int(&j, "sticks", last->n_stick);
    json_int(&j, "turns", last->n_turn);
    json_int(&j, "breakaways", last->n_break);
    json_nums(&j, "x_range", (const double[2]){last->x_min, last->x_max}, 2);
    json_object_end(&j);
    json_nums(&j, "poincare_point", (const double[2]){r->st.x, r->st.v}, 2);
    if (!isnan(z_prev[0]))
        json_num(&j, "fixed_point_residual", hypot(r->st.x - z_prev[0], r->st.v - z_prev[1]));
    json_num(&j, "psi", psi);
    json_num(&j, "psi_per_period", psi / (a->periods - a->skip));
    json_end(&j);
}

static void print_summary(const sim_args *a, const cm_model *m, const cm_fo_run *r,
                          const cm_fo_tally *last, const double z_prev[2], double psi)
{
    if (a->out.json) {
        print_json(a, m, r, last, z_prev, psi);
        return;
    }
    if (a->out.quiet)
        return;
    FILE *out = report_stream(a->out.csv, a->out.png, NULL);
    fprintf(out, "followed %d periods from (x, v) = (%s, %s) at t = %s to t = %s\n", a->periods,
            CM_NUM(a->from[0]), CM_NUM(a->from[1]), CM_NUM(a->t0), CM_NUM(r->t_section));
    fprintf(out, "last period: %d sticks, %d turns, %d breakaways; x in [%.9g, %.9g]\n", last->n_stick,
           last->n_turn, last->n_break, last->x_min, last->x_max);
    fprintf(out, "Poincare point (%s, %s)", CM_NUM(r->st.x), CM_NUM(r->st.v));
    if (!isnan(z_prev[0])) {
        const double res = hypot(r->st.x - z_prev[0], r->st.v - z_prev[1]);
        fprintf(out, "; |P(z) - z| = %.3g%s", res, res < 1e-9 ? " (a fixed point of the map)" : "");
    }
    fprintf(out, "\nPsi over the %d periods shown = %.9g (%.9g per period)\n", a->periods - a->skip, psi,
           psi / (a->periods - a->skip));
}

int cmd_simulate(int argc, char **argv)
{
    cli c = {"simulate", argc, argv, 0, NULL, NULL};
    sim_args a = simulate_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    sim_result r;
    cm_status st = simulate_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        print_summary(&a, &r.m, &r.r, &r.last, r.z_prev, fabs(r.tr.psi_sum));
        st = simulate_write(&a, &r, msg, sizeof msg);
    }
    simulate_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
