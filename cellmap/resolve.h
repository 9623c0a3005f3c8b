/* cellmap/resolve.h - the second half of a join (thesis Algorithms C.5-C.7):
 * the cells of the sink's domain in the affected regions get their groups
 * and step numbers again, now that the cluster holds a new region.
 *
 * Within a region, a sink cell's image is either in the region (a cell whose
 * step number is one less) or an exit. So the sink cells of a region form
 * trees, each rooted at a cell whose image leaves the region (a node), and
 * sorting them by step number orders every cell after its image. The join
 * works on these trees, not on the cells one by one:
 *   1. per region, each cell learns its tree's node, by one pass over the
 *      cells in step order (parallel within a step). The pass notes the
 *      nodes and the values at the region's entries (the cells that other
 *      regions' exits lead into), then leaves the region as it was;
 *   2. each node follows its exit into the cluster: to a classified cell
 *      (Stage 1 of the thesis), out of the cluster (still the sink), or into
 *      the tree of another node. Walking this small graph of nodes finds the
 *      cycles that cross region borders: the new straddling groups (Stage 2);
 *   3. the cells of those cycles are noted, and every node gets its group
 *      and step number;
 *   4. in each region with a node that changed, the pass of 1 is repeated
 *      and every cell takes its node's group, its step number moved by as
 *      much as its node's; cells in the trees of cycle nodes, whose chains
 *      can meet the cycle before the node, are walked instead (such trees
 *      are small). Regions whose nodes all still leave the cluster in as
 *      many steps are left alone.
 * Each sink cell is read and written a fixed number of times, with
 * independent memory accesses, instead of walking dependent chains; the
 * result does not depend on the thread count. Only step 4 changes regions,
 * and every step needs one region's arrays at a time, so a join fits any
 * memory budget (cm_cluster.mem_budget).
 */
#ifndef CM_RESOLVE_H
#define CM_RESOLVE_H

#include <stdint.h>

#include "cellmap/cluster.h"

/* Resolves the sink cells of the regions with affected[k] != 0 and sets
 * the links of those it changes (cm_cluster_relink), which it marks dirty.
 * New straddling groups take ids from c->ngroups + 1 on, in a fixed order.
 * Regions are acquired one at a time (step 1 in region order, the links by
 * target region in reverse order, step 4 in reverse order too, so that
 * each step starts with the regions the last one left resident). msg says
 * why a region could not be read back or saved. */
cm_status cm_resolve_sink_cells(cm_cluster *c, const uint8_t *affected, cm_join_stats *stats,
                                char *msg, size_t msg_size);

#endif
