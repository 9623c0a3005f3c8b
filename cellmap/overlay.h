/* cellmap/overlay.h - geometry a model draws over its basins.
 *
 * Overlays are lines and points in state coordinates (dimensions 0 and 1 of
 * the view; for 1-D models, the plane of the map's graph, x_j against
 * x_{j+1}). A model appends them to a caller-owned list; the renderer decides
 * colours and dash patterns from the kind, so every model's switching lines
 * look alike.
 */
#ifndef CM_OVERLAY_H
#define CM_OVERLAY_H

#include <stdbool.h>
#include <stddef.h>

enum cm_overlay_kind {
    CM_OVERLAY_SWITCHING_LINE = 0, /* segment a-b, solid (white in the thesis) */
    CM_OVERLAY_UNSTABLE_MANIFOLD,  /* segment a-b, dashed */
    CM_OVERLAY_STABLE_MANIFOLD,    /* segment a-b, dashed more finely */
    CM_OVERLAY_STICKING_ZONE,      /* segment a-b: a set of rest states */
    CM_OVERLAY_FIXED_REGULAR,      /* point a: a fixed point inside its own band */
    CM_OVERLAY_FIXED_VIRTUAL,      /* point a: a fixed point outside its band */
    CM_OVERLAY_REPELLER,           /* segment a-b: holds a chaotic repeller (transient chaos) */
    CM_OVERLAY_ESCAPE,             /* segment a-b: orbits that reach it end their transient */
    CM_OVERLAY_COLLISION,          /* point a: two neighbouring switching lines touch */
    CM_OVERLAY_COLLISION_HIGHER,   /* point a: SW_m and SW_m+n touch, n >= 2 */
    CM_OVERLAY_KINDS
};

typedef struct cm_overlay {
    int kind;    /* enum cm_overlay_kind */
    double a[2]; /* a point, or a segment's first end */
    double b[2]; /* a segment's second end (unused for points) */
} cm_overlay;

/* A caller-owned array. Appending past cap sets truncated; the renderer
 * then says so rather than silently drawing part of a picture. */
typedef struct cm_overlay_list {
    cm_overlay *items;
    size_t cap, count;
    bool truncated;
} cm_overlay_list;

/* Appends one overlay; false (and truncated set) when the list is full. */
bool cm_overlay_add(cm_overlay_list *out, int kind, const double a[2], const double b[2]);

/* Appends the part of the line {p + t d} that lies in the rectangle
 * [lo, hi] and, when n is not NULL, in the band z_lo <= n.x <= z_hi.
 * Nothing is added when that part is empty. */
void cm_overlay_add_line(cm_overlay_list *out, int kind, const double p[2], const double d[2],
                         const double lo[2], const double hi[2], const double *n, double z_lo,
                         double z_hi);

/* Whether point p lies in the rectangle [lo, hi]. */
bool cm_overlay_in_view(const double p[2], const double lo[2], const double hi[2]);

#endif
