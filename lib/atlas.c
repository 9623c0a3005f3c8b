/* lib/atlas.c - the basin atlas: tiles and point queries of a session's
 * cluster (lib/atlas.h). */
#include "lib/atlas.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/grow.h"
#include "lib/attractor_view.h"
#include "render/palette.h"
#include "render/png_out.h"
#include "render/raster.h"

struct atlas_colour {
    double anchor[CM_MAX_DIM]; /* the centre of its anchor cell */
    uint8_t cls; /* enum cm_colour_class */
};

struct atlas_kept {
    int z, layer;
    int64_t x, y;
    uint8_t *png;
    size_t size;
    uint64_t used; /* a->clock when last asked */
};

void atlas_init(atlas *a, session *s, const session_options *o, bool compute, uint64_t max_cells)
{
    memset(a, 0, sizeof *a);
    a->s = s;
    a->compute = compute;
    a->max_cells = max_cells;
    a->level[0] = s;
    if (o) {
        a->level_options = *o;
        a->level_options.mo.set = s->models; /* the plugins the file's model came from */
        a->refines = s->dim == 2;
    }
}

void atlas_level_path(const char *base, int level, char *out, size_t size)
{
    const size_t n = strlen(base), ext = strlen(".cmdb");
    const size_t stem = n > ext && strcmp(base + n - ext, ".cmdb") == 0 ? n - ext : n;
    snprintf(out, size, "%.*s.zoom%d.cmdb", (int)stem, base, level);
}

int atlas_max_level(const atlas *a)
{
    if (!a->refines)
        return 0;
    if (a->compute)
        return ATLAS_MAX_LEVEL;
    int level = 0;
    char path[4096];
    for (; level < ATLAS_MAX_LEVEL; level++) { /* read-only: the levels there are */
        atlas_level_path(a->s->path, level + 1, path, sizeof path);
        if (!a->level[level + 1] && access(path, R_OK) != 0)
            break;
    }
    return level;
}

uint64_t atlas_generation(const atlas *a)
{
    uint64_t regions = 0;
    for (int l = 0; l <= ATLAS_MAX_LEVEL; l++)
        regions += a->level[l] ? a->level[l]->c.nregions : 0;
    return regions;
}

/* The lattice of refined level `level`: level 0's with cells 2^level times
 * narrower in dimensions 0 and 1. */
static cm_lattice level_lattice(const atlas *a, int level)
{
    cm_lattice lat = a->s->c.lat;
    lat.width[0] /= (double)(1 << level);
    lat.width[1] /= (double)(1 << level);
    return lat;
}

/* Whether the file a level's session opened is that level's: level 0's
 * model and parameters on the level's lattice. */
static cm_status check_level(const atlas *a, int level, const session *s, char *msg,
                             size_t msg_size)
{
    const cm_lattice want = level_lattice(a, level);
    char params[4096], wanted[4096]; /* compared as a resumed solve's are */
    cm_params_json(&s->model.values, params, sizeof params);
    cm_params_json(&a->s->model.values, wanted, sizeof wanted);
    const bool same = strcmp(s->model.name, a->s->model.name) == 0 &&
                      strcmp(params, wanted) == 0 && cm_lattice_equal(&s->c.lat, &want);
    return same ? CM_OK
                : cm_fail(CM_EINVAL, msg, msg_size,
                          "%s is not zoom %d of %s (another model, parameters or lattice); move "
                          "it aside",
                          s->path, level, a->s->path);
}

/* Creates the file of refined level `level` at path: the level-0 file's
 * model on the level's lattice, no cells yet. */
static cm_status create_level(const atlas *a, int level, const char *path, char *msg,
                              size_t msg_size)
{
    const session *base = a->s;
    const cm_lattice lat = level_lattice(a, level);
    const cm_model_lib *lib = NULL;
    cm_model_set_find(&a->level_options.mo.set, base->model.name, &lib);
    char command[4200], plan[64];
    snprintf(command, sizeof command, "cellmap serve %s: zoom %d", base->path, level);
    snprintf(plan, sizeof plan, "explore max-steps %d", base->max_steps);
    cm_store *store = NULL;
    cm_cluster c;
    cm_status st = project_create(path, &base->model, lib, &lat, command, plan, &store, &c, msg,
                                  msg_size);
    const cm_status closed = store ? cm_store_close(store, msg, msg_size) : CM_OK;
    cm_cluster_free(&c);
    return st != CM_OK ? st : closed;
}

