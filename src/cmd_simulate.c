/* cellmap simulate: one trajectory of the dry friction oscillator, followed
 * exactly (docs/models.md 9), as a CSV of its events and as the thesis' pictures
 * of it: x(t) over the sticking region and the phase portrait (Figs. 2.3,
 * 2.9, 2.16). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/series.h"
#include "lib/simulate.h"
#include "lib/parse.h"
#include "src/args.h"
#include "src/figure_opts.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/outfile.h"

static const char simulate_help[] =
    "usage: cellmap simulate [--model friction-oscillator] [--param k=v[,k=v]] [--from X,V]\n"
    "                        [--t0 T0] [--periods N] [--skip P] [--csv FILE|-] [--png FILE]\n"
    "                        [--json] [--quiet] [--size WxH]\n"
    "       cellmap simulate --model FLOW|chip-bue [--model-lib P.so] [--param k=v[,k=v]]\n"
    "                        [--from X,Y,...] [--time T] [--skip T0] [--dt DT] [--of NAME]\n"
    "                        [--time-unit SECONDS] [--fmax F] [--spectrum FILE|-] [--returns]\n"
    "                        [--csv FILE|-] [--png FILE] [--json] [--quiet] [--size WxH]\n\n"
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
    "  --size WxH          image size, both panels (default 900x1000)\n\n"
    "The time series of a flow model (chip-4d, chip-workpiece, duffing, a plugin's\n"
    "flow; integrated as its maps are) or of the built-up-edge delay model chip-bue\n"
    "(docs/models.md 12.3; from its start-up), sampled every DT from the model's t0 to\n"
    "t0 + T, and the power spectrum of one coordinate (FFTW, Hann window, the mean\n"
    "taken out) over the samples after the transient, with its largest peaks.\n\n"
    "  --from X,Y,...      the start in the flow's coordinates (default: the centre of\n"
    "                      the model's example region, on its section plane)\n"
    "  --time T            the time followed (default 100)\n"
    "  --skip T0           the transient: samples before t0 + T0 are not kept\n"
    "  --dt DT             the sample interval (default 0.01)\n"
    "  --of NAME           the coordinate drawn and transformed (default the first)\n"
    "  --time-unit S       seconds per unit of the model's time: frequencies also in Hz\n"
    "                      (the chip models: K0 = 1.64e-4, thesis 3.3)\n"
    "  --fmax F            the spectrum drawn up to F (in Hz with --time-unit)\n"
    "  --csv FILE|-        t and every coordinate per sample (%.17g)\n"
    "  --spectrum FILE|-   frequency[,frequency_hz],power\n"
    "  --png FILE          top: the coordinate against t; below: log10 of its power\n"
    "                      spectrum (default size 900x800)\n"
    "  --returns           a third panel: the coordinate's return map at the model's\n"
    "                      section (a Poincare map's), x_k+1 against x_k (Fig. 3.6)\n";

/* What either kind of simulation was asked, and which options were seen
 * (an option of the other kind is a usage error). */
typedef struct request {
    sim_args fo;
    series_args se;
    double skip;
    const char *fo_only, *se_only; /* an option seen that only one kind takes */
    bool has_skip, has_size;
} request;

static int parse_options(cli *c, request *q)
{
    int err = 0;
    while (cli_next(c) && !err) {
        const char *opt = c->opt;
        if (strcmp(opt, "--help") == 0) {
            fputs(simulate_help, stdout);
            return -1;
        } else if (model_opts_take(c, &q->fo.mo, &err)) {
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && (!parse_doubles(c->value, q->se.from, &q->se.n_from, SERIES_MAX_DIM)))
                err = cli_usage_error(c, "--from: '%s' is not a list of numbers X,Y,...",
                                      c->value);
        } else if (cli_is(c, "--t0", true, &err)) {
            if (c->value && (!parse_double(c->value, &q->fo.t0) || !(fabs(q->fo.t0) <= 1e9)))
                err = cli_usage_error(c, "--t0: '%s' must be a time within +-1e9", c->value);
            q->fo.has_t0 = 1, q->fo_only = opt;
        } else if (cli_take_int(c, "--periods", 1, 100000, &q->fo.periods, &err)) {
            q->fo_only = opt;
        } else if (cli_take_double(c, "--skip", 0, 1e9, &q->skip, &err)) {
            q->has_skip = true;
        } else if (cli_take_double(c, "--time", 1e-9, 1e9, &q->se.time, &err) ||
                   cli_take_double(c, "--dt", 1e-12, 1e9, &q->se.dt, &err) ||
                   cli_take_double(c, "--time-unit", 0, 1e9, &q->se.time_unit, &err) ||
                   cli_take_double(c, "--fmax", 0, 1e300, &q->se.fmax, &err)) {
            q->se_only = opt;
        } else if (cli_is(c, "--of", true, &err)) {
            q->se.of = c->value, q->se_only = opt;
        } else if (cli_is(c, "--spectrum", true, &err)) {
            q->se.spectrum_csv = c->value, q->se_only = opt;
        } else if (cli_is(c, "--returns", false, &err)) {
            q->se.returns = true, q->se_only = opt;
        } else if (chart_outputs_take(c, &q->fo.out, 300, 400, &err)) {
            q->has_size |= strcmp(opt, "--size") == 0;
        } else {
            err = cli_stray(c);
        }
    }
    return err;
}

