/* lib/atlas.h - the basin atlas: a session's cluster (lib/session.h) as
 * slippy-map tiles and point queries, what `cellmap serve` shows in a
 * browser (docs/serve.md).
 *
 * Tiles. Zoom 0 draws one pixel per cell; zoom z < 0 (down to
 * ATLAS_MIN_ZOOM) one pixel per k x k cells, k = 2^-z, coloured by the
 * label most of them have (ties: the lowest), never by computing anything
 * coarser. A tile reads all its cells (at ATLAS_MIN_ZOOM 2048 x 2048), so
 * zoom stops there. Tile (z, x, y) is ATLAS_TILE pixels a side and covers the cells
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

#include "lib/session.h"

enum { ATLAS_TILE = 256, ATLAS_MIN_ZOOM = -3, ATLAS_ORBIT_MAX = 10000, ATLAS_CACHE_TILES = 512 };

typedef struct atlas_kept atlas_kept;
typedef struct atlas_colour atlas_colour;

typedef struct atlas {
    session *s;
    bool compute;       /* compute the cells a tile lacks */
    uint64_t max_cells; /* the most cells a tile computes (its cells, all depth) */
    /* private: the tiles kept, for the cluster of kept_regions regions;
     * the attractors' colours so far */
    atlas_kept *kept;
    uint32_t nkept, kept_regions;
    uint64_t clock;
    atlas_colour *colours;
    uint64_t ncolours, colours_cap;
} atlas;

/* An atlas over s (borrowed); atlas_free frees what it keeps. */
void atlas_init(atlas *a, session *s, bool compute, uint64_t max_cells);
void atlas_free(atlas *a);

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

/* Tile (z, x, y) drawn, after computing what it lacks (a->compute). */
cm_status atlas_tile_png(atlas *a, int z, int64_t x, int64_t y, atlas_tile *out, char *msg,
                         size_t msg_size);

/* One line of the map's legend: an attractor (label > 0, its name as
 * figures' legends give it: "A3 p=1"), or the fates without one
 * (CM_LABEL_DIVERGED, CM_LABEL_OUTSIDE, CM_LABEL_UNCOMPUTED), with the
 * tiles' colour. */
typedef struct atlas_key {
    int32_t label;
    cm_rgb colour;
    char name[64];
} atlas_key;

/* The legend of the cluster as it is: the attractors (sticking zones
 * share the grey of "outside or undecided"), then diverged, outside or
 * undecided, not computed; *keys (*n of them) the caller frees. */
cm_status atlas_legend(atlas *a, atlas_key **keys, uint32_t *n, char *msg,
                       size_t msg_size);

/* What a point of the map is. */
typedef struct atlas_point {
    int64_t cell[CM_MAX_DIM];
    double centre[CM_MAX_DIM];
    bool computed;  /* the cluster has the cell */
    uint32_t group; /* its group (0: the sink's domain) */
    uint32_t step;  /* its step number */
    int32_t label;  /* its attractor (> 0), or CM_LABEL_DIVERGED, _OUTSIDE, _UNCOMPUTED */
    uint32_t attractors; /* how many the cluster has */
    double *orbit;  /* the true orbit from the cell's centre: norbit states of dim numbers */
    int norbit;     /* up to the steps asked, fewer where the map gives no image */
} atlas_point;

/* The cell at state (x, y) (the slice's other coordinates), with the
 * orbit of `steps` (0..ATLAS_ORBIT_MAX) images of its centre;
 * atlas_point_free frees it. CM_EINVAL for a point that is not finite or
 * beyond the world. */
cm_status atlas_point_query(const atlas *a, double x, double y, int steps, atlas_point *out,
                            char *msg, size_t msg_size);
void atlas_point_free(atlas_point *p);

#endif
