/* lib/continuation.c - branches followed and written (lib/continuation.h). */
#include "lib/continuation.h"
#include "lib/parse.h"
#include "lib/simulate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "cellmap/numtext.h"
#include "lib/figure.h"
#include "lib/outfile.h"
#include "models/params.h"

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
void continuation_event_label(const cm_fo_branch_event *e, char *out, size_t size)
{
    const char *name = cm_fo_event_name(e->type);
    const char sym = e->at.symmetric ? 's' : 'a';
    if (e->type >= CM_FO_EVENT_CS)
        snprintf(out, size, "%s_%c", name, sym);
    else
        snprintf(out, size, "%s_%d%c", name, e->at.n_stick, sym);
}

const char *continuation_event_kind(const cm_fo_branch_event *e)
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

static cm_status continuation_write_points(const cont_args *a, const collected *c, char *msg,
                                    size_t msg_size)
{
    outfile o;
    const cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
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
    return outfile_end(&o, true, msg, msg_size);
}

static cm_status continuation_write_events(const cont_args *a, const collected *c, char *msg,
                                    size_t msg_size)
{
    outfile o;
    const cm_status st = outfile_begin(a->events, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(o.f, "branch,label,kind,fold,%s,width,x,v,phi,stable,mult1_re,mult1_im,mult2_re,"
                 "mult2_im,signature_before,signature_after\n",
            a->vary);
    for (uint64_t i = 0; i < c->n_events; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        char label[32];
        continuation_event_label(e, label, sizeof label);
        fprintf(o.f, "%d,%s,%s,%d,%.17g,%.3g,%.17g,%.17g,%.17g,%d", c->events[i].branch + 1, label,
                continuation_event_kind(e), e->fold, e->at.p, e->width, e->at.z[0], e->at.z[1], e->at.phi,
                e->at.stable);
        print_mults(o.f, &e->at);
        fprintf(o.f, ",%s,%s\n", e->before, e->after);
    }
    return outfile_end(&o, true, msg, msg_size);
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

static cm_status continuation_write_curves(const cont_args *a, const cm_fo *o, const collected *c,
                                    int *n_curves, char *msg, size_t msg_size)
{
    outfile out;
    const cm_status st = outfile_begin(a->curves, &out, msg, msg_size);
    if (st != CM_OK)
        return st;
    fprintf(out.f, "curve,label,%s,%s,x,v\n", a->vary, a->vary2);
    const int param = cm_fo_param_of(a->vary), param2 = cm_fo_param_of(a->vary2);
    const double lo[2] = {a->lo, a->lo2}, hi[2] = {a->hi, a->hi2};
    int *points = calloc(c->n_events + 1, sizeof *points); /* per event, both ways */
    if (!points) {
        outfile_end(&out, false, (char[64]){0}, 64);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the curves");
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
        continuation_event_label(e, label, sizeof label);
        for (int way = 1; way >= -1; way -= 2) {
            curve_out co = {out.f, *n_curves + 1, label};
            const int n = cm_fo_continue_curve(o, e, param, param2, lo, hi, way, 5000,
                                               write_curve_point, &co);
            points[i] += n;
            *n_curves += n > 0;
        }
    }
    free(points);
    return outfile_end(&out, true, msg, msg_size);
}

/* "x_max,stops,psi" (any of them, in any order, each once) into a->panels. */
bool continuation_parse_panels(const char *text, cont_args *a)
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

/* --mark P=TEXT into a's marks; false if it is not one or there are too many. */
bool continuation_parse_mark(const char *text, cont_args *a)
{
    const char *eq = strchr(text, '=');
    char at[64];
    if (a->n_marks == MAX_MARKS || !eq || eq - text >= (ptrdiff_t)sizeof at || !eq[1] ||
        strlen(eq + 1) > 24)
        return false;
    memcpy(at, text, (size_t)(eq - text));
    at[eq - text] = '\0';
    if (!parse_double(at, &a->mark_at[a->n_marks]))
        return false;
    a->mark_text[a->n_marks++] = eq + 1;
    return true;
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

/* The value a panel draws of solution s (for the stops, stop j); false if
 * it has none. */
static bool panel_value(int panel, int j, const cm_fo_solution *s, double *v)
{
    *v = panel == PANEL_X_MAX ? s->x_max : panel == PANEL_PSI ? s->asymmetry : NAN;
    if (panel == PANEL_STOPS && j < s->n_stops)
        *v = s->stops[j];
    return !isnan(*v);
}

/* Starts a new line in c (a NaN breaks a polyline) unless it is empty or
 * broken already. */
static bool line_break(cloud *c)
{
    return c->n == 0 || isnan(c->x[c->n - 1]) || cloud_add(c, NAN, NAN);
}

/* The branches of one panel as lines (for the stops, the j-th stop's),
 * stable ones into stable, unstable into unstable: a line goes on while
 * the branch, its stability and the number of stops stay; where the
 * stability changes, the new line starts at the last point of the old. */
static bool trace_panel(const collected *c, int panel, int j, cloud *stable, cloud *unstable)
{
    bool ok = true;
    for (uint64_t i = 0; i < c->n && ok; i++) {
        const cm_fo_solution *s = &c->points[i].s;
        const cm_fo_solution *q = i > 0 && c->points[i - 1].branch == c->points[i].branch
                                      ? &c->points[i - 1].s
                                      : NULL;
        cloud *into = s->stable ? stable : unstable;
        double v, w;
        if (!panel_value(panel, j, s, &v))
            continue;
        const bool continues = q && q->n_stops == s->n_stops && panel_value(panel, j, q, &w);
        if (!continues || q->stable != s->stable)
            ok = line_break(into);
        if (ok && continues && q->stable != s->stable)
            ok = cloud_add(into, q->p, w);
        ok = ok && cloud_add(into, s->p, v);
    }
    return ok;
}

/* The events as labelled marks of each panel (their texts, joined where
 * they fall on one place, in texts[panel]); a mark's text (--mark) is
 * added to the label of the event nearest its value. */
static bool event_marks(const cont_args *a, const collected *c, cloud *marks,
                        cm_chart_label *labels[PANELS], char (*texts[PANELS])[LABEL_SIZE])
{
    bool ok = true;
    for (uint64_t i = 0; i < c->n_events && ok; i++) {
        const cm_fo_branch_event *e = &c->events[i].e;
        const double y[PANELS] = {e->at.x_max, e->at.n_stops ? e->at.stops[0] : NAN,
                                  e->at.asymmetry};
        for (int k = 0; k < PANELS; k++) {
            continuation_event_label(e, texts[k][i], LABEL_SIZE);
            labels[k][i] = (cm_chart_label){e->at.p, y[k], texts[k][i]};
        }
        ok = cloud_add(&marks[PANEL_X_MAX], e->at.p, e->at.x_max) &&
             cloud_add(&marks[PANEL_PSI], e->at.p, e->at.asymmetry);
        for (int k = 0; k < e->at.n_stops && ok; k++)
            ok = cloud_add(&marks[PANEL_STOPS], e->at.p, e->at.stops[k]);
    }
    for (int m = 0; m < a->n_marks && c->n_events; m++) {
        uint64_t nearest = 0;
        for (uint64_t i = 1; i < c->n_events; i++)
            if (fabs(c->events[i].e.at.p - a->mark_at[m]) <
                fabs(c->events[nearest].e.at.p - a->mark_at[m]))
                nearest = i;
        for (int k = 0; k < PANELS; k++) {
            const size_t used = strlen(texts[k][nearest]);
            snprintf(texts[k][nearest] + used, LABEL_SIZE - used, " = %s", a->mark_text[m]);
        }
    }
    /* branches through one point each report its events, and several
     * events fall on one point: each point is labelled once, legibly */
    for (int k = 0; k < PANELS && ok; k++)
        cm_chart_join_labels(labels[k], (int)c->n_events, texts[k][0], LABEL_SIZE,
                             0.01 * (a->hi - a->lo), 0.02);
    return ok;
}

/* Up to three panels as Figs. 2.17-2.19: the maximal displacement, the
 * stops and Psi (2.90) against the parameter, those --panels picks in its
 * order; stable branches green, unstable red, events black and labelled. */
static cm_status continuation_write_png(const cont_args *a, const cm_model *m, const collected *c,
                                 char *msg, size_t msg_size)
{
    cloud stable[PANELS] = {{0}}, unstable[PANELS] = {{0}}, marks[PANELS] = {{0}};
    bool ok = true;
    for (int k = 0; k < PANELS && ok; k++)
        for (int j = 0; j < (k == PANEL_STOPS ? CM_FO_MAX_STOPS : 1) && ok; j++)
            ok = trace_panel(c, k, j, &stable[k], &unstable[k]);
    cm_chart_label *labels[PANELS];
    char(*texts[PANELS])[LABEL_SIZE];
    for (int k = 0; k < PANELS; k++) {
        labels[k] = calloc(c->n_events + 1, sizeof *labels[k]);
        texts[k] = calloc(c->n_events + 1, sizeof *texts[k]);
        ok = ok && labels[k] && texts[k];
    }
    ok = ok && event_marks(a, c, marks, labels, texts);
    cm_status st = ok ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the diagram");
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
        series[k][0] = (cm_series){CM_SERIES_LINE, unstable[k].x, unstable[k].y, unstable[k].n,
                                   red, 2};
        series[k][1] = (cm_series){CM_SERIES_LINE, stable[k].x, stable[k].y, stable[k].n,
                                   green, 2};
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
                               labels[k],
                               (int)c->n_events};
    }
    char range[96];
    snprintf(range, sizeof range, "%s=%s:%s", a->vary, CM_NUM(a->lo), CM_NUM(a->hi));
    const cm_png_text png_texts[] = {{"Model", m->name}, {"Parameters", params}, {"Vary", range}};
    if (ok)
        st = outfile_charts(a->png, charts, n, png_texts, 3, msg, msg_size);
    for (int k = 0; k < PANELS; k++) {
        free(stable[k].x), free(stable[k].y);
        free(unstable[k].x), free(unstable[k].y);
        free(marks[k].x), free(marks[k].y);
        free(labels[k]);
        free(texts[k]);
    }
    return st;
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
static cm_status follow_ways(const cont_args *a, const cm_fo *o, int param, double p0,
                             const double z[2], int period, bool both, collected *col, char *msg,
                             size_t msg_size)
{
    for (int way = 0; way < (both ? 2 : 1) && !col->out_of_memory; way++) {
        if (col->n_branches == MAX_BRANCHES)
            return CM_OK; /* said in the summary: no room for more */
        const int direction = both ? (way == 0 ? 1 : -1) : a->down ? -1 : 1;
        const cm_fo_continue_options opt = {param, a->lo, a->hi, direction,
                                            0,     0,     0,     a->max_points};
        branch_info *bi = &col->branches[col->n_branches];
        const uint64_t before = col->n;
        cm_fo_continue(o, &opt, p0, z, period, keep_point, keep_event, col, &bi->stop);
        bi->points = col->n - before;
        bi->direction = direction;
        if (bi->points == 0)
            return cm_fail(CM_EMODEL, msg, msg_size,
                           "the solution at (%s, %s) cannot be followed", CM_NUM(z[0]),
                           CM_NUM(z[1]));
        bi->start = col->points[before].s;
        col->n_branches++;
    }
    return CM_OK;
}

/* --switch: from each period doubling on the branches so far, the
 * period-doubled branch, both ways. */
static cm_status switch_branches(const cont_args *a, const cm_fo *o, int param, collected *col,
                                 char *msg, size_t msg_size)
{
    const uint64_t events = col->n_events;
    cm_status err = CM_OK;
    for (uint64_t i = 0; i < events && !err && !col->out_of_memory; i++) {
        const cm_fo_branch_event e = col->events[i].e;
        double z[2], q;
        if (!cm_fo_period_doubled(o, param, &e, z, &q))
            continue;
        cm_fo from;
        cm_fo_with(o, param, q, &from);
        cm_fo_init(&from, from.S, from.S0, from.Omega, param == CM_FO_P_PHI ? q : e.at.phi);
        err = follow_ways(a, &from, param, q, z, 2 * e.at.period, true, col, msg, msg_size);
    }
    return err;
}

/* Every branch: from each start, one way or both; then --switch. */
static cm_status continuation_follow(const cont_args *a, const cm_fo *o, int param, double p0,
                              collected *col, char *msg, size_t msg_size)
{
    memset(col, 0, sizeof *col);
    const int starts = a->n_from ? a->n_from : 1;
    cm_status err = CM_OK;
    for (int k = 0; k < starts && !err && !col->out_of_memory; k++) {
        double z[2];
        int period = 0;
        const double *given = a->n_from ? a->from[k] : NULL;
        const double p = given && !isnan(given[2]) ? given[2] : p0;
        const double *from = given && !isnan(given[0]) ? given : NULL;
        cm_fo at;
        cm_fo_with(o, param, p, &at);
        if (!(p >= a->lo && p <= a->hi) || !(at.S > 0 && at.S0 >= at.S && at.Omega > 0)) {
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the start's %s = %s is outside the range %s=%s:%s or the model's "
                           "domain (S0 >= S > 0, Omega > 0); start inside both",
                           a->vary, CM_NUM(p), a->vary, CM_NUM(a->lo), CM_NUM(a->hi));
        }
        if (!find_start(a, &at, from, z, &period)) {
            return cm_fail(CM_ENOTFOUND, msg, msg_size,
                           "no periodic solution%s found from (%s, %s) at %s = %s (chaotic "
                           "there, or a longer period: start near one, and give its period)",
                           a->period ? " of that period" : " of period 1..16", CM_NUM(z[0]),
                           CM_NUM(z[1]), a->vary, CM_NUM(p));
        }
        const int true_period = cm_fo_minimal_period(&at, z, period);
        if (true_period != period) {
            return cm_fail(CM_ENOTFOUND, msg, msg_size,
                           "the solution found near (%s, %s) repeats after %d period(s), not %d: "
                           "give the period %d, or start near a solution of period %d",
                           CM_NUM(from ? from[0] : z[0]), CM_NUM(from ? from[1] : z[1]),
                           true_period, period, true_period, period);
        }
        err = follow_ways(a, &at, param, p, z, period, a->both, col, msg, msg_size);
    }
    if (!err && a->switch_pd)
        err = switch_branches(a, o, param, col, msg, msg_size);
    if (!err && col->out_of_memory)
        err = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the branch");
    return err;
}

static void continuation_free(collected *col)
{
    free(col->points);
    free(col->events);
    col->points = NULL;
    col->events = NULL;
}

cm_status continuation_layout(cont_args *a, char *msg, size_t msg_size)
{
    if (a->n_panels == 0)
        for (int k = 0; k < PANELS; k++)
            a->panels[a->n_panels++] = k;
    if (a->height == 0) {
        a->width = 900;
        a->height = a->n_panels == PANELS ? 1100 : 450 * a->n_panels;
    }
    if (a->height < 150 * a->n_panels || a->width < 300 || a->width > 4096 || a->height > 4096)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%dx%d pixels: %d panels want 300..4096 pixels of width and %d..4096 of "
                       "height",
                       a->width, a->height, a->n_panels, 150 * a->n_panels);
    return CM_OK;
}

