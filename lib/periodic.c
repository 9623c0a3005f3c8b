/* lib/periodic.c - periodic orbits of maps, their branches and cascades
 * (lib/periodic.h). */
#include "lib/periodic.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/rows.h"
#include "models/flow_equilibria.h"
#include "models/ode_flow.h"
#include "models/params.h"

#define FEIGENBAUM_DELTA 4.669201609102990

po_args periodic_defaults(void)
{
    po_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "chip-4d";
    a.period = 1;
    a.b.max_points = 10000;
    return a;
}

const char *periodic_event_name(int kind)
{
    return kind == CM_PO_PD ? "pd" : kind == CM_PO_NS ? "ns" : "fold";
}

double periodic_accumulation(const po_result *r)
{
    const int n = r->n_doublings;
    if (n < 2)
        return NAN;
    const double last = r->doublings[n - 1], spacing = last - r->doublings[n - 2];
    return last + spacing / (FEIGENBAUM_DELTA - 1);
}

/* What the branch callbacks fill: the result, and for a cascade the
 * first doubling of the branch (which stops it). */
typedef struct collect {
    po_result *r;
    bool cascade;
    bool doubled;
    cm_po_event pd;
} collect;

static int on_point(void *user, const cm_periodic_point *pt)
{
    po_result *r = ((collect *)user)->r;
    if (!rows_room((void **)&r->pts, &r->cap_pts, r->n_pts, sizeof *r->pts))
        return 1;
    r->pts[r->n_pts++] = *pt;
    return 0;
}

static int on_event(void *user, const cm_po_event *ev)
{
    collect *c = user;
    po_result *r = c->r;
    if (!rows_room((void **)&r->events, &r->cap_events, r->n_events, sizeof *r->events))
        return 1;
    r->events[r->n_events++] = (po_found){*ev, r->n_pts};
    if (c->cascade && ev->kind == CM_PO_PD) {
        c->doubled = true;
        c->pd = *ev;
        return 1; /* a cascade goes on from its first doubling */
    }
    return 0;
}

static cm_status check_request(const po_args *a, const cm_model *m, double *p0, char *msg,
                               size_t msg_size)
{
    if (a->b.n_from != m->dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the start has %d value(s) but model %s's map has dimension %d", a->b.n_from,
                       m->name, m->dim);
    if (a->period < 1 || a->period > 4096 || a->settle < 0 || a->settle > 10000000)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a period of %d and %d settling iterates: give a period of 1..4096 and "
                       "0..1e7 iterates",
                       a->period, a->settle);
    if (a->cascade && (!a->b.name[0] || a->b.direction == 0 || a->cascade > PERIODIC_MAX_CASCADE))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a cascade of %d doublings: give 1..%d, the parameter it follows and the "
                       "direction it goes (up or down)",
                       a->cascade, PERIODIC_MAX_CASCADE);
    return branch_spec_check(&a->b, m, p0, msg, msg_size);
}

/* The way just followed (points from pts_from, events from events_from)
 * in the branch's order: the way down reversed, the way up without its
 * first point when the way down has given it already. */
static void join_way(po_result *r, int direction, size_t pts_from, size_t events_from,
                     bool both)
{
    const size_t m = r->n_pts - pts_from;
    if (direction < 0) {
        rows_reverse(r->pts, pts_from, r->n_pts, sizeof *r->pts);
        rows_reverse(r->events, events_from, r->n_events, sizeof *r->events);
        for (size_t k = events_from; k < r->n_events; k++)
            r->events[k].before = pts_from + (m - (r->events[k].before - pts_from));
    } else if (both && m > 0) {
        memmove(&r->pts[pts_from], &r->pts[pts_from + 1], (m - 1) * sizeof *r->pts);
        r->n_pts--;
        for (size_t k = events_from; k < r->n_events; k++)
            r->events[k].before--;
    }
}

/* The branch of period `period` from x at p, one way or both. */
static cm_status follow(const po_args *a, const param_builder *u, int period, double p,
                        const double *x, int direction, collect *c, char *msg, size_t msg_size)
{
    po_result *r = c->r;
    for (int way = 0; way < 2; way++) {
        const int dir = way == 0 ? -1 : 1;
        if (direction && direction != dir)
            continue;
        const cm_branch_options o = {a->b.lo, a->b.hi, dir, 0, a->b.ds_max, a->b.max_points};
        const size_t pts_from = r->n_pts, events_from = r->n_events;
        int why = 0;
        const cm_status st =
            cm_map_periodic_branch(param_model_at, (void *)u, period, p, x, &o, on_point,
                                   on_event, c, &why, msg, msg_size);
        if (st != CM_OK)
            return st;
        if (why == CM_BRANCH_CALLER && !c->doubled)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the branch's points");
        if (r->why[way] == 0)
            r->why[way] = why;
        join_way(r, dir, pts_from, events_from, direction == 0);
    }
    return CM_OK;
}

