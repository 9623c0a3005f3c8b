/* cellmap/cluster.h - clustered simple cell mapping (thesis 4.6.2,
 * Algorithms C.3-C.7, generalised from two solutions to any number of
 * regions in any dimension).
 *
 * A cluster is a set of non-overlapping regions on one lattice. Each region
 * keeps its own image[] (local indices, and exits into its exit table);
 * group[] holds cluster-wide group ids (0: the sink, i.e. the sequence leaves
 * the cluster or the world) and step[] the cluster-wide step numbers.
 *
 * Joining a region changes only cells whose sequences used to leave the
 * cluster into the new region: the cells of the sink's domain in the regions
 * from which the new one can be reached through exits, and the new region's
 * own. These are resolved again across region borders (cellmap/resolve.h):
 * a sequence that reaches a classified cell takes its group (Stage 1 of the
 * thesis); sequences that close a cycle across borders create the groups
 * that straddle them (Stage 2). Existing group ids never change; groups of
 * the new region and straddling groups get the next ids in a fixed order.
 *
 * The invariant (tests/test_cluster.c): for regions tiling a box, the result
 * equals cm_scm_solve on the box, cell by cell, up to the numbering of groups.
 * A join uses c->threads threads; the result does not depend on them. One
 * cluster must not be joined into from two threads at once.
 */
#ifndef CM_CLUSTER_H
#define CM_CLUSTER_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/scm.h"

typedef struct cm_cluster_region {
    cm_region r;      /* arrays NULL while the region is paged out */
    int64_t *escapes; /* target cells of the exits that leave the cluster */
    uint64_t nescapes;
    uint32_t *targets; /* regions that exits lead into (no duplicates) */
    uint32_t ntargets;
    uint64_t targets_cap;
    uint32_t *entries; /* cells that exits of other regions lead into, ascending */
    uint64_t nentries, entries_cap;
    int dirty;          /* cells changed since the owner last saved them */
    uint64_t last_used; /* paging clock of the last acquire */
    uint64_t read_at;   /* paging clock when it was last read back */
} cm_cluster_region;

/* Reads back the arrays of a paged-out region: r has box, ncells, nexits
 * and ngroups set and NULL arrays; the pager allocates and fills image,
 * group, step and exit_target exactly as they were when last saved. */
typedef cm_status (*cm_page_in_fn)(void *user, uint32_t region, cm_region *r, char *msg,
                                   size_t msg_size);

struct cm_cluster;

/* Saves region `region`'s arrays as they are now, so that it can be evicted
 * while dirty, also in the middle of a join: the owner keeps such writes
 * uncommitted until the cluster is consistent again (the next commit). */
typedef cm_status (*cm_page_out_fn)(void *user, const struct cm_cluster *c, uint32_t region,
                                    char *msg, size_t msg_size);

typedef struct cm_cluster {
    cm_lattice lat;
    cm_cluster_region *regions; /* in the order they were joined */
    uint32_t nregions;
    uint64_t cap;
    uint32_t ngroups; /* cluster-wide group ids 1..ngroups */
    int threads;      /* OpenMP threads for joins; 0: the OpenMP default */
    /* Paging, off while page_in is NULL. cm_cluster_acquire reads regions
     * back through page_in and first evicts others, least recently used
     * first, so that the resident arrays take at most mem_budget bytes
     * (more only while one region alone is bigger): clean ones (dirty == 0,
     * their cells are saved) are freed, dirty ones saved through page_out
     * if there is one. A join holds only the region it works on, so a
     * cluster whose joins touch more than the budget still fits in it. */
    cm_page_in_fn page_in;
    cm_page_out_fn page_out; /* may be NULL: dirty regions then stay */
    void *pager;
    uint64_t mem_budget; /* 0: no limit */
    uint64_t clock;
} cm_cluster;

typedef struct cm_join_stats {
    uint32_t affected_regions; /* regions whose sink cells were resolved again */
    uint64_t resolved_cells;   /* sink cells of those regions resolved again */
    uint64_t nodes;            /* of those, cells whose image leaves their region */
    uint32_t new_groups;       /* groups of the new region plus straddling ones */
    uint32_t straddling_groups;
} cm_join_stats;

void cm_cluster_init(cm_cluster *c, const cm_lattice *lat);
void cm_cluster_free(cm_cluster *c);

/* Threads a join uses: c->threads, or the OpenMP default. */
int cm_cluster_threads(const cm_cluster *c);

