/* cellmap continue: a branch of the friction oscillator's periodic solutions
 * followed in one parameter (thesis 2.5, docs/models.md 9.9): the branch
 * points with their stability, multipliers and signature, and the events
 * on it (SN, PD, NS, CS, T) located and labelled as the thesis labels them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "models/fo_continuation.h"
#include "models/params.h"
#include "src/args.h"
#include "src/commands.h"
#include "src/json.h"
#include "src/outfile.h"

static const char continue_help[] =
    "usage: cellmap continue [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                        --vary NAME=LO:HI [--down] [--from X,V] [--period K]\n"
    "                        [--max-points N] [--csv FILE|-] [--events FILE|-] [--json]\n"
    "                        [--quiet]\n\n"
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
    "crossing-sliding and its kin) and T (only slip segments change). A solution's\n"
    "signature is its cycle of modes, u (slip up), d (slip down), s (stuck).\n\n"
    "  --vary NAME=LO:HI   the parameter and its range\n"
    "  --down              the parameter decreases first (default: it increases)\n"
    "  --from X,V          start near (x, v) at the section (default: simulate 500\n"
    "                      periods from the thesis' start 1 + 0.9 S0, 0)\n"
    "  --period K          the solution's period in excitation periods (default: the\n"
    "                      smallest, 1..16, that the start settles on)\n"
    "  --max-points N      at most N branch points (default 5000)\n"
    "  --csv FILE|-        the branch points: parameter, section phase, x, v, period,\n"
    "                      stability, multipliers, x range, Psi, sticks, stops, signature\n"
    "  --events FILE|-     the events: label, kind, fold, parameter, x, v, phase,\n"
    "                      stability, multipliers, signatures before and after\n"
    "  --json              the summary and events as JSON (docs/cellmap.schema.json)\n"
    "  --quiet             no summary\n";

typedef struct cont_args {
    model_opts mo;
    char vary[16];
    double lo, hi, from[2];
    int has_vary, has_from, down, period, max_points;
    const char *csv, *events;
    bool json, quiet;
} cont_args;

static int parse_vary(cli *c, cont_args *a)
{
    const char *eq = strchr(c->value, '=');
    char range[128];
    int n = 0;
    double v[2];
    if (!eq || (size_t)(eq - c->value) >= sizeof a->vary ||
        snprintf(range, sizeof range, "%s", eq + 1) >= (int)sizeof range) {
        n = -1;
    } else {
        memcpy(a->vary, c->value, (size_t)(eq - c->value));
        a->vary[eq - c->value] = '\0';
        for (char *p = range; *p; p++)
            *p = *p == ':' ? ',' : *p;
    }
    if (n < 0 || !parse_doubles(range, v, &n, 2) || n != 2 || !(v[0] < v[1]) ||
        cm_fo_param_of(a->vary) < 0)
        return cli_usage_error(c,
                               "--vary: '%s' is not NAME=LO:HI with NAME one of S, S0, Omega, "
                               "phi and LO < HI (e.g. S=0.02:0.4)",
                               c->value);
    a->lo = v[0];
    a->hi = v[1];
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
            return -1;
        } else if (model_opts_take(c, &a->mo, &err)) {
        } else if (cli_is(c, "--vary", true, &err)) {
            if (c->value)
                err = parse_vary(c, a);
        } else if (cli_is(c, "--down", false, &err)) {
            a->down = 1;
        } else if (cli_is(c, "--from", true, &err)) {
            if (c->value && (!parse_doubles(c->value, a->from, &n, 2) || n != 2 ||
                             !isfinite(a->from[0]) || !isfinite(a->from[1])))
                err = cli_usage_error(c, "--from: '%s' is not X,V (two finite numbers)", c->value);
            a->has_from = 1;
        } else if (cli_take_int(c, "--period", 1, 64, &a->period, &err)) {
        } else if (cli_take_int(c, "--max-points", 2, 1000000, &a->max_points, &err)) {
        } else if (cli_is(c, "--csv", true, &err)) {
            a->csv = c->value;
        } else if (cli_is(c, "--events", true, &err)) {
            a->events = c->value;
        } else if (cli_is(c, "--json", false, &err)) {
            a->json = true;
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else {
            err = cli_usage_error(c, "unknown option '%s'", c->opt);
        }
    }
    if (!err && !a->has_vary)
        err = cli_usage_error(c, "--vary NAME=LO:HI is required (e.g. --vary S=0.02:0.4)");
    if (!err && a->json && (cm_output_names_stdout(a->csv) || cm_output_names_stdout(a->events)))
        err = cli_usage_error(c, "--json and an output to standard output: choose one");
    if (!err && cm_output_names_stdout(a->csv) && cm_output_names_stdout(a->events))
        err = cli_usage_error(c, "--csv - and --events -: only one can go to standard output");
    return err;
}

/* ---- the branch, collected ---- */

