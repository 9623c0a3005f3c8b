/* cellmap/join.h - joining solved regions into a cluster (thesis 4.6.2,
 * Algorithms C.3-C.7) through the cluster's node table alone.
 *
 * Only sequences that left the cluster can change when a region joins: the
 * exits of the new region, and the open nodes of the cluster whose exits
 * lead into it. Each gets its link, read once from the target cell (which
 * never changes): a final group and step (Stage 1 of the thesis), or the
 * tree of another node. Links that close a chain of nodes on itself make a
 * group that straddles region borders (Stage 2); its cycle is traced
 * through the regions it crosses, the only cells a join reads besides the
 * new region's and the target cells of its links. No region's cells are
 * ever written again, so a join costs what its new cells and its border
 * cost, whatever the size of the cluster.
 *
 * Existing group ids never change; the new region's groups take the next
 * ids, then straddling groups in the order their cycles close (links in
 * order of node id: the new region's, then the open nodes it receives).
 */
#ifndef CM_JOIN_H
#define CM_JOIN_H

#include "cellmap/cluster.h"

typedef struct cm_join_stats {
    uint32_t affected_regions; /* regions whose node records changed, the new one included */
    uint64_t resolved_cells;   /* cells whose sequences stopped leaving the cluster */
    uint64_t nodes;            /* links made */
    uint32_t new_groups;       /* groups of the new region plus straddling ones */
    uint32_t straddling_groups;
    double seconds; /* spent joining, on the joining thread (cm_seconds) */
} cm_join_stats;

/* Joins a region solved with record_exits on the cluster's lattice. The
 * cluster takes the region's arrays (r is zeroed). CM_EINVAL if its box
 * overlaps a region of the cluster. stats may be NULL. */
cm_status cm_cluster_join(cm_cluster *c, cm_region *r, cm_join_stats *stats, char *msg,
                          size_t msg_size);

/* Regions that cm_cluster_solve_boxes takes from elsewhere (other processes,
 * lib/ranks.h) instead of solving them: each made by cm_scm_solve with
 * record_exits on the cluster's lattice and the solve's max_steps, as this
 * process would make it, so the cluster is the same. */
typedef struct cm_region_source {
    /* Before a call's boxes are solved (on the calling thread): boxes[0..n)
     * are the call's, in join order. */
    cm_status (*ask)(void *user, const cm_box *boxes, uint32_t n, char *msg, size_t msg_size);
    /* Whether another process would take a box now (it has room for more
     * than it is solving); from any of the solve's threads. */
    bool (*room)(void *user);
    /* Box b of the call, just claimed (boxes are claimed in order, from
     * any of the solve's threads): whether another process solves it (it
     * is sent there now; room said so, or it took one box more); false:
     * this process does. */
    bool (*take)(void *user, uint32_t b);
    /* Box b's region, taken elsewhere, into *r (which cm_region_free
     * releases) and its trees' sizes (cm_region_trees) into *tree, a new
     * array the solve frees, if it has come (*got), without waiting; from
     * any of the solve's threads, until it has come. Meanwhile the solve
     * goes on with other boxes. */
    cm_status (*fetch)(void *user, uint32_t b, cm_region *r, uint32_t **tree, bool *got,
                       char *msg, size_t msg_size);
    uint32_t processes; /* this one and those that solve elsewhere: how far
                           ahead of the joins the boxes may go grows with it */
    void *user;
} cm_region_source;

/* Called after each join of cm_cluster_solve_boxes (box is its index);
 * a status other than CM_OK stops the solve with it. */
typedef cm_status (*cm_joined_fn)(void *user, cm_cluster *c, uint32_t box,
                                  const cm_join_stats *stats, char *msg, size_t msg_size);

/* Solves the boxes, one per thread (a lone box with every thread), and
 * joins them in the given order on the calling thread while the others go
 * on solving (at most two boxes per thread ahead of the joins, times the
 * source's processes). With c->source, each box claimed goes to the
 * source first while it has room, and the joining thread keeps it
 * supplied between joins: this process solves a box itself only when the
 * others are busy, so that the joins, which are this process's alone,
 * weigh on it as little as they can. Calls
 * joined (may be NULL) after every join. stats (may be NULL) sums the
 * joins'. The cluster is the same whatever the thread count, and whoever
 * solved each box. */
cm_status cm_cluster_solve_boxes(cm_cluster *c, const cm_model *model, const cm_box *boxes,
                                 uint32_t nboxes, const cm_scm_options *opt, cm_joined_fn joined,
                                 void *user, cm_join_stats *stats, char *msg, size_t msg_size);

#endif
