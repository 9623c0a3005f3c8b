/* lib/equilibria.c - equilibria, their branches and Hopf curves of flow
 * models (lib/equilibria.h). */
#include "lib/equilibria.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/rows.h"
#include "models/ode_flow.h"
#include "models/params.h"

eq_args equilibria_defaults(void)
{
    eq_args a;
    memset(&a, 0, sizeof a);
    a.mo.name = "chip-4d";
    a.b.max_points = 10000;
    return a;
}

const char *equilibria_event_name(int kind) { return kind == CM_EQ_HOPF ? "hopf" : "fold"; }

const char *equilibria_why(int why)
{
    switch (why) {
    case CM_BRANCH_LEFT_RANGE: return "left the range";
    case CM_BRANCH_MAX_POINTS: return "reached the most points";
    case CM_BRANCH_LOST: return "lost (Newton failed at the smallest step)";
    case CM_BRANCH_CALLER: return "stopped";
    default: return "not followed";
    }
}

static int on_point(void *user, const cm_equilibrium *e)
{
    eq_result *r = user;
    if (!rows_room((void **)&r->pts, &r->cap_pts, r->n_pts, sizeof *r->pts))
        return 1;
    r->pts[r->n_pts++] = *e;
    return 0;
}

static int on_event(void *user, const cm_eq_event *ev)
{
    eq_result *r = user;
    if (!rows_room((void **)&r->events, &r->cap_events, r->n_events, sizeof *r->events))
        return 1;
    r->events[r->n_events++] = (eq_event){*ev, r->n_pts};
    return 0;
}

static int on_hopf(void *user, double q, const cm_eq_event *ev)
{
    eq_result *r = user;
    if (!rows_room((void **)&r->hopf, &r->cap_hopf, r->n_hopf, sizeof *r->hopf))
        return 1;
    r->hopf[r->n_hopf++] = (eq_hopf){q, *ev};
    return 0;
}

static cm_status check_request(const eq_args *a, const cm_model *m, double *p0, char *msg,
                               size_t msg_size)
{
    if (!cm_model_is_flow(m))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "model %s is a map, not a flow: equilibria are those of an ODE's vector "
                       "field (e.g. chip-4d, duffing, a plugin's flow)",
                       m->name);
    const int n = cm_flow_dim(m);
    if (a->b.n_from != n) {
        char names[256] = "";
        for (int d = 0; d < n; d++)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", d ? ", " : "",
                     cm_flow_coord_name(m, d));
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the start has %d value(s) but the flow of model %s has %d coordinates "
                       "(%s)",
                       a->b.n_from, m->name, n, names);
    }
    if (a->has_curve && (!a->b.name[0] || a->b.direction))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a Hopf curve needs a branch over its whole range: name the parameter it "
                       "follows and give no direction");
    cm_status st = branch_spec_check(&a->b, m, p0, msg, msg_size);
    if (st == CM_OK && a->has_curve) {
        double q;
        if (strcmp(a->curve.name, a->b.name) == 0)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the Hopf curve's parameter must differ from the branch's (%s)",
                           a->b.name);
        st = param_number(m, a->curve.name, "the Hopf curve's parameter", &q, msg, msg_size);
    }
    return st;
}

/* The way just followed, whose points are pts[pts_from ..] and events
 * events[events_from ..], put in the branch's order: the way down
 * reversed; the way up without its first point when the way down has
 * given it already. */
static void join_way(eq_result *r, int direction, size_t pts_from, size_t events_from)
{
    const size_t m = r->n_pts - pts_from;
    if (direction < 0) {
        rows_reverse(r->pts, pts_from, r->n_pts, sizeof *r->pts);
        rows_reverse(r->events, events_from, r->n_events, sizeof *r->events);
        for (size_t k = events_from; k < r->n_events; k++)
            r->events[k].before = pts_from + (m - (r->events[k].before - pts_from));
    } else if (pts_from > 0 && m > 0) {
        memmove(&r->pts[pts_from], &r->pts[pts_from + 1], (m - 1) * sizeof *r->pts);
        r->n_pts--;
        for (size_t k = events_from; k < r->n_events; k++)
            r->events[k].before--;
    }
}

