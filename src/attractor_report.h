/* src/attractor_report.h - the attractors of a solve (cellmap/attractors.h)
 * as the commands report them: the options that set the check, the text
 * summary's table and the JSON's "attractors", and what each group's
 * cells became. */
#ifndef CM_SRC_ATTRACTOR_REPORT_H
#define CM_SRC_ATTRACTOR_REPORT_H

#include <stdio.h>

#include "cellmap/attractors.h"
#include "cellmap/cluster.h"
#include "cellmap/store.h"
#include "src/args.h"
#include "src/json.h"

#define ATTRACTOR_OPTIONS_HELP                                                                     \
    "  --attractor-steps T,R[,MAX]  the true-orbit check of each cell group: T steps of\n"         \
    "                      transient, a record of R steps (doubled while undecided), at most\n"    \
    "                      MAX steps a group (default 500,500,65536; 8192 for ODE flows)\n"         \
    "  --attractor-tol TOL[,MATCH]  recurrence within TOL cell widths is periodic; cycles\n"      \
    "                      within MATCH cell widths are one attractor (default 1e-4,1e-2)\n"

#define BY_OPTION_HELP                                                                             \
    "  --by attractors|groups  figures and labels by the system's attractors (default;\n"      \
    "                      their footprints marked) or by cell mapping's groups (the\n"          \
    "                      thesis' figures are drawn by groups)\n"

/* Handles --attractor-steps and --attractor-tol; true if the current option
 * was one of them (a bad value is reported and *error set). */
bool attractor_options_take(cli *c, cm_attractor_options *o, int *error);

/* The text summary's attractor lines (the largest basins first, at most
 * `rows`), and the cells that reach none: those of groups whose orbits
 * diverge or were undecided, and the sink's (sink_cells: the sequence left
 * the computed cells, fate unknown). */
void attractor_text(FILE *out, const cm_lattice *lat, const cm_attractor_set *s,
                    uint64_t sink_cells, uint64_t cells, int rows);

/* An attractor's id, kind, period (null when aperiodic), basin_cells and
 * centre, the fields every JSON that lists attractors has. */
void json_attractor_fields(json *j, const cm_attractor *a, const cm_lattice *lat);

/* "attractors": [...], "diverged_cells", "undecided_cells", "outside_cells"
 * (the sink's sink_cells). */
void attractor_json(json *j, const cm_lattice *lat, const cm_attractor_set *s,
                    uint64_t sink_cells);

/* Whether any --attractor-* option was given (then a file's stored
 * attractors are not the ones asked for). */
bool attractor_options_given(const cm_attractor_options *o);

/* --by groups|attractors: what figures and labels show (default: attractors). */
enum { BY_ATTRACTORS = 0, BY_GROUPS = 1 };
bool by_option_take(cli *c, int *by, int *error);

/* The attractors of a cluster's groups (groups[k]: group k + 1), the
 * cells' groups read from the cluster. */
cm_status cluster_attractors(const cm_model *m, cm_cluster *c, const cm_group_info *groups,
                             uint32_t ngroups, const cm_attractor_options *o,
                             cm_attractor_set *out, char *msg, size_t msg_size);

/* The attractors of a file's cluster: those it stores, unless o asks for
 * others (a field set) or it stores none; then found with the true map of
 * model m (NULL: the file's, rebuilt from info) and the cluster's cells
 * (cluster_attractors). */
cm_status file_attractors(cm_store *s, const cm_store_info *info, const cm_model *m,
                          cm_cluster *c, const cm_group_info *groups, uint32_t ngroups,
                          const cm_attractor_options *o, cm_attractor_set *out, char *msg,
                          size_t msg_size);

/* Group g's label by attractors: its attractor's id, or 0 when its orbit
 * diverges or is undecided (and for the sink, g = 0); CM_GROUP_NONE stays. */
uint32_t attractor_label(const cm_attractor_set *s, uint32_t g);

/* A flat region relabelled by attractors, in place: each cell's group id
 * becomes its attractor's (attractor_label), the attractors' footprint
 * cells in it take their attractor with step 0 (and no other cell has
 * step 0: the markers are the footprints); *groups (freed) becomes the
 * attractors' summaries, as groups, for the figure's colours and legend
 * (*n of them). */
cm_status attractor_view(const cm_attractor_set *s, cm_region *flat, cm_group_info **groups,
                         uint32_t *n, char *msg, size_t msg_size);

/* The groups as json_groups writes them, each with "attractor" (its id, or
 * null when its orbit diverges or is undecided). */
void attractor_json_groups(json *j, const cm_group_info *g, uint32_t n, const cm_lattice *lat,
                           const cm_attractor_set *s);

#endif
