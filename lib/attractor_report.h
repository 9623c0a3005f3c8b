/* lib/attractor_report.h - the attractors of a solve (cellmap/attractors.h)
 * as the commands and the library report them: the text summary's table
 * and the JSON's "attractors", where sink cells go, the attractors a file
 * holds, and what each group's cells became. */
#ifndef CM_LIB_ATTRACTOR_REPORT_H
#define CM_LIB_ATTRACTOR_REPORT_H

#include <stdbool.h>
#include <stdio.h>

#include "cellmap/attractors.h"
#include "cellmap/cluster.h"
#include "cellmap/outside.h"
#include "cellmap/store.h"
#include "lib/attractor_view.h"
#include "lib/json.h"

/* The text summary's attractor lines (the largest basins first, at most
 * `rows`), and the cells that reach none: diverged (groups whose orbits
 * diverge, and the sink's cells with no image, beyond the world or whose
 * orbits diverge outside), outside (left the computed cells and did not
 * come back) and undecided; then the cells that left and came back. */
void attractor_text(FILE *out, const cm_lattice *lat, const cm_attractor_set *s, uint64_t cells,
                    int rows);

/* An attractor's id, kind, period (null when aperiodic), basin_cells and
 * centre, the fields every JSON that lists attractors has. */
void json_attractor_fields(json *j, const cm_attractor *a, const cm_lattice *lat);

/* "attractors": [...], "diverged_cells", "outside_cells",
 * "undecided_cells", "returned_cells" and "outside_steps" (the budget
 * orbits that left were followed with; 0: not followed). */
void attractor_json(json *j, const cm_lattice *lat, const cm_attractor_set *s);

/* Whether any --attractor-* option was given (then a file's stored
 * attractors are not the ones asked for). */
bool attractor_options_given(const cm_attractor_options *o);

/* What figures and labels show (--by): the attractors (default) or groups. */
enum { BY_ATTRACTORS = 0, BY_GROUPS = 1 };

/* Where the sink cells of a cluster's views go (cellmap/outside.h): its
 * exits and the adapter over them; `computed` points into the struct, which
 * must stay where it is until cluster_ends_close. Zeroed: closed; opening
 * an open one does nothing (the exits cost 30-40 bytes per open node).
 * While open, the cluster's budget makes room for the pass over them
 * (cm_cluster_exits_room in c->mem_reserved): resident cells are evicted
 * to hold it. */
typedef struct cluster_ends {
    cm_exits exits;
    cm_cluster_cells cc;
    cm_computed computed;
    uint64_t reserved;
    bool open;
} cluster_ends;
cm_status cluster_ends_open(cluster_ends *e, cm_cluster *c, char *msg, size_t msg_size);
void cluster_ends_close(cluster_ends *e);
/* e, unless open, set to read each end's exit from its open node's list,
 * without listing the cluster's exits: for labels whose fates are known
 * (a file's attractors, stored or found). Opening it later lists them. */
void cluster_ends_lookup(cluster_ends *e, cm_cluster *c);

/* The attractors of a file's cluster c: those it stores, unless o asks for
 * others (a field set) or it stores none; then found with the true map of
 * model m (NULL: the file's, rebuilt from info), the cluster's cells and
 * its exits (cm_cluster_attractors), for which ends is opened (left as it
 * is when the file's attractors are read). groups[k]: group k + 1. */
cm_status file_attractors(cm_store *s, const cm_store_info *info, const cm_model *m,
                          cm_cluster *c, cluster_ends *ends, const cm_group_info *groups,
                          const cm_attractor_options *o, cm_attractor_set *out, char *msg,
                          size_t msg_size);

/* The attractors of cluster c's groups (groups[k]: group k + 1) with model
 * m's defaults, and the label of every cell of flat (a flattened part of
 * c) into *labels (ncells entries, the caller's to free; NULL on
 * failure): following only the exits the part reaches
 * (cm_cluster_view_labels), so that the cost follows the part, where the
 * cluster knows its exits and every_exit is false, through memo (NULL:
 * none; cellmap/exit_memo.h); else every exit (cm_cluster_attractors: the
 * attractors' basins are then the cluster's). The labels are the same
 * either way. open (NULL: none): flat's cells' open nodes, from
 * cm_cluster_flatten_open, which spare the first way lookups. */
cm_status part_labels(const cm_model *m, cm_cluster *c, const cm_region *flat,
                      const uint32_t *open, const cm_group_info *groups, bool every_exit,
                      cm_exit_memo *memo, cm_attractor_set *att, int32_t **labels, char *msg,
                      size_t msg_size);

/* Group g's label by attractors: its attractor's id, or 0 when its orbit
 * diverges or is undecided (and for the sink, g = 0); CM_GROUP_NONE stays. */
uint32_t attractor_label(const cm_attractor_set *s, uint32_t g);


/* The groups as json_groups writes them, each with "attractor" (its id, or
 * null when its orbit diverges or is undecided). */
void attractor_json_groups(json *j, const cm_group_info *g, uint32_t n, const cm_lattice *lat,
                           const cm_attractor_set *s);

#endif
