/* lib/attractor_report.c - the attractors of a solve as reports, labels
 * and files give them (lib/attractor_report.h). */
#include "lib/attractor_report.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lib/project.h"

static int larger_basin(const void *a, const void *b)
{
    const cm_attractor *x = a, *y = b;
    if (x->basin_cells != y->basin_cells)
        return x->basin_cells > y->basin_cells ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

static double percent(uint64_t part, uint64_t all) { return all ? 100.0 * part / all : 0; }

void attractor_text(FILE *out, const cm_lattice *lat, const cm_attractor_set *s, uint64_t cells,
                    int rows)
{
    fprintf(out, "attractors %u, by true orbits from %u cell groups: %u merged into another "
                 "group's attractor, %u artefacts (%u diverge, %u undecided)\n",
            s->n, s->ngroups, s->merged, s->diverged_groups + s->unresolved_groups,
            s->diverged_groups, s->unresolved_groups);
    cm_attractor *sorted = malloc(((size_t)s->n + 1) * sizeof *sorted);
    if (sorted && s->n) {
        memcpy(sorted, s->a, s->n * sizeof *sorted);
        qsort(sorted, s->n, sizeof *sorted, larger_basin);
        fprintf(out, "%6s  %-9s %6s %12s %7s %6s  %s\n", "attr.", "kind", "period", "basin",
                "share", "groups", "centre [in its footprint's bounds]");
        for (uint32_t k = 0; k < s->n && (int)k < rows; k++) {
            const cm_attractor *a = &sorted[k];
            char centre[CM_MAX_DIM * CM_NUM_TEXT], period[16], bounds[2 * CM_MAX_DIM * CM_NUM_TEXT + 16] = "";
            cm_point_text(lat, a->centre, ", ", centre, sizeof centre);
            snprintf(period, sizeof period, a->kind == CM_ATTRACTOR_APERIODIC ? "-" : "%u",
                     a->period);
            if (a->kind == CM_ATTRACTOR_APERIODIC) {
                char lo[CM_MAX_DIM * CM_NUM_TEXT], hi[CM_MAX_DIM * CM_NUM_TEXT];
                cm_point_text(lat, a->lo, ", ", lo, sizeof lo);
                cm_point_text(lat, a->hi, ", ", hi, sizeof hi);
                snprintf(bounds, sizeof bounds, " in (%s)..(%s)", lo, hi);
            }
            fprintf(out, "%6u  %-9s %6s %12llu %6.1f%% %6u  (%s)%s\n", a->id,
                    cm_attractor_kind_name(a->kind), period, (unsigned long long)a->basin_cells,
                    percent(a->basin_cells, cells), a->groups, centre, bounds);
        }
        if (s->n > (uint32_t)rows)
            fprintf(out, "... and %u attractors with smaller basins (--json lists all)\n",
                    s->n - (uint32_t)rows);
    }
    free(sorted);
    const uint64_t diverged = s->diverged_cells + s->sink_diverged_cells;
    fprintf(out, "diverged %llu cells (%.1f%%), outside %llu (%.1f%%", (unsigned long long)diverged,
            percent(diverged, cells), (unsigned long long)s->outside_cells,
            percent(s->outside_cells, cells));
    if (s->outside_steps)
        fprintf(out, ": left the computed cells, not back within %u steps", s->outside_steps);
    else
        fprintf(out, ": left the computed cells, not followed");
    fprintf(out, "), undecided %llu (%.1f%%)\n", (unsigned long long)s->unresolved_cells,
            percent(s->unresolved_cells, cells));
    if (s->returned_cells)
        fprintf(out, "%llu cells (%.1f%%) left the computed cells and came back (in the basins "
                     "above)\n",
                (unsigned long long)s->returned_cells, percent(s->returned_cells, cells));
}

void json_attractor_fields(json *j, const cm_attractor *a, const cm_lattice *lat)
{
    json_uint(j, "id", a->id);
    json_str(j, "kind", cm_attractor_kind_name(a->kind));
    if (a->kind == CM_ATTRACTOR_APERIODIC)
        json_raw(j, "period", "null");
    else
        json_uint(j, "period", a->period);
    json_uint(j, "basin_cells", a->basin_cells);
    json_nums(j, "centre", a->centre, lat->dim);
}

void attractor_json(json *j, const cm_lattice *lat, const cm_attractor_set *s)
{
    json_array(j, "attractors");
    for (uint32_t k = 0; k < s->n; k++) {
        const cm_attractor *a = &s->a[k];
        json_object(j, NULL);
        json_attractor_fields(j, a, lat);
        json_array(j, "groups");
        for (uint32_t g = 1; g <= s->ngroups; g++)
            if (s->of_group[g] == a->id)
                json_uint(j, NULL, g);
        json_array_end(j);
        json_nums(j, "lo", a->lo, lat->dim);
        json_nums(j, "hi", a->hi, lat->dim);
        json_array(j, "anchor");
        for (int d = 0; d < lat->dim; d++)
            json_int(j, NULL, a->anchor[d]);
        json_array_end(j);
        json_uint(j, "footprint_cells", a->footprint_cells);
        json_object_end(j);
    }
    json_array_end(j);
    json_uint(j, "diverged_cells", s->diverged_cells + s->sink_diverged_cells);
    json_uint(j, "outside_cells", s->outside_cells);
    json_uint(j, "undecided_cells", s->unresolved_cells);
    json_uint(j, "returned_cells", s->returned_cells);
    json_uint(j, "outside_steps", s->outside_steps);
}

void attractor_json_groups(json *j, const cm_group_info *g, uint32_t n, const cm_lattice *lat,
                           const cm_attractor_set *s)
{
    json_array(j, "groups");
    for (uint32_t k = 0; k < n; k++) {
        json_object(j, NULL);
        json_group_fields(j, &g[k], lat);
        const uint32_t a = s->of_group[g[k].id];
        if (a == CM_FATE_DIVERGED || a == CM_FATE_UNRESOLVED)
            json_raw(j, "attractor", "null");
        else
            json_uint(j, "attractor", a);
        json_object_end(j);
    }
    json_array_end(j);
}

bool attractor_options_given(const cm_attractor_options *o)
{
    return o->transient || o->record || o->max_steps || o->tol || o->match || o->outside;
}

cm_status cluster_ends_open(cluster_ends *e, cm_cluster *c, char *msg, size_t msg_size)
{
    if (e->open)
        return CM_OK;
    e->cc = (cm_cluster_cells){c, &e->exits, NULL};
    e->computed = cm_cluster_computed(&e->cc);
    e->reserved = c->page_in && c->mem_budget ? cm_cluster_exits_room(c) : 0;
    c->mem_reserved += e->reserved;
    cm_cluster_trim(c);
    const cm_status st = cm_cluster_exits(c, &e->exits, msg, msg_size);
    e->open = st == CM_OK;
    if (!e->open)
        cluster_ends_close(e);
    return st;
}

void cluster_ends_lookup(cluster_ends *e, cm_cluster *c)
{
    if (e->open)
        return;
    cluster_ends_close(e);
    e->cc = (cm_cluster_cells){c, NULL, NULL};
    e->computed = cm_cluster_computed(&e->cc);
}

void cluster_ends_close(cluster_ends *e)
{
    cm_exits_free(&e->exits);
    if (e->cc.c)
        e->cc.c->mem_reserved -= e->reserved;
    e->reserved = 0;
    e->open = false;
}

cm_status file_attractors(cm_store *s, const cm_store_info *info, const cm_model *m,
                          cm_cluster *c, cluster_ends *ends, const cm_group_info *groups,
                          const cm_attractor_options *o, cm_attractor_set *out, char *msg,
                          size_t msg_size)
{
    if (!o || !attractor_options_given(o)) {
        const cm_status st =
            cm_store_get_attractors(s, c->lat.dim, c->ngroups, out, NULL, msg, msg_size);
        if (st != CM_ENOTFOUND)
            return st;
    }
    cm_status st = cluster_ends_open(ends, c, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (m)
        return cm_cluster_attractors(m, &ends->cc, groups, o, out, msg, msg_size);
    cm_model_set set = {0};
    cm_model own;
    st = model_of_store(info, &set, &own, msg, msg_size);
    if (st == CM_OK) {
        st = cm_cluster_attractors(&own, &ends->cc, groups, o, out, msg, msg_size);
        cm_model_release(&own);
    }
    return st;
}

cm_status part_labels(const cm_model *m, cm_cluster *c, const cm_region *flat,
                      const uint32_t *open, const cm_group_info *groups, bool every_exit,
                      cm_exit_memo *memo, cm_attractor_set *att, int32_t **labels, char *msg,
                      size_t msg_size)
{
    *labels = cm_cells_array((flat->ncells + 1) * sizeof **labels);
    if (!*labels)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
    cm_status st;
    if (!every_exit && c->keep_exits && !c->resolved_cells && !c->open_released) {
        st = cm_attractors_find(m, &c->lat, groups, c->ngroups, cm_cluster_cells_group, c, NULL,
                                att, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_view_labels(m, c, flat, open, NULL, memo, att, *labels, msg,
                                        msg_size);
    } else {
        cluster_ends ends;
        memset(&ends, 0, sizeof ends);
        st = cluster_ends_open(&ends, c, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_attractors(m, &ends.cc, groups, NULL, att, msg, msg_size);
        if (st == CM_OK)
            st = cm_attractor_cell_labels(att, flat, &ends.computed, *labels, msg, msg_size);
        cluster_ends_close(&ends);
    }
    if (st != CM_OK) {
        free(*labels);
        *labels = NULL;
    }
    return st;
}

uint32_t attractor_label(const cm_attractor_set *s, uint32_t g)
{
    const int32_t label = cm_attractor_label(s, g);
    return g == CM_GROUP_NONE ? g : label > 0 ? (uint32_t)label : 0;
}