/* Joins a region solved with record_exits on the cluster's lattice. The
 * cluster takes the region's arrays (r is zeroed). CM_EINVAL if its box
 * overlaps a region of the cluster. stats may be NULL. */
cm_status cm_cluster_join(cm_cluster *c, cm_region *r, cm_join_stats *stats, char *msg,
                          size_t msg_size);

/* Called after each join of cm_cluster_solve_boxes (box is its index);
 * a status other than CM_OK stops the solve with it. */
typedef cm_status (*cm_joined_fn)(void *user, cm_cluster *c, uint32_t box,
                                  const cm_join_stats *stats, char *msg, size_t msg_size);

/* Solves the boxes in batches of one box per thread (images included) and
 * joins each batch in the given order, calling joined (may be NULL) after
 * every join, so at most a batch of unjoined regions is held at once.
 * stats (may be NULL) sums the joins'. */
cm_status cm_cluster_solve_boxes(cm_cluster *c, const cm_model *model, const cm_box *boxes,
                                 uint32_t nboxes, const cm_scm_options *opt, cm_joined_fn joined,
                                 void *user, cm_join_stats *stats, char *msg, size_t msg_size);

/* The region holding the cell and the cell's local index, or -1. *hint is
 * the region tried first (any value will do) and is set to the one found. */
int64_t cm_cluster_locate(const cm_cluster *c, const int64_t *cell, uint32_t *hint,
                          uint64_t *local);

/* Restores a region from its record (box, ncells, nexits, ngroups), the
 * target cells of its exits and its targets list as saved, paged out: a
 * cluster reopened from a file. Regions must be restored in join order. */
cm_status cm_cluster_restore(cm_cluster *c, const cm_region *record, const int64_t *exit_target,
                             const uint32_t *targets, uint32_t ntargets, char *msg,
                             size_t msg_size);

/* Makes region k resident (reading it back if paged out) and marks it used.
 * Under a budget it may evict other regions (never k): pointers into other
 * regions' arrays are invalid after it. */
cm_status cm_cluster_acquire(cm_cluster *c, uint32_t k, char *msg, size_t msg_size);

/* Makes every region resident, whatever the budget (for work that follows
 * sequences through the whole cluster at once, such as cm_extend_choose);
 * the next cm_cluster_trim or commit brings it back within the budget. */
cm_status cm_cluster_acquire_all(cm_cluster *c, char *msg, size_t msg_size);

/* Evicts clean resident regions, those no sequence leaves (all neighbours
 * known) first, then the least recently used, until the resident arrays
 * fit c->mem_budget. Does nothing without a pager. */
void cm_cluster_trim(cm_cluster *c);

/* The position of `cell` in region k's entries, or -1 if no exit of another
 * region leads to it. */
int64_t cm_cluster_entry(const cm_cluster_region *cr, uint32_t cell);

/* Adds `target` to region k's links (the regions the exits of its sink
 * cells lead into) unless it is there. Joins set the links of every region
 * whose sink cells they resolved: only those cells can change later, so a
 * region none of whose sink cells leads towards a new region is neither
 * resolved nor read back when it is joined. */
cm_status cm_cluster_add_target(cm_cluster *c, uint32_t k, uint32_t target);

/* Bytes held by the resident regions' cell arrays and exit tables. */
uint64_t cm_cluster_resident_bytes(const cm_cluster *c);

/* The smallest box holding every region (the cluster must have one). */
void cm_cluster_bounds(const cm_cluster *c, cm_box *box);

/* Bytes held by the resident regions' arrays and exit tables, and by
 * every region's escape, target and entry lists. */
uint64_t cm_cluster_bytes(const cm_cluster *c);

/* A flat region over box with no cell computed (group CM_GROUP_NONE,
 * image CM_IMAGE_SINK) and ngroups groups, for cm_flat_copy. */
cm_status cm_flat_alloc(const cm_box *box, uint32_t ngroups, cm_region *out, char *msg,
                        size_t msg_size);
/* Copies the cells of region r inside out's box into out: groups, steps,
 * images as out's indices (exits and cells beyond it as CM_IMAGE_EXIT). */
void cm_flat_copy(const cm_region *r, cm_region *out);

/* The cluster as one region over `box`: group and step of every cell (group
 * CM_GROUP_NONE outside every region), images as box indices (exits and
 * cells beyond the box as CM_IMAGE_EXIT). out->ngroups is the cluster's. */
cm_status cm_cluster_flatten(cm_cluster *c, const cm_box *box, cm_region *out, char *msg,
                             size_t msg_size);

#endif
