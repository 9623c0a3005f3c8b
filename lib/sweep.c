/* lib/sweep.c - a parameter swept (lib/sweep.h). */
#include "lib/sweep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lib/param_grid.h"
#include "lib/work.h"

static bool in_window(const sweep_args *a, const cm_group_info *g)
{
    for (int d = 0; d < a->n_near; d++)
        if (!(g->centre[d] >= a->near_lo[d] && g->centre[d] <= a->near_hi[d]))
            return false;
    return true;
}

/* The system's attractors (cellmap/attractors.h) in the window: sticking
 * zones are kept as cell mapping gives them. */
static void count_attractors(const sweep_args *a, const cm_attractor_set *s, uint32_t ngroups,
                             sweep_point *pt)
{
    pt->groups = ngroups;
    for (uint32_t k = 0; k < s->n; k++) {
        const cm_attractor *at = &s->a[k];
        cm_group_info as_group = {.kind = at->kind == CM_ATTRACTOR_STICKING ? CM_GROUP_STICKING
                                                                          : CM_GROUP_ATTRACTOR};
        memcpy(as_group.centre, at->centre, sizeof at->centre);
        if (!in_window(a, &as_group))
            continue;
        if (at->kind == CM_ATTRACTOR_STICKING) {
            pt->sticking++;
            pt->sticking_cells += at->basin_cells;
        } else {
            pt->attractors++;
            pt->attractor_cells += at->basin_cells;
        }
    }
}

static void count_groups(const sweep_args *a, const cm_group_info *groups, uint32_t n,
                         sweep_point *pt)
{
    pt->groups = n;
    for (uint32_t k = 0; k < n; k++) {
        if (!in_window(a, &groups[k]))
            continue;
        if (groups[k].kind == CM_GROUP_STICKING) {
            pt->sticking++;
            pt->sticking_cells += groups[k].basin_cells;
        } else {
            pt->attractors++;
            pt->attractor_cells += groups[k].basin_cells;
        }
    }
}

cm_status sweep_solve_at(const sweep_args *a, const cm_lattice *lat, const cm_box *box,
                         double value, sweep_point *pt, char *msg, size_t msg_size)
{
    memset(pt, 0, sizeof *pt);
    pt->value = value;
    const double t0 = cm_seconds();
    cm_model m;
    const char *name = a->name;
    if (!model_with_values(&a->mo, &name, &value, 1, &m, msg, msg_size))
        return CM_EINVAL;
    const cm_scm_options opt = {.max_steps = a->max_steps,
                                .threads = a->threads,
                                .record_exits = 1}; /* exits followed */
    cm_region r;
    memset(&r, 0, sizeof r);
    cm_group_info *groups = NULL;
    cm_exits exits = {0};
    cm_status st = cm_region_alloc(&r, box, msg, msg_size);
    if (st == CM_OK)
        st = cm_scm_solve(&m, lat, &opt, &r, msg, msg_size);
    if (st == CM_OK)
        st = cm_region_settle_exits(&r, a->threads, &exits, msg, msg_size);
    if (st == CM_OK)
        st = cm_scm_describe(&m, lat, &r, &groups, &pt->sink_cells, msg, msg_size);
    cm_attractor_set att;
    memset(&att, 0, sizeof att);
    if (st == CM_OK && a->by == BY_ATTRACTORS) {
        cm_attractor_options o = a->att;
        o.threads = a->threads;
        st = cm_region_attractors(&m, lat, &r, a->max_steps, &exits, groups, &o, &att, msg,
                                  msg_size);
        if (st == CM_OK)
            count_attractors(a, &att, r.ngroups, pt);
    } else if (st == CM_OK) {
        count_groups(a, groups, r.ngroups, pt);
    }
    cm_attractors_free(&att);
    cm_exits_free(&exits);
    free(groups);
    cm_region_free(&r);
    cm_model_release(&m);
    pt->seconds = cm_seconds() - t0;
    return st;
}

bool sweep_write_csv(const sweep_args *a, const sweep_point *pts, int n, char *msg, size_t msg_size)
{
    outfile o;
    if (outfile_begin(a->csv, &o, msg, msg_size) != CM_OK)
        return false;
    fprintf(o.f,
            "%s,attractors,sticking,attractor_cells,sticking_cells,groups,sink_cells,seconds\n",
            a->name);
    for (int k = 0; k < n; k++)
        fprintf(o.f, "%.17g,%u,%u,%llu,%llu,%u,%llu,%.3f\n", pts[k].value, pts[k].attractors,
                pts[k].sticking, (unsigned long long)pts[k].attractor_cells,
                (unsigned long long)pts[k].sticking_cells, pts[k].groups,
                (unsigned long long)pts[k].sink_cells, pts[k].seconds);
    return (outfile_end(&o, true, msg, msg_size) == CM_OK);
}

