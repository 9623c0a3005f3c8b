/* cellmap/outside.h - orbits that leave the computed cells.
 *
 * Simple cell mapping sends every cell whose image leaves the computed
 * cells to the sink, so "sink" means "left the box once", not "diverged":
 * Newton's method leaves -2:2^2 from near the origin and comes back to a
 * root. This layer follows each such image on the true orbit.
 *
 * The cells an image leaves into (the *exits*: distinct cells outside the
 * computed ones, in the world) are followed from their centres by the
 * true map for at most `steps` steps:
 *   - the orbit lands in a computed cell u: the exit's fate is u's, the
 *     attractor label of u's group (cm_attractor_label), or, when u's
 *     sequence leaves the computed cells in turn, the fate of the exit it
 *     leaves into (an orbit that keeps leaving and returning through a
 *     chain of exits back to one of them is *outside*: its attractor lies
 *     partly outside the computed cells);
 *   - the map gives no image or the orbit leaves the world: *diverged*;
 *   - it is still outside after `steps` steps: *outside* (fate unknown).
 * Every cell of the sink's domain takes the fate of the exit its sequence
 * leaves into, or diverges when the sequence ends in the world's sink (no
 * image, or an image beyond the world).
 *
 * The fate of an exit depends on the exit cell, the model and which cells
 * are computed, never on how they were solved: a cluster of any split,
 * extension, pans or resume gives its exits the fates the single-box solve
 * of the same cells gives them (the exits are the targets of its open
 * nodes, which are the targets of the single box's exits). Fates are found
 * again whenever the computed cells change (a join or a pan changes what
 * an orbit returns to). Following is per exit cell, not per cell, on
 * `threads` OpenMP threads, and gives the same fates for any number.
 */
#ifndef CM_OUTSIDE_H
#define CM_OUTSIDE_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/attractors.h"
#include "cellmap/cluster.h"
#include "cellmap/exit_memo.h"
#include "cellmap/model.h"
#include "cellmap/scm.h"


/* The exits of a set of computed cells. */
typedef struct cm_exits {
    uint64_t n;          /* distinct exit cells */
    int64_t *cell;       /* n cells, dim coordinates each, in box order (cm_cell_less) */
    uint64_t *weight;    /* cells whose sequences leave into each */
    uint64_t world_cells; /* cells of the sink's domain whose sequences end in the world's sink */
    uint64_t unknown_cells; /* cells of the sink's domain whose exits are not known (a cluster
                               of resolved cells, cm_cluster.resolved_cells): outside */
    /* a cluster's open nodes (ascending ids) and the exit each leads to;
     * none for a region */
    uint64_t nnodes;
    uint32_t *node;
    uint64_t *node_exit;
} cm_exits;

/* The exits of a region solved with its exits recorded (record_exits),
 * whose sink cells hold node references (cellmap/classify.h): their
 * weights counted, the references turned into 0 (the sink), so that r
 * becomes a resolved region whose images still name its exits. O(cells),
 * on `threads` threads. */
cm_status cm_region_settle_exits(cm_region *r, int threads, cm_exits *out, char *msg,
                                 size_t msg_size);

/* The exits of a cluster: the targets of its open nodes, with their
 * weights (no cell is read; open lists paged out are read back one at a
 * time, cm_cluster_each_escape). */
cm_status cm_cluster_exits(cm_cluster *c, cm_exits *out, char *msg, size_t msg_size);

/* The most a pass over a cluster's exits holds beside the cluster, in
 * bytes: CM_EXITS_PASS_BYTES per open node (2-D and more per coordinate
 * beyond two): cm_cluster_exits' listing at its peak, then the exits, their
 * fates and chains while cm_cluster_attractors follows them (and 8 bytes
 * and a cell more for each exit whose orbit returns to a computed cell,
 * whose end is asked after: 1 % of a 400-pan explore session's). An owner that
 * pages the cluster adds it to c->mem_reserved for the pass, so that the
 * budget bounds the pass's arrays too (a long session's close lists a
 * million open nodes and more). Reads no cell or node table. */
#define CM_EXITS_PASS_BYTES 64
uint64_t cm_cluster_exits_room(const cm_cluster *c);

void cm_exits_free(cm_exits *x);

/* Where a computed cell's sequence ends: its group (1..G; 0: the sink's
 * domain; CM_GROUP_NONE: not a computed cell) and, in the sink's domain,
 * whether the sequence leaves the computed cells (*leaves; into the exit
 * cell `exit`, dim coordinates) or ends in the world's sink. Called on the
 * calling thread only. */
typedef cm_status (*cm_cell_end_fn)(void *user, const int64_t *cell, uint32_t *group,
                                    bool *leaves, int64_t *exit, char *msg, size_t msg_size);
/* Whether a cell is computed. Pure and thread-safe: the followers call it
 * from every thread. */
typedef bool (*cm_cell_holds_fn)(const void *user, const int64_t *cell);

