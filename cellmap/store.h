/* cellmap/store.h - the .cmdb cluster database (SQLite): the cluster's
 * page store and the file users keep, query and export.
 *
 * A .cmdb file holds one cluster: metadata (model, parameters as JSON,
 * lattice, tool version, command line, solve plan), the regions in join
 * order, their cell arrays as compressed pages of CM_STORE_PAGE_CELLS cells
 * (cellmap/codec.h), their exit tables, node tables and open nodes, the
 * cell count per group, the periodic groups (table `attractors`, a name
 * kept from version 2), and (version 6) the system's attractors that the
 * groups' true orbits give (cellmap/attractors.h) with each group's, and
 * (version 7) the fates of the orbits that leave the computed cells
 * (cellmap/outside.h). The
 * view `groups` adds basin sizes and the sink. Layout: docs/format.md.
 *
 * The file carries application_id CM_STORE_APP_ID and user_version
 * CM_STORE_VERSION; files that are not SQLite, not cellmap's, of another
 * version or corrupt are refused (CM_EFORMAT) and never modified. Files of
 * versions 2 and 3 (regions stored resolved, no node tables; version 2
 * without group kinds), 4 (no table of open nodes: every node table is
 * read at open), 5 (no system attractors) and 6 (attractors found without
 * following orbits out of the cells: read as none) are read as they are; writing
 * needs cm_store_upgrade.
 *
 * Crash safety: the file is in WAL mode while open for writing, and
 * cm_store_commit writes everything a join changed in one transaction, so
 * a killed process leaves the cluster of the last commit. Closing switches
 * the file back to a single file (rollback journal).
 *
 * Paging: cm_store_attach makes the store the cluster's pager. Regions are
 * read back on demand; saved ones can be evicted at any time, and a store
 * open for writing also saves a region never saved when it must be evicted
 * in the middle of a join (cm_cluster_acquire under a budget). Those writes go into
 * the transaction that the join's commit ends, so a kill still leaves the
 * cluster of the last commit. A store is used from one thread at a time.
 */
#ifndef CM_STORE_H
#define CM_STORE_H

#include <stdbool.h>

#include "cellmap/attractors.h"
#include "cellmap/join.h"
#include "cellmap/model.h"
#include "cellmap/scm.h"

#define CM_STORE_APP_ID 0x434D4442 /* "CMDB" */
#define CM_STORE_VERSION 7
#define CM_STORE_PAGE_CELLS 65536

typedef struct cm_store cm_store;

typedef struct cm_store_meta {
    const cm_model *model; /* name and parameter values */
    const cm_lattice *lattice;
    const char *command; /* command line that made the file, may be NULL */
    const char *plan;    /* what a resumed solve must repeat, may be NULL */
    const char *tool_version;
    long long created; /* seconds since the epoch (SOURCE_DATE_EPOCH or 0) */
    const char *model_lib;      /* the plugin the model came from (NULL: built in) */
    const char *model_lib_hash; /* its hash, so that a changed plugin is noticed */
} cm_store_meta;

/* What a file says about itself (cm_store_read_info). */
typedef struct cm_store_info {
    char model[64];
    char params[4096]; /* JSON object */
    char command[4096];
    char plan[1024];
    char tool_version[64];
    char model_lib[1024];     /* the model's plugin ("": built in) */
    char model_lib_hash[24];
    cm_lattice lattice;
    uint32_t regions;
    uint64_t cells;
    uint32_t groups;     /* periodic groups (attractors) */
    uint64_t file_bytes; /* database file, WAL included */
    uint64_t page_bytes; /* encoded cell arrays */
    int version;         /* the file's format version (2 and 3 need cm_store_upgrade to be written) */
} cm_store_info;

/* Paging and commit figures since the store was opened. */
typedef struct cm_store_stats {
    uint64_t regions_read, regions_written, pages_written, node_tables_written;
    uint64_t regions_evicted;           /* unsaved, saved by the pager in a join */
    uint64_t bytes_read, bytes_written; /* encoded */
    uint64_t page_bytes_written;        /* of them, cell pages */
    double read_seconds, evict_seconds, commit_seconds;
} cm_store_stats;