/* The session of refined level `level` (1..ATLAS_MAX_LEVEL): its file
 * beside the level-0 file (atlas_level_path), made when the atlas computes
 * and opened on first use. */
static cm_status level_session(atlas *a, int level, session **out, char *msg, size_t msg_size)
{
    *out = a->level[level];
    if (*out)
        return CM_OK;
    char path[4096];
    atlas_level_path(a->s->path, level, path, sizeof path);
    cm_status st = CM_OK;
    if (access(path, F_OK) != 0) {
        if (!a->compute)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "zoom %d: %s is not there, and the atlas is read-only", level, path);
        st = create_level(a, level, path, msg, msg_size);
    }
    session *s = st == CM_OK ? calloc(1, sizeof *s) : NULL;
    char *kept_path = s ? strdup(path) : NULL;
    if (st == CM_OK && !kept_path) {
        free(s);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for zoom %d", level);
    }
    if (st != CM_OK)
        return st;
    session_options o = a->level_options;
    o.path = kept_path;
    o.mo.name = NULL; /* the file's own model */
    o.mo.n_texts = 0;
    o.depth_text = NULL;
    session_opened opened;
    st = session_open(s, &o, &opened, msg, msg_size);
    if (st == CM_OK)
        st = check_level(a, level, s, msg, msg_size);
    if (st != CM_OK) {
        char ignored[256];
        session_close(s, ignored, sizeof ignored);
        free(s);
        free(kept_path);
        return st;
    }
    a->level[level] = *out = s;
    return CM_OK;
}

/* Forgets the kept tiles. */
static void drop_kept(atlas *a)
{
    for (uint32_t i = 0; i < a->nkept; i++)
        free(a->kept[i].png);
    a->nkept = 0;
}

cm_status atlas_free(atlas *a, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (int l = 1; l <= ATLAS_MAX_LEVEL; l++) {
        if (!a->level[l])
            continue;
        const cm_status closed = session_close(a->level[l], msg, msg_size);
        st = st != CM_OK ? st : closed;
        free((char *)a->level[l]->path);
        free(a->level[l]);
        a->level[l] = NULL;
    }
    drop_kept(a);
    free(a->kept);
    free(a->colours);
    a->kept = NULL;
    a->colours = NULL;
    return st;
}

/* The kept tile (z, x, y) of layer, or NULL. */
static atlas_kept *find_kept(atlas *a, int z, int64_t x, int64_t y, int layer)
{
    for (uint32_t i = 0; i < a->nkept; i++)
        if (a->kept[i].z == z && a->kept[i].x == x && a->kept[i].y == y &&
            a->kept[i].layer == layer)
            return &a->kept[i];
    return NULL;
}

/* The place of the kept tile asked least recently. */
static uint32_t least_recent(const atlas *a)
{
    uint32_t k = 0;
    for (uint32_t i = 1; i < a->nkept; i++)
        k = a->kept[i].used < a->kept[k].used ? i : k;
    return k;
}

/* Keeps a copy of tile t (z, x, y, layer) in place of the least recently
 * asked one when ATLAS_CACHE_TILES are kept; without memory, keeps nothing. */
static void keep(atlas *a, int z, int64_t x, int64_t y, int layer, const atlas_tile *t)
{
    if (!a->kept && !(a->kept = calloc(ATLAS_CACHE_TILES, sizeof *a->kept)))
        return;
    const uint32_t slot = a->nkept < ATLAS_CACHE_TILES ? a->nkept : least_recent(a);
    uint8_t *png = malloc(t->size);
    if (!png)
        return;
    memcpy(png, t->png, t->size);
    if (slot == a->nkept)
        a->nkept++;
    else
        free(a->kept[slot].png);
    a->kept[slot] = (atlas_kept){z, layer, x, y, png, t->size, a->clock};
}

/* Cells (of its level's lattice) along a tile's side at zoom z. */
static int64_t tile_side(int z) { return (int64_t)ATLAS_TILE << (z < 0 ? -z : 0); }

/* The refusal of a one-dimensional model: the atlas draws two state
 * coordinates. */
static cm_status one_coordinate(const session *s, char *msg, size_t msg_size)
{
    return cm_fail(CM_EINVAL, msg, msg_size,
                   "the atlas draws two state coordinates; model %s has one", s->model.name);
}

