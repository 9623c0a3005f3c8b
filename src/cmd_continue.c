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
#include "lib/json.h"
#include "src/figure_opts.h"
#include "src/outfile.h"

static const char continue_help[] =
    "usage: cellmap continue [--model friction-oscillator] [--param k=v[,k=v]]\n"
    "                        --vary NAME=LO:HI [--down|--both] [--from X,V[,P] ...]\n"
    "                        [--start P ...] [--period K]\n"
    "                        [--switch] [--curve NAME2=LO:HI --curves FILE|-]\n"
    "                        [--max-points N] [--csv FILE|-] [--events FILE|-] [--png FILE]\n"
    "                        [--panels LIST] [--size WxH] [--json] [--quiet]\n\n"
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
    "                      parameter; stable points green, unstable red, events marked\n"
    "                      and labelled\n"
    "  --panels LIST       the diagram's panels, in order: x_max, stops, psi (default\n"
    "                      all three; e.g. psi for Fig. 2.19, stops for Fig. 2.22's\n"
    "                      bottom panel)\n"
    "  --size WxH          image size (default 900x1100; 900x380 per panel when\n"
    "                      --panels picks fewer)\n"
    "  --json              the summary and events as JSON (docs/cellmap.schema.json)\n"
    "  --quiet             no summary\n";

enum { MAX_STARTS = 8, MAX_BRANCHES = 64 };

/* The diagram's panels. */
enum { PANEL_X_MAX = 0, PANEL_STOPS, PANEL_PSI, PANELS };
static const char *const panel_names[PANELS] = {"x_max", "stops", "psi"};

typedef struct cont_args {
    model_opts mo;
    char vary[16], vary2[16];
    double lo, hi, lo2, hi2;
    /* the starts: x, v (NaN: simulate) and the parameter's value (NaN: --param's) */
    double from[MAX_STARTS][3];
    int has_vary, n_from, down, both, switch_pd, period, max_points, width, height;
    int panels[PANELS], n_panels;
    const char *csv, *events, *png, *curves;
    bool json, quiet;
} cont_args;

/* "x_max,stops,psi" (any of them, in any order, each once) into a->panels. */
static bool parse_panels(const char *text, cont_args *a)
{
    a->n_panels = 0;
    bool seen[PANELS] = {false};
    for (const char *p = text;;) {
        const size_t len = strcspn(p, ",");
        int k = 0;
        while (k < PANELS && !(strlen(panel_names[k]) == len && strncmp(p, panel_names[k], len) == 0))
            k++;
        if (k == PANELS || seen[k])
            return false;
        seen[k] = true;
        a->panels[a->n_panels++] = k;
        if (p[len] == '\0')
            return true;
        p += len + 1;
    }
}

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
            if (c->value && !parse_panels(c->value, a))
                err = cli_usage_error(c,
                                      "--panels: '%s' is not a list of x_max, stops and psi, "
                                      "each at most once (e.g. psi or x_max,stops)",
                                      c->value);
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
    if (!err && a->n_panels == 0)
        for (int k = 0; k < PANELS; k++)
            a->panels[a->n_panels++] = k;
    if (!err && a->height == 0) {
        a->width = 900;
        a->height = a->n_panels == PANELS ? 1100 : 450 * a->n_panels;
    }
    if (!err && a->height < 150 * a->n_panels)
        err = cli_usage_error(c, "--size: %d panels want at least %d pixels of height",
                              a->n_panels, 150 * a->n_panels);
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

/* ---- the branches, collected ---- */

typedef struct tagged_point {
    int branch;
    cm_fo_solution s;
} tagged_point;

typedef struct tagged_event {
    int branch;
    cm_fo_branch_event e;
} tagged_event;

typedef struct branch_info {
    cm_fo_solution start;
    int direction, stop;
    uint64_t points;
} branch_info;

