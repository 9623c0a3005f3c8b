/* cellmap continue: a branch of the friction oscillator's periodic solutions
 * followed in one parameter (thesis 2.5, docs/models.md 9.9): the branch
 * points with their stability, multipliers and signature, and the events
 * on it (SN, PD, NS, CS, T) located and labelled as the thesis labels them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/continuation.h"
#include "src/args.h"
#include "src/commands.h"
#include "lib/json.h"
#include "src/figure_opts.h"
#include "src/outfile.h"

static const char continue_help[] =
    "usage: cellmap continue [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                        --vary NAME=LO:HI [--down|--both] [--from X,V[,P] ...]\n"
    "                        [--start P ...] [--period K]\n"
    "                        [--switch] [--curve NAME2=LO:HI --curves FILE|-]\n"
    "                        [--max-points N] [--csv FILE|-] [--events FILE|-] [--png FILE]\n"
    "                        [--panels LIST] [--mark P=TEXT] [--size WxH] [--json] [--quiet]\n\n"
    "Follows a periodic solution of the dry friction oscillator in parameter NAME\n"
    "(S, S0, Omega or phi) by pseudo-arclength continuation of the fixed points of\n"
    "P^K, the K-th iterate of the stroboscopic Poincare map, with Newton's method on\n"
    "the exact monodromy (docs/models.md 9.9). It starts at the value --param gives\n"
    "NAME (or its default), which must lie in LO:HI, and goes up (or --down) until\n"
    "the branch leaves LO:HI, N points are made, or it cannot be followed; through\n"
    "folds it goes on along the other side.\n\n"
    "Along the branch it reports, located on it and labelled as the thesis does\n"
    "(the number of sticking segments per period and s/a for a symmetric or an\n"
    "asymmetric solution): SN (a multiplier through +1: a fold, or a branch point\n"
    "where the branch goes on), PD (through -1), NS (a complex pair through the\n"
    "unit circle), CS (sticking segments appear, vanish or change neighbours:\n"
    "crossing-sliding and its kin), SS (a pause, a stick between two slips the same\n"
    "way, appears or vanishes) and T (only slip segments change, or one grazes v = 0\n"
    "and the map jumps). A solution's signature is its cycle of modes, u (slip up),\n"
    "d (slip down), s (stuck). A branch ends where the map jumps or the signature\n"
    "changes past what it can follow, where it comes back to its start (a loop),\n"
    "or where the map is nearly singular; the summary says which.\n\n"
    ;

/* Split from continue_help: C11 wants no string over 4095 characters. */
static const char continue_options[] =
    "  --vary NAME=LO:HI   the parameter and its range\n"
    "  --down              the parameter decreases first (default: it increases)\n"
    "  --both              from each start, both ways: the whole branch through it\n"
    "  --switch            at each period doubling, switch to the doubled branch and\n"
    "                      follow it both ways too\n"
    "  --curve NAME2=LO:HI from each fold, PD, CS, SS and T event, its curve in the\n"
    "                      plane of NAME and NAME2 (S, S0 or Omega), both ways: where a\n"
    "                      multiplier stays +1 or -1 (two-parameter continuation), or\n"
    "                      where the signature changes (the event located again on the\n"
    "                      branch in NAME as NAME2 moves in steps)\n"
    "  --curves FILE|-     those curves as CSV: curve, label, NAME, NAME2, x, v (lyapunov\n"
    "                      --curves draws them over its heat map)\n"
    "  --from X,V[,P]      start near (x, v) at the section, at NAME = P (default: the\n"
    "                      value --param gives NAME; without --from: simulate 500\n"
    "                      periods from the thesis' start 1 + 0.9 S0, 0); repeat it\n"
    "                      (up to 8) for several branches in one diagram\n"
    "  --start P           start where a simulation of 500 periods from the thesis'\n"
    "                      start settles at NAME = P; repeatable, with --from too\n"
    "  --period K          the solution's period in excitation periods (default: the\n"
    "                      smallest, 1..16, that the start settles on)\n"
    "  --max-points N      at most N branch points (default 5000)\n"
    "  --csv FILE|-        the branch points: branch, parameter, section phase, x, v,\n"
    "                      period, stability, multipliers, x range, psi (the signed sum\n"
    "                      of x at the velocity zeros), asymmetry (the thesis' Psi,\n"
    "                      (2.90)), sticks, stops, signature\n"
    "  --events FILE|-     the events: branch, label, kind, fold, parameter, x, v, phase,\n"
    "                      stability, multipliers, signatures before and after\n"
    "  --png FILE          the thesis' diagram (Figs. 2.17-2.19): maximal displacement,\n"
    "                      stop positions and the asymmetry Psi (2.90) against the\n"
    "                      parameter; stable branches green, unstable red, events\n"
    "                      marked and labelled in every panel\n"
    "  --mark P=TEXT       add TEXT to the label of the event nearest P (a name the\n"
    "                      thesis gives it: --mark 0.03562=N); repeatable\n"
    "  --panels LIST       the diagram's panels, in order: x_max, stops, psi (default\n"
    "                      all three; e.g. psi for Fig. 2.19, stops for Fig. 2.22's\n"
    "                      bottom panel)\n"
    "  --size WxH          image size (default 900x1100; 900x380 per panel when\n"
    "                      --panels picks fewer)\n"
    "  --json              the summary and events as JSON (docs/cellmap.schema.json)\n"
    "  --quiet             no summary\n";

