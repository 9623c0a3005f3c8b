/* cellmap/cover.h - the part of a box that a cluster has not computed yet:
 * what a pan or a zoom uncovers (thesis 4.6.4: "a separate SCM solution at
 * the (narrow) state space region entering into the computer's screen").
 *
 * The box minus every region of the cluster, as disjoint boxes. Each region
 * (in join order) cuts the boxes it overlaps into at most two slabs per
 * dimension, dimension 0 first: a box uncovered to the right of the
 * cluster comes out as one strip of the box's full height, a zoom out as
 * a strip on either side plus the rest above and below. The result
 * depends only on the box and the regions, so a session replayed after a
 * kill computes the same boxes as it would have. Pure; thread-safe.
 */
#ifndef CM_COVER_H
#define CM_COVER_H

#include <stdint.h>

#include "cellmap/cluster.h"

/* The uncovered boxes of `box` into *out (malloc'd, the caller frees; NULL
 * when none), their number into *n. CM_ENOMEM only. */
cm_status cm_cluster_uncovered(const cm_cluster *c, const cm_box *box, cm_box **out, uint32_t *n,
                               char *msg, size_t msg_size);

/* Cells of the boxes together. */
uint64_t cm_boxes_cells(const cm_box *boxes, uint32_t n);

/* Puts the boxes of a grid (a split of a box) in the order to join them
 * under a memory budget: a scan whose fastest dimension has the fewest
 * places in the grid and whose slowest has the most (on a tie, dimension 0
 * fastest). A join reads the regions next to its box, and those joined
 * but still next to boxes to come (the frontier) are then fewest: about
 * one row along the short side of a 2-D grid, against up to twice that in
 * Z order (a 20 x 10 grid of 1 M-cell regions under --mem 256M: no region
 * read back, against 5). Deterministic; CM_ENOMEM only (then the order
 * stays). */
cm_status cm_boxes_scan_order(cm_box *boxes, uint32_t n);

#endif