/* The request's own limits (the command checks them as it parses). */
static cm_status check_request(cont_args *a, char *msg, size_t msg_size)
{
    if (!a->has_vary || cm_fo_param_of(a->vary) < 0 || !(a->lo < a->hi))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a parameter NAME=LO:HI to vary is required, NAME one of S, S0, Omega, "
                       "phi and LO < HI (e.g. S=0.02:0.4)");
    if (a->down && a->both)
        return cm_fail(CM_EINVAL, msg, msg_size, "down and both ways: choose one");
    if ((a->vary2[0] != '\0') != (a->curves != NULL))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a second parameter NAME2=LO:HI and the curves' file go together");
    if (a->vary2[0] && (cm_fo_param_of(a->vary2) < 0 || !(a->lo2 < a->hi2) ||
                        strcmp(a->vary2, a->vary) == 0 || strcmp(a->vary2, "phi") == 0 ||
                        strcmp(a->vary, "phi") == 0))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the curves' second parameter must be S, S0 or Omega over LO < HI, other "
                       "than the varied one, and neither may be phi");
    if (a->n_from < 0 || a->n_from > MAX_STARTS || a->period < 0 || a->period > 64 ||
        a->max_points < 0 || a->max_points > 1000000)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d starts, period %d, %d points: need at most %d starts, a period of "
                       "1..64 and at most 10^6 points",
                       a->n_from, a->period, a->max_points, MAX_STARTS);
    return continuation_layout(a, msg, msg_size);
}