cm_status atlas_tile_box(const atlas *a, int z, int64_t x, int64_t y, cm_box *box, char *msg,
                         size_t msg_size)
{
    const session *s = a->s;
    if (s->dim < 2)
        return one_coordinate(s, msg, msg_size);
    if (z < ATLAS_MIN_ZOOM || z > atlas_max_level(a))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "zoom %d: tiles are drawn at zoom %d..%d (0: one pixel per cell of the "
                       "file, above it finer cells)",
                       z, ATLAS_MIN_ZOOM, atlas_max_level(a));
    const int64_t side = tile_side(z), limit = CM_WORLD_LIMIT / side;
    if (x < -limit || x >= limit || y < -limit || y >= limit)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "tile %lld,%lld at zoom %d lies beyond the lattice's world (cell "
                       "coordinates below 2^40)",
                       (long long)x, (long long)y, z);
    session_slice_box(s, box);
    box->lo[0] = x * side;
    box->hi[0] = box->lo[0] + side;
    box->lo[1] = -(y + 1) * side;
    box->hi[1] = box->lo[1] + side;
    return CM_OK;
}

/* The cells of shown (all of the session's depth) the cluster lacks,
 * computed when the atlas computes and they are few enough. */
static cm_status compute_missing(const atlas *a, session *s, const cm_box *shown,
                                 uint64_t *computed, char *msg, size_t msg_size)
{
    cm_box all = *shown;
    for (int d = 2; d < s->dim; d++) {
        all.lo[d] = s->depth_lo[d];
        all.hi[d] = s->depth_hi[d];
    }
    *computed = 0;
    if (!a->compute || cm_box_cells(&all) > a->max_cells)
        return CM_OK;
    session_work done;
    const cm_status st = session_add_box(s, &all, &done, msg, msg_size);
    *computed = done.cells;
    return st;
}

/* The colour class an attractor had in a tile before, else
 * CM_CLASS_NOT_COMPUTED: known by where its anchor cell lies, to within a
 * cell of level 0 (refined levels find the same attractor with other
 * cells). */
static uint8_t known_class(const atlas *a, const double *anchor, int dim)
{
    const double *width = a->s->c.lat.width;
    for (uint32_t i = 0; i < a->ncolours; i++) {
        bool near = true;
        for (int d = 0; d < dim && near; d++)
            near = fabs(a->colours[i].anchor[d] - anchor[d]) <= width[d];
        if (near)
            return a->colours[i].cls;
    }
    return CM_CLASS_NOT_COMPUTED;
}

/* Whether an attractor seen before has class cls. */
static bool class_taken(const atlas *a, uint8_t cls)
{
    for (uint32_t i = 0; i < a->ncolours; i++)
        if (a->colours[i].cls == cls)
            return true;
    return false;
}

/* The class of a new attractor: the one proposed unless an attractor seen
 * before has it, else the first free one (all taken: the one proposed). */
static uint8_t new_class(const atlas *a, uint8_t proposed)
{
    const int n = cm_class_count(NULL);
    for (int cls = CM_CLASS_FIRST_GROUP; class_taken(a, proposed) && cls < n; cls++)
        if (!class_taken(a, (uint8_t)cls))
            return (uint8_t)cls;
    return proposed;
}

/* The colours of the figure's groups attractor_view made (0 the sink,
 * 1..n the attractors, then the grey one), into rgb[0..n]: the palette's
 * classes over all of them (by basin, no neighbour rule), except that an
 * attractor keeps the colour it had in the atlas's earlier tiles, and a
 * new one takes a colour no earlier one has while there is one. Attractor
 * ids change as the cluster grows; their anchors, and so their colours,
 * stay. */
