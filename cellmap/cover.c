#include "cellmap/cover.h"

#include <stdlib.h>

#include "cellmap/grow.h"

typedef struct box_list {
    cm_box *items;
    uint64_t n, cap;
} box_list;

static cm_status push(box_list *list, const cm_box *b)
{
    if (cm_grow((void **)&list->items, &list->cap, list->n + 1, sizeof *list->items) != CM_OK)
        return CM_ENOMEM;
    list->items[list->n++] = *b;
    return CM_OK;
}

/* b minus the cells of `cut` (which it overlaps) into list: below and above
 * `cut` in dimension 0, then, within cut's extent there, in dimension 1... */
static cm_status subtract(const cm_box *b, const cm_box *cut, box_list *list)
{
    cm_box rest = *b;
    for (int d = 0; d < b->dim; d++) {
        if (rest.lo[d] < cut->lo[d]) {
            cm_box below = rest;
            below.hi[d] = cut->lo[d];
            rest.lo[d] = cut->lo[d];
            if (push(list, &below) != CM_OK)
                return CM_ENOMEM;
        }
        if (rest.hi[d] > cut->hi[d]) {
            cm_box above = rest;
            above.lo[d] = cut->hi[d];
            rest.hi[d] = cut->hi[d];
            if (push(list, &above) != CM_OK)
                return CM_ENOMEM;
        }
    }
    return CM_OK; /* what is left of `rest` lies inside `cut` */
}

cm_status cm_cluster_uncovered(const cm_cluster *c, const cm_box *box, cm_box **out, uint32_t *n,
                               char *msg, size_t msg_size)
{
    box_list now = {NULL, 0, 0}, next = {NULL, 0, 0};
    cm_status st = push(&now, box);
    for (uint32_t k = 0; k < c->nregions && st == CM_OK && now.n > 0; k++) {
        const cm_box *region = &c->regions[k].r.box;
        next.n = 0;
        for (uint64_t i = 0; i < now.n && st == CM_OK; i++) {
            cm_box both;
            st = cm_box_intersect(&now.items[i], region, &both)
                     ? subtract(&now.items[i], &both, &next)
                     : push(&next, &now.items[i]);
        }
        const box_list swap = now;
        now = next;
        next = swap;
    }
    free(next.items);
    if (st == CM_OK && now.n > UINT32_MAX)
        st = CM_ENOMEM;
    if (st != CM_OK) {
        free(now.items);
        *out = NULL;
        *n = 0;
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the uncovered boxes");
    }
    *out = now.n ? now.items : NULL;
    if (!now.n)
        free(now.items);
    *n = (uint32_t)now.n;
    return CM_OK;
}

uint64_t cm_boxes_cells(const cm_box *boxes, uint32_t n)
{
    uint64_t cells = 0;
    for (uint32_t k = 0; k < n; k++)
        cells += cm_box_cells(&boxes[k]);
    return cells;
}
