/* cellmap/store_db.h - private to the store's modules, not part of the
 * engine's API: the store itself and the helpers its files share.
 *   store.c         schema, opening and creating files, metadata, notes
 *   store_pages.c   region rows, cell pages, exit and node tables; the
 *                   pager; loading a saved cluster
 *   store_commit.c  groups, basins and commits
 *   store_upgrade.c files of versions 2 to 5 to version 6
 *   store_attractors.c the system's attractors (version 6)
 */
#ifndef CM_STORE_DB_H
#define CM_STORE_DB_H

#include <sqlite3.h>

#include "cellmap/codec.h"
#include "cellmap/store.h"

struct cm_store {
    sqlite3 *db;
    const cm_model *model; /* labels new groups (cm_store_set_model), may be NULL */
    const cm_cluster *cluster; /* the cluster it pages for (cm_store_attach), may be NULL */
    char *path;
    /* a new cluster that replaces the file at replaces when complete
     * (cm_store_finish); until then it is written at tmp_path */
    char *replaces, *tmp_path;
    int replaces_lock_fd; /* an flock on the file it replaces, or -1 */
    int writable;
    int lock_fd; /* writable: an flock on the file, so that a second writer is refused */
    int wal;     /* in WAL mode since the first write (store_begin) */
    int version; /* of the file: 2 and 3 are read (regions resolved, no node table) */
    int in_transaction;             /* evictions in a join write into it; the commit ends it */
    int failed;                     /* a write failed: the cluster and the file differ */
    int cluster_written; /* the open transaction wrote regions or nodes: the commit forgets
                            the stored attractors (store_forget_attractors) */
    unsigned char *blobs; /* a region's encoded pages, read or to write */
    uint64_t blobs_cap;
    /* page encoders, one per thread, kept from one batch of pages to the
     * next: a new zstd context and scratch for every batch cost their
     * memory's first touch each time (store_pages.c) */
    struct store_encoder *encoders;
    int n_encoders;
    /* the buffers store_encode reuses for tables (exits, nodes, open nodes) */
    unsigned char *table_values, *table_scratch, *table_blob;
    uint64_t table_values_cap, table_scratch_cap, table_blob_cap;
    int threads;     /* for encoding and decoding pages: the cluster's */
    cm_store_stats stats;
};

typedef struct store_encoder {
    cm_codec_ctx *ctx;
    unsigned char *scratch; /* 4 * CM_STORE_PAGE_CELLS bytes */
} store_encoder;

/* Frees s's page encoders and table buffers. */
void store_free_encoders(cm_store *s);

/* A buffer of at least `bytes` for a table's values, s's until the next
 * call (NULL: out of memory). */
void *store_table_values(cm_store *s, size_t bytes);

/* Encodes n values of `width` bytes (cm_codec_encode, no index delta) with
 * s's first encoder into s's table blob: *blob and *len stay valid until the
 * next call. Reuses the encoder and buffers, whose first touch costs more
 * than the encoding on small tables. */
cm_status store_encode(cm_store *s, const void *v, size_t n, int width, const unsigned char **blob,
                       size_t *len);

/* Node records as saved: little-endian uint32 columns of n entries, encoded
 * as one BLOB: next, dist, group, target, tree, then (version 5) first_in
 * and sibling. Version 5 keeps a row per CM_NODE_CHUNK nodes, version 4 one
 * per region. */
#define NODE_FIELDS 7
#define NODE_FIELDS_V4 5

/* The tables and view of a version 5 file, meta excepted; the two tables
 * version 5 changed (for the upgrade of version 4). */
extern const char *const store_tables_sql;
#define NODES_TABLE_SQL                                                                            \
    "CREATE TABLE nodes(region INTEGER NOT NULL REFERENCES regions(id),"                           \
    " first INTEGER NOT NULL, count INTEGER NOT NULL, data BLOB NOT NULL,"                         \
    " PRIMARY KEY(region, first));"
#define OPEN_NODES_TABLE_SQL                                                                       \
    "CREATE TABLE open_nodes(region INTEGER PRIMARY KEY REFERENCES regions(id),"                   \
    " count INTEGER NOT NULL, data BLOB NOT NULL);"
/* Version 6's tables of the system's attractors (store_attractors.c), and 7's. */
#define SYSTEM_ATTRACTORS_SQL                                                                      \
    "CREATE TABLE system_attractors(id INTEGER PRIMARY KEY,"                                       \
    " kind TEXT NOT NULL CHECK(kind IN ('periodic', 'aperiodic', 'sticking')), period INTEGER,"   \
    " basin_cells INTEGER NOT NULL, groups INTEGER NOT NULL, centre TEXT NOT NULL,"               \
    " lo TEXT NOT NULL, hi TEXT NOT NULL, anchor TEXT NOT NULL,"                                   \
    " footprint_cells INTEGER NOT NULL, footprint BLOB NOT NULL);"                                 \
    "CREATE TABLE group_fates(grp INTEGER PRIMARY KEY, attractor INTEGER NOT NULL);"           \
    EXIT_FATES_SQL
