/* src/project.h - a .cmdb project as the commands use one: opened to read
 * (render, export, info), created or resumed to be extended (solve --db,
 * explore), with the rules they share: a file is checked read-only before
 * anything is written to it, older formats are upgraded only once the file
 * proves to be the caller's, new files carry the command line, plan and a
 * reproducible creation time. */
#ifndef CM_SRC_PROJECT_H
#define CM_SRC_PROJECT_H

#include "cellmap/join.h"
#include "cellmap/model.h"
#include "cellmap/store.h"

/* Opens path read-only, reads what it says about itself and restores its
 * cluster (paged out; regions are read back on demand within mem_budget
 * bytes). Prints "cellmap CMD: problem" and returns EXIT_FAIL on failure,
 * leaving nothing open. */
int project_open_read(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
                      cm_store_info *info, cm_cluster *c);

/* Closes what project_open_read, project_create or project_resume opened. */
void project_close(cm_store *s, cm_cluster *c);

/* The model a file was made with, rebuilt from its name and parameters
 * (which must rebuild exactly). */
cm_status model_of_store(const cm_store_info *info, cm_model *m, char *msg, size_t msg_size);

/* A new file at path for model m, lattice, command line and plan (created
 * at SOURCE_DATE_EPOCH, else time 0), replacing an older cellmap database
 * there once cm_store_finish says the new cluster is complete (never
 * another file), and an empty cluster c saved into it; m
 * labels its groups' kinds and must outlive the store. */
cm_status project_create(const char *path, const cm_model *m, const cm_lattice *lat,
                         const char *command, const char *plan, cm_store **s, cm_cluster *c,
                         char *msg, size_t msg_size);

/* Says whether a file is the caller's to extend (model, parameters,
 * lattice, plan...) and gives the model to extend it with (*model, which
 * must outlive the store); anything but CM_OK refuses it with the message. */
typedef cm_status (*project_fits_fn)(void *user, const cm_store_info *info,
                                     const cm_model **model, char *msg, size_t msg_size);

/* Resumes path to extend it: reads what it says about itself (into *info)
 * read-only, asks `fits`, upgrades a file of an older format in place
 * (said on stderr as "cellmap CMD: ..."), opens it for writing and restores
 * its cluster into c (paged out, the store attached as pager). A refused
 * file is left byte-identical. */
cm_status project_resume(const char *cmd, const char *path, project_fits_fn fits, void *user,
                         cm_store **s, cm_store_info *info, cm_cluster *c, char *msg,
                         size_t msg_size);

/* The name of coordinate d: x, y, z, w, v, u. */
const char *axis_name(int d);

#endif