static cm_status group_colours(atlas *a, const cm_lattice *lat, const cm_group_info *groups,
                               uint32_t n, cm_rgb *rgb, char *msg, size_t msg_size)
{
    const int dim = lat->dim;
    uint8_t *classes = malloc((size_t)n + 1);
    if (!classes || cm_grow((void **)&a->colours, &a->colours_cap, a->ncolours + n,
                            sizeof *a->colours) != CM_OK) {
        free(classes);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u colours", n);
    }
    cm_palette_classes(NULL, groups, n, lat, NULL, 1, NULL, classes);
    rgb[0] = cm_colour_sink;
    for (uint32_t g = 1; g <= n; g++) {
        uint8_t cls = classes[g - 1];
        if (cls >= CM_CLASS_FIRST_GROUP) {
            double anchor[CM_MAX_DIM];
            for (int d = 0; d < dim; d++)
                anchor[d] = lat->origin[d] + ((double)groups[g - 1].anchor[d] + 0.5) * lat->width[d];
            const uint8_t known = known_class(a, anchor, dim);
            cls = known != CM_CLASS_NOT_COMPUTED ? known : new_class(a, cls);
            if (known == CM_CLASS_NOT_COMPUTED) {
                atlas_colour *c = &a->colours[a->ncolours++];
                memcpy(c->anchor, anchor, sizeof c->anchor);
                c->cls = cls;
            }
        }
        rgb[g] = cm_class_colour(NULL, cls);
    }
    free(classes);
    return CM_OK;
}

/* flat relabelled by the system's attractors (attractor_view) and the
 * colours of its n groups into a new *rgb (n + 1 of them, group_colours). */
static cm_status attractor_colours(atlas *a, const cm_lattice *lat, cm_region *flat,
                                   const int32_t *labels, const cm_attractor_set *att,
                                   cm_rgb **rgb, uint32_t *n, char *msg, size_t msg_size)
{
    cm_group_info *groups = NULL;
    *rgb = NULL;
    cm_status st = attractor_view(att, flat, labels, &groups, n, msg, msg_size);
    *rgb = st == CM_OK ? malloc(((size_t)*n + 1) * sizeof **rgb) : NULL;
    if (st == CM_OK && !*rgb)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u colours", *n);
    if (st == CM_OK)
        st = group_colours(a, lat, groups, *n, *rgb, msg, msg_size);
    if (st != CM_OK) {
        free(*rgb);
        *rgb = NULL;
    }
    free(groups);
    return st;
}

/* The label most of the k x k block's cells have (ties: the lowest; a
 * computed cell's before CM_GROUP_NONE), the block's ids in v (k^2 <= 64). */