/* Version 7's: where the orbits that leave the computed cells go. */
#define EXIT_FATES_SQL                                                                             \
    "CREATE TABLE exit_fates(attractor INTEGER PRIMARY KEY, exits INTEGER NOT NULL,"               \
    " cells BLOB NOT NULL);"

/* ---- store_sql.c: the lowest helpers, which call no other store file ---- */
int store_exec(sqlite3 *db, const char *sql);
int64_t store_query_int(sqlite3 *db, const char *sql);
/* The text of the first column of the first row of sql into out. */
cm_status store_read_text(sqlite3 *db, const char *sql, char *out, size_t size, char *msg,
                          size_t msg_size);
/* The meta table's value of key into out; CM_EFORMAT if it has none. */
cm_status store_meta_text(sqlite3 *db, const char *key, char *out, size_t size, char *msg,
                          size_t msg_size);
/* SQLite's error, or for a full disk, a read-only or missing file the
 * file system's reason with the file and the fix, after "what: ". */
cm_status store_db_error(sqlite3 *db, const char *what, char *msg, size_t msg_size);
/* Steps a statement that returns no row, and resets it. */
cm_status store_step_done(sqlite3 *db, sqlite3_stmt *st, const char *what, char *msg,
                          size_t msg_size);
void store_json_doubles(char *buf, size_t size, const double *v, int n);
void store_json_ints(char *buf, size_t size, const int64_t *v, int n);
/* Numbers of a JSON array text into out (at most cap); how many, or -1. */
int store_parse_json_numbers(const char *text, double *out, int cap);
cm_status store_read_lattice(sqlite3 *db, cm_lattice *lat, char *msg, size_t msg_size);
/* Puts the file in WAL mode for writing (once: the first store_begin). */
cm_status store_use_wal(cm_store *s, char *msg, size_t msg_size);
/* Transactions: begin one unless open; abandon rolls back after a failed write. */
cm_status store_begin(cm_store *s, char *msg, size_t msg_size);
cm_status store_abandon(cm_store *s, cm_status st);
/* A CM_EFORMAT message prefixed "PATH is damaged: " unless it names the
 * file already; other statuses as they are. */
cm_status store_damaged(const cm_store *s, cm_status st, char *msg, size_t msg_size);
/* Checks the groups: attractors numbered 1..N with periods, N what the
 * meta table says, basins of those groups only and within the cells. */
cm_status store_check_groups(const cm_store *s, char *msg, size_t msg_size);
/* Bytes of the pages' blobs: the meta value 'page_bytes', or, in files
 * without it, their sum; -1 if damaged or on a database error. */
int64_t store_page_bytes(sqlite3 *db);
/* Cells in the sink's basin (group 0); -1 on a database error. */
int64_t store_sink_cells(const cm_store *s);

/* ---- store.c: files ---- */
/* Opens and checks an existing file (full: every page too); old: a file of
 * version 2 or 3 may be opened for writing (to upgrade it). */
cm_status store_open_checked(const char *path, int full, int writable, int old, sqlite3 **out,
                             char *msg, size_t msg_size);
cm_status store_new(const char *path, sqlite3 *db, int writable, cm_store **out, char *msg,
                    size_t msg_size);

/* ---- store_pages.c: regions, their pages and node tables ---- */
/* Region k's row and exit table; its pages (each once). */
cm_status store_insert_region(cm_store *s, uint32_t k, const cm_region *r, char *msg,
                              size_t msg_size);
cm_status store_write_pages(cm_store *s, uint32_t k, const cm_region *r, char *msg,
                            size_t msg_size);
/* Region k's node records (replacing the saved ones). */
cm_status store_write_nodes(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                            size_t msg_size);
/* The node table's reader (cm_nodes_in_fn with the store as user). */
cm_status store_nodes_in(void *user, uint32_t k, cm_node *nodes, uint64_t n, char *msg,
                         size_t msg_size);
/* The pager (cm_page_in_fn and cm_page_out_fn with the store as user):
 * the page out saves a dirty region about to be evicted. */
cm_status store_page_in(void *user, uint32_t k, cm_region *r, char *msg, size_t msg_size);
cm_status store_groups_in(void *user, uint32_t k, uint32_t *group, char *msg, size_t msg_size);
cm_status store_page_out(void *user, const cm_cluster *c, uint32_t k, char *msg,
                         size_t msg_size);
/* Region k's row, exit table and pages, whole. */
cm_status store_write_region(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                             size_t msg_size);

/* ---- store_commit.c: commits ---- */
/* Region k's open nodes (replacing the saved ones). */
cm_status store_write_open_nodes(cm_store *s, cm_cluster *c, uint32_t k, char *msg,
                                 size_t msg_size);

/* ---- store_attractors.c ---- */
/* Removes the stored system attractors (a file of version 7 on; in the
 * open transaction): a commit that changes the cluster makes them stale,
 * and a reader then finds them afresh rather than reading another
 * cluster's (cm_store_get_attractors: CM_ENOTFOUND). */
cm_status store_forget_attractors(cm_store *s, char *msg, size_t msg_size);

/* Everything the cluster changed since it was last saved, in the open
 * transaction (cm_store_commit without BEGIN and COMMIT). */
cm_status store_write_changes(cm_store *s, cm_cluster *c, char *msg, size_t msg_size);

#endif
