/* cellmap/basin_measure.h - measures of basins on a window of cell labels
 * (one int32 per cell, as `export --labels` writes them: an attractor's
 * id, 0 diverged, -2 outside, -1 not computed), any dimension:
 *
 *   - basin entropy Sb and boundary basin entropy Sbb (Daza, Wagemakers,
 *     Georgeot, Guery-Odelin and Sanjuan, Sci. Rep. 6, 31416, 2016): the
 *     window tiled by boxes of eps cells a side; a box's entropy is
 *     -sum p_j ln p_j over the shares p_j of its labels; Sb is the mean
 *     over the boxes, Sbb over the boxes with more than one label. Sbb >
 *     ln 2 is a sufficient condition for a fractal boundary;
 *   - the fraction f(eps) of eps-uncertain cells (Grebogi, McDonald, Ott
 *     and Yorke, Phys. Lett. A 99, 415, 1983): a cell is uncertain when a
 *     cell eps cells away along some axis has another label; f ~ eps^alpha,
 *     alpha the uncertainty exponent, d - alpha the boundary's dimension;
 *   - a Wada test on the lattice: the boundary cells (those with a
 *     neighbour of another label, the 3^d - 1 around them) and the share
 *     of them that see every basin within r cells (Chebyshev distance),
 *     r = 1, 2, ...: near 1 for all r when every boundary point is on the
 *     boundary of every basin (Wada), as in Daza et al.'s grid method.
 *
 * Labels -1 are left out: boxes holding one, and cells with such a
 * neighbour, are not counted. Every other label, 0 and -2 included, is a
 * basin. Pure functions of their inputs: thread-safe, the same result
 * every run. */
#ifndef CM_CELLMAP_BASIN_MEASURE_H
#define CM_CELLMAP_BASIN_MEASURE_H

#include <stdint.h>

#include "cellmap/lattice.h"
#include "cellmap/status.h"

/* Labels over a window: n[d] cells along dimension d, C order (dimension
 * 0 the slowest), values in lo .. hi (the caller's bounds: -2 .. the
 * largest attractor id).
 *
 * A grid may be a slab of a window too large to hold (window_rows 0: the
 * grid is the whole window): its rows along dimension 0 are the window's
 * rows row0 .. row0 + n[0] - 1 of window_rows, and only the cells of its
 * rows core_lo .. core_hi - 1 are measured (the boxes starting there, for
 * basin entropy); the rows around the core are their neighbours, and must
 * reach as far as the measure looks (eps - 1 rows below the core for boxes
 * of eps, eps rows each side for uncertain cells, the radius each side for
 * the Wada test) or to the window's edge. The counts of slabs whose cores
 * tile the window add up to the window's (the sums, boxes, counted,
 * boundary and seeing fields). */
typedef struct cm_label_grid {
    int dim;
    int64_t n[CM_MAX_DIM];
    const int32_t *label;
    int32_t lo, hi;
    int64_t row0, window_rows, core_lo, core_hi;
    int basins; /* the Wada test's basins in the whole window (0: those of the grid) */
} cm_label_grid;

typedef struct cm_entropy {
    int eps;               /* cells a side */
    uint64_t boxes;        /* full boxes of computed cells */
    uint64_t boundary;     /* those with more than one label */
    double sum, sum_boundary; /* of their entropies */
    double sb, sbb;        /* NAN without boxes / boundary boxes */
} cm_entropy;

/* map (may be NULL; the caller's, one entry per box, boxes in C order)
 * gets each box's entropy, NAN for a box holding an uncomputed cell.
 * CM_EINVAL when eps < 1 or the window has no full box of eps cells a
 * side; CM_ENOMEM. */
cm_status cm_basin_entropy(const cm_label_grid *g, int eps, cm_entropy *out, double *map,
                           char *msg, size_t msg_size);

/* The fraction of eps-uncertain cells among those whose 2d neighbours eps
 * away lie in the window, all computed (*counted of them, *uncertain
 * uncertain; may be NULL); NAN when none. CM_EINVAL when eps < 1. */
cm_status cm_uncertain_fraction(const cm_label_grid *g, int eps, double *fraction,
                                uint64_t *counted, uint64_t *uncertain, char *msg,
                                size_t msg_size);

typedef struct cm_wada {
    int basins;                /* distinct labels among the computed cells */
    uint64_t boundary;         /* boundary cells */
    int radius;                /* fraction[0 .. radius - 1] for r = 1 .. radius */
    uint64_t seeing[16];       /* boundary cells seeing every basin within r */
    double fraction[16];       /* their share of the boundary cells */
} cm_wada;

/* The Wada test with r = 1 .. radius (1..16). CM_EINVAL for a radius out
 * of range or fewer than 3 basins (with 2 every boundary cell sees both:
 * the test says nothing); CM_ENOMEM. */
cm_status cm_wada_test(const cm_label_grid *g, int radius, cm_wada *out, char *msg,
                       size_t msg_size);

#endif