/* The computed cells as following orbits reads them. */
typedef struct cm_computed {
    cm_cell_holds_fn holds;
    cm_cell_end_fn end;
    void *user;
    cm_box bounds; /* every computed cell is in it */
    /* NULL, or called between chunks of exits followed, when nothing read
     * through end is held: the cluster's adapter evicts what its budget
     * does not hold (node tables the ends read) */
    void (*between)(void *user);
    /* NULL, or the order in which end() reads n cells (dim coordinates
     * each) best: *order lists their indices (n entries, the caller's to
     * free; the cluster's adapter: region by region, so that a paged
     * cluster reads each region once); CM_ENOMEM */
    cm_status (*order)(void *user, const int64_t *cells, uint64_t n, uint64_t **order);
} cm_computed;

/* The adapters for a resolved region (its exits recorded, else found
 * again from the model with max_steps) and for a cluster (cm_cluster_exits'
 * exits); cm_computed.user points at the struct given. */
typedef struct cm_region_cells {
    const cm_region *r;
    const cm_model *m;
    const cm_lattice *lat;
    int max_steps;
} cm_region_cells;
typedef struct cm_cluster_cells {
    cm_cluster *c;
    /* cm_cluster_exits' exits, or NULL: an end's exit is read from its open
     * node's list (cm_cluster_open_target), which serves lookups without
     * listing the cluster's exits; cm_cluster_attractors needs them */
    const cm_exits *exits;
    /* NULL, or exits itself when its owner needs no more of it than
     * cm_exits_free once cm_cluster_attractors has run: the set then takes
     * its cells instead of a copy, and the rest of it is freed when the
     * fates are found (36 bytes an exit at the peak of a whole cluster's
     * pass, a long explore session's close) */
    cm_exits *spent;
} cm_cluster_cells;
cm_computed cm_region_computed(cm_region_cells *rc);
cm_computed cm_cluster_computed(cm_cluster_cells *cc);

/* Follows the exits x of the cells `cells` (the groups' attractors s found
 * on them) for at most `steps` steps each (0: none is followed, every exit
 * is outside) and records their fates in s: exit_label, and the counts
 * sink_diverged_cells, outside_cells, returned_cells and the attractors'
 * basin_cells (their basins gain the cells whose orbits return to them).
 * CM_EMODEL when the model aborts. */
cm_status cm_attractors_outside(const cm_model *m, const cm_lattice *lat, const cm_exits *x,
                                const cm_computed *cells, uint32_t steps, int threads,
                                cm_attractor_set *s, char *msg, size_t msg_size);

/* The label of every cell of a flat region (a single-box solve, or a
 * flattened cluster or part of it) by attractors into labels[ncells]: the
 * attractor of its group; for the sink's domain, the fate of the exit its
 * sequence leaves into (followed along the region's images; a sequence
 * that leaves the region's box is asked of `cells`), 0 (diverged) when it
 * ends in the world's sink; -1 where no cell is computed. */
cm_status cm_attractor_cell_labels(const cm_attractor_set *s, const cm_region *flat,
                                   const cm_computed *cells, int32_t *labels, char *msg,
                                   size_t msg_size);

/* The labels of a flattened part of cluster c (flat: cm_cluster_flatten of
 * a box) by the attractors s found on the cluster's groups
 * (cm_attractors_find), as cm_attractor_cell_labels gives them with every
 * exit of the cluster followed; here only the exits the part's sequences
 * reach are followed (opt->outside steps each), and those the orbits from
 * them return to, so that the cost follows the part, not the cluster. s
 * then holds those exits (exit_cell, exit_label), and its counts are of
 * their weights only (the cells whose sequences leave through the open
 * nodes found): outside_cells, returned_cells, the returned cells in the
 * attractors' basin_cells (the cluster's when the part holds every
 * computed cell), and sink_diverged_cells without the cells that end in
 * the world's sink. Reads (and pages in) the regions its sequences
 * and orbits reach; threads: opt->threads. memo (NULL: none) is what
 * earlier calls on this cluster and model found following exits
 * (cellmap/exit_memo.h): exits it knows are not followed again, and it
 * keeps what this call used; the labels and s are the same with or
 * without it. open (NULL: none) is what cm_cluster_flatten_open gave with
 * flat: the cells whose sequences leave the part are then not looked up in
 * the cluster; the result is the same. CM_EINVAL for a cluster that keeps
 * no exits (keep_exits 0, released, or resolved cells). */
cm_status cm_cluster_view_labels(const cm_model *m, cm_cluster *c, const cm_region *flat,
                                 const uint32_t *open, const cm_attractor_options *opt,
                                 cm_exit_memo *memo, cm_attractor_set *s, int32_t *labels,
                                 char *msg, size_t msg_size);