/* NAME=LO:HI into name (size 16), lo, hi; false if it is not one. */
static bool parse_range(const char *text, char *name, double *lo, double *hi)
{
    const char *eq = strchr(text, '=');
    int n = 0;
    if (!eq || eq - text >= 16)
        return false;
    memcpy(name, text, (size_t)(eq - text));
    name[eq - text] = '\0';
    return cm_fo_param_of(name) >= 0 && parse_ranges(eq + 1, lo, hi, &n, 1);
}

static int parse_vary(cli *c, cont_args *a)
{
    if (!parse_range(c->value, a->vary, &a->lo, &a->hi))
        return cli_usage_error(c,
                               "--vary: '%s' is not NAME=LO:HI with NAME one of S, S0, Omega, "
                               "phi and LO < HI (e.g. S=0.02:0.4)",
                               c->value);
    a->has_vary = 1;
    return 0;
}

static int parse_args(cli *c, cont_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        int n = 0;
        if (strcmp(c->opt, "--help") == 0) {
            fputs(continue_help, stdout);
            fputs(continue_options, stdout);
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--vary", true, &err)) {
            if (c->value)
                err = parse_vary(c, a);
        } else if (cli_is(c, "--down", false, &err)) {
            a->down = 1;
        } else if (cli_is(c, "--both", false, &err)) {
            a->both = 1;
        } else if (cli_is(c, "--switch", false, &err)) {
            a->switch_pd = 1;
        } else if (cli_is(c, "--curve", true, &err)) {
            if (c->value && !parse_range(c->value, a->vary2, &a->lo2, &a->hi2))
                err = cli_usage_error(c,
                                      "--curve: '%s' is not NAME2=LO:HI with NAME2 one of S, S0, "
                                      "Omega and LO < HI (e.g. Omega=0.2:0.8)",
                                      c->value);
        } else if (cli_is(c, "--curves", true, &err)) {
            a->curves = c->value;
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && a->n_from == MAX_STARTS)
                err = cli_usage_error(c, "--from and --start: at most %d starts", MAX_STARTS);
            else if (c->value) {
                double *f = a->from[a->n_from++];
                if (!parse_doubles(c->value, f, &n, 3) || n < 2 || !isfinite(f[0]) ||
                    !isfinite(f[1]) || (n == 3 && !isfinite(f[2])))
                    err = cli_usage_error(
                        c, "--from: '%s' is not X,V or X,V,P (finite numbers)", c->value);
                if (n == 2)
                    f[2] = NAN;
            }
        } else if (cli_is(c, "--start", true, &err)) {
            double p;
            if (c->value && a->n_from == MAX_STARTS)
                err = cli_usage_error(c, "--from and --start: at most %d starts", MAX_STARTS);
            else if (c->value && !parse_double(c->value, &p))
                err = cli_usage_error(c, "--start: '%s' is not a number", c->value);
            else if (c->value)
                memcpy(a->from[a->n_from++], (double[3]){NAN, NAN, p}, sizeof a->from[0]);
        } else if (cli_take_int(c, "--period", 1, 64, &a->period, &err)) {
        } else if (cli_take_int(c, "--max-points", 2, 1000000, &a->max_points, &err)) {
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--events", true, &err)) {
            a->events = c->value;
        } else if (cli_is(c, "--png", true, &err)) {
            a->png = c->value;
        } else if (cli_is(c, "--panels", true, &err)) {
            if (c->value && !continuation_parse_panels(c->value, a))
                err = cli_usage_error(c,
                                      "--panels: '%s' is not a list of x_max, stops and psi, "
                                      "each at most once (e.g. psi or x_max,stops)",
                                      c->value);
        } else if (cli_is(c, "--mark", true, &err)) {
            if (c->value && !continuation_parse_mark(c->value, a))
                err = cli_usage_error(c, "--mark: '%s' is not P=TEXT (a number, a name of 1..24 "
                                         "characters; at most %d marks)",
                                      c->value, MAX_MARKS);
        } else if (cli_take_size(c, 300, 300, 4096, &a->width, &a->height, &err)) {
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !a->has_vary)
        err = cli_usage_error(c, "--vary NAME=LO:HI is required (e.g. --vary S=0.02:0.4)");
    char msg[256];
    if (!err && continuation_layout(a, msg, sizeof msg) != CM_OK)
        err = cli_usage_error(c, "--size: %s", msg);
    if (!err && a->json && (cm_output_names_stdout(a->csv) || cm_output_names_stdout(a->events)))
        err = cli_usage_error(c, "--json and an output to standard output: choose one");
    if (!err && (cm_output_names_stdout(a->csv) + cm_output_names_stdout(a->events) +
                     cm_output_names_stdout(a->png) >
                 1))
        err = cli_usage_error(c, "--csv, --events and --png: only one can go to standard output");
    if (!err && a->down && a->both)
        err = cli_usage_error(c, "--down and --both: choose one");
    if (!err && (a->vary2[0] != '\0') != (a->curves != NULL))
        err = cli_usage_error(c, "--curve NAME2=LO:HI and --curves FILE go together");
    if (!err && a->vary2[0] &&
        (strcmp(a->vary2, a->vary) == 0 || strcmp(a->vary2, "phi") == 0 ||
         strcmp(a->vary, "phi") == 0))
        err = cli_usage_error(c, "--curve: the second parameter must differ from --vary's, and "
                                 "neither may be phi");
    if (!err && cm_output_names_stdout(a->curves) &&
        (cm_output_names_stdout(a->csv) || cm_output_names_stdout(a->events) ||
         cm_output_names_stdout(a->png) || a->json))
        err = cli_usage_error(c, "--curves - and another output to standard output: choose one");
    return err;
}