cm_status continuation_compute(cont_args *a, cont_result *r, char *msg, size_t msg_size)
{
    *r = (cont_result){0};
    cm_status st = check_request(a, msg, msg_size);
    if (st == CM_OK)
        st = simulate_oscillator(&a->mo, "continue", &r->m, &r->o, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->param = cm_fo_param_of(a->vary);
    const cm_fo *o = r->o;
    r->p0 = (double[4]){o->S, o->S0, o->Omega, o->phi}[r->param];
    if (!(r->p0 >= a->lo && r->p0 <= a->hi))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s = %s (the model's parameter, or its default) is outside the range "
                       "%s=%s:%s; start inside the range",
                       a->vary, CM_NUM(r->p0), a->vary, CM_NUM(a->lo), CM_NUM(a->hi));
    return continuation_follow(a, o, r->param, r->p0, &r->col, msg, msg_size);
}

cm_status continuation_write(const cont_args *a, cont_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (a->csv)
        st = continuation_write_points(a, &r->col, msg, msg_size);
    if (st == CM_OK && a->events)
        st = continuation_write_events(a, &r->col, msg, msg_size);
    if (st == CM_OK && a->png)
        st = continuation_write_png(a, &r->m, &r->col, msg, msg_size);
    if (st == CM_OK && a->curves)
        st = continuation_write_curves(a, r->o, &r->col, &r->n_curves, msg, msg_size);
    return st;
}

void continuation_result_free(cont_result *r)
{
    continuation_free(&r->col);
    cm_model_release(&r->m);
}