typedef struct collected {
    tagged_point *points;
    uint64_t n, cap;
    tagged_event *events;
    uint64_t n_events, cap_events;
    branch_info branches[MAX_BRANCHES];
    int n_branches;
    bool out_of_memory;
} collected;

static int keep_point(void *user, const cm_fo_solution *s)
{
    collected *c = user;
    if (cm_grow((void **)&c->points, &c->cap, c->n + 1, sizeof *c->points) != CM_OK) {
        c->out_of_memory = true;
        return 1;
    }
    c->points[c->n++] = (tagged_point){c->n_branches, *s};
    return 0;
}

static int keep_event(void *user, const cm_fo_branch_event *e)
{
    collected *c = user;
    if (cm_grow((void **)&c->events, &c->cap_events, c->n_events + 1, sizeof *c->events) != CM_OK) {
        c->out_of_memory = true;
        return 1;
    }
    c->events[c->n_events++] = (tagged_event){c->n_branches, *e};
    return 0;
}

/* The thesis' label: SN_2s, PD_1a, ...; the sliding bifurcations carry the
 * symmetry only (CS_s). */
static void event_label(const cm_fo_branch_event *e, char *out, size_t size)
{
    const char *name = cm_fo_event_name(e->type);
    const char sym = e->at.symmetric ? 's' : 'a';
    if (e->type >= CM_FO_EVENT_CS)
        snprintf(out, size, "%s_%c", name, sym);
    else
        snprintf(out, size, "%s_%d%c", name, e->at.n_stick, sym);
}

static const char *event_kind(const cm_fo_branch_event *e)
{
    switch (e->type) {
    case CM_FO_EVENT_SN: return e->fold ? "fold" : "branch point";
    case CM_FO_EVENT_PD: return "period doubling";
    case CM_FO_EVENT_NS: return "Neimark-Sacker";
    case CM_FO_EVENT_CS: return e->jump ? "sticking segments change and the map jumps"
                                        : "sticking segments change";
    case CM_FO_EVENT_SS: return e->jump ? "a pause appears or vanishes and the map jumps"
                                        : "a pause appears or vanishes";
    default: return e->jump ? "grazing: the map jumps" : "slip segments change";
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
    fprintf(o.f, "branch,%s,phi,x,v,period,stable,mult1_re,mult1_im,mult2_re,mult2_im,x_max,x_min,"
                 "psi,asymmetry,sticks,stops,signature\n",
            a->vary);
    for (uint64_t i = 0; i < c->n; i++) {
        const cm_fo_solution *s = &c->points[i].s;
        fprintf(o.f, "%d,%.17g,%.17g,%.17g,%.17g,%d,%d", c->points[i].branch + 1, s->p, s->phi,
                s->z[0], s->z[1], s->period, s->stable);
        print_mults(o.f, s);
        fprintf(o.f, ",%.17g,%.17g,%.17g,%.17g,%d,", s->x_max, s->x_min, s->psi, s->asymmetry,
                s->n_stick);
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
    fprintf(o.f, "branch,label,kind,fold,%s,width,x,v,phi,stable,mult1_re,mult1_im,mult2_re,"
                 "mult2_im,signature_before,signature_after\n",
            a->vary);
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        char label[32];
        event_label(e, label, sizeof label);
        fprintf(o.f, "%d,%s,%s,%d,%.17g,%.3g,%.17g,%.17g,%.17g,%d", c->events[i].branch + 1, label,
                event_kind(e), e->fold, e->at.p, e->width, e->at.z[0], e->at.z[1], e->at.phi,
                e->at.stable);
        print_mults(o.f, &e->at);
        fprintf(o.f, ",%s,%s\n", e->before, e->after);
    }
    return outfile_close("continue", &o, true);
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
        event_label(e, label, sizeof label);
        json_object(&j, NULL);
        json_int(&j, "branch", c->events[i].branch + 1);
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
            event_label(e, label, sizeof label);
            fprintf(out, "  %-6s %s = %.9g  (%s; %s -> %s)\n", label, a->vary, e->at.p,
                    event_kind(e), e->before, e->after);
        }
        fprintf(out, "  %llu points; stopped: %s\n", (unsigned long long)bi->points,
                cm_fo_stop_name(bi->stop));
    }
}

