/* cellmap/attractors.h - the system's attractors over a solve's cell groups.
 *
 * Simple cell mapping's periodic groups belong to the lattice as much as to
 * the system: a period-1 attractor can show as a cell cycle of period 3, one
 * attractor as several groups, a cell the map moves by less than a cell as a
 * fixed "group" of its own. This layer checks every group by the true map in
 * full precision: from the centre of its anchor cell (its smallest periodic
 * cell, cm_group_info.anchor) the orbit is followed for a transient, then
 * recorded, and the recording decides
 *   - periodic: the orbit recurs in state space, |x_n - x_{n-p}| <= tol
 *     cell widths in every coordinate over its last two cycles, at the
 *     smallest such p (the true period);
 *   - aperiodic (chaotic or quasi-periodic): the second half of the record
 *     visits almost no cell that the first half did not (at most 2 % new
 *     cells); the cells visited are the attractor's footprint;
 *   - diverged: the map gives no image, or the orbit leaves the world;
 *   - unresolved: none of these within the step budget (the record doubles,
 *     the old record becoming transient, until the budget is spent).
 * Groups whose true orbits end on one attractor are that attractor: two
 * periodic results are one when their periods agree and their cycles lie
 * within match cell widths of each other, two aperiodic ones when their
 * footprints share at least a quarter of the smaller one's cells. A
 * sticking zone of a friction model (CM_GROUP_STICKING) is kept as it is,
 * an attractor of kind CM_ATTRACTOR_STICKING of its own.
 *
 * Attractors are numbered 1..n in the box order (cm_cell_less) of their
 * anchors (the smallest cell of their footprints), and every result here
 * depends only on the groups' anchors, never on their ids or on the thread
 * count: a split, extended or resumed solve gives the attractors of the
 * single-box solve of the same cells. Cost: per group, not per cell (at
 * most max_steps steps of the map each); the groups are followed on
 * `threads` OpenMP threads.
 */
#ifndef CM_ATTRACTORS_H
#define CM_ATTRACTORS_H

#include <stdint.h>

#include "cellmap/model.h"
#include "cellmap/scm.h"

/* The budget and tolerances of the check; 0 in a field: its default. */
typedef struct cm_attractor_options {
    uint32_t transient; /* steps of the probe before its window; default 16 */
    uint32_t record;    /* steps of the first record; default 500 */
    uint32_t max_steps; /* every group's budget, transient and records; default
                           2^20 for maps, 8192 for flows (an image costs an
                           integration over a period) */
    double tol;         /* recurrence tolerance, in cell widths; default 1e-4 */
    double match;       /* two cycles are one within this, in cell widths; default 1e-2 */
    uint32_t outside;   /* steps an orbit that leaves the computed cells is followed
                           (cellmap/outside.h); default 100; CM_OUTSIDE_OFF: not followed */
    int threads;        /* OpenMP threads; 0: the OpenMP default */
} cm_attractor_options;

/* Newton's method for z^3 - 1 needs about 30 steps back into -2:2^2 from
 * the cells next to the origin at 1000^2 cells: 100 leaves room. */
#define CM_OUTSIDE_STEPS 100
#define CM_OUTSIDE_OFF UINT32_MAX
#define CM_OUTSIDE_MAX_STEPS 1048576 /* the largest budget other than CM_OUTSIDE_OFF */

#define CM_ATTRACTOR_TRANSIENT 16
#define CM_ATTRACTOR_RECORD 500
#define CM_ATTRACTOR_MAX_STEPS 1048576
#define CM_ATTRACTOR_MAX_STEPS_FLOW 8192
#define CM_ATTRACTOR_TOL 1e-4
#define CM_ATTRACTOR_MATCH 1e-2

enum cm_attractor_kind {
    CM_ATTRACTOR_PERIODIC = 0,
    CM_ATTRACTOR_APERIODIC = 1,
    CM_ATTRACTOR_STICKING = 2 /* a sticking zone of rest states, as SCM gives it */
};

/* "periodic", "aperiodic" or "sticking". */
const char *cm_attractor_kind_name(int kind);

/* What became of a group (cm_attractor_set.of_group) besides an attractor
 * id: its true orbit diverges, or is undecided within the budget. */
#define CM_FATE_DIVERGED UINT32_C(0)
#define CM_FATE_UNRESOLVED UINT32_C(0xFFFFFFFE)

typedef struct cm_attractor {
    uint32_t id;                  /* 1..n */
    int kind;                     /* enum cm_attractor_kind */
    uint32_t period;              /* true period; 0 when aperiodic */
    double centre[CM_MAX_DIM];    /* mean of the cycle's points, or of the recorded orbit */
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM]; /* bounds of those points */
    int64_t anchor[CM_MAX_DIM];   /* the smallest cell of its footprint: its identity */
    uint32_t groups;              /* the cell groups that are this attractor */
    uint64_t basin_cells;         /* their basins' cells */
    uint64_t footprint_cells;     /* distinct cells of its footprint */
} cm_attractor;

