/* src/export_arrays.h - `cellmap export --labels` and `--steps`: the
 * cells of a window as an n-D array for numpy, Julia (NPZ.jl) or MATLAB.
 *
 * FILE.npy holds one little-endian int32 per cell, shape (n_0, ..., n_d-1)
 * (cells per state dimension, axis k = dimension k), C order: the
 * attractor id (0 diverged; -2 outside: the sequence left the computed
 * cells and its orbit did not come back, or its group's true orbit was
 * undecided; -1 not computed: cm_attractor_cell_labels), or
 * with --by groups the group id (0 the sink, -1 not computed), or the step
 * number (-1 not computed).
 * FILE.json beside it (docs/cellmap.schema.json, "export") says where the
 * array lies on the lattice and in state space, the model, and each group
 * in it with its kind, period, centre and figure colour. */
#ifndef CM_SRC_EXPORT_ARRAYS_H
#define CM_SRC_EXPORT_ARRAYS_H

#include "cellmap/cluster.h"
#include "cellmap/store.h"
#include "src/progress.h"

typedef struct array_export {
    const char *labels, *steps; /* FILE.npy, or NULL */
    const char *source;         /* the .cmdb file, for the sidecar */
    const cm_store_info *info;
    const cm_group_info *groups; /* groups 1..ngroups */
    uint32_t ngroups;
    const char *const *names; /* the state coordinates' names */
    const struct cm_attractor_set *attractors; /* not NULL: labels by attractors */
    const struct cm_computed *computed;        /* where sink cells' sequences go beyond a
                                                  slab (by attractors) */
} array_export;

/* The sidecar's path: FILE.npy -> FILE.json. */
void array_sidecar_path(const char *npy, char *out, size_t size);

/* Writes the arrays (and their sidecars) of the cells in window; each file
 * reaches its path only when complete. Prints problems as "cellmap export:
 * ..." and returns false then. */
bool export_arrays(cm_cluster *c, const cm_box *window, const array_export *x, progress *pr);

#endif