/* Creates a new, empty database at path (a symlink is followed; a device,
 * FIFO, socket or directory is refused). An existing cellmap database there
 * is replaced, but only when the new cluster is complete: until
 * cm_store_finish the new one is written to PATH.tmp-PID and the old one is
 * left intact (cm_store_close without cm_store_finish discards the new one).
 * Any other existing file is refused (CM_EFORMAT), untouched. */
cm_status cm_store_create(const char *path, const cm_store_meta *meta, cm_store **out, char *msg,
                          size_t msg_size);

/* Opens an existing database, read-only or for writing (to resume). Checks
 * application id, version and (for writing) integrity before any write. */
cm_status cm_store_open(const char *path, int writable, cm_store **out, char *msg, size_t msg_size);

/* Upgrades a file of version 2, 3 or 4 to this version in one transaction
 * (*upgraded = 1; 0 for a file of this version, which is left alone).
 * Version 4 gets the table of its open nodes. Versions 2 and 3: the regions
 * are classified again from their saved images and joined again in their
 * saved order (no model step is taken; the cluster is held in memory, 12
 * bytes per cell); the result must give every cell the group and step the
 * file holds, and the same `groups` rows (model labels the groups' kinds:
 * pass the file's), or nothing is written and the message says why. Check
 * the file's model, parameters and plan before upgrading it. */
cm_status cm_store_upgrade(const char *path, const cm_model *model, int *upgraded, char *msg,
                           size_t msg_size);

/* Makes a read-only store read the first 64 MiB of its file through a
 * memory map: for readers of scattered records (info, export --groups),
 * not for readers of every cell, whose resident memory the mapped pages
 * would join. Does nothing on a writable store. */
void cm_store_map_reads(cm_store *s);

/* A read-only store reads one snapshot from cm_store_snapshot_begin to
 * cm_store_snapshot_end: its statements share one lock of the file, where
 * each would otherwise take and drop it and look for a journal. Keep
 * snapshots short: in rollback mode they hold a writer off. A file in WAL
 * mode (a writer at work) keeps the snapshot until cm_store_close, so that
 * every region and node read later belongs to the records read first. */
cm_status cm_store_snapshot_begin(cm_store *s, char *msg, size_t msg_size);
void cm_store_snapshot_end(cm_store *s);

/* Closes and frees (NULL-safe). A writable store returns to rollback mode.
 * A new cluster that was to replace an older file is discarded. */
cm_status cm_store_close(cm_store *s, char *msg, size_t msg_size);

/* The cluster is complete: closes as cm_store_close does and, for a new
 * cluster that replaces an older file, puts it in the old one's place. */
cm_status cm_store_finish(cm_store *s, char *msg, size_t msg_size);

/* Whether the store writes a new cluster that is to replace an older file
 * (so that closing it without cm_store_finish leaves the old one). */
bool cm_store_replacing(const cm_store *s);

/* Checks that path is a cellmap database this version can read. */
cm_status cm_store_check(const char *path, char *msg, size_t msg_size);

/* The quick check of a file the user names as a database, before any
 * work: by its header alone (nothing is opened through SQLite), whether
 * it exists and is readable (else CM_ENOTFOUND, with the reason) and is a
 * cellmap database of a version this cellmap reads (else CM_EFORMAT). Its
 * contents (damage) are checked when it is opened. */
cm_status cm_store_probe(const char *path, char *msg, size_t msg_size);

cm_status cm_store_read_info(cm_store *s, cm_store_info *info, char *msg, size_t msg_size);

void cm_store_get_stats(const cm_store *s, cm_store_stats *stats);

/* Makes the store the pager of c (c->page_in, c->page_out, c->pager). */
void cm_store_attach(cm_store *s, cm_cluster *c);