typedef struct cm_attractor_set {
    uint32_t n;          /* attractors */
    cm_attractor *a;     /* n entries; a[k].id = k + 1 */
    uint32_t ngroups;
    uint32_t *of_group;  /* ngroups + 1 entries: group g's attractor id, CM_FATE_DIVERGED or
                            CM_FATE_UNRESOLVED; [0] (the sink) CM_FATE_DIVERGED */
    int64_t *footprint;  /* the attractors' footprint cells, dim coordinates each, attractor
                            by attractor in box order */
    uint64_t *footprint_at; /* n + 1 offsets (in cells) into footprint */
    uint32_t merged;     /* groups that are another group's attractor (groups - n) */
    uint32_t diverged_groups, unresolved_groups;
    uint64_t unresolved_cells; /* the basins of unresolved groups */
    uint64_t diverged_cells;   /* the basins of groups whose orbits diverge (not the sink) */
    uint64_t steps;      /* map steps taken */
    /* orbits that left the computed cells (cellmap/outside.h) */
    uint32_t outside_steps;       /* the budget they were followed with; 0: not followed */
    uint64_t nexits;              /* exit cells */
    int64_t *exit_cell;           /* nexits cells, dim coordinates each, in box order */
    int32_t *exit_label;          /* each one's fate: an attractor id, 0 diverged, -2 outside */
    uint64_t sink_diverged_cells; /* sink cells that diverge: no image, beyond the world, or
                                     an orbit that does */
    uint64_t outside_cells;       /* sink cells whose orbits stay outside (or keep leaving) */
    uint64_t returned_cells;      /* sink cells whose orbits return to an attractor's basin
                                     (counted in its basin_cells) */
    uint64_t outside_steps_taken; /* map steps taken following them */
} cm_attractor_set;

/* Labels by attractors: an attractor's id (1..n), or one of these. */
#define CM_LABEL_DIVERGED 0
#define CM_LABEL_UNCOMPUTED (-1) /* no cell computed there */
#define CM_LABEL_OUTSIDE (-2) /* left the computed cells and did not come back; undecided */

/* The options with every 0 replaced by its default for model m. */
void cm_attractor_defaults(const cm_model *m, const cm_attractor_options *in,
                           cm_attractor_options *out);

/* Checks the options (tolerances > 0 and finite, match >= tol, a budget
 * that holds the transient and one record): CM_EINVAL naming the bad one. */
cm_status cm_attractor_check(const cm_attractor_options *o, char *msg, size_t msg_size);

/* The groups of n cells (dim coordinates each, cells[i * dim ..]) into
 * group[0..n) (its id; 0: the sink; CM_GROUP_NONE: no cell computed
 * there). Called on the calling thread only, once for all the cells a step
 * needs, so that a paged cluster reads each region once
 * (cm_cluster_cells_group). */
typedef cm_status (*cm_cells_group_fn)(void *user, const int64_t *cells, uint64_t n,
                                       uint32_t *group, char *msg, size_t msg_size);

/* A cm_cells_group_fn over one resolved region (user: the cm_region). */
cm_status cm_region_cells_group(void *region, const int64_t *cells, uint64_t n, uint32_t *group,
                                char *msg, size_t msg_size);

/* The attractors of groups[0..ngroups) (entry k: group k + 1, as
 * cm_scm_groups and cm_store_groups give them) into *out, which the caller
 * releases with cm_attractors_free (also on failure). label (may be NULL:
 * every group is checked on its own) gives the cells' groups. opt NULL:
 * defaults. */
cm_status cm_attractors_find(const cm_model *m, const cm_lattice *lat,
                             const cm_group_info *groups, uint32_t ngroups,
                             cm_cells_group_fn label, void *label_user,
                             const cm_attractor_options *opt, cm_attractor_set *out, char *msg,
                             size_t msg_size);

/* Group g's label by attractors, as `export --labels` writes it: its
 * attractor's id, 0 when its true orbit diverges, -2 outside (the sink,
 * g = 0, or an undecided orbit), -1 for CM_GROUP_NONE (no cell computed).
 * The sink's cells have labels of their own: cm_attractor_cell_labels. */
int32_t cm_attractor_label(const cm_attractor_set *s, uint32_t g);
/* The fate of exit cell `cell` (cellmap/outside.h): an attractor id, 0
 * diverged, -2 outside (also for a cell that is not one of s's exits). */
int32_t cm_attractor_exit_label(const cm_attractor_set *s, int dim, const int64_t *cell);
/* Group g's fate as a file stores it (group_fates): its attractor's id, 0
 * when its orbit diverges, -1 undecided. g in 1..s->ngroups. */
int64_t cm_attractor_fate(const cm_attractor_set *s, uint32_t g);

void cm_attractors_free(cm_attractor_set *s);

#endif
