#include "cellmap/extend.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"

/* A tile of the grid: its index and its box clipped to the bounds. */
typedef struct tile_ref {
    int64_t index[CM_MAX_DIM];
    cm_box box;
    uint64_t covered;  /* cells of the tile in the cluster (cluster tiles) */
    uint64_t escaping; /* sequences escaping into it (candidates) */
} tile_ref;

typedef struct tile_list {
    tile_ref *items;
    uint64_t n, cap;
} tile_list;

static int64_t floor_div(int64_t a, int64_t b)
{
    const int64_t q = a / b;
    return q * b > a ? q - 1 : q;
}

static void tile_of(const cm_box *tile, const int64_t *cell, int64_t *index)
{
    for (int d = 0; d < tile->dim; d++)
        index[d] = floor_div(cell[d] - tile->lo[d], tile->hi[d] - tile->lo[d]);
}

/* The tile's box clipped to the bounds; false if nothing is left. */
static bool tile_box(const cm_box *tile, const cm_box *bounds, const int64_t *index, cm_box *box)
{
    memset(box, 0, sizeof *box);
    box->dim = tile->dim;
    for (int d = 0; d < tile->dim; d++) {
        const int64_t size = tile->hi[d] - tile->lo[d];
        box->lo[d] = tile->lo[d] + index[d] * size;
        box->hi[d] = box->lo[d] + size;
        if (bounds) {
            box->lo[d] = box->lo[d] > bounds->lo[d] ? box->lo[d] : bounds->lo[d];
            box->hi[d] = box->hi[d] < bounds->hi[d] ? box->hi[d] : bounds->hi[d];
        }
        if (box->lo[d] >= box->hi[d])
            return false;
    }
    return true;
}

bool cm_extend_tile(const cm_box *tile, const cm_box *bounds, const int64_t *cell, cm_box *box)
{
    int64_t index[CM_MAX_DIM];
    tile_of(tile, cell, index);
    return tile_box(tile, bounds, index, box);
}

static int64_t find_tile(const tile_list *list, const int64_t *index, int dim)
{
    for (uint64_t k = 0; k < list->n; k++)
        if (memcmp(list->items[k].index, index, (size_t)dim * sizeof *index) == 0)
            return (int64_t)k;
    return -1;
}

static cm_status add_tile(tile_list *list, const int64_t *index, const cm_box *box)
{
    if (cm_grow((void **)&list->items, &list->cap, list->n + 1, sizeof *list->items) != CM_OK)
        return CM_ENOMEM;
    tile_ref *t = &list->items[list->n++];
    memset(t, 0, sizeof *t);
    memcpy(t->index, index, sizeof t->index);
    t->box = *box;
    return CM_OK;
}

/* Adds every tile that region box `rb` overlaps (in index order) that the
 * list does not hold yet. */
static cm_status add_region_tiles(const cm_box *tile, const cm_box *rb, tile_list *tiles)
{
    int64_t first[CM_MAX_DIM], last[CM_MAX_DIM], index[CM_MAX_DIM] = {0}, top[CM_MAX_DIM];
    for (int d = 0; d < tile->dim; d++)
        top[d] = rb->hi[d] - 1;
    tile_of(tile, rb->lo, first);
    tile_of(tile, top, last);
    memcpy(index, first, sizeof first);
    do {
        cm_box box;
        tile_box(tile, NULL, index, &box);
        if (find_tile(tiles, index, tile->dim) < 0 && add_tile(tiles, index, &box) != CM_OK)
            return CM_ENOMEM;
    } while (cm_index_next(tile->dim, first, last, index));
    return CM_OK;
}

/* The tiles the cluster's regions overlap, in join order, with the cells
 * of each that the cluster covers. */
static cm_status cluster_tiles(const cm_cluster *c, const cm_box *tile, tile_list *tiles)
{
    for (uint32_t k = 0; k < c->nregions; k++)
        if (add_region_tiles(tile, &c->regions[k].r.box, tiles) != CM_OK)
            return CM_ENOMEM;
    for (uint64_t t = 0; t < tiles->n; t++)
        for (uint32_t k = 0; k < c->nregions; k++) {
            cm_box both;
            if (cm_box_intersect(&tiles->items[t].box, &c->regions[k].r.box, &both))
                tiles->items[t].covered += cm_box_cells(&both);
        }
    return CM_OK;
}

