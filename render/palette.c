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
/* pale cream: present, not one group; CM_NEIGHBOUR_DISTANCE from the grey
 * of sticking zones (the cells outside, by attractors) and every colour of
 * the default palette */
const cm_rgb cm_colour_other = {250, 244, 184};
const cm_rgb cm_colour_repeller = {230, 159, 0};
const cm_rgb cm_colour_escape = {0, 114, 178};
const cm_rgb cm_colour_collision = {220, 30, 30};
const cm_rgb cm_colour_collision_higher = {255, 150, 0};

/* No red (the sink), black (markers), white (not computed) or grey
 * (sticking zones) in any palette. */
static const cm_palette builtin[] = {
    /* The default: Tol's bright and vibrant blue, green, yellow, cyan,
     * purple, orange and teal, then 17 colours each chosen as far as
     * possible from those before in cm_colour_distance (lightness 40-85,
     * chroma 25-65, CM_NEIGHBOUR_DISTANCE from the fixed colours):
     * docs/make-palette.py. */
    {"cellmap",
     24,
     {{0x44, 0x77, 0xaa}, {0x22, 0x88, 0x33}, {0xcc, 0xbb, 0x44}, {0x66, 0xcc, 0xee},
      {0xaa, 0x33, 0x77}, {0xee, 0x77, 0x33}, {0x00, 0x99, 0x88}, {0xf0, 0xb4, 0x96},
      {0xa5, 0x87, 0xf0}, {0xa5, 0xe1, 0x78}, {0x87, 0xa5, 0x69}, {0x0f, 0x5a, 0xc3},
      {0xc3, 0x96, 0xc3}, {0xa5, 0x69, 0x5a}, {0x96, 0xb4, 0xff}, {0xd2, 0xa5, 0x5a},
      {0x1e, 0x87, 0x96}, {0x4b, 0x69, 0x0f}, {0xd2, 0x78, 0xd2}, {0xff, 0x87, 0x78},
      {0x5a, 0x5a, 0xa5}, {0x00, 0x78, 0xd2}, {0x96, 0x87, 0x4b}, {0x1e, 0x87, 0x5a}}},
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
                   "no palette '%s': use cellmap (the default), tol, okabe-ito or tab20, or a file "
                   "of #rrggbb lines",
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

/* ---- colour distances ------------------------------------------------------------ */

/* A colour as seen with normal vision, deuteranopia and protanopia
 * (Machado, Oliveira and Fernandes 2009, severity 1, on linear RGB), each
 * in CIELAB (D65). */
typedef struct seen {
    double lab[3][3];
} seen;

static double linear(uint8_t v)
{
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static double lab_f(double t)
{
    const double e = 6.0 / 29.0;
    return t > e * e * e ? cbrt(t) : t / (3 * e * e) + 4.0 / 29.0;
}

static void lab_of(const double rgb[3], double lab[3])
{
    double c[3];
    for (int k = 0; k < 3; k++) /* simulated colours can leave the gamut */
        c[k] = rgb[k] < 0 ? 0 : rgb[k] > 1 ? 1 : rgb[k];
    const double x = (0.4124564 * c[0] + 0.3575761 * c[1] + 0.1804375 * c[2]) / 0.95047;
    const double y = 0.2126729 * c[0] + 0.7151522 * c[1] + 0.0721750 * c[2];
    const double z = (0.0193339 * c[0] + 0.1191920 * c[1] + 0.9503041 * c[2]) / 1.08883;
    lab[0] = 116 * lab_f(y) - 16;
    lab[1] = 500 * (lab_f(x) - lab_f(y));
    lab[2] = 200 * (lab_f(y) - lab_f(z));
}

static seen seen_of(cm_rgb c)
{
    static const double deficiency[2][3][3] = {
        {{0.367322, 0.860646, -0.227968}, {0.280085, 0.672501, 0.047413},
         {-0.011820, 0.042940, 0.968881}}, /* deuteranopia */
        {{0.152286, 1.052583, -0.204868}, {0.114503, 0.786281, 0.099216},
         {-0.003882, -0.048116, 1.051998}}, /* protanopia */
    };
    const double lin[3] = {linear(c.r), linear(c.g), linear(c.b)};
    seen s;
    lab_of(lin, s.lab[0]);
    for (int v = 0; v < 2; v++) {
        double sim[3];
        for (int k = 0; k < 3; k++)
            sim[k] = deficiency[v][k][0] * lin[0] + deficiency[v][k][1] * lin[1] +
                     deficiency[v][k][2] * lin[2];
        lab_of(sim, s.lab[v + 1]);
    }
    return s;
}

static double lab_distance(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

static double seen_distance(const seen *a, const seen *b)
{
    double d = lab_distance(a->lab[0], b->lab[0]);
    for (int v = 1; v < 3; v++) {
        const double dv = 2 * lab_distance(a->lab[v], b->lab[v]);
        d = dv < d ? dv : d;
    }
    return d;
}

double cm_delta_e(cm_rgb a, cm_rgb b)
{
    const seen x = seen_of(a), y = seen_of(b);
    return lab_distance(x.lab[0], y.lab[0]);
}

double cm_colour_distance(cm_rgb a, cm_rgb b)
{
    const seen x = seen_of(a), y = seen_of(b);
    return seen_distance(&x, &y);
}

/* ---- choosing the colours ---------------------------------------------------------- */

/* Who touches whom, by item: groups 1..n, the sink 0, not computed n + 1. */
typedef struct neighbours {
    uint32_t *start; /* n + 3 offsets into item */
    uint32_t *item;
} neighbours;

static uint32_t item_of(uint32_t label, uint32_t n)
{
    return label == CM_GROUP_NONE ? n + 1 : label;
}

static bool neighbours_build(const cm_touching *t, uint32_t n, neighbours *nb)
{
    const size_t items = (size_t)n + 2;
    nb->start = calloc(items + 1, sizeof *nb->start);
    nb->item = malloc((2 * t->n + 1) * sizeof *nb->item);
    if (!nb->start || !nb->item || 2 * t->n >= UINT32_MAX)
        return false;
    for (int pass = 0; pass < 2; pass++) { /* count, then place */
        for (size_t k = 0; k < t->n; k++) {
            const uint32_t a = item_of((uint32_t)(t->pair[k] >> 32), n);
            const uint32_t b = item_of((uint32_t)t->pair[k], n);
            if (a >= items || b >= items)
                continue;
            if (pass == 0)
                nb->start[a + 1]++, nb->start[b + 1]++;
            else
                nb->item[nb->start[a]++] = b, nb->item[nb->start[b]++] = a;
        }
        if (pass == 0)
            for (size_t i = 0; i < items; i++)
                nb->start[i + 1] += nb->start[i];
        else /* each start moved to the next one's: shift back */
            for (size_t i = items; i > 0; i--)
                nb->start[i] = nb->start[i - 1];
        nb->start[0] = 0;
    }
    return true;
}

/* The smallest distance from palette colour c to the neighbours' classes
 * (infinite without neighbours). */
static double distance_to(size_t c, const int *neighbour_class, size_t nneighbours,
                          const seen *class_seen)
{
    double d = INFINITY;
    for (size_t k = 0; k < nneighbours; k++) {
        const double dk =
            seen_distance(&class_seen[CM_CLASS_FIRST_GROUP + c], &class_seen[neighbour_class[k]]);
        d = dk < d ? dk : d;
    }
    return d;
}

/* The palette colour for a group, counting from its hash's on: the first
 * one free in this round and CM_NEIGHBOUR_DISTANCE from every neighbour
 * coloured so far; else the first that far though taken (neighbours
 * matter more than a colour seen twice); else the free one farthest from
 * the neighbours. */
static size_t choose_colour(size_t preferred, size_t size, const bool *taken,
                            const int *neighbour_class, size_t nneighbours, const seen *class_seen)
{
    size_t farthest = size;
    double farthest_distance = -1;
    for (int pass = 0; pass < 2; pass++)
        for (size_t t = 0; t < size; t++) {
            const size_t c = (preferred + t) % size;
            if (pass == 0 && taken[c])
                continue;
            const double d = distance_to(c, neighbour_class, nneighbours, class_seen);
            if (d >= CM_NEIGHBOUR_DISTANCE)
                return c;
            if (pass == 0 && d > farthest_distance)
                farthest = c, farthest_distance = d;
        }
    return farthest < size ? farthest : preferred;
}

/* The classes of the coloured groups, in rank order; neighbours (NULL:
 * none known) keep touching groups apart. */
static void assign_colours(const cm_palette *p, const ranked *order, uint32_t coloured, uint32_t n,
                           const neighbours *nb, uint8_t *classes)
{
    const size_t size = (size_t)p->n;
    seen class_seen[CM_CLASS_FIRST_GROUP + CM_PALETTE_MAX];
    for (int c = 0; nb && c < cm_class_count(p); c++)
        class_seen[c] = seen_of(cm_class_colour(p, c));
    int *decided = nb ? malloc(((size_t)n + 2) * sizeof *decided) : NULL; /* class or -1 */
    int *near = nb ? malloc(((size_t)n + 2) * sizeof *near) : NULL;
    const bool rule = decided && near; /* out of memory: no neighbour rule */
    if (rule) {
        decided[0] = CM_CLASS_SINK;
        decided[n + 1] = CM_CLASS_NOT_COMPUTED;
        for (uint32_t k = 0; k < n; k++) /* sticking and "other" are fixed */
            decided[k + 1] = classes[k] == CM_CLASS_OTHER || classes[k] == CM_CLASS_STICKING
                                 ? classes[k]
                                 : -1;
    }
    bool taken[CM_PALETTE_MAX];
    for (uint32_t r = 0; r < coloured; r++) {
        if (r % size == 0) /* every colour taken: a new round */
            memset(taken, 0, sizeof taken);
        const uint32_t item = order[r].index + 1;
        size_t nnear = 0;
        for (uint32_t k = rule ? nb->start[item] : 0; rule && k < nb->start[item + 1]; k++)
            if (decided[nb->item[k]] >= 0)
                near[nnear++] = decided[nb->item[k]];
        const size_t c = choose_colour(order[r].hash % size, size, taken, near, nnear, class_seen);
        taken[c] = true;
        classes[order[r].index] = (uint8_t)(CM_CLASS_FIRST_GROUP + c);
        if (rule)
            decided[item] = classes[order[r].index];
    }
    free(decided);
    free(near);
}

uint32_t cm_palette_classes(const cm_palette *p, const cm_group_info *groups, uint32_t n,
                            const cm_lattice *lat, const uint64_t *in_view, uint64_t min_basin,
                            const cm_touching *touching, uint8_t *classes)
{
    p = p ? p : cm_palette_default();
    const size_t size = (size_t)p->n;
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
    neighbours nb = {0};
    const bool known = touching && neighbours_build(touching, n, &nb); /* else: no rule */
    assign_colours(p, order, coloured, n, known ? &nb : NULL, classes);
    free(nb.start);
    free(nb.item);
    free(order);
    return coloured > size ? coloured - (uint32_t)size : 0;
}
