/* cellmap/extend.h - adaptive extension of a cluster (thesis 4.6.4 and
 * Fig. 4.25): solve next where the sequences that leave the cluster go.
 *
 * The state space is cut into tiles of one size on a grid aligned to a
 * given tile (the first region solved, or the view of an explore session).
 * Among the tiles that the cluster holds only in part and those that share
 * a face with a tile of the cluster and hold none of it, clipped to optional
 * bounds, the next one is the tile where the most sequences escape: every
 * exit that leaves the cluster (an open node, cellmap/cluster.h) counts the
 * cells whose sequences take it for the tile it lands in, as the thesis chooses "the adjacent region
 * to where most of the trajectories escape" (4.6.2). Ties go to the first candidate in a
 * fixed order (cluster tiles in join order, each itself before its
 * neighbours, by dimension, lower side first), so the choice is
 * deterministic. Regions need not be aligned to the grid; the caller
 * computes the part of the chosen tile that the cluster lacks
 * (cellmap/cover.h).
 */
#ifndef CM_EXTEND_H
#define CM_EXTEND_H

#include <stdint.h>

#include <stdbool.h>

#include "cellmap/join.h"

typedef struct cm_extend_choice {
    cm_box box;            /* the chosen tile, clipped to the bounds */
    uint64_t escaping;     /* cells whose sequences leave the cluster into it */
    uint64_t all_escaping; /* cells whose sequences leave the cluster into the world */
    uint64_t cluster_cells;
} cm_extend_choice;

/* The tile of the grid cm_extend_choose uses (tiles of `tile`'s size
 * aligned to it) that holds `cell`, clipped to bounds (may be NULL): the
 * box a step of the extension adds there. False if the clipping leaves
 * nothing. */
bool cm_extend_tile(const cm_box *tile, const cm_box *bounds, const int64_t *cell, cm_box *box);

/* Chooses the next tile. `tile` is the grid's tile (0, 0, ...); `bounds`
 * may be NULL (unbounded). Fills choice->all_escaping and cluster_cells in
 * any case; CM_ENOTFOUND when no sequence escapes into a neighbouring tile.
 * Reads the open nodes only (their lists paged back one at a time), no
 * region's cells. */
cm_status cm_extend_choose(cm_cluster *c, const cm_box *tile, const cm_box *bounds,
                           cm_extend_choice *choice, char *msg, size_t msg_size);

#endif
