/* cellmap/scm.h - simple cell mapping (SCM) on one region (thesis 4.6.1,
 * Algorithm C.8).
 *
 * A region is a box of cells of a lattice with three per-cell arrays
 * (structure of arrays, 12 bytes per cell):
 *   image[i]  local index of the image cell; for an image in the world but
 *             outside the box, CM_IMAGE_EXIT_BASE + k when exits are recorded
 *             (k indexes the exit table, which holds the target cell), else
 *             CM_IMAGE_EXIT; CM_IMAGE_SINK when the model gives no image or
 *             the image is outside the world;
 *   group[i]  0 for the sink's domain of attraction, else a group id 1..G;
 *             with exits recorded, a cell whose chain leaves the box holds
 *             CM_NODE_REF | k instead of 0, k its chain's exit (classify.h);
 *   step[i]   steps to the periodic group (0 for periodic cells; a cell whose
 *             image is the sink has step 1).
 *
 * Images are computed in parallel (OpenMP) by the centre-point method;
 * classification (cellmap/classify.h) runs O(n) on one thread, so group ids
 * (numbered in order of the lowest local index that reaches them) never
 * depend on the thread count. Ownership: cm_region_alloc allocates, cm_region_free releases.
 */
#ifndef CM_SCM_H
#define CM_SCM_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/classify.h"
#include "cellmap/lattice.h"
#include "cellmap/model.h"
#include "cellmap/status.h"

/* group[] of a cell that was not computed (outside every region of a
 * flattened cluster); cm_scm_groups and the renderer skip it. */
#define CM_GROUP_NONE UINT32_C(0xFFFFFFFF)

/* Largest number of cells in one region: local indices stay below the
 * image marks, and step numbers below 2^31 (classification keeps a flag in
 * the top bit). */
#define CM_REGION_MAX_CELLS UINT64_C(0x7FFFFFF0)

typedef struct cm_region {
    cm_box box;
    uint64_t ncells;
    uint32_t *image;
    uint32_t *group;
    uint32_t *step;
    uint32_t ngroups;     /* periodic groups other than the sink */
    int exits_recorded;   /* images were computed with record_exits */
    uint64_t nexits;      /* recorded exits */
    int64_t *exit_target; /* nexits * box.dim cell coordinates, in local index order */
} cm_region;

/* Whether cell i is a periodic cell of a group (not the sink, not a cell
 * outside the computed regions). */
static inline int cm_is_periodic(const cm_region *r, uint64_t i)
{
    return r->step[i] == 0 && r->group[i] != 0 && r->group[i] != CM_GROUP_NONE;
}

/* Target cell of recorded exit k of a region (box.dim coordinates). */
static inline const int64_t *cm_region_exit(const cm_region *r, uint64_t k)
{
    return r->exit_target + k * (uint64_t)r->box.dim;
}

/* Progress callback, called on the calling thread: phase "images" with the
 * fraction of them done in [0, 1], always last with 1 when they are done,
 * then (cm_scm_solve) "classification" with 0 as it starts. Nonzero
 * cancels: the call returns CM_ECANCELED. */
typedef int (*cm_progress_fn)(void *user, const char *phase, double fraction);

typedef struct cm_scm_options {
    /* Re-step from the image while it stays in the starting cell, up to this
     * many steps in all (0 and 1 both mean a single step). Useful for flows. */
    int max_steps;
    int threads;             /* 0: the OpenMP default */
    cm_progress_fn progress; /* optional */
    void *user;
    int record_exits; /* keep the target cell of every image that leaves the box
                         (needed to join regions into a cluster) */
} cm_scm_options;

/* What a periodic group is. A sticking zone is a set of rest states held
 * by static friction (cm_model.at_rest): its cells do not move at all. */
enum cm_group_kind { CM_GROUP_ATTRACTOR = 0, CM_GROUP_STICKING = 1 };

/* "attractor" or "sticking", as the database and the summaries write it. */
const char *cm_group_kind_name(int kind);

/* Summary of one periodic group. */
typedef struct cm_group_info {
    uint32_t id;
    uint32_t period;                       /* number of periodic cells */
    uint64_t basin_cells;                  /* cells with this group, periodic ones included */
    double centre[CM_MAX_DIM];             /* mean centre of the periodic cells */
    int64_t anchor[CM_MAX_DIM];            /* lexicographically smallest periodic cell:
                                              the group's identity, whatever its id */
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM]; /* bounding box of periodic cells' centres */
    int kind;                              /* enum cm_group_kind */
} cm_group_info;

/* Memory for one of a region's per-cell arrays, `bytes` long, freed by
 * free(): in transparent huge pages where the system has them (whose first
 * touch costs a tenth of 4 KiB pages' here), rounded up to whole ones when
 * that adds at most a quarter to `bytes`, else with the tail in 4 KiB
 * pages. cm_region_alloc, the store's page-in and the node tables of
 * regions about to join (cm_region_nodes) use it. */
void *cm_cells_array(size_t bytes);

cm_status cm_region_alloc(cm_region *r, const cm_box *box, char *msg, size_t msg_size);