/* Doubling after doubling: each branch followed to its first period
 * doubling, the next one started next to it. */
static cm_status cascade(const po_args *a, const param_builder *u, po_result *r, double p0,
                         char *msg, size_t msg_size)
{
    double x[CM_MAX_DIM], p = p0;
    memcpy(x, r->start.x, sizeof x);
    int period = a->period;
    for (int k = 0; k < a->cascade; k++) {
        collect c = {r, true, false, {0}};
        cm_status st = follow(a, u, period, p, x, a->b.direction, &c, msg, msg_size);
        if (st != CM_OK)
            return st;
        if (!c.doubled)
            return k > 0 ? CM_OK /* the range holds no more doublings */
                         : cm_fail(CM_ENOTFOUND, msg, msg_size,
                                   "the period-%d branch has no period doubling in %s=%g:%g",
                                   period, a->b.name, a->b.lo, a->b.hi);
        r->doublings[r->n_doublings++] = c.pd.at.p;
        if (k + 1 == a->cascade)
            break;
        /* the step from the doubling: 1e-4 shrinking as the cascade's
         * spacing does */
        const double dp = a->b.direction * 1e-4 * pow(FEIGENBAUM_DELTA, -k);
        st = cm_map_period_doubled(param_model_at, (void *)u, &c.pd, dp, x, &p, msg, msg_size);
        if (st != CM_OK)
            return st;
        period *= 2;
    }
    return CM_OK;
}

/* The model spec with the flow's tolerances at 1e-12 first (the user's
 * parameters after them win); mo has room for one more text. */
static void tightened(const model_spec *mo, model_spec *out)
{
    *out = *mo;
    out->texts[0] = "abs_tol=1e-12,rel_tol=1e-12";
    memcpy(&out->texts[1], mo->texts, (size_t)mo->n_texts * sizeof *mo->texts);
    out->n_texts = mo->n_texts + 1;
}

/* Whether the user's parameters set the integrator's tolerances. */
static bool sets_tolerances(const model_spec *mo)
{
    for (int i = 0; i < mo->n_texts; i++)
        if (strstr(mo->texts[i], "abs_tol") || strstr(mo->texts[i], "rel_tol"))
            return true;
    return false;
}

static int stop_at_hopf(void *user, const cm_eq_event *ev)
{
    cm_eq_event *found = user;
    if (ev->kind != CM_EQ_HOPF)
        return 0;
    *found = *ev;
    return 1;
}

/* The start of a branch born at the first Hopf point of the flow's
 * equilibrium from a->b.from: its orbit's point on the plane through the
 * equilibrium (mo gets level=), into r->start; *p0 its parameter value. */
static cm_status hopf_start(const po_args *a, model_spec *mo, char level_text[64], po_result *r,
                            double *p0, char *msg, size_t msg_size)
{
    const cm_model *m = &r->m;
    if (!m->flow.plane || a->b.n_from != cm_flow_dim(m) || !a->b.name[0] || a->cascade ||
        a->period != 1 || a->settle)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "--hopf starts from an equilibrium of a flow with a section plane: give "
                       "its %d flow coordinates, the branch P=LO:HI to search, and no period, "
                       "settle or cascade",
                       cm_flow_dim(m));
    if (mo->n_texts >= MODEL_SPEC_TEXTS)
        return cm_fail(CM_EINVAL, msg, msg_size, "too many --param options for --hopf");
    cm_status st = param_number(m, a->b.name, "--branch", p0, msg, msg_size);
    if (st != CM_OK)
        return st;
    const param_builder eq = {mo, {a->b.name, NULL}};
    const cm_branch_options o = {a->b.lo, a->b.hi, a->b.direction ? a->b.direction : 1, 0,
                                 a->b.ds_max, a->b.max_points};
    cm_eq_event hopf = {0};
    int why = 0;
    st = cm_flow_equilibrium_branch(param_model_at, (void *)&eq, *p0, a->b.from, &o, NULL,
                                    stop_at_hopf, &hopf, &why, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (hopf.kind != CM_EQ_HOPF)
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "the equilibrium's branch from %s = %g meets no Hopf point %s to %g",
                       a->b.name, *p0, o.direction > 0 ? "up" : "down",
                       o.direction > 0 ? a->b.hi : a->b.lo);
    /* the section plane through the equilibrium */
    const int k = m->flow.plane - 1;
    snprintf(level_text, 64, "level=%.17g", hopf.at.x[k]);
    mo->texts[mo->n_texts++] = level_text;
    r->from_hopf = true;
    r->hopf_p = hopf.at.p, r->hopf_omega = hopf.omega, r->level = hopf.at.x[k];
    const param_builder u = {mo, {a->b.name, NULL}};
    const double dp = 1e-3 * fmax(1, fabs(hopf.at.p));
    double x[CM_MAX_DIM];
    st = cm_map_hopf_orbit(param_model_at, (void *)&u, &hopf.at, hopf.omega, dp, x, p0, msg,
                           msg_size);
    cm_model hm;
    if (st == CM_OK)
        st = param_model_at((void *)&u, *p0, &hm, msg, msg_size);
    if (st == CM_OK) {
        st = cm_map_periodic_point(&hm, *p0, 1, x, &r->start, msg, msg_size);
        cm_model_release(&hm);
    }
    return st;
}

