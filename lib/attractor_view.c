/* lib/attractor_view.c - a flat region drawn by the system's attractors
 * (lib/attractor_view.h). */
#include "lib/attractor_view.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The summary of attractor a, as a group for the figure's colours. */
static cm_group_info attractor_group(const cm_attractor *at)
{
    cm_group_info g = {.id = at->id,
                       .period = at->period,
                       .basin_cells = at->basin_cells,
                       .kind = at->kind == CM_ATTRACTOR_STICKING ? CM_GROUP_STICKING
                                                                 : CM_GROUP_ATTRACTOR};
    memcpy(g.centre, at->centre, sizeof at->centre);
    memcpy(g.lo, at->lo, sizeof at->lo);
    memcpy(g.hi, at->hi, sizeof at->hi);
    memcpy(g.anchor, at->anchor, sizeof at->anchor);
    return g;
}

/* Marks the attractors' footprint cells in flat (step 0: the markers). */
static void mark_footprints(const cm_attractor_set *s, cm_region *flat)
{
    const int dim = flat->box.dim;
    for (uint32_t a = 0; a < s->n; a++)
        for (uint64_t c = s->footprint_at[a]; c < s->footprint_at[a + 1]; c++) {
            const int64_t *cell = s->footprint + c * dim;
            if (!cm_box_contains(&flat->box, cell))
                continue;
            const uint64_t i = cm_box_index(&flat->box, cell);
            if (flat->group[i] == CM_GROUP_NONE)
                continue; /* not computed: nothing to mark */
            flat->group[i] = s->a[a].id; /* visited by its orbit: on it */
            flat->step[i] = 0;
        }
}

cm_status attractor_view(const cm_attractor_set *s, cm_region *flat, const int32_t *label,
                         cm_group_info **groups, uint32_t *n, char *msg, size_t msg_size)
{
    cm_group_info *g = calloc((size_t)s->n + 2, sizeof *g);
    if (!g)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the figure");
    const uint32_t outside = s->n + 1; /* the figure's group of cells that reach no attractor known */
    int any_outside = 0;
    const int64_t cells = (int64_t)flat->ncells;
#pragma omp parallel for schedule(static) reduction(| : any_outside)
    for (int64_t i = 0; i < cells; i++) {
        const uint32_t was = flat->group[i];
        if (was != CM_GROUP_NONE && was != 0 && flat->step[i] == 0)
            flat->step[i] = 1; /* a cell cycle's cell: the footprints are the markers */
        const int32_t l = label[i];
        flat->group[i] = l > 0                   ? (uint32_t)l
                         : l == CM_LABEL_OUTSIDE ? outside
                         : l == CM_LABEL_UNCOMPUTED ? CM_GROUP_NONE
                                                    : 0;
        any_outside |= l == CM_LABEL_OUTSIDE;
    }
    for (uint32_t a = 0; a < s->n; a++)
        g[a] = attractor_group(&s->a[a]);
    mark_footprints(s, flat);
    *n = s->n;
    if (any_outside) { /* grey, as "fate unknown" reads */
        g[s->n] = (cm_group_info){.id = outside, .period = 1, .kind = CM_GROUP_STICKING};
        g[s->n].basin_cells = s->outside_cells + s->unresolved_cells; /* grey: no hash needed */
        *n = outside;
    }
    free(*groups);
    *groups = g;
    flat->ngroups = *n;
    return CM_OK;
}

void attractor_name(const cm_attractor *a, char *out, size_t size)
{
    if (a->kind == CM_ATTRACTOR_PERIODIC)
        snprintf(out, size, "A%u p=%u", a->id, a->period);
    else
        snprintf(out, size, "A%u %s", a->id, cm_attractor_kind_name(a->kind));
}

int attractor_legend(const cm_attractor_set *s, uint32_t n, cm_group_label *labels, int used,
                     int cap)
{
    for (uint32_t a = 0; a < s->n && used < cap; a++) {
        bool named = false;
        for (int k = 0; k < used; k++)
            named |= !labels[k].by_anchor && labels[k].id == s->a[a].id;
        /* sticking zones share a grey and one legend line (render/figure.h)
         * unless the user names them */
        if (named || s->a[a].kind == CM_ATTRACTOR_STICKING)
            continue;
        cm_group_label *l = &labels[used++];
        memset(l, 0, sizeof *l);
        l->id = s->a[a].id;
        attractor_name(&s->a[a], l->text, sizeof l->text);
    }
    if (n > s->n && used < cap) {
        cm_group_label *l = &labels[used++];
        memset(l, 0, sizeof *l);
        l->id = n;
        snprintf(l->text, sizeof l->text, "outside or undecided");
    }
    return used;
}
