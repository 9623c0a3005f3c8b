/* cellmap/join_stage1.h - Stage 1 of joining separately solved regions
 * (thesis Algorithm C.5) on its own, as Fig. 4.27 shows it.
 *
 * Each region's sink cells form chains that leave the region. Stage 1
 * follows every chain to where it leaves, looking at the other regions as
 * they were solved alone: a chain entering a cell of a periodic group's
 * domain there now leads to that group (Case 1b); a chain leaving every
 * region stays in the (reduced) sink (Case 1a); a chain entering another
 * region's sink domain has no known destination yet (Case 2: pending,
 * left to Stage 2's cell tree mapping). The cluster's own join
 * (resolve.h) does both stages at once; this is for figures and checks.
 */
#ifndef CM_JOIN_STAGE1_H
#define CM_JOIN_STAGE1_H

#include <stdint.h>

#include "cellmap/scm.h"

typedef struct cm_stage1_stats {
    uint64_t sink_cells; /* the regions' sink domains before Stage 1 */
    uint64_t to_group;   /* Case 1b: now in a group's domain */
    uint64_t to_sink;    /* Case 1a: leave every region */
    uint64_t pending;    /* Case 2: enter another region's sink domain */
} cm_stage1_stats;

/* regions: n disjoint regions of one lattice, each solved alone with its
 * exits recorded (cm_scm_options.record_exits) and classified. Rewrites
 * their group[] in one id space: group g of region k becomes base_k + g,
 * base_k being the groups of regions 0..k-1, and the sink cells of Case 1b
 * take the group they lead to; the others stay 0. If pending is not NULL,
 * pending[k][i] is set to 1 for the Case 2 cells of region k, else 0
 * (caller-owned, ncells bytes each). Steps and images are left alone.
 * Results do not depend on the thread count. */
cm_status cm_join_stage1(cm_region *regions, uint32_t n, uint8_t **pending, cm_stage1_stats *stats,
                         char *msg, size_t msg_size);

#endif