/* ---- two-parameter curves ---- */

typedef struct curve_out {
    FILE *f;
    int id;
    const char *label;
} curve_out;

static int write_curve_point(void *user, double p, double p2, const double z[2])
{
    const curve_out *c = user;
    fprintf(c->f, "%d,%s,%.17g,%.17g,%.17g,%.17g\n", c->id, c->label, p, p2, z[0], z[1]);
    return 0;
}

/* From every SN and PD event, its curve in (vary, vary2), both ways; each
 * way is one curve. */
/* Whether an earlier event gives the same curves: the same event (another
 * branch through the same point reports it too), or its mirror image (the
 * same kind at the same value) if that gave curves of 20 points or more.
 * The mirror's curves coincide in the parameter plane, but are computed
 * from another state, and where one stops early the other may go on. */
static bool already_curved(const collected *c, uint64_t i, const int *points)
{
    const cm_fo_branch_event *e = &c->events[i].e;
    for (uint64_t j = 0; j < i; j++) {
        const cm_fo_branch_event *f = &c->events[j].e;
        if (f->type != e->type || f->at.period != e->at.period || f->at.n_stick != e->at.n_stick ||
            fabs(f->at.p - e->at.p) >= 1e-6)
            continue;
        if ((strcmp(f->before, e->before) == 0 && strcmp(f->after, e->after) == 0) ||
            points[j] >= 20)
            return true;
    }
    return false;
}

static bool write_curves(const cont_args *a, const cm_fo *o, const collected *c, int *n_curves)
{
    outfile out;
    if (!outfile_open("continue", a->curves, &out))
        return false;
    fprintf(out.f, "curve,label,%s,%s,x,v\n", a->vary, a->vary2);
    const int param = cm_fo_param_of(a->vary), param2 = cm_fo_param_of(a->vary2);
    const double lo[2] = {a->lo, a->lo2}, hi[2] = {a->hi, a->hi2};
    int *points = calloc(c->n_events + 1, sizeof *points); /* per event, both ways */
    if (!points) {
        fprintf(stderr, "cellmap continue: out of memory for the curves\n");
        outfile_close("continue", &out, false);
        return false;
    }
    *n_curves = 0;
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        /* NS has no curve yet; at a branch point, and where a side branch
         * turns back at one, the fold's extended system is singular (the
         * symmetric branch's own tangent is in the kernel): no curve */
        if (e->type == CM_FO_EVENT_NS ||
            (e->type == CM_FO_EVENT_SN && (!e->fold || e->touch)) ||
            already_curved(c, i, points))
            continue;
        char label[32];
        event_label(e, label, sizeof label);
        for (int way = 1; way >= -1; way -= 2) {
            curve_out co = {out.f, *n_curves + 1, label};
            const int n = cm_fo_continue_curve(o, e, param, param2, lo, hi, way, 5000,
                                               write_curve_point, &co);
            points[i] += n;
            *n_curves += n > 0;
        }
    }
    free(points);
    return outfile_close("continue", &out, true);
}

/* ---- the diagram ---- */

typedef struct cloud {
    double *x, *y;
    uint64_t n, cap;
} cloud;

static bool cloud_add(cloud *c, double x, double y)
{
    if (c->n == c->cap) {
        const uint64_t cap = c->cap ? 2 * c->cap : 256;
        double *nx = realloc(c->x, cap * sizeof *nx);
        if (nx)
            c->x = nx;
        double *ny = nx ? realloc(c->y, cap * sizeof *ny) : NULL;
        if (!ny)
            return false;
        c->y = ny;
        c->cap = cap;
    }
    c->x[c->n] = x;
    c->y[c->n++] = y;
    return true;
}

