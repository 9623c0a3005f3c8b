/* cellmap/view_keep.h - a view's labels kept between views of a growing
 * cluster, so that a pan's labelling pays for its new cells.
 *
 * cm_cluster_view_labels labels every cell of a view afresh: each sink
 * cell's sequence is followed to where it leaves the cluster, and every
 * exit it reaches is followed on the true orbit (cellmap/outside.h). A
 * panning session labels views that mostly overlap, over a cluster that
 * only gains regions, and most of that comes out as before. What stays
 * true from one view to the next:
 *   - A computed cell's end (its group, the world's sink, or the exit cell
 *     where its sequence leaves the cluster) changes only when that exit
 *     cell is computed; the cell then ends where the exit cell's sequence
 *     ends. So each cell of the view keeps a key (its group, diverged, or
 *     an exit's slot), and a slot whose exit is computed now points to the
 *     key of its own end. Those links never form a circle: an end is an
 *     uncomputed cell.
 *   - An exit's orbit holds until a region added meets the box of the
 *     cells it visited (as cellmap/exit_memo.h keeps it); its fate is the
 *     key of the cell it lands in.
 * A view after a pan therefore takes the keys of the cells it shares with
 * the last view, finds afresh only those of its new cells and of regions
 * added since, follows again the orbits new regions meet, and turns keys
 * into labels in one pass over its cells.
 *
 * Ownership and limits: one keep serves one cluster, one model and one
 * step budget (another budget, another dimension or a cluster of fewer
 * regions than it has seen resets it; the owner makes a new keep for
 * another cluster or model). One labelling at a time; it runs on
 * opt->threads threads and gives the same result for any number. Memory:
 * 20 bytes per cell of the largest view (two arrays of keys, the labels
 * and the shown cells), 3 dim words and 10 bytes per exit slot, and 256
 * bytes per tile of 8 x 8 cells that holds exits; slots that the last
 * view no longer reaches are dropped once they outnumber those it reaches
 * (by 65536). At most 2^30 - 16 groups and slots (CM_ETOOBIG). */
#ifndef CM_VIEW_KEEP_H
#define CM_VIEW_KEEP_H

#include <stdint.h>

#include "cellmap/attractors.h"
#include "cellmap/cluster.h"
#include "cellmap/model.h"
#include "cellmap/scm.h"

typedef struct cm_view_keep cm_view_keep;

/* An empty keep (NULL when out of memory); _free frees it (NULL: nothing). */
cm_view_keep *cm_view_keep_new(void);
void cm_view_keep_free(cm_view_keep *k);

/* The bytes the keep holds between labellings. */
uint64_t cm_view_keep_bytes(const cm_view_keep *k);

/* The labels of the cells of box in cluster c by the attractors s found
 * on its groups (cm_attractors_find), into *labels (cells of box): the
 * labels cm_cluster_view_labels gives for cm_cluster_flatten_open of box,
 * and the counts it leaves in s (outside_cells, returned_cells,
 * sink_diverged_cells, the attractors' basin_cells, outside_steps and
 * outside_steps_taken). s's list of exits is left empty (nexits 0).
 * shown gets what a figure by attractors reads of the cells besides their
 * labels (lib/attractor_view): group 0 and step 1 for every cell, as no
 * computed cell other than an attractor's footprint is drawn as a
 * periodic one. *labels and shown's arrays are the keep's: valid until
 * its next labelling or _free, not to be freed; the caller may change
 * them (each labelling writes them whole). cache (NULL: none) is the
 * cluster's resolve cache, used for the cells flattened afresh
 * (cm_cluster_flatten_cached). opt: the orbits' budget of steps and the
 * threads (NULL: the model's defaults, every thread). CM_EINVAL for a
 * cluster that keeps no exits (keep_exits 0, released, or resolved
 * cells); on failure the keep is reset. */
cm_status cm_view_keep_labels(cm_view_keep *k, const cm_model *m, cm_cluster *c,
                              cm_resolve_cache *cache, const cm_box *box,
                              const cm_attractor_options *opt, cm_attractor_set *s,
                              int32_t **labels, cm_region *shown, char *msg, size_t msg_size);

#endif