cm_status periodic_compute(const po_args *a, po_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    model_spec mo = a->mo;
    cm_status st = model_spec_build(&a->mo, &r->m, msg, msg_size);
    if (st == CM_OK && cm_model_is_flow(&r->m) && !sets_tolerances(&a->mo) &&
        a->mo.n_texts < MODEL_SPEC_TEXTS) {
        tightened(&a->mo, &mo);
        cm_model_release(&r->m);
        r->tightened = true;
        st = model_spec_build(&mo, &r->m, msg, msg_size);
    }
    double p0 = NAN, x[CM_MAX_DIM], y[CM_MAX_DIM];
    char level_text[64];
    if (st == CM_OK && a->hopf) {
        st = hopf_start(a, &mo, level_text, r, &p0, msg, msg_size);
        if (st != CM_OK)
            return st;
        const param_builder u = {&mo, {a->b.name, NULL}};
        collect c = {r, false, false, {0}};
        return follow(a, &u, 1, p0, r->start.x, a->b.direction, &c, msg, msg_size);
    }
    if (st == CM_OK)
        st = check_request(a, &r->m, &p0, msg, msg_size);
    if (st != CM_OK)
        return st;
    memcpy(x, a->b.from, sizeof x);
    for (int k = 0; k < a->settle; k++) {
        if (r->m.step(&r->m, x, y) != CM_STEP_OK) /* step need not take its image in place */
            return cm_fail(CM_ENOTFOUND, msg, msg_size,
                           "the orbit from the start has no image after %d iterates: start "
                           "elsewhere or settle fewer",
                           k);
        memcpy(x, y, sizeof x);
    }
    if ((st = cm_map_periodic_point(&r->m, p0, a->period, x, &r->start, msg, msg_size)) != CM_OK)
        return st;
    if (!a->b.name[0])
        return CM_OK;
    const param_builder u = {&mo, {a->b.name, NULL}};
    if (a->cascade)
        return cascade(a, &u, r, p0, msg, msg_size);
    collect c = {r, false, false, {0}};
    return follow(a, &u, a->period, p0, r->start.x, a->b.direction, &c, msg, msg_size);
}

/* One CSV row. */
static void row(FILE *f, const po_args *a, const char *kind, const cm_periodic_point *pt)
{
    fprintf(f, "%s,%d", kind, pt->period);
    if (a->b.name[0])
        fprintf(f, ",%.17g", pt->p);
    for (int d = 0; d < pt->dim; d++)
        fprintf(f, ",%.17g", pt->x[d]);
    for (int d = 0; d < pt->dim; d++)
        fprintf(f, ",%.17g,%.17g", pt->re[d], pt->im[d]);
    fprintf(f, ",%d\n", pt->outside);
}