/* The records of the file's n regions (n from cm_store_read_info), in
 * order: box and counts, no cells (every array NULL). For what a reader
 * needs to know of the regions without loading the cluster. */
cm_status cm_store_regions(cm_store *s, cm_region *regions, uint32_t n, char *msg,
                           size_t msg_size);

/* Rebuilds the saved cluster into c (initialised on the file's lattice):
 * every region restored paged out, the store attached as pager. */
cm_status cm_store_load_cluster(cm_store *s, cm_cluster *c, char *msg, size_t msg_size);

/* Writes, in one transaction, every region of c never saved (row, exit
 * table, pages: each page once), the node records that changed, the cell
 * counts of the groups that changed and the groups new since the last
 * commit; then tells the cluster (cm_cluster_saved). */
cm_status cm_store_commit(cm_store *s, cm_cluster *c, char *msg, size_t msg_size);

/* A cm_joined_fn for cm_cluster_solve_boxes with the store as user: commits
 * the join (the next join pages out what c->mem_budget cannot hold, once it
 * knows the regions it reads). */
cm_status cm_store_commit_join(void *store, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                               char *msg, size_t msg_size);

/* The model whose rest states (cm_model.at_rest) label the groups the next
 * commits write: a group whose periodic cells all map to rest states is
 * saved as a sticking zone (kind 'sticking'). Without it every group is an
 * attractor. The model must outlive the store's commits. */
void cm_store_set_model(cm_store *s, const cm_model *model);

/* Summaries of the saved groups 1..n into a caller array (entry k: group
 * k+1, kind included), n = the info's groups, and the sink's cell count. */
cm_status cm_store_groups(cm_store *s, cm_group_info *groups, uint32_t n, uint64_t *sink_cells,
                          char *msg, size_t msg_size);

/* The k groups of most cells (k at most the info's groups), largest first,
 * ties by id, into a caller array; and the sink's cell count. Reads k rows,
 * not every group's. */
cm_status cm_store_largest_groups(cm_store *s, cm_group_info *groups, uint32_t k,
                                  uint64_t *sink_cells, char *msg, size_t msg_size);

/* Application notes kept with the cluster (e.g. an explore session's
 * view), under keys that begin with "note.": set (in its own transaction,
 * or in the open one) and get; CM_ENOTFOUND when the key is not there. */
cm_status cm_store_set_note(cm_store *s, const char *key, const char *value, char *msg,
                            size_t msg_size);
cm_status cm_store_get_note(cm_store *s, const char *key, char *out, size_t size, char *msg,
                            size_t msg_size);

/* The system's attractors of the file's groups (dim: the lattice's) with
 * the options they were found with: replaced (in its own transaction, or
 * in the open one). */
cm_status cm_store_put_attractors(cm_store *s, const cm_attractor_set *a,
                                  const cm_attractor_options *o, int dim, char *msg,
                                  size_t msg_size);
/* Reads them back into *a (released with cm_attractors_free) for the
 * file's ngroups groups, and their options into *o (may be NULL);
 * CM_ENOTFOUND when the file holds none (version 5 or older, or a solve
 * stopped before them), CM_EFORMAT when damaged. Reads no cell. */
cm_status cm_store_get_attractors(cm_store *s, int dim, uint32_t ngroups, cm_attractor_set *a,
                                  cm_attractor_options *o, char *msg, size_t msg_size);
/* Whether the file holds them, as cm_store_get_attractors answers, without
 * reading the exits' cells (their rows are checked by size alone): for an
 * owner that only needs to know they are there, such as a session closing
 * on a cluster that did not grow (18 million exits after 800 pans). */
cm_status cm_store_check_attractors(cm_store *s, int dim, uint32_t ngroups, char *msg,
                                    size_t msg_size);

/* Parameters as a JSON object text, e.g. {"alpha":0.078,"mode":"output"}. */
void cm_params_json(const cm_params *p, char *buf, size_t size);

#endif
