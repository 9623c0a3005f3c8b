/* lib/export.h - a .cmdb file's cells and groups for other tools: the
 * groups as CSV, the cells as CSV, a numpy record array (.npy) or a flat
 * SQLite database, and the cells of a window as n-D .npy arrays of labels
 * or steps with a JSON sidecar (docs/format.md, docs/cellmap.schema.json).
 *
 * An exporter is opened over a file's cluster (lib/project.h:
 * project_open_cluster) and finds what every output needs once: the
 * groups, their attractors (stored, or found with the true map) and where
 * the sink cells' sequences go. Each output is written to a temporary file
 * and reaches its path only when complete (lib/outfile.h); a failed or
 * stopped export leaves no file. Cells are read a slab of 2^22 at a time,
 * so memory stays within the cluster's budget whatever the window.
 *
 * The .npy arrays hold one little-endian int32 per cell, shape (n_0, ...,
 * n_d-1) (cells per state dimension, axis k = dimension k), C order: the
 * attractor id (0 diverged; -2 outside: the sequence left the computed
 * cells and its orbit did not come back, or its group's true orbit was
 * undecided; -1 not computed: cm_attractor_cell_labels), or by groups the
 * group id (0 the sink, -1 not computed), or the step number (-1 not
 * computed). FILE.json beside FILE.npy says where the array lies on the
 * lattice and in state space, the model, and each group or attractor in
 * it with its kind, period, centre and figure colour. */
#ifndef CM_LIB_EXPORT_H
#define CM_LIB_EXPORT_H

#include <stdint.h>

#include "lib/attractor_report.h"
#include "lib/work.h"

typedef struct exporter {
    cm_store *store;
    const cm_store_info *info;
    cm_cluster *c;
    const char *source;        /* the .cmdb file, for provenance */
    cm_group_info *groups;     /* groups 1..info->groups (entry k: group k + 1) */
    uint64_t sink;             /* the sink's cells */
    cm_attractor_set att;      /* the groups' attractors */
    cluster_ends ends;         /* the cluster's exits */
    const char *names[CM_MAX_DIM]; /* the state coordinates' names */
    cm_box window;             /* the cells written */
    int32_t *node_labels;      /* the nodes' labels, once export_labels needed them */
} exporter;

/* The cells of c whose centres lie in the window text "X0:X1[,Y0:Y1...]"
 * (state units, one range per dimension), within the cluster's bounds.
 * CM_EINVAL, with the cells' width and centres, when it is malformed or
 * holds no cell centre. */
cm_status export_window(const cm_cluster *c, const char *text, cm_box *window, char *msg,
                        size_t msg_size);

/* Opens an exporter over a file's open store, its records and its loaded
 * cluster (all must outlive it) for the cells of window (NULL: all): reads
 * the groups and the attractors the file stores, or finds them with o (a
 * field set: others than the stored ones are asked for). source names the
 * file in outputs and messages. */
cm_status exporter_open(exporter *x, cm_store *s, const cm_store_info *info, cm_cluster *c,
                        const cm_box *window, const char *source, const cm_attractor_options *o,
                        char *msg, size_t msg_size);
void exporter_close(exporter *x);

/* The groups as CSV at path: id, period, basin_cells, is_sink, centre_*,
 * lo_*, hi_*, anchor_i*, kind, attractor (the sink first, as group 0). */
cm_status export_groups(const exporter *x, const char *path, char *msg, size_t msg_size);

/* export_groups from the file's records alone, without its cluster (as
 * info reads it): CM_ENOTFOUND when the file stores no attractors (or o
 * asks for others), which only the cluster can find. */
cm_status export_groups_of_file(const char *file, const char *path,
                                const cm_attractor_options *o, char *msg, size_t msg_size);

/* The window's computed cells as rows (cell indices, centre, grp, step,
 * periodic, attractor) into cells (.csv or .npy by its ending; "-" CSV on
 * stdout) and flat (SQLite with the groups and the lattice), either may
 * be NULL; *rows: the cells written. hooks count cells. */
cm_status export_cells(exporter *x, const char *cells, const char *flat, const work_hooks *hooks,
                       uint64_t *rows, char *msg, size_t msg_size);

/* The window's cells as .npy arrays at labels (by attractors, or by groups
 * when by_groups) and steps, either may be NULL, each with its JSON
 * sidecar (export_sidecar_path). hooks count cells. */
cm_status export_arrays(exporter *x, const char *labels, const char *steps, bool by_groups,
                        const work_hooks *hooks, char *msg, size_t msg_size);

/* The labels by attractors (as the .npy array of export_arrays has them)
 * of the cells of box (within the window) into labels (box's cells, C
 * order, the caller's): region by region from the nodes' labels, made at
 * the first call (cm_cluster_cell_labels); a cluster of resolved cells
 * (a file before version 4) a slab at a time. hooks count cells. */
cm_status export_labels(exporter *x, const cm_box *box, int32_t *labels,
                        const work_hooks *hooks, char *msg, size_t msg_size);

/* Makes x an exporter of labels only: the nodes' labels made now, the
 * exits' fates (20 bytes per exit) and the cluster's open nodes' index
 * (about 70 bytes per open node, cm_cluster_release_open), which only they
 * needed, released on the way; export_cells and export_arrays refuse
 * afterwards (the cluster's exits are no longer known), and the cluster
 * can no longer be saved or joined. A cluster
 * of resolved cells keeps them (export_labels follows its cells' exits). */
cm_status exporter_labels_only(exporter *x, char *msg, size_t msg_size);

/* An array's sidecar path: FILE.npy -> FILE.json. */
void export_sidecar_path(const char *npy, char *out, size_t size);

#endif