static void print_json(const cont_args *a, const cm_model *m, const collected *c)
{
    json j;
    json_begin(&j, stdout, "continue");
    json_model(&j, m);
    json_str(&j, "vary", a->vary);
    json_nums(&j, "range", (const double[2]){a->lo, a->hi}, 2);
    json_array(&j, "branches");
    for (int b = 0; b < c->n_branches; b++) {
        const branch_info *bi = &c->branches[b];
        json_object(&j, NULL);
        json_int(&j, "period", bi->start.period);
        json_nums(&j, "start", bi->start.z, 2);
        json_num(&j, "phi", bi->start.phi);
        json_str(&j, "direction", bi->direction > 0 ? "up" : "down");
        json_uint(&j, "points", bi->points);
        json_str(&j, "stop", cm_fo_stop_name(bi->stop));
        json_object_end(&j);
    }
    json_array_end(&j);
    json_array(&j, "events");
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        char label[32];
        continuation_event_label(e, label, sizeof label);
        json_object(&j, NULL);
        json_int(&j, "branch", c->events[i].branch + 1);
        json_str(&j, "label", label);
        json_str(&j, "kind", continuation_event_kind(e));
        json_num(&j, "value", e->at.p);
        json_num(&j, "width", e->width);
        json_nums(&j, "state", e->at.z, 2);
        json_num(&j, "phi", e->at.phi);
        json_str(&j, "before", e->before);
        json_str(&j, "after", e->after);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_end(&j);
}

static void print_text(const cont_args *a, const collected *c)
{
    FILE *out = report_stream(a->csv, a->events, a->png);
    for (int b = 0; b < c->n_branches; b++) {
        const branch_info *bi = &c->branches[b];
        fprintf(out,
                "branch %d: period-%d solution at %s = %s, (x, v) = (%s, %s) at phase %s, "
                "signature %s; %s %s\n",
                b + 1, bi->start.period, a->vary, CM_NUM(bi->start.p), CM_NUM(bi->start.z[0]),
                CM_NUM(bi->start.z[1]), CM_NUM(bi->start.phi), bi->start.signature, a->vary,
                bi->direction > 0 ? "up" : "down");
        for (uint64_t i = 0; i < c->n_events; i++) {
            if (c->events[i].branch != b)
                continue;
            const cm_fo_branch_event *e = &c->events[i].e;
            char label[32];
            continuation_event_label(e, label, sizeof label);
            fprintf(out, "  %-6s %s = %.9g  (%s; %s -> %s)\n", label, a->vary, e->at.p,
                    continuation_event_kind(e), e->before, e->after);
        }
        fprintf(out, "  %llu points; stopped: %s\n", (unsigned long long)bi->points,
                cm_fo_stop_name(bi->stop));
    }
}

int cmd_continue(int argc, char **argv)
{
    cli c = {"continue", argc, argv, 0, NULL, NULL};
    cont_args a = {.mo = {.name = "friction-oscillator"}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    const char *const outs[] = {a.csv, a.events};
    int werr = outfiles_check("continue", outs, 2);
    if (werr == EXIT_OK)
        werr = chart_png_check("continue", a.png);
    if (werr != EXIT_OK)
        return werr;
    char msg[1024];
    cont_result r;
    cm_status st = continuation_compute(&a, &r, msg, sizeof msg);
    if (st == CM_OK) {
        if (a.json)
            print_json(&a, &r.m, &r.col);
        else if (!a.quiet)
            print_text(&a, &r.col);
        st = continuation_write(&a, &r, msg, sizeof msg);
    }
    if (st == CM_OK && a.curves && !a.quiet && !a.json)
        fprintf(report_stream(a.csv, a.events, a.png), "%d curves in (%s, %s) to %s\n",
                r.n_curves, a.vary, a.vary2,
                cm_output_names_stdout(a.curves) ? "standard output" : a.curves);
    continuation_result_free(&r);
    return analysis_said(c.cmd, st, msg);
}
