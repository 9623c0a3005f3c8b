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

/* Puts the boxes of a grid (a split of a box) in Z order (Morton order of
 * their places in the grid, dimension 0 fastest): neighbours are joined a
 * few boxes apart, so that under a memory budget the regions a join reads
 * are still resident. Deterministic; CM_ENOMEM only (then the order stays). */
cm_status cm_boxes_z_order(cm_box *boxes, uint32_t n);

#endif
