/* cellmap amplitude: the friction oscillator's amplitude-frequency diagram
 * (thesis 2.2, Figs. 2.4, 2.6, 2.7, 2.12-2.14): the symmetric non-sticking
 * solution's amplitude (2.25) with its conditions of validity (2.27),
 * (2.29) and its stability, against simulation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/amplitude.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"
#include "lib/param_grid.h"

static const char amplitude_help[] =
    "usage: cellmap amplitude [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                         --omega LO:HI:N [--periods P] [--csv FILE|-] [--png FILE]\n"
    "                         [--ymax Y] [--size WxH] [--json] [--quiet] [--threads T]\n"
    "       cellmap amplitude [--param k=v[,k=v]] --h OMEGA[,...] | --extremal EPS |\n"
    "                         --converge N [--csv FILE|-] [--png FILE] [--json] [--quiet]\n\n"
    "The amplitude-frequency diagram of the dry friction oscillator (thesis 2.2)\n"
    "at N excitation frequencies Omega (centres of N cells of LO:HI): the amplitude\n"
    "x0 of the symmetric non-sticking solution by (2.25), the slipping condition\n"
    "x0 >= S0/Omega^2 (2.27) and the condition of two turnarounds x0 >= S H_max\n"
    "(2.29); where both hold, the solution's stability by its exact monodromy; and\n"
    "a simulation from the thesis' start (1 + 0.9 S0, 0) over P periods (default\n"
    "400), whose half range of x and sticking segments per period over the last\n"
    "40 periods are the numerical amplitude and N of Figs. 2.4, 2.12-2.14.\n"
    "Frequencies run in parallel; the results do not depend on the thread count.\n\n"
    "  --omega LO:HI:N     the frequencies (N <= 100000)\n"
    "  --periods P         simulated periods, 50..100000 (default 400)\n"
    "  --csv FILE|-        Omega,x0,slip_limit,turn_limit,valid,mult_max,stable,\n"
    "                      sim_amplitude,sim_sticks per frequency (nan: none)\n"
    "  --png FILE          the diagram: x0 (green stable, red unstable, grey where\n"
    "                      (2.27) or (2.29) fails), S0/Omega^2 (blue), S H_max\n"
    "                      (purple), simulated amplitudes (black) and sticking\n"
    "                      segments per period / 10 (orange columns)\n"
    "  --ymax Y            the diagram's top (default 5; the resonance at Omega = 1\n"
    "                      is unbounded)\n"
    "  --size WxH          image size (default 1000x700)\n"
    "  --json              the summary as JSON on standard output\n"
    "  --quiet             no summary\n"
    "  --threads T         OpenMP threads (default: all cores)\n\n"
    "Instead of the diagram (docs/models.md 9.11):\n"
    "  --h OMEGA[,...]     H(t, Omega) of (2.29) over 0 < t < pi/Omega, a panel per\n"
    "                      frequency (1..6), with 1/Omega^2 and H_max (Fig. 2.5)\n"
    "  --extremal EPS      the map eps -> eps' of a perturbation that moves the extremal\n"
    "                      asymmetric solution to x0 = 1 + S - eps, into the sticking\n"
    "                      region, by simulation, 0 < eps <= EPS < S, against the thesis'\n"
    "                      eps - 2 eps^2 (Fig. 2.10; the thesis sets S0 = S)\n"
    "  --converge N        the relative error of the simulation from (1 + 0.9 S0, 0)\n"
    "                      against the solution it settles on, over N periods (after N\n"
    "                      to settle), and the envelope |lambda_max|^n of its leading\n"
    "                      multiplier (Fig. 2.11)\n";

/* One analysis instead of the diagram. */
static int take_mode(const cli *c, fo_transient_args *t, int kind)
{
    if (t->kind && t->kind != kind)
        return cli_usage_error(c, "--h, --extremal and --converge are different charts: give one");
    t->kind = kind;
    return 0;
}

