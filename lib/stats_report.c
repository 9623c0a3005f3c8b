/* The `stats` of an explore session's view (lib/stats_report.h). */
#include "lib/stats_report.h"

#include <stdlib.h>

#include "lib/json.h"

enum { VIEW_TEXT = 512 };

/* Most attractors `stats` lists (those with the most cells in view). */
enum { STATS_GROUPS = 20 };

typedef struct group_count {
    uint64_t cells;
    uint32_t id;
} group_count;

static int more_in_view(const void *a, const void *b)
{
    const group_count *x = a, *y = b;
    if (x->cells != y->cells)
        return x->cells > y->cells ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

/* The groups with cells in view, the most first. */
static void print_groups(FILE *f, const session *s, uint32_t ngroups, const cm_group_info *g,
                         const uint64_t *in_view)
{
    group_count *ids = malloc(((size_t)ngroups + 1) * sizeof *ids);
    uint32_t n = 0;
    if (!ids)
        return;
    for (uint32_t k = 1; k <= ngroups; k++)
        if (in_view[k])
            ids[n++] = (group_count){in_view[k], k};
    qsort(ids, n, sizeof *ids, more_in_view);
    fprintf(f, "%6s %8s %12s %12s  %s\n", "group", "period", "in view", "basin", "centre");
    for (uint32_t k = 0; k < n && k < STATS_GROUPS; k++) {
        const cm_group_info *gi = &g[ids[k].id - 1];
        char centre[CM_MAX_DIM * CM_NUM_TEXT];
        cm_point_text(&s->c.lat, gi->centre, ", ", centre, sizeof centre);
        fprintf(f, "%6u %8u %12llu %12llu  (%s)\n", gi->id, gi->period,
                (unsigned long long)ids[k].cells, (unsigned long long)gi->basin_cells, centre);
    }
    if (n > STATS_GROUPS)
        fprintf(f, "... and %u groups with fewer cells in view\n", n - STATS_GROUPS);
    free(ids);
}

/* The attractors with cells in view, the most first, and the cells that
 * diverge or stay outside. */
static void print_attractors(FILE *f, const session *s, const session_stats *v)
{
    const cm_attractor_set *att = &v->att;
    group_count *ids = malloc(((size_t)att->n + 1) * sizeof *ids);
    uint32_t n = 0;
    if (!ids)
        return;
    for (uint32_t a = 1; a <= att->n; a++)
        if (v->by_label[a + 2])
            ids[n++] = (group_count){v->by_label[a + 2], a};
    qsort(ids, n, sizeof *ids, more_in_view);
    fprintf(f, "attractors in view %u; diverged %llu cells, outside or undecided %llu\n", n,
            (unsigned long long)v->by_label[CM_LABEL_DIVERGED + 2],
            (unsigned long long)v->by_label[CM_LABEL_OUTSIDE + 2]);
    fprintf(f, "%6s  %-9s %6s %12s %12s  %s\n", "attr.", "kind", "period", "in view",
            "basin", "centre");
    for (uint32_t k = 0; k < n && k < STATS_GROUPS; k++) {
        const cm_attractor *a = &att->a[ids[k].id - 1];
        char centre[CM_MAX_DIM * CM_NUM_TEXT], period[16];
        cm_point_text(&s->c.lat, a->centre, ", ", centre, sizeof centre);
        snprintf(period, sizeof period, a->kind == CM_ATTRACTOR_APERIODIC ? "-" : "%u", a->period);
        fprintf(f, "%6u  %-9s %6s %12llu %12llu  (%s)\n", a->id,
                cm_attractor_kind_name(a->kind), period, (unsigned long long)ids[k].cells,
                (unsigned long long)a->basin_cells, centre);
    }
    if (n > STATS_GROUPS)
        fprintf(f, "... and %u attractors with fewer cells in view\n", n - STATS_GROUPS);
    free(ids);
}

void stats_report(FILE *f, const session *s, const session_stats *v)
{
    char view[VIEW_TEXT];
    session_view_text(s, view, sizeof view);
    fprintf(f,
            "view %s: %llu cells, %llu not computed, %llu in the sink's domain, %llu groups\n",
            view, (unsigned long long)v->cells, (unsigned long long)v->missing,
            (unsigned long long)v->in_view[0], (unsigned long long)v->groups_in_view);
    print_groups(f, s, v->flat.ngroups, v->groups, v->in_view);
    print_attractors(f, s, v);
    fprintf(f,
            "cluster: %u regions, %llu cells, %u groups; memory %.1f MiB (cell arrays, "
            "node tables and open lists %.1f MiB%s); disk %.1f MiB (%.2f bytes/cell)\n"
            "kept of the views rendered: %.1f MiB (labels, exits, resolved nodes)\n",
            s->c.nregions, (unsigned long long)v->cluster_cells, s->c.ngroups,
            (double)v->memory_bytes / 1048576.0,
            (double)v->resident_bytes / 1048576.0,
            s->c.mem_budget ? ", within --mem" : "", (double)v->file_bytes / 1048576.0,
            v->cluster_cells ? (double)v->file_bytes / (double)v->cluster_cells : 0.0,
            (double)v->view_bytes / 1048576.0);
}

void stats_json(FILE *f, const session *s, const session_stats *v)
{
    const cm_region *flat = &v->flat;
    const cm_group_info *groups = v->groups;
    json j;
    json_begin(&j, f, "stats");
    json_model(&j, &s->model);
    json_lattice(&j, &s->c.lat);
    json_box(&j, "box", &s->c.lat, &flat->box);
    json_uint(&j, "cells", v->cells);
    json_uint(&j, "not_computed", v->missing);
    json_uint(&j, "sink_cells", v->in_view[0]);
    json_array(&j, "groups");
    for (uint32_t k = 1; k <= flat->ngroups; k++) {
        if (!v->in_view[k])
            continue;
        const cm_group_info *g = &groups[k - 1];
        json_object(&j, NULL);
        json_group_fields(&j, g, &s->c.lat);
        json_uint(&j, "in_view", v->in_view[k]);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_array(&j, "attractors");
    for (uint32_t k = 0; k < v->att.n; k++) {
        const cm_attractor *a = &v->att.a[k];
        if (!v->by_label[a->id + 2])
            continue;
        json_object(&j, NULL);
        json_attractor_fields(&j, a, &s->c.lat);
        json_uint(&j, "in_view", v->by_label[a->id + 2]);
        json_object_end(&j);
    }
    json_array_end(&j);
    json_uint(&j, "diverged_cells", v->by_label[CM_LABEL_DIVERGED + 2]);
    json_uint(&j, "outside_cells", v->by_label[CM_LABEL_OUTSIDE + 2]);
    json_object(&j, "cluster");
    json_uint(&j, "regions", s->c.nregions);
    json_uint(&j, "cells", v->cluster_cells);
    json_uint(&j, "groups", s->c.ngroups);
    json_uint(&j, "memory_bytes", v->memory_bytes);
    json_uint(&j, "resident_bytes", v->resident_bytes);
    json_uint(&j, "file_bytes", v->file_bytes);
    json_uint(&j, "view_bytes", v->view_bytes);
    json_object_end(&j);
    json_end(&j);
}