static uint32_t block_mode(uint32_t *v, int n)
{
    for (int i = 1; i < n; i++) { /* insertion sort: at most 64 */
        const uint32_t x = v[i];
        int j = i;
        for (; j > 0 && v[j - 1] > x; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
    uint32_t best = v[0];
    int best_run = 0;
    for (int i = 0; i < n;) {
        int j = i;
        while (j < n && v[j] == v[i])
            j++;
        if (j - i > best_run) {
            best_run = j - i;
            best = v[i];
        }
        i = j;
    }
    return best;
}

/* A cell's value as a tile shows it: attractor_view's group (basins), or
 * the step number (steps); CM_GROUP_NONE where nothing is computed. */
static uint32_t cell_value(const cm_region *flat, uint64_t i, int layer)
{
    return layer == ATLAS_STEPS && flat->group[i] != CM_GROUP_NONE ? flat->step[i]
                                                                   : flat->group[i];
}

/* The colour of a tile's pixel of value v (cell_value; the most frequent
 * of its block). */
static cm_rgb pixel_colour(uint32_t v, int layer, bool marker, const cm_rgb *rgb, uint32_t n,
                           const uint8_t *grey)
{
    if (v == CM_GROUP_NONE)
        return cm_colour_not_computed;
    if (layer == ATLAS_STEPS) {
        const uint8_t g = grey[v < ATLAS_STEP_CAP ? v : ATLAS_STEP_CAP];
        return (cm_rgb){g, g, g};
    }
    return marker ? cm_colour_marker : v <= n ? rgb[v] : cm_colour_other;
}

/* The tile's pixels (RGBA, row 0 at the top) from the cells (basins:
 * relabelled by attractor_view, rgb their n colours). */
static void paint_tile(const cm_region *flat, int layer, const cm_rgb *rgb, uint32_t n,
                       uint32_t attractors, int z, int threads, uint8_t *rgba)
{
    const int k = 1 << -z;
    const int64_t width = flat->box.hi[0] - flat->box.lo[0];
    uint8_t grey[ATLAS_STEP_CAP + 1];
    for (int t = 0; t <= ATLAS_STEP_CAP; t++)
        grey[t] = (uint8_t)cm_step_shade(log1p(t) / log1p(ATLAS_STEP_CAP), CM_RASTER_STEPS);
#pragma omp parallel for schedule(static) num_threads(threads > 0 ? threads : 1)
    for (int py = 0; py < ATLAS_TILE; py++) {
        uint32_t block[64];
        const int64_t low = (int64_t)(ATLAS_TILE - 1 - py) * k; /* the block's lowest row */
        for (int px = 0; px < ATLAS_TILE; px++) {
            int used = 0;
            for (int r = 0; r < k; r++)
                for (int c = 0; c < k; c++)
                    block[used++] =
                        cell_value(flat, (uint64_t)((low + r) * width + px * k + c), layer);
            const uint32_t v = k == 1 ? block[0] : block_mode(block, used);
            const uint64_t at = (uint64_t)(low * width + px * k);
            const bool marker = k == 1 && v >= 1 && v <= attractors && flat->step[at] == 0;
            const cm_rgb col = pixel_colour(v, layer, marker, rgb, n, grey);
            uint8_t *p = rgba + 4 * ((size_t)py * ATLAS_TILE + (size_t)px);
            p[0] = col.r;
            p[1] = col.g;
            p[2] = col.b;
            p[3] = 255;
        }
    }
}

/* Draws labelled cells (flat, labels, att: session_labels) as the tile. */
static cm_status draw_tile(atlas *a, const session *s, int z, int layer, cm_region *flat,
                           const int32_t *labels, const cm_attractor_set *att, atlas_tile *out,
                           char *msg, size_t msg_size)
{
    cm_rgb *rgb = NULL; /* the steps layer has no group colours */
    uint32_t n = 0;
    cm_status st = layer == ATLAS_BASINS ? attractor_colours(a, &s->c.lat, flat, labels, att,
                                                             &rgb, &n, msg, msg_size)
                                         : CM_OK;
    uint8_t *rgba = st == CM_OK ? malloc((size_t)4 * ATLAS_TILE * ATLAS_TILE) : NULL;
    if (st == CM_OK && !rgba)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a tile");
    if (st == CM_OK) {
        paint_tile(flat, layer, rgb, n, layer == ATLAS_BASINS ? att->n : 0, z < 0 ? z : 0,
                   s->threads, rgba);
        st = cm_png_encode(rgba, ATLAS_TILE, ATLAS_TILE, &out->png, &out->size, msg, msg_size);
    }
    free(rgb);
    free(rgba);
    return st;
}

cm_status atlas_tile_png(atlas *a, int z, int64_t x, int64_t y, int layer, atlas_tile *out,
                         char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (layer != ATLAS_BASINS && layer != ATLAS_STEPS)
        return cm_fail(CM_EINVAL, msg, msg_size, "layer %d: basins (0) or steps (1)", layer);
    cm_box box;
    session *s = a->s;
    cm_status st = atlas_tile_box(a, z, x, y, &box, msg, msg_size);
    if (st == CM_OK && z > 0)
        st = level_session(a, z, &s, msg, msg_size);
    if (st == CM_OK)
        st = compute_missing(a, s, &box, &out->computed, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (a->kept_generation != atlas_generation(a)) { /* a level grew: tiles may change */
        drop_kept(a);
        a->kept_generation = atlas_generation(a);
    }
    a->clock++;
    atlas_kept *k = find_kept(a, z, x, y, layer);
    if (k) {
        k->used = a->clock;
        out->kept = true;
        out->size = k->size;
        if (!(out->png = malloc(k->size)))
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a tile");
        memcpy(out->png, k->png, k->size);
        return CM_OK;
    }
    cm_region flat;
    int32_t *labels = NULL;
    cm_attractor_set att;
    st = session_labels(s, &box, &flat, &labels, &att, msg, msg_size);
    if (st != CM_OK)
        return st;
    st = draw_tile(a, s, z, layer, &flat, labels, &att, out, msg, msg_size);
    free(labels);
    cm_region_free(&flat);
    cm_attractors_free(&att);
    if (st == CM_OK)
        keep(a, z, x, y, layer, out);
    return st;
}

/* The cell of the slice at the lattice's origin: any box gives the
 * cluster's attractors. */
static void origin_cell(const session *s, cm_box *box)
{
    session_slice_box(s, box);
    for (int d = 0; d < 2; d++) {
        box->lo[d] = 0;
        box->hi[d] = 1;
    }
}

/* The name the user gave attractor at (of level 0), or NULL. */
static const char *given_name(const atlas *a, const cm_attractor *at)
{
    for (int k = 0; k < a->nnames; k++) {
        const cm_group_label *l = &a->names[k];
        bool same = l->by_anchor || l->id == at->id;
        for (int d = 0; l->by_anchor && d < a->s->dim; d++)
            same = same && l->anchor[d] == at->anchor[d];
        if (same)
            return l->text;
    }
    return NULL;
}

/* The legend's keys from the labelled cells of any box (session_labels). */
static cm_status legend_keys(atlas *a, cm_region *flat, const int32_t *labels,
                             const cm_attractor_set *att, atlas_key **keys, uint32_t *n,
                             char *msg, size_t msg_size)
{
    cm_rgb *rgb = NULL;
    uint32_t ngroups = 0;
    cm_status st = attractor_colours(a, &a->s->c.lat, flat, labels, att, &rgb, &ngroups, msg,
                                     msg_size);
    cm_group_label *names = st == CM_OK ? calloc((size_t)att->n + 1, sizeof *names) : NULL;
    *keys = st == CM_OK ? calloc((size_t)att->n + 3, sizeof **keys) : NULL;
    if (st == CM_OK && (!names || !*keys))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the legend");
    if (st == CM_OK) {
        const int named = attractor_legend(att, att->n, names, 0, (int)att->n);
        uint32_t used = 0;
        for (int k = 0; k < named; k++, used++) {
            atlas_key *key = &(*keys)[used];
            *key = (atlas_key){.label = (int32_t)names[k].id, .colour = rgb[names[k].id]};
            const cm_attractor *at = &att->a[names[k].id - 1];
            const char *given = given_name(a, at);
            snprintf(key->name, sizeof key->name, "%s", given ? given : names[k].text);
            memcpy(key->centre, at->centre, sizeof key->centre);
        }
        (*keys)[used++] = (atlas_key){CM_LABEL_DIVERGED, cm_colour_sink, "diverged", {0}};
        (*keys)[used++] =
            (atlas_key){CM_LABEL_OUTSIDE, cm_colour_sticking, "outside or undecided", {0}};
        (*keys)[used++] =
            (atlas_key){CM_LABEL_UNCOMPUTED, cm_colour_not_computed, "not computed", {0}};
        *n = used;
    }
    if (st != CM_OK) {
        free(*keys);
        *keys = NULL;
    }
    free(rgb);
    free(names);
    return st;
}

cm_status atlas_legend(atlas *a, atlas_key **keys, uint32_t *n, char *msg,
                       size_t msg_size)
{
    *keys = NULL;
    *n = 0;
    if (a->s->dim < 2)
        return one_coordinate(a->s, msg, msg_size);
    cm_box box;
    origin_cell(a->s, &box);
    cm_region flat;
    int32_t *labels = NULL;
    cm_attractor_set att;
    cm_status st = session_labels(a->s, &box, &flat, &labels, &att, msg, msg_size);
    if (st != CM_OK)
        return st;
    st = legend_keys(a, &flat, labels, &att, keys, n, msg, msg_size);
    free(labels);
    cm_region_free(&flat);
    cm_attractors_free(&att);
    return st;
}

void atlas_overlays(const atlas *a, const double lo[2], const double hi[2], cm_overlay_list *out)
{
    out->count = 0;
    out->truncated = false;
    if (a->s->model.overlays)
        a->s->model.overlays(&a->s->model, lo, hi, out);
}

/* The true orbit of steps images from p->centre into p->orbit. */
static cm_status follow_orbit(const cm_model *m, int steps, atlas_point *p, char *msg,
                              size_t msg_size)
{
    const int dim = m->dim;
    p->orbit = malloc(((size_t)steps + 1) * (size_t)dim * sizeof *p->orbit);
    if (!p->orbit)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for an orbit of %d steps", steps);
    memcpy(p->orbit, p->centre, (size_t)dim * sizeof *p->orbit);
    p->norbit = 1;
    for (int k = 0; k < steps; k++) {
        const double *x = p->orbit + (size_t)k * (size_t)dim;
        double *y = p->orbit + (size_t)(k + 1) * (size_t)dim;
        const int rc = m->step(m, x, y);
        if (rc < 0)
            return cm_fail(CM_EINVAL, msg, msg_size, "model %s stopped the orbit at step %d",
                           m->name, k + 1);
        bool finite = rc == 0;
        for (int d = 0; d < dim && finite; d++)
            finite = isfinite(y[d]);
        if (!finite)
            break; /* no image: the sink */
        p->norbit++;
    }
    return CM_OK;
}

/* The colour tiles give the one cell of flat (labelled, session_labels). */
static cm_status label_colour(atlas *a, const session *s, cm_region *flat, const int32_t *labels,
                              const cm_attractor_set *att, cm_rgb *out, char *msg,
                              size_t msg_size)
{
    cm_rgb *rgb = NULL;
    uint32_t n = 0;
    const cm_status st =
        attractor_colours(a, &s->c.lat, flat, labels, att, &rgb, &n, msg, msg_size);
    const uint32_t g = flat->group[0];
    if (st == CM_OK)
        *out = g == CM_GROUP_NONE ? cm_colour_not_computed : g <= n ? rgb[g] : cm_colour_other;
    free(rgb);
    return st;
}

/* The legend's name of label (an attractor of s, or a fate without one):
 * at level 0 the name the user gave it, if any. */
static void name_label(const atlas *a, int level, const cm_attractor_set *s, int32_t label,
                       char *out, size_t size)
{
    const cm_attractor *at = label > 0 && (uint32_t)label <= s->n ? &s->a[label - 1] : NULL;
    const char *given = at && level == 0 ? given_name(a, at) : NULL;
    if (given)
        snprintf(out, size, "%s", given);
    else if (at)
        attractor_name(at, out, size);
    else
        snprintf(out, size, "%s", label == CM_LABEL_DIVERGED    ? "diverged"
                                  : label == CM_LABEL_UNCOMPUTED ? "not computed"
                                                                 : "outside or undecided");
}

cm_status atlas_point_query(atlas *a, double x, double y, int zoom, int steps, atlas_point *out,
                            char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (!isfinite(x) || !isfinite(y))
        return cm_fail(CM_EINVAL, msg, msg_size, "the point needs finite coordinates x and y");
    if (steps < 0 || steps > ATLAS_ORBIT_MAX)
        return cm_fail(CM_EINVAL, msg, msg_size, "an orbit of %d steps: give 0..%d", steps,
                       ATLAS_ORBIT_MAX);
    if (a->s->dim < 2)
        return one_coordinate(a->s, msg, msg_size);
    const int top = atlas_max_level(a);
    const int level = zoom < 0 ? 0 : zoom < top ? zoom : top;
    session *s = a->s;
    if (level > 0) {
        const cm_status st = level_session(a, level, &s, msg, msg_size);
        if (st != CM_OK)
            return st;
    }
    const cm_lattice *lat = &s->c.lat;
    out->level = level;
    double state[CM_MAX_DIM] = {x, y};
    for (int d = 2; d < s->dim; d++)
        state[d] = lat->origin[d] + ((double)s->slice[d] + 0.5) * lat->width[d];
    if (!cm_lattice_cell(lat, state, out->cell))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the point %g,%g lies beyond the lattice's world (cell coordinates "
                       "below 2^40)",
                       x, y);
    cm_box box = {.dim = s->dim};
    for (int d = 0; d < s->dim; d++) {
        box.lo[d] = out->cell[d];
        box.hi[d] = out->cell[d] + 1;
        out->centre[d] = lat->origin[d] + ((double)out->cell[d] + 0.5) * lat->width[d];
    }
    cm_region flat;
    int32_t *labels = NULL;
    cm_attractor_set att;
    cm_status st = session_labels(s, &box, &flat, &labels, &att, msg, msg_size);
    if (st != CM_OK)
        return st;
    out->computed = flat.group[0] != CM_GROUP_NONE;
    out->group = out->computed ? flat.group[0] : 0;
    out->step = out->computed ? flat.step[0] : 0;
    out->label = labels[0];
    out->attractors = att.n;
    name_label(a, level, &att, out->label, out->name, sizeof out->name);
    st = label_colour(a, s, &flat, labels, &att, &out->colour, msg, msg_size);
    free(labels);
    cm_region_free(&flat);
    cm_attractors_free(&att);
    if (st == CM_OK)
        st = follow_orbit(&s->model, steps, out, msg, msg_size);
    if (st != CM_OK)
        atlas_point_free(out);
    return st;
}

void atlas_point_free(atlas_point *p)
{
    free(p->orbit);
    p->orbit = NULL;
    p->norbit = 0;
}
