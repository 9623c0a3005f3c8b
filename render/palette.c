#include "render/palette.h"

#include "cellmap/output.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const cm_rgb cm_colour_sink = {214, 39, 40};
const cm_rgb cm_colour_not_computed = {255, 255, 255};
const cm_rgb cm_colour_marker = {0, 0, 0};
const cm_rgb cm_colour_sticking = {180, 180, 180};
const cm_rgb cm_colour_sticking_marker = {96, 96, 96};
const cm_rgb cm_colour_other = {236, 226, 208}; /* pale beige: present, not one group */
const cm_rgb cm_colour_repeller = {230, 159, 0};
const cm_rgb cm_colour_escape = {0, 114, 178};
const cm_rgb cm_colour_collision = {220, 30, 30};
const cm_rgb cm_colour_collision_higher = {255, 150, 0};

/* No red (the sink), black (markers), white (not computed) or grey
 * (sticking zones) in any palette. */
static const cm_palette builtin[] = {
    {"tol", /* Tol's rose is left out: next to the sink's red it vanishes */
     14,
     {{0x33, 0x22, 0x88}, {0x88, 0xcc, 0xee}, {0x44, 0xaa, 0x99}, {0x11, 0x77, 0x33},
      {0x99, 0x99, 0x33}, {0xdd, 0xcc, 0x77}, {0xaa, 0x44, 0x99},
      {0x77, 0xaa, 0xdd}, {0xee, 0x88, 0x66}, {0xee, 0xdd, 0x88}, {0xff, 0xaa, 0xbb},
      {0xbb, 0xcc, 0x33}, {0x44, 0x77, 0xaa}, {0xaa, 0x33, 0x77}}},
    {"okabe-ito",
     6,
     {{0xe6, 0x9f, 0x00}, {0x56, 0xb4, 0xe9}, {0x00, 0x9e, 0x73}, {0xf0, 0xe4, 0x42},
      {0x00, 0x72, 0xb2}, {0xcc, 0x79, 0xa7}}},
    {"tab20",
     20,
     {{31, 119, 180},  {44, 160, 44},   {255, 127, 14},  {148, 103, 189}, {140, 86, 75},
      {227, 119, 194}, {188, 189, 34},  {23, 190, 207},  {174, 199, 232}, {152, 223, 138},
      {255, 187, 120}, {197, 176, 213}, {196, 156, 148}, {247, 182, 210}, {219, 219, 141},
      {158, 218, 229}, {57, 59, 121},   {99, 121, 57},   {140, 109, 49},  {123, 65, 115}}},
};

const cm_palette *cm_palette_default(void) { return &builtin[0]; }

cm_status cm_palette_named(const char *name, const cm_palette **out, char *msg, size_t msg_size)
{
    for (size_t k = 0; k < sizeof builtin / sizeof builtin[0]; k++)
        if (strcmp(name, builtin[k].name) == 0) {
            *out = &builtin[k];
            return CM_OK;
        }
    return cm_fail(CM_ENOTFOUND, msg, msg_size,
                   "no palette '%s': use tol (the default), okabe-ito or tab20, or a file of "
                   "#rrggbb lines",
                   name);
}

cm_status cm_palette_read(const char *path, cm_palette *out, char *msg, size_t msg_size)
{
    FILE *f;
    const cm_status opened = cm_input_open(path, "palette", 1 << 20, &f, msg, msg_size);
    if (opened != CM_OK)
        return opened;
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", path);
    char line[256];
    cm_status st = CM_OK;
    for (int no = 1; st == CM_OK && fgets(line, sizeof line, f); no++) {
        char *s = line + strspn(line, " \t");
        s[strcspn(s, "\r\n")] = 0;
        unsigned r, g, b;
        char end;
        if (!*s || strncmp(s, "//", 2) == 0)
            continue;
        if (strlen(s) != 7 || sscanf(s, "#%2x%2x%2x%c", &r, &g, &b, &end) != 3)
            st = cm_fail(CM_EINVAL, msg, msg_size, "%s:%d: '%.40s' is not a colour #rrggbb",
                         path, no, s);
        else if (out->n == CM_PALETTE_MAX)
            st = cm_fail(CM_EINVAL, msg, msg_size, "%s: more than %d colours", path,
                         CM_PALETTE_MAX);
        else
            out->colour[out->n++] = (cm_rgb){(uint8_t)r, (uint8_t)g, (uint8_t)b};
    }
    fclose(f);
    if (st == CM_OK && out->n == 0)
        st = cm_fail(CM_EINVAL, msg, msg_size, "%s holds no colour (#rrggbb lines)", path);
    return st;
}

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
        /* unsigned: a damaged file's anchor must not overflow */
        const uint64_t from_zero = fabs(shift) < 0x1p52 ? (uint64_t)anchor[d] + (uint64_t)(int64_t)shift
                                                        : (uint64_t)anchor[d];
        h = mix(h ^ from_zero);
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

int cm_class_count(const cm_palette *p)
{
    return CM_CLASS_FIRST_GROUP + (p ? p : cm_palette_default())->n;
}

cm_rgb cm_class_colour(const cm_palette *p, int cls)
{
    p = p ? p : cm_palette_default();
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
        return p->colour[(cls - CM_CLASS_FIRST_GROUP) % p->n];
    }
}

uint32_t cm_palette_classes(const cm_palette *p, const cm_group_info *groups, uint32_t n,
                            const cm_lattice *lat, const uint64_t *in_view, uint64_t min_basin,
                            uint8_t *classes)
{
    const size_t size = (size_t)(p ? p : cm_palette_default())->n;
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
            classes[k] = (uint8_t)(CM_CLASS_FIRST_GROUP + h % size);
    }
    if (!order)
        return 0;
    qsort(order, coloured, sizeof *order, compare_ranked);
    bool taken[CM_PALETTE_MAX];
    memset(taken, 0, sizeof taken);
    for (uint32_t r = 0; r < coloured; r++) {
        if (r % size == 0) /* every colour taken: a new round */
            memset(taken, 0, sizeof taken);
        size_t c = order[r].hash % size;
        while (taken[c])
            c = (c + 1) % size;
        taken[c] = true;
        classes[order[r].index] = (uint8_t)(CM_CLASS_FIRST_GROUP + c);
    }
    free(order);
    return coloured > size ? coloured - (uint32_t)size : 0;
}