static void cloud_range(const cloud *c, double *lo, double *hi)
{
    for (uint64_t i = 0; i < c->n; i++) {
        *lo = fmin(*lo, c->y[i]);
        *hi = fmax(*hi, c->y[i]);
    }
}

enum { LABEL_SIZE = 64 };

/* Up to three panels as Figs. 2.17-2.19: the maximal displacement, the
 * stops and Psi (2.90) against the parameter, those --panels picks in its
 * order; stable green, unstable red, events black with their labels on the
 * top panel. */
static bool write_png(const cont_args *a, const cm_model *m, const collected *c)
{
    cloud stable[PANELS] = {{0}}, unstable[PANELS] = {{0}}, marks[PANELS] = {{0}};
    bool ok = true;
    for (uint64_t i = 0; i < c->n && ok; i++) {
        const cm_fo_solution *s = &c->points[i].s;
        cloud *into = s->stable ? stable : unstable;
        ok = cloud_add(&into[PANEL_X_MAX], s->p, s->x_max) &&
             cloud_add(&into[PANEL_PSI], s->p, s->asymmetry);
        for (int k = 0; k < s->n_stops && ok; k++)
            ok = cloud_add(&into[PANEL_STOPS], s->p, s->stops[k]);
    }
    cm_chart_label *labels = calloc(c->n_events + 1, sizeof *labels);
    char(*texts)[LABEL_SIZE] = calloc(c->n_events + 1, sizeof *texts);
    ok = ok && labels && texts;
    for (uint64_t i = 0; i < c->n_events && ok; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        event_label(e, texts[i], sizeof texts[i]);
        const double y[PANELS] = {e->at.x_max, e->at.n_stops ? e->at.stops[0] : NAN,
                                  e->at.asymmetry};
        labels[i] = (cm_chart_label){e->at.p, y[a->panels[0]], texts[i]};
        ok = cloud_add(&marks[PANEL_X_MAX], e->at.p, e->at.x_max) &&
             cloud_add(&marks[PANEL_PSI], e->at.p, e->at.asymmetry);
        for (int k = 0; k < e->at.n_stops && ok; k++)
            ok = cloud_add(&marks[PANEL_STOPS], e->at.p, e->at.stops[k]);
    }
    if (!ok)
        fprintf(stderr, "cellmap continue: out of memory for the diagram\n");
    /* branches through one point each report its events, and several
     * events fall on one point: each point is labelled once, legibly */
    if (ok)
        cm_chart_join_labels(labels, (int)c->n_events, texts[0], LABEL_SIZE,
                             0.01 * (a->hi - a->lo), 0.02);
    static const char *const y_names[PANELS] = {"x_max", "stops", "Psi"};
    static const char *const panel_titles[PANELS] = {"maximal displacement", "stop positions",
                                                     "asymmetry Psi (2.90)"};
    char title[512], params[400];
    const char *const varied[] = {a->vary, NULL};
    cm_params_format_with(&m->values, varied, params, sizeof params);
    snprintf(title, sizeof title, "continuation in %s, %s; stable green, unstable red", a->vary,
             params);

    const cm_rgb green = {26, 152, 80}, red = {215, 48, 39}, black = {0, 0, 0};
    cm_series series[PANELS][3];
    cm_chart charts[PANELS];
    const int n = a->n_panels, h = a->height / n;
    char first_title[600];
    snprintf(first_title, sizeof first_title, "%s: %s", panel_titles[a->panels[0]], title);
    for (int i = 0; i < n && ok; i++) {
        const int k = a->panels[i];
        double lo = INFINITY, hi = -INFINITY;
        cloud_range(&stable[k], &lo, &hi);
        cloud_range(&unstable[k], &lo, &hi);
        if (!(lo <= hi))
            lo = -1, hi = 1;
        const double pad = hi > lo ? 0.06 * (hi - lo) : 0.5;
        series[k][0] = (cm_series){CM_SERIES_POINTS, unstable[k].x, unstable[k].y, unstable[k].n,
                                   red, 3};
        series[k][1] = (cm_series){CM_SERIES_POINTS, stable[k].x, stable[k].y, stable[k].n,
                                   green, 3};
        series[k][2] = (cm_series){CM_SERIES_POINTS, marks[k].x, marks[k].y, marks[k].n, black, 7};
        charts[i] = (cm_chart){a->width,
                               i < n - 1 ? h : a->height - (n - 1) * h,
                               {a->lo, lo - pad},
                               {a->hi, hi + pad},
                               a->vary,
                               y_names[k],
                               i == 0 ? first_title : panel_titles[k],
                               NULL,
                               series[k],
                               3,
                               figure_font(),
                               0,
                               i == 0 ? labels : NULL,
                               i == 0 ? (int)c->n_events : 0};
    }
    char range[96];
    snprintf(range, sizeof range, "%s=%s:%s", a->vary, CM_NUM(a->lo), CM_NUM(a->hi));
    const cm_png_text png_texts[] = {{"Model", m->name}, {"Parameters", params}, {"Vary", range}};
    if (ok)
        ok = write_chart_png("continue", a->png, charts, n, png_texts, 3);
    for (int k = 0; k < PANELS; k++) {
        free(stable[k].x), free(stable[k].y);
        free(unstable[k].x), free(unstable[k].y);
        free(marks[k].x), free(marks[k].y);
    }
    free(labels);
    free(texts);
    return ok;
}

