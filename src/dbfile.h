/* src/dbfile.h - opening a .cmdb file for the commands that read one. */
#ifndef CM_SRC_DBFILE_H
#define CM_SRC_DBFILE_H

#include "cellmap/join.h"
#include "cellmap/model.h"
#include "cellmap/store.h"

/* Opens path read-only, reads what it says about itself and restores its
 * cluster (paged out; regions are read back on demand within mem_budget
 * bytes). Prints "cellmap CMD: problem" and returns EXIT_FAIL on failure,
 * leaving nothing open. */
int open_cluster_file(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
                      cm_store_info *info, cm_cluster *c);

/* Closes what open_cluster_file opened. */
void close_cluster_file(cm_store *s, cm_cluster *c);

/* The model a file was made with, rebuilt from its name and parameters
 * (which must rebuild exactly). */
cm_status model_of_store(const cm_store_info *info, cm_model *m, char *msg, size_t msg_size);

/* Opens path for writing (to extend its cluster) once its info was
 * checked; a file of an older format is first upgraded in place (said on
 * stderr as "cellmap CMD: ..."). model: the file's. */
cm_status open_cluster_for_writing(const char *cmd, const char *path, const cm_store_info *info,
                                   const cm_model *model, cm_store **s, char *msg,
                                   size_t msg_size);

/* The name of coordinate d: x, y, z, w, v, u. */
const char *axis_name(int d);

#endif
