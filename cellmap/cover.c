#include "cellmap/cover.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

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

/* The place of v among the n sorted distinct values. */
static uint64_t rank_of(const int64_t *values, uint32_t n, int64_t v)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (values[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static int compare_int64(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* A box's place in the grid: its rank in each dimension, slowest first. */
typedef struct scan_entry {
    uint32_t place[CM_MAX_DIM];
    uint32_t at;
} scan_entry;

static int compare_places(const void *a, const void *b)
{
    const scan_entry *x = a, *y = b;
    for (int d = 0; d < CM_MAX_DIM; d++)
        if (x->place[d] != y->place[d])
            return x->place[d] < y->place[d] ? -1 : 1;
    return (x->at > y->at) - (x->at < y->at);
}

/* Whether dimension a is scanned slower than b: it has more places, or as
 * many and comes later (a square grid keeps its row order). */
static bool slower(const uint32_t *places, int a, int b)
{
    return places[a] > places[b] || (places[a] == places[b] && a > b);
}

cm_status cm_boxes_scan_order(cm_box *boxes, uint32_t n)
{
    if (n < 2)
        return CM_OK;
    const int dim = boxes[0].dim;
    int64_t *lo = malloc((size_t)n * (size_t)dim * sizeof *lo);
    scan_entry *e = calloc(n, sizeof *e);
    cm_box *sorted = malloc(n * sizeof *sorted);
    if (!lo || !e || !sorted) {
        free(lo);
        free(e);
        free(sorted);
        return CM_ENOMEM;
    }
    /* each dimension's distinct lower bounds, sorted: a box's place is its rank */
    uint32_t distinct[CM_MAX_DIM];
    for (int d = 0; d < dim; d++) {
        int64_t *v = lo + (size_t)d * n;
        for (uint32_t k = 0; k < n; k++)
            v[k] = boxes[k].lo[d];
        qsort(v, n, sizeof *v, compare_int64);
        distinct[d] = 0;
        for (uint32_t k = 0; k < n; k++)
            if (distinct[d] == 0 || v[k] != v[distinct[d] - 1])
                v[distinct[d]++] = v[k];
    }
    int slow[CM_MAX_DIM]; /* the dimensions from slowest to fastest */
    for (int d = 0; d < dim; d++)
        slow[d] = d;
    for (int i = 1; i < dim; i++)
        for (int j = i; j > 0 && slower(distinct, slow[j], slow[j - 1]); j--) {
            const int t = slow[j];
            slow[j] = slow[j - 1];
            slow[j - 1] = t;
        }
    for (uint32_t k = 0; k < n; k++) {
        e[k].at = k;
        for (int i = 0; i < dim; i++)
            e[k].place[i] = (uint32_t)rank_of(lo + (size_t)slow[i] * n, distinct[slow[i]],
                                              boxes[k].lo[slow[i]]);
    }
    qsort(e, n, sizeof *e, compare_places);
    for (uint32_t k = 0; k < n; k++)
        sorted[k] = boxes[e[k].at];
    memcpy(boxes, sorted, n * sizeof *boxes);
    free(lo);
    free(e);
    free(sorted);
    return CM_OK;
}