/* The start from (x, v): a fixed point of P^K at the model's parameters. */
static bool find_start(const cont_args *a, const cm_fo *o, const double *from, double z[2],
                       int *period)
{
    z[0] = from ? from[0] : 1 + 0.9 * o->S0;
    z[1] = from ? from[1] : 0;
    if (a->period) {
        *period = a->period;
        if (cm_fo_periodic_point(o, z, a->period))
            return true;
        /* not near enough for Newton: let the solution attract it first */
        *period = cm_fo_find_periodic(o, z, 500, 64);
        return *period == a->period;
    }
    *period = cm_fo_find_periodic(o, z, from ? 0 : 500, 16);
    if (*period == 0 && from)
        *period = cm_fo_find_periodic(o, z, 500, 16);
    return *period > 0;
}

/* The branch through the period-k solution z at p0 of o: one way or both. */
static int follow_ways(const cont_args *a, const cm_fo *o, int param, double p0, const double z[2],
                       int period, bool both, collected *col)
{
    for (int way = 0; way < (both ? 2 : 1) && !col->out_of_memory; way++) {
        if (col->n_branches == MAX_BRANCHES)
            return EXIT_OK; /* said in the summary: no room for more */
        const int direction = both ? (way == 0 ? 1 : -1) : a->down ? -1 : 1;
        const cm_fo_continue_options opt = {param, a->lo, a->hi, direction,
                                            0,     0,     0,     a->max_points};
        branch_info *bi = &col->branches[col->n_branches];
        const uint64_t before = col->n;
        cm_fo_continue(o, &opt, p0, z, period, keep_point, keep_event, col, &bi->stop);
        bi->points = col->n - before;
        bi->direction = direction;
        if (bi->points == 0) {
            fprintf(stderr, "cellmap continue: the solution at (%s, %s) cannot be followed\n",
                    CM_NUM(z[0]), CM_NUM(z[1]));
            return EXIT_FAIL;
        }
        bi->start = col->points[before].s;
        col->n_branches++;
    }
    return EXIT_OK;
}

/* --switch: from each period doubling on the branches so far, the
 * period-doubled branch, both ways. */
