/* lib/atlas.h - the basin atlas: a session's cluster (lib/session.h) as
 * slippy-map tiles and point queries, what `cellmap serve` shows in a
 * browser (docs/serve.md).
 *
 * Tiles. Zoom 0 draws one pixel per cell; zoom z < 0 (down to
 * ATLAS_MIN_ZOOM) one pixel per k x k cells, k = 2^-z, coloured by the
 * label most of them have (ties: the lowest), never by computing anything
 * coarser. A tile reads all its cells (at ATLAS_MIN_ZOOM 2048 x 2048), so
 * zoom stops there. Zoom z > 0 (up to ATLAS_MAX_LEVEL) draws one pixel per
 * cell of refined level z: the same model on a lattice of the same origin
 * and cells 2^z times narrower in dimensions 0 and 1, a cluster of its own
 * in the file beside (atlas_level_path), computed as level 0 is, so that
 * zooming in on a boundary shows its detail. Tile (z, x, y) is ATLAS_TILE pixels a side and covers the cells
 * c0 in [x T k, (x + 1) T k) and c1 in [-(y + 1) T k, -y T k) (T =
 * ATLAS_TILE), its row 0 at the top: Leaflet's CRS.Simple with the
 * transformation (1/h0, -o0/h0, -1/h1, o1/h1) (h the cell widths, o the
 * lattice origin) puts state coordinates there, so the map's coordinates
 * are the state's. Models of more than two dimensions show the session's
 * slice.
 *
 * Colours. An attractor keeps one colour in every tile: the palette's
 * classes are chosen over all the attractors the cluster has (by basin, no
 * neighbour rule, cm_palette_classes), so neighbouring tiles agree, and an
 * attractor (known by its anchor: ids change as the cluster grows) keeps
 * the colour it had in the atlas's earlier tiles, a new one taking a
 * colour no earlier one has while the palette has one.
 * Diverged cells are the sink's red, cells whose fate is outside or
 * undecided grey, cells not computed the figures' not-computed colour, and
 * at zoom 0 an attractor's footprint cells are black, as figures mark
 * them.
 *
 * Computing on demand. With compute set, a tile of at most max_cells cells
 * (all of the session's depth) first computes the cells of it the cluster
 * lacks, as an explore pan would (session_add_box: new regions, joined and
 * committed before the tile is drawn); a larger tile draws what there is.
 *
 * Tiles drawn are kept (the last ATLAS_CACHE_TILES, about 2-20 KB each)
 * until the cluster grows: a tile asked again costs a copy.
 *
 * An atlas borrows its session and is used by one thread at a time;
 * everything it returns is the caller's. */
#ifndef CM_LIB_ATLAS_H
#define CM_LIB_ATLAS_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/overlay.h"
#include "lib/session.h"

enum {
    ATLAS_TILE = 256,
    ATLAS_MIN_ZOOM = -3,
    ATLAS_MAX_LEVEL = 3, /* refined levels: zoom 1..3 */
    ATLAS_ORBIT_MAX = 10000,
    ATLAS_CACHE_TILES = 512,
    ATLAS_STEP_CAP = 64 /* step numbers from here up are the darkest grey */
};

/* What a tile shows: the basins (as above), or the cells' step numbers in
 * grey, light (few) to dark (ATLAS_STEP_CAP and more) on the figures'
 * logarithmic scale (render/raster.h: cm_step_shade), a block of cells at
 * zoom < 0 its most frequent step number. */
enum atlas_layer { ATLAS_BASINS = 0, ATLAS_STEPS = 1 };

typedef struct atlas_kept atlas_kept;
typedef struct atlas_colour atlas_colour;

typedef struct atlas {
    session *s;         /* level 0: the file's session (borrowed) */
    bool compute;       /* compute the cells a tile lacks */
    uint64_t max_cells; /* the most cells a tile computes (its cells, all depth) */
    /* the legend's names the user gave (png_opts_labels: by attractor id
     * or anchor cell, of level 0; borrowed; NULL: none) */
    const cm_group_label *names;
    int nnames;
    /* private: the levels' sessions ([0] = s; the others the atlas's, opened
     * on first use as level_options say); the tiles kept, for the levels as
     * they were at kept_generation; the attractors' colours so far */
    session *level[ATLAS_MAX_LEVEL + 1];
    session_options level_options;
    bool refines;
    atlas_kept *kept;
    uint32_t nkept;
    uint64_t kept_generation, clock;
    atlas_colour *colours;
    uint64_t ncolours, colours_cap;
} atlas;