typedef struct collected {
    cm_fo_solution *points;
    uint64_t n, cap;
    cm_fo_branch_event *events;
    uint64_t n_events, cap_events;
    bool out_of_memory;
} collected;

static int keep_point(void *user, const cm_fo_solution *s)
{
    collected *c = user;
    if (cm_grow((void **)&c->points, &c->cap, c->n + 1, sizeof *c->points) != CM_OK) {
        c->out_of_memory = true;
        return 1;
    }
    c->points[c->n++] = *s;
    return 0;
}

static int keep_event(void *user, const cm_fo_branch_event *e)
{
    collected *c = user;
    if (cm_grow((void **)&c->events, &c->cap_events, c->n_events + 1, sizeof *c->events) != CM_OK) {
        c->out_of_memory = true;
        return 1;
    }
    c->events[c->n_events++] = *e;
    return 0;
}

/* The thesis' label: SN_2s, PD_1a, ...; the sliding bifurcations carry the
 * symmetry only (CS_s). */
static void event_label(const cm_fo_branch_event *e, char *out, size_t size)
{
    const char *name = cm_fo_event_name(e->type);
    const char sym = e->at.symmetric ? 's' : 'a';
    if (e->type == CM_FO_EVENT_CS || e->type == CM_FO_EVENT_T)
        snprintf(out, size, "%s_%c", name, sym);
    else
        snprintf(out, size, "%s_%d%c", name, e->at.n_stick / e->at.period, sym);
}

static const char *event_kind(const cm_fo_branch_event *e)
{
    switch (e->type) {
    case CM_FO_EVENT_SN: return e->fold ? "fold" : "branch point";
    case CM_FO_EVENT_PD: return "period doubling";
    case CM_FO_EVENT_NS: return "Neimark-Sacker";
    case CM_FO_EVENT_CS: return "sticking segments change";
    default: return "slip segments change";
    }
}

static void print_mults(FILE *f, const cm_fo_solution *s)
{
    for (int k = 0; k < 2; k++)
        fprintf(f, ",%.17g,%.17g", s->mult[k][0], s->mult[k][1]);
}

static bool write_points(const cont_args *a, const collected *c)
{
    outfile o;
    if (!outfile_open("continue", a->csv, &o))
        return false;
    fprintf(o.f, "%s,phi,x,v,period,stable,mult1_re,mult1_im,mult2_re,mult2_im,x_max,x_min,psi,"
                 "sticks,stops,signature\n",
            a->vary);
    for (uint64_t i = 0; i < c->n; i++) {
        const cm_fo_solution *s = &c->points[i];
        fprintf(o.f, "%.17g,%.17g,%.17g,%.17g,%d,%d", s->p, s->phi, s->z[0], s->z[1], s->period,
                s->stable);
        print_mults(o.f, s);
        fprintf(o.f, ",%.17g,%.17g,%.17g,%d,", s->x_max, s->x_min, s->psi, s->n_stick);
        for (int k = 0; k < s->n_stops; k++)
            fprintf(o.f, "%s%.9g", k ? ";" : "", s->stops[k]);
        fprintf(o.f, ",%s\n", s->signature);
    }
    return outfile_close("continue", &o, true);
}

static bool write_events(const cont_args *a, const collected *c)
{
    outfile o;
    if (!outfile_open("continue", a->events, &o))
        return false;
    fprintf(o.f, "label,kind,fold,%s,x,v,phi,stable,mult1_re,mult1_im,mult2_re,mult2_im,"
                 "signature_before,signature_after\n",
            a->vary);
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i];
        char label[32];
        event_label(e, label, sizeof label);
        fprintf(o.f, "%s,%s,%d,%.17g,%.17g,%.17g,%.17g,%d", label, event_kind(e), e->fold,
                e->at.p, e->at.z[0], e->at.z[1], e->at.phi, e->at.stable);
        print_mults(o.f, &e->at);
        fprintf(o.f, ",%s,%s\n", e->before, e->after);
    }
    return outfile_close("continue", &o, true);
}

static void print_json(const cont_args *a, const cm_model *m, const collected *c, int stop)
{
    json j;
    json_begin(&j, stdout, "continue");
    json_model(&j, m);
    json_str(&j, "vary", a->vary);
    json_nums(&j, "range", (const double[2]){a->lo, a->hi}, 2);
    json_int(&j, "period", c->points[0].period);
    json_nums(&j, "start", c->points[0].z, 2);
    json_uint(&j, "points", c->n);
    json_str(&j, "stop", cm_fo_stop_name(stop));
    json_array(&j, "events");
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i];
        char label[32];
        event_label(e, label, sizeof label);
        json_object(&j, NULL);
        json_str(&j, "label", label);
        json_str(&j, "kind", event_kind(e));
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

