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