cm_status periodic_write(const po_args *a, const po_result *r, char *msg, size_t msg_size)
{
    if (!a->csv)
        return CM_OK;
    outfile o;
    cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = r->m.dim;
    fprintf(o.f, "kind,period");
    if (a->b.name[0])
        fprintf(o.f, ",%s", a->b.name);
    for (int d = 0; d < n; d++)
        fprintf(o.f, ",%s", cm_model_coord_name(&r->m, d));
    for (int d = 1; d <= n; d++)
        fprintf(o.f, ",re_%d,im_%d", d, d);
    fprintf(o.f, ",outside\n");
    if (!a->b.name[0]) {
        row(o.f, a, "point", &r->start);
    } else {
        size_t e = 0;
        for (size_t k = 0; k <= r->n_pts; k++) {
            for (; e < r->n_events && r->events[e].before <= k; e++)
                row(o.f, a, periodic_event_name(r->events[e].ev.kind), &r->events[e].ev.at);
            if (k < r->n_pts)
                row(o.f, a, "point", &r->pts[k]);
        }
    }
    return outfile_end(&o, true, msg, msg_size);
}

static void print_point(FILE *f, const cm_model *m, const cm_periodic_point *pt)
{
    for (int d = 0; d < pt->dim; d++)
        fprintf(f, "%s%s = %.9g", d ? ", " : "", cm_model_coord_name(m, d), pt->x[d]);
    fprintf(f, "; multipliers ");
    for (int d = 0; d < pt->dim; d++) {
        if (pt->im[d] < 0)
            continue; /* a pair prints once */
        fprintf(f, "%s%.6g", d ? ", " : "", pt->re[d]);
        if (pt->im[d] > 0)
            fprintf(f, " +- %.6gi", pt->im[d]);
    }
}

void periodic_report(FILE *f, const po_args *a, const po_result *r)
{
    if (r->tightened)
        fprintf(f, "(the flow's tolerances: 1e-12)\n");
    if (r->from_hopf)
        fprintf(f, "Hopf point at %s = %.9g (omega %.6g); the section plane through it: level %.9g\n",
                a->b.name, r->hopf_p, r->hopf_omega, r->level);
    fprintf(f, "period-%d point: ", a->period);
    print_point(f, &r->m, &r->start);
    fprintf(f, "\n%s\n", r->start.outside ? "unstable" : "stable");
    if (!a->b.name[0])
        return;
    fprintf(f, "%s over %g:%g: %zu points\n", a->b.name, a->b.lo, a->b.hi, r->n_pts);
    for (size_t k = 0; k < r->n_events; k++) {
        const cm_po_event *ev = &r->events[k].ev;
        fprintf(f, "%s of period %d at %s = %.9g (", periodic_event_name(ev->kind),
                ev->at.period, a->b.name, ev->at.p);
        print_point(f, &r->m, &ev->at);
        fprintf(f, ")\n");
    }
    for (int k = 1; k + 1 < r->n_doublings; k++)
        fprintf(f, "Feigenbaum ratio %d: %.4f\n", k,
                (r->doublings[k] - r->doublings[k - 1]) / (r->doublings[k + 1] - r->doublings[k]));
    if (r->n_doublings >= 2)
        fprintf(f, "the cascade accumulates near %s = %.6g (delta = 4.6692)\n", a->b.name,
                periodic_accumulation(r));
}

void periodic_json(FILE *f, const po_args *a, const po_result *r)
{
    json j;
    json_begin(&j, f, "periodic");
    json_model(&j, &r->m);
    json_nums(&j, "from", a->b.from, a->b.n_from);
    json_int(&j, "period", a->period);
    json_nums(&j, "point", r->start.x, r->start.dim);
    json_nums(&j, "re", r->start.re, r->start.dim);
    json_nums(&j, "im", r->start.im, r->start.dim);
    json_int(&j, "outside", r->start.outside);
    if (a->b.name[0]) {
        json_str(&j, "branch", a->b.name);
        json_int(&j, "points", (long long)r->n_pts);
        json_array(&j, "events");
        for (size_t k = 0; k < r->n_events; k++) {
            const cm_po_event *ev = &r->events[k].ev;
            json_object(&j, NULL);
            json_str(&j, "kind", periodic_event_name(ev->kind));
            json_int(&j, "period", ev->at.period);
            json_num(&j, "p", ev->at.p);
            json_nums(&j, "x", ev->at.x, ev->at.dim);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    if (a->cascade) {
        json_nums(&j, "doublings", r->doublings, r->n_doublings);
        if (r->n_doublings >= 2)
            json_num(&j, "accumulation", periodic_accumulation(r));
    }
    json_end(&j);
}

void periodic_result_free(po_result *r)
{
    cm_model_release(&r->m);
    free(r->pts);
    free(r->events);
    memset(r, 0, sizeof *r);
}