cm_status sweep_check_setup(const sweep_args *a, sweep_result *r, char *msg, size_t msg_size)
{
    *r = (sweep_result){0};
    if (a->n_values < 2 || a->n_values > MAX_VALUES || a->refine < 0 || a->refine > MAX_REFINE ||
        a->max_steps < 0 || a->max_steps > PROJECT_MAX_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%d values, refine %d, max steps %d: need 2..%d values, 0..%d bisections "
                       "and 0..%d steps",
                       a->n_values, a->refine, a->max_steps, MAX_VALUES, MAX_REFINE,
                       PROJECT_MAX_STEPS);
    for (int k = 1; k < a->n_values; k++)
        if (!(a->values[k] > a->values[k - 1]))
            return cm_fail(CM_EINVAL, msg, msg_size, "the values must increase");
    for (int d = 0; d < a->n_near; d++)
        if (!(a->near_lo[d] < a->near_hi[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "the window needs LO < HI in each dimension");
    cm_model m;
    cm_status st = model_spec_build(&a->mo, &m, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (cm_params_find(&m.values, a->name) < 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "'%s' is not a parameter of %s (`cellmap models`)",
                     a->name, m.name);
    else if (a->n_near > m.dim)
        st = cm_fail(CM_EINVAL, msg, msg_size,
                     "the window has %d range(s) but model %s has dimension %d", a->n_near,
                     m.name, m.dim);
    else
        st = lattice_of_spec(&a->lat, &m, &a->mo.set, &r->lat, &r->box, msg, msg_size);
    cm_model_release(&m);
    for (int k = 0; k < a->n_values && st == CM_OK; k++) {
        const char *name = a->name;
        char why[256];
        if (!model_with_values(&a->mo, &name, &a->values[k], 1, &m, why, sizeof why))
            st = cm_fail(CM_EINVAL, msg, msg_size, "%s = %s: %s", a->name, CM_NUM(a->values[k]),
                         why);
        else
            cm_model_release(&m);
    }
    return st;
}

/* Changes are changes of the number of attractors: sticking zones are sets
 * of rest cells whose count grows with the zones' width. */
static bool same_counts(const sweep_point *x, const sweep_point *y)
{
    return x->attractors == y->attractors;
}

/* Solves value into the next point of r (r->failed_value on failure). */
static cm_status solve_next(const sweep_args *a, const work_hooks *h, sweep_result *r,
                            double value, char *msg, size_t msg_size)
{
    const cm_status stopped = work_check(h, msg, msg_size);
    if (stopped != CM_OK)
        return stopped;
    r->failed_value = value;
    const cm_status st = sweep_solve_at(a, &r->lat, &r->box, value, &r->pts[r->n], msg, msg_size);
    r->n += st == CM_OK;
    return st;
}

/* Bisects between ch->lo and ch->hi (whose counts differ) a->refine times;
 * the solved midpoints are appended to r's points. */
static cm_status refine_change(const sweep_args *a, const work_hooks *h, sweep_result *r,
                               sweep_change *ch, char *msg, size_t msg_size)
{
    sweep_point lo = ch->lo, hi = ch->hi;
    for (int k = 0; k < a->refine; k++) {
        const cm_status st = solve_next(a, h, r, 0.5 * (lo.value + hi.value), msg, msg_size);
        if (st != CM_OK)
            return st;
        const sweep_point *mid = &r->pts[r->n - 1];
        if (same_counts(mid, &lo))
            lo = *mid;
        else
            hi = *mid;
    }
    ch->lo = lo;
    ch->hi = hi;
    return CM_OK;
}

static int by_value(const void *x, const void *y)
{
    const double u = ((const sweep_point *)x)->value, v = ((const sweep_point *)y)->value;
    return (u > v) - (u < v);
}

cm_status sweep_compute(const sweep_args *a, const work_hooks *h, const sweep_report *rep,
                        sweep_result *r, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    r->pts = malloc((size_t)(a->n_values * (1 + a->refine)) * sizeof *r->pts);
    r->changes = malloc((size_t)a->n_values * sizeof *r->changes);
    if (!r->pts || !r->changes)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory");
    for (int k = 0; k < a->n_values && st == CM_OK; k++) {
        st = solve_next(a, h, r, a->values[k], msg, msg_size);
        if (st == CM_OK && rep && rep->point)
            rep->point(rep->user, a, &r->pts[r->n - 1]);
        work_progress(h, (uint64_t)r->n, NULL);
    }
    /* the listed values are pts[0 .. n_values-1]; refinements follow them */
    for (int k = 1; k < a->n_values && st == CM_OK; k++)
        if (!same_counts(&r->pts[k - 1], &r->pts[k])) {
            sweep_change *ch = &r->changes[r->n_changes++];
            ch->lo = r->pts[k - 1];
            ch->hi = r->pts[k];
            ch->several = ch->lo.attractors > ch->hi.attractors + 1 ||
                          ch->hi.attractors > ch->lo.attractors + 1;
            if (a->refine)
                st = refine_change(a, h, r, ch, msg, msg_size);
            if (st == CM_OK && a->refine && rep && rep->change)
                rep->change(rep->user, a, ch);
        }
    if (st == CM_OK)
        qsort(r->pts, (size_t)r->n, sizeof *r->pts, by_value);
    return st;
}

void sweep_result_free(sweep_result *r)
{
    free(r->pts);
    free(r->changes);
    r->pts = NULL, r->changes = NULL;
}
