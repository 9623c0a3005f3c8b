#include "render/palette.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

const cm_rgb cm_colour_sink = {214, 39, 40};
const cm_rgb cm_colour_not_computed = {255, 255, 255};
const cm_rgb cm_colour_marker = {0, 0, 0};
const cm_rgb cm_colour_sticking = {180, 180, 180};
const cm_rgb cm_colour_sticking_marker = {96, 96, 96};
const cm_rgb cm_colour_other = {222, 210, 190}; /* muted sand: present, not one group */

/* Well-separated categorical colours (no red: red is the sink; no black: the
 * markers; no white: not computed; no grey: sticking zones). */
static const cm_rgb palette[] = {
    {31, 119, 180},  {44, 160, 44},   {255, 127, 14},  {148, 103, 189}, {140, 86, 75},
    {227, 119, 194}, {188, 189, 34},  {23, 190, 207},  {174, 199, 232}, {152, 223, 138},
    {255, 187, 120}, {197, 176, 213}, {196, 156, 148}, {247, 182, 210}, {219, 219, 141},
    {158, 218, 229}, {57, 59, 121},   {99, 121, 57},   {140, 109, 49},  {123, 65, 115},
};
enum { PALETTE_SIZE = sizeof palette / sizeof palette[0] };

static uint64_t mix(uint64_t h)
{
    h ^= h >> 33;
    h *= UINT64_C(0xff51afd7ed558ccd);
    h ^= h >> 33;
    h *= UINT64_C(0xc4ceb9fe1a85ec53);
    h ^= h >> 33;
    return h;
}

/* The anchor's cell counted from the state origin rather than the lattice
 * origin: lattices of the same cell size whose origins lie whole cells
 * apart (a region solved at 0:500 and one at 100:600) give an attractor
 * the same hash, hence the same colour. */
static uint64_t anchor_hash(const int64_t *anchor, const cm_lattice *lat)
{
    uint64_t h = UINT64_C(0x9e3779b97f4a7c15);
    for (int d = 0; d < lat->dim; d++) {
        const double shift = round(lat->origin[d] / lat->width[d]);
        const int64_t from_zero = fabs(shift) < 0x1p52 ? anchor[d] + (int64_t)shift : anchor[d];
        h = mix(h ^ (uint64_t)from_zero);
    }
    return h;
}

typedef struct ranked {
    uint64_t cells; /* in view */
    uint64_t hash;
    const int64_t *anchor;
    int dim;
    uint32_t index;
} ranked;

/* Most cells in view first, then by hash and anchor (never by id). */
static int compare_ranked(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->cells != y->cells)
        return x->cells > y->cells ? -1 : 1;
    if (x->hash != y->hash)
        return x->hash < y->hash ? -1 : 1;
    for (int d = x->dim - 1; d >= 0; d--)
        if (x->anchor[d] != y->anchor[d])
            return x->anchor[d] < y->anchor[d] ? -1 : 1;
    return 0;
}

int cm_class_count(void) { return CM_CLASS_FIRST_GROUP + PALETTE_SIZE; }

int cm_palette_size(void) { return PALETTE_SIZE; }

cm_rgb cm_class_colour(int cls)
{
    switch (cls) {
    case CM_CLASS_NOT_COMPUTED:
        return cm_colour_not_computed;
    case CM_CLASS_SINK:
        return cm_colour_sink;
    case CM_CLASS_MARKER:
        return cm_colour_marker;
    case CM_CLASS_STICKING:
        return cm_colour_sticking;
    case CM_CLASS_STICKING_MARKER:
        return cm_colour_sticking_marker;
    case CM_CLASS_OTHER:
        return cm_colour_other;
    default:
        return palette[(cls - CM_CLASS_FIRST_GROUP) % PALETTE_SIZE];
    }
}

uint32_t cm_palette_classes(const cm_group_info *groups, uint32_t n, const cm_lattice *lat,
                            const uint64_t *in_view, uint64_t min_basin, uint8_t *classes)
{
    ranked *order = malloc(((size_t)n + 1) * sizeof *order);
    uint32_t coloured = 0;
    for (uint32_t k = 0; k < n; k++) {
        const uint64_t h = anchor_hash(groups[k].anchor, lat);
        if (groups[k].kind == CM_GROUP_STICKING) /* all grey, as in Fig. 4.30 */
            classes[k] = CM_CLASS_STICKING;
        else if (groups[k].basin_cells < min_basin || (in_view && !in_view[k]))
            classes[k] = CM_CLASS_OTHER;
        else if (order)
            order[coloured++] = (ranked){in_view ? in_view[k] : groups[k].basin_cells, h,
                                         groups[k].anchor, lat->dim, k};
        else /* out of memory: plain hashing, collisions and all */
            classes[k] = (uint8_t)(CM_CLASS_FIRST_GROUP + h % PALETTE_SIZE);
    }
    if (!order)
        return 0;
    qsort(order, coloured, sizeof *order, compare_ranked);
    bool taken[PALETTE_SIZE];
    memset(taken, 0, sizeof taken);
    for (uint32_t r = 0; r < coloured; r++) {
        if (r % PALETTE_SIZE == 0) /* every colour taken: a new round */
            memset(taken, 0, sizeof taken);
        size_t c = order[r].hash % PALETTE_SIZE;
        while (taken[c])
            c = (c + 1) % PALETTE_SIZE;
        taken[c] = true;
        classes[order[r].index] = (uint8_t)(CM_CLASS_FIRST_GROUP + c);
    }
    free(order);
    return coloured > PALETTE_SIZE ? coloured - PALETTE_SIZE : 0;
}