/* Both ways (or the one asked for) from the start, lo side first. */
static cm_status follow_branch(const eq_args *a, eq_result *r, double p0, char *msg,
                               size_t msg_size)
{
    param_builder u = {&a->mo, {a->b.name, NULL}};
    for (int way = 0; way < 2; way++) {
        const int direction = way == 0 ? -1 : 1;
        if (a->b.direction && a->b.direction != direction)
            continue;
        const cm_branch_options o = {a->b.lo, a->b.hi, direction, 0, a->b.ds_max, a->b.max_points};
        const size_t pts_from = r->n_pts, events_from = r->n_events;
        const cm_status st =
            cm_flow_equilibrium_branch(param_model_at, &u, p0, r->start.x, &o, on_point,
                                       on_event, r, &r->why[way], msg, msg_size);
        if (st != CM_OK)
            return st;
        if (r->why[way] == CM_BRANCH_CALLER)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the branch's points");
        join_way(r, direction, pts_from, events_from);
    }
    return CM_OK;
}

cm_status equilibria_compute(const eq_args *a, eq_result *r, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    cm_status st = model_spec_build(&a->mo, &r->m, msg, msg_size);
    if (st != CM_OK)
        return st;
    r->base = r->m.values;
    double p0 = NAN;
    if ((st = check_request(a, &r->m, &p0, msg, msg_size)) != CM_OK)
        return st;
    double x[CM_MAX_DIM];
    memcpy(x, a->b.from, sizeof x);
    if ((st = cm_flow_equilibrium(&r->m, p0, x, &r->start, msg, msg_size)) != CM_OK)
        return st;
    if (a->b.name[0] && (st = follow_branch(a, r, p0, msg, msg_size)) != CM_OK)
        return st;
    if (!a->has_curve)
        return CM_OK;
    double q[PARAM_AXIS_MAX];
    for (int k = 0; k < a->curve.n; k++)
        q[k] = param_axis_value(&a->curve, k);
    /* each value's branch from the lowest point of this one, upwards */
    param_builder u = {&a->mo, {a->b.name, a->curve.name}};
    const cm_branch_options o = {a->b.lo, a->b.hi, 1, 0, a->b.ds_max, a->b.max_points};
    const cm_equilibrium *low = r->n_pts ? &r->pts[0] : &r->start;
    return cm_flow_hopf_curve(param_model_at2, &u, low->p, low->x, q, a->curve.n, &o, on_hopf,
                              r, msg, msg_size);
}

/* One CSV row: kind, the branch's and curve's values (when asked), the
 * equilibrium and its eigenvalues, omega. */
static void row(FILE *f, const eq_args *a, const char *kind, double q, const cm_equilibrium *e,
                double omega)
{
    fprintf(f, "%s", kind);
    if (a->b.name[0])
        fprintf(f, ",%.17g", e->p);
    if (a->has_curve)
        fprintf(f, ",%.17g", q);
    for (int d = 0; d < e->dim; d++)
        fprintf(f, ",%.17g", e->x[d]);
    for (int d = 0; d < e->dim; d++)
        fprintf(f, ",%.17g,%.17g", e->re[d], e->im[d]);
    fprintf(f, ",%d,%.17g\n", e->unstable, omega);
}