static int parse_args(cli *c, amp_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(amplitude_help, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--omega", true, &err)) {
            char text[160];
            snprintf(text, sizeof text, "Omega=%s", c->value ? c->value : "");
            if (c->value && (!param_axis_parse(text, strlen(text), &a->omega) || a->omega.lo <= 0 ||
                             a->omega.n > 100000 || !param_axis_even(&a->omega)))
                err = cli_usage_error(c,
                                      "--omega: '%s' is not LO:HI:N with 0 < LO < HI and "
                                      "1 <= N <= 100000 (e.g. 0.1:3:300)",
                                      c->value);
            a->has_omega = 1;
        } else if (cli_is(c, "--h", true, &err)) {
            fo_transient_args *t = &a->transient;
            if (c->value && !parse_doubles(c->value, t->omegas, &t->n_omegas, FO_H_MAX_CURVES))
                err = cli_usage_error(c, "--h: '%s' is not 1..6 frequencies OMEGA[,OMEGA...]",
                                      c->value);
            err = err ? err : take_mode(c, t, FO_H);
        } else if (cli_is(c, "--extremal", true, &err)) {
            if (c->value && !parse_double(c->value, &a->transient.eps_max))
                err = cli_usage_error(c, "--extremal: '%s' is not a number", c->value);
            err = err ? err : take_mode(c, &a->transient, FO_EXTREMAL);
        } else if (cli_take_int(c, "--converge", 10, 1000000, &a->transient.periods, &err)) {
            err = err ? err : take_mode(c, &a->transient, FO_CONVERGE);
        } else if (cli_take_int(c, "--periods", 50, 100000, &a->periods, &err)) {
        } else if (cli_is(c, "--ymax", true, &err)) {
            if (c->value && (!parse_double(c->value, &a->ymax) || !(a->ymax > 0 && a->ymax < 1e6)))
                err = cli_usage_error(c, "--ymax: '%s' must be a number in (0, 1e6)", c->value);
        } else if (cli_take_int(c, "--threads", 1, THREADS_LIMIT, &a->threads, &err)) {
        } else if (chart_outputs_take(c, &a->out, 300, 200, &err)) {
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && a->has_omega && a->transient.kind)
        err = cli_usage_error(c, "--omega sweeps the diagram; --h, --extremal and --converge "
                                 "take the model's Omega (--param)");
    if (!err && !a->has_omega && !a->transient.kind)
        err = cli_usage_error(c, "--omega LO:HI:N is required (e.g. --omega 0.1:3:300)");
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

int cmd_amplitude(int argc, char **argv)
{
    cli c = {"amplitude", argc, argv, 0, NULL, NULL};
    amp_args a = amplitude_defaults();
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr =
        sweep_check(&c, &a.mo, "friction-oscillator", &a.omega, a.has_omega, &base);
    if (verr)
        return verr;
    char msg[1024];
    if (a.transient.kind)
        return analysis_said(c.cmd,
                             fo_transient_run(&a.transient, a.mo.name, &base, &a.out,
                                              a.out.quiet || a.out.json
                                                  ? NULL
                                                  : report_stream(a.out.csv, a.out.png, NULL),
                                              msg, sizeof msg),
                             msg);
    amp_result r;
    cm_status st = amplitude_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.out.json) {
            json j;
            json_begin(&j, stdout, "amplitude");
            param_base_json(&j, a.mo.name, &r.base);
            param_axes_json(&j, "omega", &a.omega, 1);
            json_int(&j, "periods", a.periods);
            json_int(&j, "valid", r.valid);
            json_int(&j, "stable", r.stable);
            json_int(&j, "lost", r.lost);
            json_end(&j);
        } else if (!a.out.quiet) {
            fprintf(report_stream(a.out.csv, a.out.png, NULL),
                    "%d frequencies: (2.25) valid at %d, the symmetric non-sticking solution "
                    "stable at %d; %d simulations lost%s\n",
                    a.omega.n, r.valid, r.stable, r.lost,
                    r.invalid ? "; some frequencies could not be built (S > S0)" : "");
        }
        st = amplitude_write(&a, &r, msg, sizeof msg);
    }
    amplitude_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
