/* cellmap/exit_memo.h - what following a view's exits found, kept between
 * views of a growing cluster.
 *
 * Labelling a view (cm_cluster_view_labels) follows the true orbit of every
 * exit its cells' sequences reach (cellmap/outside.h). A panning session
 * labels views that overlap, over a cluster that grows by a few regions
 * between them, so most exits, and what their orbits do, come again: late
 * in a 200-pan session of the 4.6.3 example, four fifths of a view's 130
 * thousand exits, at about 90 map steps each.
 *
 * Why an entry stays true: an exit's orbit depends only on the exit cell,
 * the model, the step budget and which cells are computed, and until it
 * lands it visits only cells that are not computed. So what it found holds
 * until a region added to the cluster meets the box of the cells it
 * visited (exit cell and landing cell included); then the entry is
 * dropped. What the landing cell's sequence ends on is not kept: it is
 * looked up again each time (joins change it).
 *
 * Ownership and limits: one memo serves one cluster and one model; the
 * owner makes a new memo when either changes. Regions are only ever added
 * to a cluster, which the memo relies on (it knows how many it has seen; a
 * cluster with fewer empties it, as does another dimension or step
 * budget). One labelling at a time (not thread-safe). Memory: 4 dim + 2
 * words of 8 bytes per exit of the last view labelled, plus a hash of at
 * most 8 bytes per exit; the rest is dropped after each labelling
 * (cm_exit_memo_keep_used).
 */
#ifndef CM_EXIT_MEMO_H
#define CM_EXIT_MEMO_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/cluster.h"

/* What following one exit found: how (outside.c's outcome), the steps its
 * orbit took, the computed cell it landed in (when it did), and the box of
 * the cells it visited, lo..hi inclusive. */
typedef struct cm_exit_fate {
    int how;
    uint32_t taken;
    int64_t cell[CM_MAX_DIM];
    int64_t lo[CM_MAX_DIM], hi[CM_MAX_DIM];
} cm_exit_fate;

typedef struct cm_exit_memo cm_exit_memo;

/* An empty memo (NULL when out of memory); cm_exit_memo_free frees it
 * (NULL: nothing). */
cm_exit_memo *cm_exit_memo_new(void);
void cm_exit_memo_free(cm_exit_memo *memo);

/* Entries held, and the bytes they and the hash take (0 for NULL). */
uint64_t cm_exit_memo_count(const cm_exit_memo *memo);
uint64_t cm_exit_memo_bytes(const cm_exit_memo *memo);

/* Before a labelling of cluster c with a budget of `steps`: drops the
 * entries the regions added since the last call meet (every entry for
 * another dimension or budget, or a cluster of fewer regions), and marks
 * the rest unused. O(entries x regions added). */
void cm_exit_memo_sync(cm_exit_memo *memo, const cm_cluster *c, uint32_t steps);

/* Whether the exit `cell` has an entry; if so *out gets it and the entry is
 * marked used. */
bool cm_exit_memo_find(cm_exit_memo *memo, const int64_t *cell, cm_exit_fate *out);

/* Adds (or replaces) the entry of exit `cell`, marked used. CM_ENOMEM
 * leaves the memo as it was. */
cm_status cm_exit_memo_put(cm_exit_memo *memo, const int64_t *cell, const cm_exit_fate *f);

/* After a labelling: keeps only the entries it found or added. */
void cm_exit_memo_keep_used(cm_exit_memo *memo);

#endif
