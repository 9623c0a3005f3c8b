#include "render/palette.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

const cm_rgb cm_colour_sink = {214, 39, 40};
const cm_rgb cm_colour_not_computed = {255, 255, 255};
const cm_rgb cm_colour_marker = {0, 0, 0};
const cm_rgb cm_colour_sticking = {180, 180, 180};
const cm_rgb cm_colour_sticking_marker = {96, 96, 96};

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

static uint64_t anchor_hash(const int64_t *anchor, int dim)
{
    uint64_t h = UINT64_C(0x9e3779b97f4a7c15);
    for (int d = 0; d < dim; d++)
        h = mix(h ^ (uint64_t)anchor[d]);
    return h;
}

typedef struct ranked {
    const int64_t *anchor;
    int dim;
    uint32_t index;
} ranked;

static int compare_anchor(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    for (int d = x->dim - 1; d >= 0; d--)
        if (x->anchor[d] != y->anchor[d])
            return x->anchor[d] < y->anchor[d] ? -1 : 1;
    return 0;
}

int cm_class_count(void) { return CM_CLASS_FIRST_GROUP + PALETTE_SIZE; }

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
    default:
        return palette[(cls - CM_CLASS_FIRST_GROUP) % PALETTE_SIZE];
    }
}

void cm_palette_classes(const cm_group_info *groups, uint32_t n, int dim, uint8_t *classes)
{
    ranked *order = malloc((size_t)n * sizeof *order);
    if (!order) { /* fall back to plain hashing */
        for (uint32_t k = 0; k < n; k++)
            classes[k] = groups[k].kind == CM_GROUP_STICKING
                             ? CM_CLASS_STICKING
                             : (uint8_t)(CM_CLASS_FIRST_GROUP +
                                         anchor_hash(groups[k].anchor, dim) % PALETTE_SIZE);
        return;
    }
    uint32_t coloured = 0; /* sticking zones are all grey, as in Fig. 4.30 */
    for (uint32_t k = 0; k < n; k++) {
        if (groups[k].kind == CM_GROUP_STICKING)
            classes[k] = CM_CLASS_STICKING;
        else
            order[coloured++] = (ranked){groups[k].anchor, dim, k};
    }
    qsort(order, coloured, sizeof *order, compare_anchor);
    bool taken[PALETTE_SIZE];
    memset(taken, 0, sizeof taken);
    uint32_t used = 0;
    for (uint32_t r = 0; r < coloured; r++) {
        if (used == PALETTE_SIZE) { /* every colour taken: start a new round */
            memset(taken, 0, sizeof taken);
            used = 0;
        }
        size_t c = anchor_hash(order[r].anchor, dim) % PALETTE_SIZE;
        while (taken[c])
            c = (c + 1) % PALETTE_SIZE;
        taken[c] = true;
        used++;
        classes[order[r].index] = (uint8_t)(CM_CLASS_FIRST_GROUP + c);
    }
    free(order);
}