static void print_text(const cont_args *a, const collected *c, int stop)
{
    FILE *out = report_stream(a->csv, a->events, NULL);
    const cm_fo_solution *s0 = &c->points[0];
    fprintf(out, "period-%d solution at %s = %s, (x, v) = (%s, %s) at phase %s, signature %s\n",
            s0->period, a->vary, CM_NUM(s0->p), CM_NUM(s0->z[0]), CM_NUM(s0->z[1]),
            CM_NUM(s0->phi), s0->signature);
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i];
        char label[32];
        event_label(e, label, sizeof label);
        fprintf(out, "  %-6s %s = %.9g  (%s; %s -> %s)\n", label, a->vary, e->at.p, event_kind(e),
                e->before, e->after);
    }
    fprintf(out, "%llu branch points; stopped: %s\n", (unsigned long long)c->n,
            cm_fo_stop_name(stop));
}

/* The start: a fixed point of P^K at the model's parameters. */
static bool find_start(const cont_args *a, const cm_fo *o, double z[2], int *period)
{
    z[0] = a->has_from ? a->from[0] : 1 + 0.9 * o->S0;
    z[1] = a->has_from ? a->from[1] : 0;
    if (a->period) {
        *period = a->period;
        if (cm_fo_periodic_point(o, z, a->period))
            return true;
        /* not near enough for Newton: let the solution attract it first */
        *period = cm_fo_find_periodic(o, z, 500, 64);
        return *period == a->period;
    }
    *period = cm_fo_find_periodic(o, z, a->has_from ? 0 : 500, 16);
    if (*period == 0 && a->has_from)
        *period = cm_fo_find_periodic(o, z, 500, 16);
    return *period > 0;
}

int cmd_continue(int argc, char **argv)
{
    cli c = {"continue", argc, argv, 0, NULL, NULL};
    cont_args a = {.mo = {.name = "friction-oscillator"}};
    const int perr = parse_args(&c, &a);
    if (perr)
        return perr < 0 ? EXIT_OK : perr;
    if (!outfile_check("continue", a.csv) || !outfile_check("continue", a.events))
        return EXIT_FAIL;
    cm_model m;
    const int merr = model_opts_build(&c, &a.mo, &m);
    if (merr)
        return merr;
    const cm_fo *o = cm_fo_of_model(&m);
    const int param = cm_fo_param_of(a.vary);
    const double p0 = o ? (double[4]){o->S, o->S0, o->Omega, o->phi}[param] : 0;
    int err = 0;
    if (!o)
        err = cli_usage_error(&c, "model %s: continue follows friction-oscillator only",
                              a.mo.name);
    else if (!(p0 >= a.lo && p0 <= a.hi))
        err = cli_usage_error(&c,
                              "%s = %s (from --param or the default) is outside --vary %s=%s:%s; "
                              "start inside the range",
                              a.vary, CM_NUM(p0), a.vary, CM_NUM(a.lo), CM_NUM(a.hi));
    double z[2];
    int period = 0;
    if (!err && !find_start(&a, o, z, &period)) {
        fprintf(stderr,
                "cellmap continue: no periodic solution%s found from (%s, %s) at %s = %s "
                "(chaotic there, or a longer period: give --from near one, and --period)\n",
                a.period ? " of that period" : " of period 1..16", CM_NUM(z[0]), CM_NUM(z[1]),
                a.vary, CM_NUM(p0));
        err = EXIT_FAIL;
    }
    if (err) {
        cm_model_release(&m);
        return err;
    }
    const cm_fo_continue_options opt = {param, a.lo, a.hi, a.down ? -1 : 1, 0, 0, 0, a.max_points};
    collected col = {0};
    int stop = 0;
    cm_fo_continue(o, &opt, p0, z, period, keep_point, keep_event, &col, &stop);
    bool ok = !col.out_of_memory && col.n > 0;
    if (col.out_of_memory)
        fprintf(stderr, "cellmap continue: out of memory for the branch\n");
    else if (col.n == 0)
        fprintf(stderr, "cellmap continue: the solution at the start cannot be followed\n");
    if (ok && a.json)
        print_json(&a, &m, &col, stop);
    else if (ok && !a.quiet)
        print_text(&a, &col, stop);
    if (ok && a.csv)
        ok = write_points(&a, &col);
    if (ok && a.events)
        ok = write_events(&a, &col);
    free(col.points);
    free(col.events);
    cm_model_release(&m);
    return ok ? EXIT_OK : EXIT_FAIL;
}