static int switch_branches(const cont_args *a, const cm_fo *o, int param, collected *col)
{
    const uint64_t events = col->n_events;
    int err = EXIT_OK;
    for (uint64_t i = 0; i < events && !err && !col->out_of_memory; i++) {
        const cm_fo_branch_event e = col->events[i].e;
        double z[2], q;
        if (!cm_fo_period_doubled(o, param, &e, z, &q))
            continue;
        cm_fo from;
        cm_fo_with(o, param, q, &from);
        cm_fo_init(&from, from.S, from.S0, from.Omega, param == CM_FO_P_PHI ? q : e.at.phi);
        err = follow_ways(a, &from, param, q, z, 2 * e.at.period, true, col);
    }
    return err;
}

/* Every branch: from each start, one way or both; then --switch. */
static int follow(const cont_args *a, const cm_fo *o, int param, double p0, collected *col)
{
    const int starts = a->n_from ? a->n_from : 1;
    int err = EXIT_OK;
    for (int k = 0; k < starts && !err && !col->out_of_memory; k++) {
        double z[2];
        int period = 0;
        const double *given = a->n_from ? a->from[k] : NULL;
        const double p = given && !isnan(given[2]) ? given[2] : p0;
        const double *from = given && !isnan(given[0]) ? given : NULL;
        cm_fo at;
        cm_fo_with(o, param, p, &at);
        if (!(p >= a->lo && p <= a->hi) || !(at.S > 0 && at.S0 >= at.S && at.Omega > 0)) {
            fprintf(stderr,
                    "cellmap continue: the start's %s = %s is outside --vary %s=%s:%s or the "
                    "model's domain (S0 >= S > 0, Omega > 0); start inside both\n",
                    a->vary, CM_NUM(p), a->vary, CM_NUM(a->lo), CM_NUM(a->hi));
            return EXIT_USAGE;
        }
        if (!find_start(a, &at, from, z, &period)) {
            fprintf(stderr,
                    "cellmap continue: no periodic solution%s found from (%s, %s) at %s = %s "
                    "(chaotic there, or a longer period: give --from near one, and --period)\n",
                    a->period ? " of that period" : " of period 1..16", CM_NUM(z[0]),
                    CM_NUM(z[1]), a->vary, CM_NUM(p));
            return EXIT_FAIL;
        }
        const int true_period = cm_fo_minimal_period(&at, z, period);
        if (true_period != period) {
            fprintf(stderr,
                    "cellmap continue: the solution found near (%s, %s) repeats after %d "
                    "period(s), not %d: give --period %d, or --from near a solution of period "
                    "%d\n",
                    CM_NUM(from ? from[0] : z[0]), CM_NUM(from ? from[1] : z[1]), true_period,
                    period, true_period, period);
            return EXIT_FAIL;
        }
        err = follow_ways(a, &at, param, p, z, period, a->both, col);
    }
    if (!err && a->switch_pd)
        err = switch_branches(a, o, param, col);
    if (!err && col->out_of_memory) {
        fprintf(stderr, "cellmap continue: out of memory for the branch\n");
        err = EXIT_FAIL;
    }
    return err;
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
    collected col = {0};
    if (!err)
        err = follow(&a, o, param, p0, &col);
    bool ok = !err;
    if (ok && a.json)
        print_json(&a, &m, &col);
    else if (ok && !a.quiet)
        print_text(&a, &col);
    if (ok && a.csv)
        ok = write_points(&a, &col);
    if (ok && a.events)
        ok = write_events(&a, &col);
    if (ok && a.png)
        ok = write_png(&a, &m, &col);
    int n_curves = 0;
    if (ok && a.curves)
        ok = write_curves(&a, o, &col, &n_curves);
    if (ok && a.curves && !a.quiet && !a.json)
        fprintf(report_stream(a.csv, a.events, a.png), "%d curves in (%s, %s) to %s\n", n_curves,
                a.vary, a.vary2, cm_output_names_stdout(a.curves) ? "standard output" : a.curves);
    free(col.points);
    free(col.events);
    cm_model_release(&m);
    return ok ? EXIT_OK : err ? err : EXIT_FAIL;
}