/* The friction oscillator's request out of q. */
static int check_oscillator(cli *c, request *q)
{
    if (q->se_only)
        return cli_usage_error(c, "%s is for flows and chip-bue, not friction-oscillator",
                               q->se_only);
    if (q->se.n_from && q->se.n_from != 2)
        return cli_usage_error(c, "--from: friction-oscillator starts from X,V (two numbers)");
    if (q->se.n_from)
        q->fo.from[0] = q->se.from[0], q->fo.from[1] = q->se.from[1];
    if (q->has_skip && q->skip != floor(q->skip))
        return cli_usage_error(c, "--skip: friction-oscillator skips whole periods");
    q->fo.skip = (int)q->skip;
    int err = chart_outputs_check(c, &q->fo.out);
    if (!err && q->fo.skip >= q->fo.periods)
        err = cli_usage_error(c, "--skip %d leaves nothing of %d periods to show", q->fo.skip,
                              q->fo.periods);
    return err;
}

/* A flow's or chip-bue's request out of q. */
static int check_series(cli *c, request *q)
{
    if (q->fo_only)
        return cli_usage_error(c, "%s is for friction-oscillator; a flow takes --time, --skip "
                               "and --dt", q->fo_only);
    q->se.mo = q->fo.mo;
    q->se.skip = q->skip;
    const int w = q->se.out.width, h = q->se.out.height;
    q->se.out = q->fo.out;
    if (!q->has_size)
        q->se.out.width = w, q->se.out.height = h;
    int err = chart_outputs_check(c, &q->se.out);
    if (!err && q->se.out.json && cm_output_names_stdout(q->se.spectrum_csv))
        err = cli_usage_error(c, "--json and --spectrum -: both want standard output");
    if (!err && cm_output_names_stdout(q->se.spectrum_csv) &&
        (cm_output_names_stdout(q->se.out.csv) || cm_output_names_stdout(q->se.out.png)))
        err = cli_usage_error(c, "only one output can go to standard output");
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

static int run_series(cli *c, series_args *a)
{
    int werr = outfile_check(c->cmd, a->spectrum_csv, false);
    if (werr == EXIT_OK)
        werr = chart_outputs_writable(c, &a->out);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    series_result r;
    cm_status st = series_compute(a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a->out.json)
            series_json(stdout, a, &r);
        else if (!a->out.quiet)
            series_report(report_stream(a->out.csv, a->out.png, a->spectrum_csv), a, &r);
        st = series_write(a, &r, msg, sizeof msg);
    }
    series_result_free(&r);
    return analysis_said(c->cmd, st, msg);
}

static int run_oscillator(cli *c, sim_args *a)
{
    const int werr = chart_outputs_writable(c, &a->out);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    sim_result r;
    cm_status st = simulate_compute(a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        print_summary(a, &r.m, &r.r, &r.last, r.z_prev, fabs(r.tr.psi_sum));
        st = simulate_write(a, &r, msg, sizeof msg);
    }
    simulate_result_free(&r);
    return analysis_said(c->cmd, st, msg);
}

int cmd_simulate(int argc, char **argv)
{
    cli c = {"simulate", argc, argv, 0, NULL, NULL};
    request q = {.fo = simulate_defaults(), .se = series_defaults()};
    int err = parse_options(&c, &q);
    if (err)
        return err < 0 ? EXIT_OK : err;
    if (series_model(&q.fo.mo)) {
        err = check_series(&c, &q);
        return err ? err : run_series(&c, &q.se);
    }
    err = check_oscillator(&c, &q);
    return err ? err : run_oscillator(&c, &q.fo);
}