/* An atlas over s (borrowed), which o opened (NULL: no refined levels;
 * they are opened as o says, their own file's model, for models of two
 * dimensions); atlas_free closes the levels it opened (their attractors
 * written, as session_close does) and frees what it keeps, whatever the
 * status. */
void atlas_init(atlas *a, session *s, const session_options *o, bool compute, uint64_t max_cells);
cm_status atlas_free(atlas *a, char *msg, size_t msg_size);

/* The file of refined level `level` beside the file at base: BASE.zoomL.cmdb
 * (BASE without its .cmdb). */
void atlas_level_path(const char *base, int level, char *out, size_t size);

/* The highest zoom tiles are drawn at: ATLAS_MAX_LEVEL when the atlas
 * computes (a model of two dimensions), else the levels whose files are
 * there (0: none). */
int atlas_max_level(const atlas *a);

/* The regions of the levels open: it grows whenever one of them does. */
uint64_t atlas_generation(const atlas *a);

/* The cells of tile (z, x, y): dimensions 0 and 1 by the scheme above,
 * the others the session's slice. CM_EINVAL (why in msg) for a zoom
 * outside ATLAS_MIN_ZOOM..0 or a tile beyond the lattice's world. */
cm_status atlas_tile_box(const atlas *a, int z, int64_t x, int64_t y, cm_box *box, char *msg,
                         size_t msg_size);

typedef struct atlas_tile {
    uint8_t *png;      /* the tile as an RGB PNG (the caller frees it) */
    size_t size;       /* its bytes */
    uint64_t computed; /* cells computed for it */
    bool kept;         /* it was drawn before (for this cluster) */
} atlas_tile;

/* Tile (z, x, y) of layer (enum atlas_layer) drawn, after computing what
 * it lacks (a->compute). */
cm_status atlas_tile_png(atlas *a, int z, int64_t x, int64_t y, int layer, atlas_tile *out,
                         char *msg, size_t msg_size);

/* What the model draws over its basins in the rectangle lo..hi (switching
 * lines, fixed points, manifolds: cellmap/overlay.h) into out, a list the
 * caller sized (its truncated flag says whether more there were); none
 * for a model without overlays. */
void atlas_overlays(const atlas *a, const double lo[2], const double hi[2], cm_overlay_list *out);

/* One line of the map's legend: an attractor (label > 0, its name as
 * figures' legends give it: "A3 p=1"), or the fates without one
 * (CM_LABEL_DIVERGED, CM_LABEL_OUTSIDE, CM_LABEL_UNCOMPUTED), with the
 * tiles' colour. */
typedef struct atlas_key {
    int32_t label;
    cm_rgb colour;
    char name[64];
    double centre[CM_MAX_DIM]; /* an attractor's: the mean of its cycle or recorded orbit */
} atlas_key;

/* The legend of the cluster as it is: the attractors (sticking zones
 * share the grey of "outside or undecided"; named as a->names say, else as
 * figures name them), then diverged, outside or undecided, not computed;
 * *keys (*n of them) the caller frees. */
cm_status atlas_legend(atlas *a, atlas_key **keys, uint32_t *n, char *msg,
                       size_t msg_size);

/* What a point of the map is. */
typedef struct atlas_point {
    int level;      /* the lattice's level (0: the file's) */
    int64_t cell[CM_MAX_DIM];
    double centre[CM_MAX_DIM];
    bool computed;  /* the cluster has the cell */
    uint32_t group; /* its group (0: the sink's domain) */
    uint32_t step;  /* its step number */
    int32_t label;  /* its attractor (> 0), or CM_LABEL_DIVERGED, _OUTSIDE, _UNCOMPUTED */
    char name[64];  /* the label as the legend names it ("A3 p=1", or the name --labels
                       gives it at level 0; ids are the level's) */
    cm_rgb colour;  /* the label's colour in the tiles (a footprint cell's too: not black) */
    uint32_t attractors; /* how many the cluster has */
    double *orbit;  /* the true orbit from the cell's centre: norbit states of dim numbers */
    int norbit;     /* up to the steps asked, fewer where the map gives no image */
} atlas_point;

/* The cell at state (x, y) (the slice's other coordinates) of the level
 * that zoom shows (0 for zoom <= 0, at most atlas_max_level), with the
 * orbit of `steps` (0..ATLAS_ORBIT_MAX) images of its centre;
 * atlas_point_free frees it. CM_EINVAL for a point that is not finite or
 * beyond the world. */
cm_status atlas_point_query(atlas *a, double x, double y, int zoom, int steps, atlas_point *out,
                            char *msg, size_t msg_size);
void atlas_point_free(atlas_point *p);

#endif