/* Checks a region's arrays and exit table as read from a file (O(cells),
 * a few ns per cell): every image a cell of the region, the sink, or a
 * recorded exit, exits numbered in cell order; every exit target outside
 * the box and inside the world; every group 0, a group id up to max_group
 * or (node_refs) the node of one of its exits; and group and step agreeing
 * with the image's (a cell's group is its image's, its step one more, or 0
 * on a cycle; a cell whose image is the sink has group 0, step 1; with
 * node_refs an exit's cell is its own node's, step 1). A region of
 * resolved cells (node_refs false) holds cluster-wide groups and steps at
 * its exits, which only a cluster can check. Runs on `threads` threads.
 * CM_EFORMAT with what is wrong where ("cell 17: ...") in msg. */
cm_status cm_region_check(const cm_region *r, uint32_t max_group, bool node_refs, int threads,
                          char *msg, size_t msg_size);
/* The groups alone of a region of ncells cells and nexits exits, as read
 * without the other arrays: each 0, a group up to max_group or a node of
 * one of its exits. CM_EFORMAT with the first bad cell in msg. */
cm_status cm_groups_check(const uint32_t *group, uint64_t ncells, uint64_t nexits,
                          uint32_t max_group, char *msg, size_t msg_size);
void cm_region_free(cm_region *r);
/* Bytes held by the region's per-cell arrays and its exit table. */
uint64_t cm_region_bytes(const cm_region *r);

/* Computes image[] for every cell. CM_EMODEL if the model aborted. */
cm_status cm_scm_images(const cm_model *model, const cm_lattice *lat, const cm_scm_options *opt,
                        cm_region *r, char *msg, size_t msg_size);

/* The image cell of cell `from` by the rule cm_scm_images uses (the
 * centre's image, re-stepped while it stays in `from`, max_steps steps in
 * all) into cell; *in_world false when there is none (no image, or beyond
 * the world). Returns the model's status (< 0: it aborted). */
int cm_scm_image_cell(const cm_model *model, const cm_lattice *lat, const int64_t *from,
                      int max_steps, int64_t *cell, bool *in_world);

/* Slow directions: for each dimension d, the share of the cells whose image
 * is another cell of the box in the same slab of d (equal coordinate d),
 * into share[d]; NaN where no cell's image is another cell of the box. A
 * large share means the map moves less than a cell per step in d there:
 * restarting each step from a cell's centre then undoes the motion in d,
 * and a coordinate that decays slowly never decays (docs/engine.md, "Slow
 * directions"). Finer cells in d are the cure. On `threads` threads (0:
 * the OpenMP default; the shares do not depend on their number). */
void cm_scm_slow_share(const cm_region *r, int threads, double share[CM_MAX_DIM]);

/* Classifies the functional graph in image[] into group[] and step[], on
 * `threads` threads (0: every core; regions below 65536 cells on one). The
 * result does not depend on the number of threads. */
cm_status cm_scm_classify(cm_region *r, int threads, char *msg, size_t msg_size);

/* Images then classification. */
cm_status cm_scm_solve(const cm_model *model, const cm_lattice *lat, const cm_scm_options *opt,
                       cm_region *r, char *msg, size_t msg_size);

/* Box order of cells: the last coordinate first (true if a comes before b). */
bool cm_cell_less(const int64_t *a, const int64_t *b, int dim);
/* The index of `cell` among n distinct cells in box order (dim coordinates
 * each), or UINT64_MAX when it is not one of them. O(log n). */
uint64_t cm_cell_search(const int64_t *cells, uint64_t n, int dim, const int64_t *cell);

/* Adds a periodic cell to a group's summary (period, anchor, bounds, the
 * centre's running sum); cells must come in box order (cm_cell_less) for
 * the centre to be the same bits whoever sums it. cm_group_finish turns
 * the sum into the mean. */
void cm_group_add_periodic(cm_group_info *gi, const cm_lattice *lat, const int64_t *cell);
void cm_group_finish(cm_group_info *gi, int dim);

/* Summaries of groups 1..ngroups into a caller array of r->ngroups entries
 * (entry k describes group k+1). Also counts the sink's cells if sink_cells. */
cm_status cm_scm_groups(const cm_region *r, const cm_lattice *lat, cm_group_info *groups,
                        uint64_t *sink_cells);

/* Whether the image of the cell's centre is a rest state of the model
 * (false for models without cm_model.at_rest). */
bool cm_cell_at_rest(const cm_model *model, const cm_lattice *lat, const int64_t *cell);

/* Sets groups[k].kind for the groups with periodic cells in r (ids 1..n,
 * entry k for group k+1): CM_GROUP_STICKING when every such cell is at
 * rest (cm_cell_at_rest), else CM_GROUP_ATTRACTOR. */
cm_status cm_scm_label_groups(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                              cm_group_info *groups, uint32_t n, char *msg, size_t msg_size);

/* Both: the labelled summaries of r's groups in *groups, a new array of
 * r->ngroups + 1 entries that the caller frees (also on failure). */
cm_status cm_scm_describe(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                          cm_group_info **groups, uint64_t *sink_cells, char *msg, size_t msg_size);

#endif
