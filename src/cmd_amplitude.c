/* cellmap amplitude: the friction oscillator's amplitude-frequency diagram
 * (thesis 2.2, Figs. 2.4, 2.6, 2.7, 2.12-2.14): the symmetric non-sticking
 * solution's amplitude (2.25) with its conditions of validity (2.27),
 * (2.29) and its stability, against simulation. */
#include <math.h>
#include <omp.h>
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
    "                         [--ymax Y] [--size WxH] [--json] [--quiet] [--threads T]\n\n"
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
    "  --threads T         OpenMP threads (default: all cores)\n";

enum { RECORD = 40 };

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
    if (!err && !a->has_omega)
        err = cli_usage_error(c, "--omega LO:HI:N is required (e.g. --omega 0.1:3:300)");
    if (!err)
        err = chart_outputs_check(c, &a->out);
    return err;
}

typedef struct counts {
    int valid, stable, lost;
} counts;

static void summarise(const amp_args *a, const cm_fo_amplitude *v, counts *c)
{
    *c = (counts){0, 0, 0};
    for (int i = 0; i < a->omega.n; i++) {
        c->valid += v[i].valid;
        c->stable += v[i].stable;
        c->lost += isnan(v[i].sim_amplitude);
    }
}

int cmd_amplitude(int argc, char **argv)
{
    cli c = {"amplitude", argc, argv, 0, NULL, NULL};
    amp_args a = {.mo = {.name = "friction-oscillator"}, .periods = 400, .ymax = 5,
                  .out = {.width = 1000, .height = 700}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const int werr = chart_outputs_writable(&c, &a.out);
    if (werr != EXIT_OK)
        return werr;
    cm_params base;
    const int verr = sweep_check(&c, &a.mo, "friction-oscillator", &a.omega, 1, &base);
    if (verr)
        return verr;
    const int n = a.omega.n;
    cm_fo_amplitude *v = calloc((size_t)n, sizeof *v);
    if (!v) {
        fprintf(stderr, "cellmap amplitude: out of memory for %d frequencies\n", n);
        return EXIT_FAIL;
    }
    int invalid = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a.threads ? a.threads : omp_get_max_threads()) reduction(| : invalid)
    for (int i = 0; i < n; i++) {
        const int idx[1] = {i};
        cm_model m;
        if (!model_at_point(&a.mo, &a.omega, idx, 1, &m)) {
            invalid = 1;
            v[i] = (cm_fo_amplitude){NAN, NAN, NAN, false, NAN, false, NAN, NAN};
            continue;
        }
        cm_fo_amplitude_at(cm_fo_of_model(&m), a.periods, RECORD, &v[i]);
        cm_model_release(&m);
    }
    counts cnt;
    summarise(&a, v, &cnt);
    if (a.out.json) {
        json j;
        json_begin(&j, stdout, "amplitude");
        param_base_json(&j, a.mo.name, &base);
        param_axes_json(&j, "omega", &a.omega, 1);
        json_int(&j, "periods", a.periods);
        json_int(&j, "valid", cnt.valid);
        json_int(&j, "stable", cnt.stable);
        json_int(&j, "lost", cnt.lost);
        json_end(&j);
    } else if (!a.out.quiet) {
        fprintf(report_stream(a.out.csv, a.out.png, NULL),
                "%d frequencies: (2.25) valid at %d, the symmetric non-sticking solution "
                "stable at %d; %d simulations lost%s\n",
                n, cnt.valid, cnt.stable, cnt.lost,
                invalid ? "; some frequencies could not be built (S > S0)" : "");
    }
    char msg[1024];
    bool ok = true;
    if (a.out.csv)
        ok = amplitude_write_csv(&a, v, msg, sizeof msg);
    if (ok && a.out.png)
        ok = amplitude_write_png(&a, &base, v, msg, sizeof msg);
    if (!ok)
        fprintf(stderr, "cellmap amplitude: %s\n", msg);
    free(v);
    return ok ? EXIT_OK : EXIT_FAIL;
}