/* What following one exit's true orbit found (cm_exits_follow). */
enum { CM_FOLLOW_DIVERGED = 0, CM_FOLLOW_OUTSIDE, CM_FOLLOW_RETURNED, CM_FOLLOW_ABORTED };
typedef struct cm_followed {
    int how;                  /* CM_FOLLOW_* */
    uint32_t taken;           /* steps the orbit took */
    int64_t cell[CM_MAX_DIM]; /* CM_FOLLOW_RETURNED: the computed cell it lands in */
} cm_followed;

/* The true orbits from the centres of n exit cells (dim coordinates each)
 * as the header's comment describes, at most `steps` steps each, until
 * each lands in a computed cell of `cells`, diverges or runs out of steps
 * (outside), on `threads` OpenMP threads (0: all), into f[0..n); box (NULL:
 * not wanted) gets each orbit's box of the cells it visited, exit and
 * landing cell included (lo then hi, dim words each, per exit); the steps
 * taken are added to *taken. The same results for any number of threads.
 * CM_EMODEL when the model aborts, CM_ENOMEM. */
cm_status cm_exits_follow(const cm_model *m, const cm_lattice *lat, const cm_computed *cells,
                          const int64_t *exit_cell, uint64_t n, uint32_t steps, int threads,
                          cm_followed *f, int64_t *box, uint64_t *taken, char *msg,
                          size_t msg_size);

/* The steps an exit's orbit is followed for under opt (NULL: the model's
 * defaults); 0 when orbits are not followed. */
uint32_t cm_outside_budget(const cm_model *m, const cm_attractor_options *opt);

/* The exit cell open node id of cluster c leads to, into cell (dim
 * coordinates): from its region's open list, else from the region's exit
 * table (the region is paged in). */
cm_status cm_cluster_open_exit(cm_cluster *c, uint32_t id, int64_t *cell, char *msg,
                               size_t msg_size);

/* The label of every node of cluster c (node_label[id]): the label its
 * exit's chain of links ends on (a group's attractor; for an open node,
 * the fate s gives its exit, found from the cluster's escape index; 0 when
 * the chain ends in the world's sink), the group cm_cluster_resolve would
 * give it, labelled. Each node table is read once, one at a time within
 * the cluster's budget; the chains are then settled in memory, in the
 * labels themselves (4 bytes per node, at most 2^31 - 5 nodes:
 * CM_ETOOBIG). *node_label is the caller's to free (NULL on failure). Not
 * for a cluster of resolved cells (files before version 4,
 * cm_cluster.resolved_cells: CM_EINVAL), whose sink sequences must be
 * followed across regions (cm_cluster_flatten and
 * cm_attractor_cell_labels); CM_EFORMAT for broken links. */
cm_status cm_cluster_node_labels(cm_cluster *c, const cm_attractor_set *s, int32_t **node_label,
                                 char *msg, size_t msg_size);

/* The same in two steps, so that an owner who only reads labels can
 * release the open nodes' index and s's exit fates in between
 * (cm_cluster_release_open): _open allocates the labels and gives the open
 * nodes theirs (*node_label NULL on failure); _settle reads the node tables
 * and settles the chains (node_label stays the caller's to free). */
cm_status cm_node_labels_open(cm_cluster *c, const cm_attractor_set *s,
                              int32_t **node_label, char *msg, size_t msg_size);
cm_status cm_node_labels_settle(cm_cluster *c, const cm_attractor_set *s, int32_t *node_label,
                                char *msg, size_t msg_size);

/* The labels cm_attractor_cell_labels gives the flattened cluster, for the
 * cells of `box`, read region by region from the cells and the node labels
 * (cm_cluster_node_labels) without flattening: each region that meets the
 * box is paged in once. labels[sum over d of (cell[d] - box->lo[d]) *
 * stride[d]] gets the label of cell `cell` (stride NULL: cm_box_index's
 * order, dimension 0 fastest); cells of no region get -1. Threads: the
 * cluster's (cm_cluster_threads). */
cm_status cm_cluster_cell_labels(cm_cluster *c, const cm_attractor_set *s,
                                 const int32_t *node_label, const cm_box *box,
                                 const int64_t *stride, int32_t *labels, char *msg,
                                 size_t msg_size);

/* The attractors of the groups (entry k: group k + 1) with the exits
 * followed: cm_attractors_find, then the exits (a region's x, from
 * cm_region_settle_exits, or the cluster's, cc->exits from
 * cm_cluster_exits, which callers keep for the cells' labels) followed
 * opt->outside steps
 * (cm_attractors_outside). *out is the caller's to release
 * (cm_attractors_free), also on failure. */
cm_status cm_region_attractors(const cm_model *m, const cm_lattice *lat, const cm_region *r,
                               int max_steps, const cm_exits *x, const cm_group_info *groups,
                               const cm_attractor_options *opt, cm_attractor_set *out, char *msg,
                               size_t msg_size);
cm_status cm_cluster_attractors(const cm_model *m, cm_cluster_cells *cc,
                                const cm_group_info *groups, const cm_attractor_options *opt,
                                cm_attractor_set *out, char *msg, size_t msg_size);

#endif