cm_status equilibria_write(const eq_args *a, const eq_result *r, char *msg, size_t msg_size)
{
    if (!a->csv)
        return CM_OK;
    outfile o;
    cm_status st = outfile_begin(a->csv, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int n = cm_flow_dim(&r->m);
    fprintf(o.f, "kind");
    if (a->b.name[0])
        fprintf(o.f, ",%s", a->b.name);
    if (a->has_curve)
        fprintf(o.f, ",%s", a->curve.name);
    for (int d = 0; d < n; d++)
        fprintf(o.f, ",%s", cm_flow_coord_name(&r->m, d));
    for (int d = 1; d <= n; d++)
        fprintf(o.f, ",re_%d,im_%d", d, d);
    fprintf(o.f, ",unstable,omega\n");
    if (a->has_curve) {
        for (size_t k = 0; k < r->n_hopf; k++)
            row(o.f, a, "hopf", r->hopf[k].q, &r->hopf[k].ev.at, r->hopf[k].ev.omega);
    } else if (!a->b.name[0]) {
        row(o.f, a, "equilibrium", NAN, &r->start, NAN);
    } else {
        /* the points and, between them, the events in branch order */
        size_t e = 0;
        for (size_t k = 0; k <= r->n_pts; k++) {
            for (; e < r->n_events && r->events[e].before <= k; e++) {
                const cm_eq_event *ev = &r->events[e].ev;
                row(o.f, a, equilibria_event_name(ev->kind), NAN, &ev->at,
                    ev->kind == CM_EQ_HOPF ? ev->omega : NAN);
            }
            if (k < r->n_pts)
                row(o.f, a, "point", NAN, &r->pts[k], NAN);
        }
    }
    return outfile_end(&o, true, msg, msg_size);
}

static void print_eigenvalues(FILE *f, const cm_equilibrium *e)
{
    for (int d = 0; d < e->dim; d++) {
        if (e->im[d] < 0)
            continue; /* a pair prints once, as re +- im i */
        fprintf(f, "%s%.6g", d ? ", " : "", e->re[d]);
        if (e->im[d] > 0)
            fprintf(f, " +- %.6gi", e->im[d]);
    }
}

static void print_state(FILE *f, const cm_model *m, const cm_equilibrium *e)
{
    for (int d = 0; d < e->dim; d++)
        fprintf(f, "%s%s = %.9g", d ? ", " : "", cm_flow_coord_name(m, d), e->x[d]);
}

void equilibria_report(FILE *f, const eq_args *a, const eq_result *r)
{
    fprintf(f, "equilibrium: ");
    print_state(f, &r->m, &r->start);
    fprintf(f, "\neigenvalues: ");
    print_eigenvalues(f, &r->start);
    fprintf(f, "\n%s\n", r->start.unstable ? "unstable" : "stable");
    if (a->b.name[0]) {
        fprintf(f, "branch in %s over %g:%g: %zu points", a->b.name, a->b.lo, a->b.hi, r->n_pts);
        if (r->why[0])
            fprintf(f, "; down: %s", equilibria_why(r->why[0]));
        if (r->why[1])
            fprintf(f, "; up: %s", equilibria_why(r->why[1]));
        fprintf(f, "\n");
        for (size_t k = 0; !a->has_curve && k < r->n_events; k++) {
            const cm_eq_event *ev = &r->events[k].ev;
            fprintf(f, "%s at %s = %.9g", equilibria_event_name(ev->kind), a->b.name, ev->at.p);
            if (ev->kind == CM_EQ_HOPF)
                fprintf(f, ", omega %.6g", ev->omega);
            fprintf(f, " (");
            print_state(f, &r->m, &ev->at);
            fprintf(f, ")\n");
        }
    }
    for (size_t k = 0; k < r->n_hopf; k++)
        fprintf(f, "hopf at %s = %.9g, %s = %.9g, omega %.6g\n", a->curve.name, r->hopf[k].q,
                a->b.name, r->hopf[k].ev.at.p, r->hopf[k].ev.omega);
}

void equilibria_json(FILE *f, const eq_args *a, const eq_result *r)
{
    json j;
    json_begin(&j, f, "equilibria");
    json_model(&j, &r->m);
    json_nums(&j, "from", a->b.from, a->b.n_from);
    json_nums(&j, "equilibrium", r->start.x, r->start.dim);
    json_nums(&j, "re", r->start.re, r->start.dim);
    json_nums(&j, "im", r->start.im, r->start.dim);
    json_int(&j, "unstable", r->start.unstable);
    if (a->b.name[0]) {
        json_str(&j, "branch", a->b.name);
        json_int(&j, "points", (long long)r->n_pts);
        json_array(&j, "events");
        for (size_t k = 0; k < r->n_events; k++) {
            const cm_eq_event *ev = &r->events[k].ev;
            json_object(&j, NULL);
            json_str(&j, "kind", equilibria_event_name(ev->kind));
            json_num(&j, "p", ev->at.p);
            json_nums(&j, "x", ev->at.x, ev->at.dim);
            if (ev->kind == CM_EQ_HOPF)
                json_num(&j, "omega", ev->omega);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    if (a->has_curve) {
        json_array(&j, "hopf_curve");
        for (size_t k = 0; k < r->n_hopf; k++) {
            json_object(&j, NULL);
            json_num(&j, "q", r->hopf[k].q);
            json_num(&j, "p", r->hopf[k].ev.at.p);
            json_num(&j, "omega", r->hopf[k].ev.omega);
            json_object_end(&j);
        }
        json_array_end(&j);
    }
    json_end(&j);
}

void equilibria_result_free(eq_result *r)
{
    cm_model_release(&r->m);
    free(r->pts);
    free(r->events);
    free(r->hopf);
    memset(r, 0, sizeof *r);
}