/* Candidates: each cluster tile the cluster does not cover whole (regions
 * need not be aligned to the grid), then the tiles sharing a face with it
 * that hold no cluster cell; all within bounds. */
static cm_status neighbour_tiles(const tile_list *tiles, const cm_box *tile, const cm_box *bounds,
                                 tile_list *candidates)
{
    for (uint64_t k = 0; k < tiles->n; k++) {
        const tile_ref *t = &tiles->items[k];
        cm_box box;
        if (tile_box(tile, bounds, t->index, &box) && t->covered < cm_box_cells(&box) &&
            add_tile(candidates, t->index, &box) != CM_OK)
            return CM_ENOMEM;
        for (int d = 0; d < tile->dim; d++)
            for (int side = -1; side <= 1; side += 2) {
                int64_t index[CM_MAX_DIM];
                memcpy(index, t->index, sizeof index);
                index[d] += side;
                if (find_tile(tiles, index, tile->dim) >= 0 ||
                    find_tile(candidates, index, tile->dim) >= 0 ||
                    !tile_box(tile, bounds, index, &box))
                    continue;
                if (add_tile(candidates, index, &box) != CM_OK)
                    return CM_ENOMEM;
            }
    }
    return CM_OK;
}

typedef struct escape_count {
    const cm_box *tile;
    tile_list *candidates;
    cm_extend_choice *choice;
} escape_count;

/* An open node: the cells whose sequences leave the cluster through it
 * (its weight) count for the candidate tile its exit lands in. */
static void count_escape(void *user, uint32_t node, const int64_t *cell, uint64_t w)
{
    (void)node;
    const escape_count *ec = user;
    int64_t index[CM_MAX_DIM] = {0};
    ec->choice->all_escaping += w;
    tile_of(ec->tile, cell, index);
    const int64_t t = find_tile(ec->candidates, index, ec->tile->dim);
    if (t >= 0 && cm_box_contains(&ec->candidates->items[t].box, cell))
        ec->candidates->items[t].escaping += w;
}

/* Where the sequences that leave the cluster go, from the node table alone:
 * each open node carries the cells whose sequences reach it. */
static cm_status count_escapes(cm_cluster *c, const cm_box *tile, tile_list *candidates,
                               cm_extend_choice *choice, char *msg, size_t msg_size)
{
    escape_count ec = {tile, candidates, choice};
    choice->cluster_cells = c->cells;
    return cm_cluster_each_escape(c, count_escape, &ec, msg, msg_size);
}

cm_status cm_extend_choose(cm_cluster *c, const cm_box *tile, const cm_box *bounds,
                           cm_extend_choice *choice, char *msg, size_t msg_size)
{
    memset(choice, 0, sizeof *choice);
    if (c->nregions == 0 || tile->dim != c->lat.dim || cm_box_cells(tile) == 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "extension needs a cluster with a region and a non-empty tile of its "
                       "dimension");
    tile_list tiles = {NULL, 0, 0}, candidates = {NULL, 0, 0};
    cm_status st = cluster_tiles(c, tile, &tiles);
    if (st == CM_OK)
        st = neighbour_tiles(&tiles, tile, bounds, &candidates);
    if (st == CM_OK)
        st = count_escapes(c, tile, &candidates, choice, msg, msg_size);
    else
        st = cm_fail(st, msg, msg_size, "out of memory following the escaping sequences");
    if (st == CM_OK) {
        int64_t best = -1;
        for (uint64_t k = 0; k < candidates.n; k++)
            if (candidates.items[k].escaping > 0 &&
                (best < 0 || candidates.items[k].escaping > candidates.items[best].escaping))
                best = (int64_t)k;
        if (best < 0) {
            st = cm_fail(CM_ENOTFOUND, msg, msg_size,
                         "no neighbouring tile%s receives an escaping sequence",
                         bounds ? " within the bounds" : "");
        } else {
            choice->box = candidates.items[best].box;
            choice->escaping = candidates.items[best].escaping;
        }
    }
    free(tiles.items);
    free(candidates.items);
    return st;
}
