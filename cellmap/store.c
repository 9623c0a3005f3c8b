#include "cellmap/store_db.h"

#include "cellmap/numtext.h"
#include "cellmap/output.h"

#include <errno.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>






static int pragma_int(sqlite3 *db, const char *sql, int *value)
{
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        *value = sqlite3_column_int(st, 0);
        rc = SQLITE_OK;
    }
    sqlite3_finalize(st);
    return rc;
}

/* The view of the groups, with the sink as group 0; `kind` is "sink",
 * "attractor" or "sticking" (a sticking zone: rest states held by static
 * friction). Version 4 counts cells per group in `basins`; versions 2 and
 * 3 per region and group in `region_groups`. */
#define GROUPS_VIEW_SQL(TEMP, KIND)                                                                \
    "CREATE " TEMP "VIEW groups(id, period, basin_cells, is_sink, centre, lo, hi, anchor,"         \
    " periodic_cells, kind) AS"                                                                    \
    " SELECT 0, 1, (SELECT IFNULL(SUM(cells), 0) FROM regions) -"                                  \
    "  (SELECT IFNULL(SUM(cells), 0) FROM basins), 1,"                                             \
    "  NULL, NULL, NULL, NULL, NULL, 'sink'"                                                       \
    " UNION ALL"                                                                                   \
    " SELECT a.id, a.period, IFNULL((SELECT cells FROM basins WHERE grp = a.id), 0), 0,"           \
    "  a.centre, a.lo, a.hi, a.anchor, a.periodic_cells, " KIND " FROM main.attractors a;"
#define GROUPS_VIEW_V3_SQL(TEMP, KIND)                                                             \
    "CREATE " TEMP "VIEW groups(id, period, basin_cells, is_sink, centre, lo, hi, anchor,"         \
    " periodic_cells, kind) AS"                                                                    \
    " SELECT 0, 1, (SELECT IFNULL(SUM(cells), 0) FROM region_groups WHERE grp = 0), 1,"            \
    "  NULL, NULL, NULL, NULL, NULL, 'sink'"                                                       \
    " UNION ALL"                                                                                   \
    " SELECT a.id, a.period,"                                                                      \
    "  (SELECT IFNULL(SUM(cells), 0) FROM region_groups WHERE grp = a.id), 0,"                     \
    "  a.centre, a.lo, a.hi, a.anchor, a.periodic_cells, " KIND " FROM main.attractors a;"

static const char *const meta_sql = "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);";
const char *const store_tables_sql =
    "CREATE TABLE regions(id INTEGER PRIMARY KEY, lo TEXT NOT NULL, hi TEXT NOT NULL,"
    " cells INTEGER NOT NULL, exits INTEGER NOT NULL, own_groups INTEGER NOT NULL,"
    " status TEXT NOT NULL);"
    "CREATE TABLE pages(region INTEGER NOT NULL REFERENCES regions(id),"
    " first_cell INTEGER NOT NULL, cells INTEGER NOT NULL,"
    " image BLOB NOT NULL, grp BLOB NOT NULL, step BLOB NOT NULL,"
    " PRIMARY KEY(region, first_cell));"
    "CREATE TABLE exits(region INTEGER PRIMARY KEY REFERENCES regions(id),"
    " count INTEGER NOT NULL, targets BLOB NOT NULL);"
    NODES_TABLE_SQL
    "CREATE TABLE basins(grp INTEGER PRIMARY KEY, cells INTEGER NOT NULL);"
    OPEN_NODES_TABLE_SQL
    "CREATE TABLE attractors(id INTEGER PRIMARY KEY, period INTEGER NOT NULL,"
    " centre TEXT NOT NULL, lo TEXT NOT NULL, hi TEXT NOT NULL, anchor TEXT NOT NULL,"
    " periodic_cells BLOB NOT NULL,"
    " kind TEXT NOT NULL DEFAULT 'attractor' CHECK(kind IN ('attractor', "
    "'sticking')));" GROUPS_VIEW_SQL("", "a.kind") SYSTEM_ATTRACTORS_SQL;

/* Version 2 had no kinds: every group of such a file is an attractor (no
 * model with rest states existed); read-only, a temporary view shadows the
 * old one. */
static const char *const shadow_v2_sql = GROUPS_VIEW_V3_SQL("TEMP ", "'attractor'");

/* Tables a file of this version (or of versions 2 to 4) must have; their
 * absence means corruption. */
#define CHECK_V4_SQL                                                                               \
    "SELECT EXISTS(SELECT 1 FROM meta), EXISTS(SELECT 1 FROM regions),"                            \
    " EXISTS(SELECT 1 FROM exits), EXISTS(SELECT 1 FROM attractors),"                              \
    " EXISTS(SELECT 1 FROM nodes), EXISTS(SELECT 1 FROM basins),"                                  \
    " EXISTS(SELECT 1 FROM pages WHERE region = 1)"
#define CHECK_V5_SQL CHECK_V4_SQL ", EXISTS(SELECT 1 FROM open_nodes)"
#define CHECK_V6_SQL                                                                               \
    CHECK_V5_SQL ", EXISTS(SELECT 1 FROM system_attractors), EXISTS(SELECT 1 FROM group_fates)"
static const char *const check_sql = CHECK_V6_SQL ", EXISTS(SELECT 1 FROM exit_fates)";
static const char *const check_v6_sql = CHECK_V6_SQL;
static const char *const check_v5_sql = CHECK_V5_SQL;
static const char *const check_v4_sql = CHECK_V4_SQL;
static const char *const check_v3_sql =
    "SELECT EXISTS(SELECT 1 FROM meta), EXISTS(SELECT 1 FROM regions),"
    " EXISTS(SELECT 1 FROM exits), EXISTS(SELECT 1 FROM attractors),"
    " EXISTS(SELECT 1 FROM region_groups), EXISTS(SELECT 1 FROM pages WHERE region = 1)";





/* The application id and version a file of this cellmap must carry. */
static cm_status check_ids(const char *path, int app, int version, char *msg, size_t msg_size)
{
    if (app != CM_STORE_APP_ID)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s is an SQLite file but not a cellmap database (application_id %d)", path,
                       app);
    if (version > CM_STORE_VERSION)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s has format version %d, newer than this cellmap reads (%d): use a "
                       "newer cellmap",
                       path, version, CM_STORE_VERSION);
    if (version < 2)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s has format version %d (single region, no exits), which cannot be "
                       "migrated to version %d: solve it again with --db",
                       path, version, CM_STORE_VERSION);
    return CM_OK;
}

/* Checks an open connection: SQLite, cellmap's application id, a version
 * this cellmap reads, the tables present (and, if full, every page sound). */
static cm_status check_file(sqlite3 *db, const char *path, int full, char *msg, size_t msg_size)
{
    int app = 0, version = 0;
    if (pragma_int(db, "PRAGMA application_id", &app) != SQLITE_OK ||
        pragma_int(db, "PRAGMA user_version", &version) != SQLITE_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       sqlite3_errcode(db) == SQLITE_CORRUPT
                           ? "%s is a damaged database (%s); restore it from a copy or solve again"
                           : "%s is not a cellmap database (%s)",
                       path, sqlite3_errmsg(db));
    const cm_status ids = check_ids(path, app, version, msg, msg_size);
    if (ids != CM_OK)
        return ids;
    sqlite3_stmt *st = NULL;
    const char *sql = version >= 7   ? check_sql
                      : version == 6 ? check_v6_sql
                      : version == 5 ? check_v5_sql
                      : version == 4 ? check_v4_sql
                                     : check_v3_sql;
    int rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st) == SQLITE_ROW ? SQLITE_OK : SQLITE_CORRUPT;
    sqlite3_finalize(st);
    char result[64] = "ok";
    if (rc == SQLITE_OK && full)
        rc = store_read_text(db, "PRAGMA quick_check(1)", result, sizeof result, msg, msg_size) == CM_OK
                 ? SQLITE_OK
                 : SQLITE_CORRUPT;
    if (rc != SQLITE_OK || strcmp(result, "ok") != 0)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is a damaged cellmap database (%s)", path,
                       rc != SQLITE_OK ? sqlite3_errmsg(db) : result);
    return CM_OK;
}

static cm_status open_db(const char *path, int flags, sqlite3 **out, char *msg, size_t msg_size)
{
    *out = NULL;
    sqlite3 *db = NULL;
    if (sqlite3_open_v2(path, &db, flags, NULL) != SQLITE_OK) {
        const cm_status st = cm_fail(CM_EIO, msg, msg_size, "cannot open %s: %s", path,
                                     db ? sqlite3_errmsg(db) : "out of memory");
        sqlite3_close(db);
        return st;
    }
    sqlite3_busy_timeout(db, 5000);
    *out = db;
    return CM_OK;
}

/* Reads the file header itself: SQLite's magic, and the application id and
 * version SQLite keeps at bytes 68 and 60 (big-endian). Nothing is opened
 * through SQLite before this passes, so a file that is not ours, or is of
 * another version, is never written, not even to recover a journal. */
static cm_status check_header(const char *path, char *msg, size_t msg_size)
{
    unsigned char h[100];
    FILE *f = fopen(path, "rb");
    if (!f)
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "%s does not exist or cannot be read (%s); give the path of a .cmdb file",
                       path, strerror(errno));
    const size_t n = fread(h, 1, sizeof h, f);
    fclose(f);
    if (n < sizeof h || memcmp(h, "SQLite format 3", 16) != 0)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s is not a cellmap database (not an SQLite 3 file)", path);
    const int32_t app =
        (int32_t)((uint32_t)h[68] << 24 | (uint32_t)h[69] << 16 | (uint32_t)h[70] << 8 | h[71]);
    const int32_t version =
        (int32_t)((uint32_t)h[60] << 24 | (uint32_t)h[61] << 16 | (uint32_t)h[62] << 8 | h[63]);
    return check_ids(path, app, version, msg, msg_size);
}

/* Opens an existing cellmap database and checks it (check_file; full: every
 * page too); on failure nothing stays open. A read-only open that finds a
 * WAL left by a killed writer opens read-write so SQLite can recover it:
 * the header has shown the file is ours. */
cm_status store_open_checked(const char *path, int full, int writable, int old, sqlite3 **out,
                             char *msg, size_t msg_size)
{
    *out = NULL;
    cm_status st = check_header(path, msg, msg_size);
    if (st != CM_OK)
        return st;
    sqlite3 *db = NULL;
    st = open_db(path, writable ? SQLITE_OPEN_READWRITE : SQLITE_OPEN_READONLY, &db, msg, msg_size);
    if (st == CM_OK)
        st = check_file(db, path, full, msg, msg_size);
    if (st != CM_OK && !writable && db && (sqlite3_errcode(db) & 0xff) == SQLITE_READONLY) {
        sqlite3_close(db);
        return store_open_checked(path, full, 1, old, out, msg, msg_size);
    }
    int version = CM_STORE_VERSION;
    if (st == CM_OK && pragma_int(db, "PRAGMA user_version", &version) != SQLITE_OK)
        st = store_db_error(db, "read the version", msg, msg_size);
    if (st == CM_OK && writable && !old && version < CM_STORE_VERSION)
        st = cm_fail(CM_EFORMAT, msg, msg_size,
                     "%s has format version %d, which this cellmap reads but extends only "
                     "after upgrading it to version %d (cm_store_upgrade; solve --resume and "
                     "explore do that)",
                     path, version, CM_STORE_VERSION);
    if (st == CM_OK && version == 2 && store_exec(db, shadow_v2_sql) != SQLITE_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "cannot read %s of format version 2: %s", path,
                     sqlite3_errmsg(db));
    if (st != CM_OK) {
        sqlite3_close(db);
        return st;
    }
    *out = db;
    return CM_OK;
}

cm_status cm_store_probe(const char *path, char *msg, size_t msg_size)
{
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "%s is a directory; give the path of a .cmdb file", path);
    return check_header(path, msg, msg_size);
}

cm_status cm_store_check(const char *path, char *msg, size_t msg_size)
{
    sqlite3 *db = NULL;
    const cm_status st = store_open_checked(path, 0, 0, 0, &db, msg, msg_size);
    sqlite3_close(db);
    return st;
}

/* Takes an exclusive flock on path (held in *fd until the store closes):
 * a second process that wants to write the file is refused at once. flock
 * and SQLite's POSIX locks do not interact. */
static cm_status lock_file(const char *path, int *fd, char *msg, size_t msg_size)
{
    *fd = open(path, O_RDONLY | O_CLOEXEC);
    if (*fd < 0)
        return cm_fail(CM_EIO, msg, msg_size, "cannot open %s: %s", path, strerror(errno));
    if (flock(*fd, LOCK_EX | LOCK_NB) == 0)
        return CM_OK;
    const int e = errno;
    close(*fd);
    *fd = -1;
    if (e == EWOULDBLOCK)
        return cm_fail(CM_EIO, msg, msg_size,
                       "%s is in use by another cellmap process (writing it); wait for it to "
                       "finish, or read the file meanwhile (info, render, export)",
                       path);
    return cm_fail(CM_EIO, msg, msg_size, "cannot lock %s: %s", path, strerror(e));
}

cm_status store_new(const char *path, sqlite3 *db, int writable, cm_store **out, char *msg,
                           size_t msg_size)
{
    cm_store *s = calloc(1, sizeof *s);
    if (s)
        s->path = strdup(path);
    if (!s || !s->path) {
        free(s);
        sqlite3_close(db);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory opening %s", path);
    }
    s->db = db;
    s->writable = writable;
    s->lock_fd = s->replaces_lock_fd = -1;
    if (writable) {
        const cm_status st = lock_file(path, &s->lock_fd, msg, msg_size);
        if (st != CM_OK) {
            sqlite3_close(db);
            free(s->path);
            free(s);
            return st;
        }
    }
    s->version = CM_STORE_VERSION;
    pragma_int(db, "PRAGMA user_version", &s->version);
    s->threads = 1;
    *out = s;
    return CM_OK;
}


static cm_status write_meta(sqlite3 *db, const cm_store_meta *meta, char *msg, size_t msg_size)
{
    char params[8192], origin[512], width[512], created[32], dim[8], page[16];
    const cm_lattice *lat = meta->lattice;
    cm_params_json(&meta->model->values, params, sizeof params);
    store_json_doubles(origin, sizeof origin, lat->origin, lat->dim);
    store_json_doubles(width, sizeof width, lat->width, lat->dim);
    snprintf(created, sizeof created, "%lld", meta->created);
    snprintf(dim, sizeof dim, "%d", lat->dim);
    snprintf(page, sizeof page, "%d", CM_STORE_PAGE_CELLS);
    const char *rows[][2] = {
        {"format", "cellmap cluster database"},
        {"tool_version", meta->tool_version ? meta->tool_version : ""},
        {"model", meta->model->name},
        {"params", params},
        {"dim", dim},
        {"lattice_origin", origin},
        {"lattice_width", width},
        {"command", meta->command ? meta->command : ""},
        {"plan", meta->plan ? meta->plan : ""},
        {"created", created},
        {"codec", "zstd-planes-1"},
        {"page_cells", page},
        {"groups", "0"},
        {"page_bytes", "0"}, /* the pages' blobs, kept by store_write_pages */
    };
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, "INSERT INTO meta(key, value) VALUES(?, ?)", -1, &st, NULL))
        return store_db_error(db, "prepare meta", msg, msg_size);
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        sqlite3_bind_text(st, 1, rows[i][0], -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, rows[i][1], -1, SQLITE_TRANSIENT);
        if (sqlite3_step(st) != SQLITE_DONE) {
            sqlite3_finalize(st);
            return store_db_error(db, "write meta", msg, msg_size);
        }
        sqlite3_reset(st);
    }
    const char *lib[][2] = {{"model_lib", meta->model_lib}, {"model_lib_hash", meta->model_lib_hash}};
    for (size_t i = 0; meta->model_lib && i < 2; i++) {
        sqlite3_bind_text(st, 1, lib[i][0], -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, lib[i][1] ? lib[i][1] : "", -1, SQLITE_TRANSIENT);
        if (sqlite3_step(st) != SQLITE_DONE) {
            sqlite3_finalize(st);
            return store_db_error(db, "write meta", msg, msg_size);
        }
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    return CM_OK;
}

/* Checks that an existing file at path is a cellmap database (which a new
 * one may replace once it is complete). */
static cm_status check_replaceable(const char *path, const char *given, char *msg,
                                   size_t msg_size)
{
    char why[512];
    if (cm_store_check(path, why, sizeof why) != CM_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "refusing to overwrite %s: %s; choose another --db file", given, why);
    return CM_OK;
}

/* With no database at path: that no WAL or rollback journal is left there
 * from one that was removed (a solve stopped, then its file deleted).
 * SQLite would read it into the new file at that name: its pages over the
 * new one's. Refused rather than removed: it may hold the last joins of
 * the database that was there. */
static cm_status check_no_leftovers(const char *path, const char *given, char *msg,
                                    size_t msg_size)
{
    const char *suffixes[] = {"-wal", "-journal"};
    for (int k = 0; k < 2; k++) {
        char side[CM_OUTPUT_PATH_MAX + 16];
        struct stat sb;
        snprintf(side, sizeof side, "%s%s", path, suffixes[k]);
        if (stat(side, &sb) == 0 && sb.st_size > 0)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s%s (%lld bytes) is left from a database %s that is gone, and "
                           "SQLite would read it into the new one: remove it (and %s-shm), or "
                           "move it away if it holds joins you want, or choose another --db file",
                           given, suffixes[k], (long long)sb.st_size, given, given);
    }
    return CM_OK;
}

/* Removes the journal, WAL and shared-memory files next to path. */
static void remove_side_files(const char *path)
{
    char side[CM_OUTPUT_PATH_MAX + 16];
    const char *suffixes[] = {"-wal", "-shm", "-journal"};
    for (int k = 0; k < 3 && path[0]; k++) {
        snprintf(side, sizeof side, "%s%s", path, suffixes[k]);
        unlink(side);
    }
}

/* Writes the schema and metadata of an empty cluster to a new file. */
static cm_status write_empty(const char *path, const cm_store_meta *meta, char *msg,
                             size_t msg_size)
{
    sqlite3 *db = NULL; /* path is cm_output's new empty (and locked) file */
    cm_status st = open_db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, &db, msg, msg_size);
    if (st != CM_OK)
        return st;
    char pragmas[128];
    snprintf(pragmas, sizeof pragmas, "PRAGMA application_id=%d; PRAGMA user_version=%d;",
             CM_STORE_APP_ID, CM_STORE_VERSION);
    if (store_exec(db, "BEGIN") != SQLITE_OK || store_exec(db, pragmas) != SQLITE_OK ||
        store_exec(db, meta_sql) != SQLITE_OK ||
        store_exec(db, store_tables_sql) != SQLITE_OK)
        st = store_db_error(db, "create schema", msg, msg_size);
    if (st == CM_OK)
        st = write_meta(db, meta, msg, msg_size);
    if (st == CM_OK && store_exec(db, "COMMIT") != SQLITE_OK)
        st = store_db_error(db, "commit", msg, msg_size);
    if (sqlite3_close(db) != SQLITE_OK && st == CM_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "closing %s failed", path);
    return st;
}

cm_status cm_store_create(const char *path, const cm_store_meta *meta, cm_store **out, char *msg,
                          size_t msg_size)
{
    *out = NULL;
    /* The new cluster is written to a temporary file. A new name gets the
     * empty cluster by a rename at once (a killed solve leaves a file to
     * resume); an existing cluster is replaced only by cm_store_finish, so
     * that until the new one is complete the old one is intact. */
    cm_output o;
    struct stat sb;
    cm_status st = cm_output_begin(&o, path, true, msg, msg_size);
    const bool replacing = st == CM_OK && stat(o.dest, &sb) == 0;
    int old_lock = -1;
    if (st == CM_OK && replacing)
        st = check_replaceable(o.dest, path, msg, msg_size);
    if (st == CM_OK && replacing)
        st = lock_file(o.dest, &old_lock, msg, msg_size);
    if (st == CM_OK && !replacing)
        st = check_no_leftovers(o.dest, path, msg, msg_size);
    if (st == CM_OK && !replacing) /* what is left holds nothing: an old -shm, empty files */
        remove_side_files(o.dest);
    if (st == CM_OK) {
        remove_side_files(o.tmp);
        st = write_empty(o.tmp, meta, msg, msg_size);
    }
    if (st == CM_OK && !replacing && rename(o.tmp, o.dest) != 0)
        st = cm_output_fail(path, errno, msg, msg_size);
    /* the store's own lock (cm_store_open) marks the file as being written
     * from here on; o's is let go, as both cannot be held */
    char tmp[CM_OUTPUT_PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s", o.tmp);
    if (st == CM_OK) {
        const int fd = cm_output_release(&o);
        if (fd >= 0)
            close(fd);
    }
    if (st == CM_OK)
        st = cm_store_open(replacing ? tmp : o.dest, 1, out, msg, msg_size);
    if (st == CM_OK && replacing) {
        (*out)->replaces_lock_fd = old_lock;
        old_lock = -1;
        (*out)->replaces = strdup(o.dest);
        (*out)->tmp_path = strdup(tmp);
        free((*out)->path);
        (*out)->path = strdup(path);
        if (!(*out)->replaces || !(*out)->tmp_path || !(*out)->path)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory creating %s", path);
    }
    if (st != CM_OK) {
        cm_store_close(*out, NULL, 0);
        *out = NULL;
        cm_output_abandon(&o); /* o's file, if o still has it */
        if (replacing && tmp[0])
            unlink(tmp);
        remove_side_files(tmp);
    }
    if (old_lock >= 0)
        close(old_lock);
    return st;
}

cm_status cm_store_open(const char *path, int writable, cm_store **out, char *msg, size_t msg_size)
{
    *out = NULL;
    sqlite3 *db = NULL;
    cm_status st = store_open_checked(path, writable, writable, 0, &db, msg, msg_size);
    if (st != CM_OK) {
        sqlite3_close(db);
        return st;
    }
    return store_new(path, db, writable, out, msg, msg_size);
}

void cm_store_map_reads(cm_store *s)
{
    /* A read copies a page into a slot of SQLite's cache, a fresh page of
       memory each (a page fault, dear on virtual machines); through a map,
       one fault maps 16 of the file's pages. Measured on `info` of a file
       of 8 M cells and 1188 groups: 7.6 -> 6.7 and 8.2 -> 7.0 ms. Without
       a map (the system refuses one), SQLite reads as before. */
    if (!s->writable)
        store_exec(s->db, "PRAGMA mmap_size=67108864");
}

cm_status cm_store_snapshot_begin(cm_store *s, char *msg, size_t msg_size)
{
    if (s->writable || s->in_transaction)
        return CM_OK; /* a writer's transactions are its commits */
    if (store_exec(s->db, "BEGIN") != SQLITE_OK)
        return store_db_error(s->db, "read", msg, msg_size);
    s->in_transaction = 1;
    return CM_OK;
}

/* Whether the file is in WAL mode: a writer is at work (or closed beside
 * readers and left it so). */
static bool in_wal_mode(sqlite3 *db)
{
    char mode[16] = "";
    return store_read_text(db, "PRAGMA journal_mode", mode, sizeof mode, NULL, 0) == CM_OK &&
           strcmp(mode, "wal") == 0;
}

void cm_store_snapshot_end(cm_store *s)
{
    if (!s || s->writable || !s->in_transaction)
        return;
    /* beside a writer, the regions and nodes read later must be those of
     * the records read: the snapshot lasts until the store closes (a WAL
     * reader holds no writer off) */
    if (in_wal_mode(s->db))
        return;
    store_exec(s->db, "COMMIT"); /* nothing was written: it cannot fail to apply */
    s->in_transaction = 0;
}

/* Leaves WAL mode (one self-contained file again) and closes; frees s
 * but for its paths. */
static cm_status close_db(cm_store *s, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (s->in_transaction)
        store_exec(s->db, "ROLLBACK"); /* a join that did not finish */
    /* Back to one self-contained file for users and their sqlite3 shell.
     * Readers at it hold the switch off (SQLite does not wait for it): it
     * is tried again for up to 10 s; readers that stay longer leave the
     * file in WAL mode, which is no failure, once every commit is copied
     * into the file itself (a full checkpoint waits for the readers of
     * older snapshots): the .cmdb alone holds the whole cluster */
    bool switched = !s->wal;
    for (int tries = 0; !switched && st == CM_OK && tries < 200; tries++) {
        switched = store_exec(s->db, "PRAGMA journal_mode=DELETE") == SQLITE_OK;
        const int code = sqlite3_errcode(s->db) & 0xff;
        if (!switched && code != SQLITE_BUSY && code != SQLITE_LOCKED)
            st = store_db_error(s->db, "leave WAL mode", msg, msg_size);
        else if (!switched)
            nanosleep(&(struct timespec){0, 50000000}, NULL);
    }
    if (!switched && st == CM_OK &&
        sqlite3_wal_checkpoint_v2(s->db, NULL, SQLITE_CHECKPOINT_FULL, NULL, NULL) != SQLITE_OK)
        st = store_db_error(s->db, "copy the log into the file beside its readers", msg,
                            msg_size);
    if (sqlite3_close(s->db) != SQLITE_OK && st == CM_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "closing %s failed", s->path);
    if (s->lock_fd >= 0)
        close(s->lock_fd); /* after SQLite's: its locks live while the file is open */
    free(s->blobs);
    store_free_encoders(s);
    return st;
}

static void free_store(cm_store *s)
{
    if (s->replaces_lock_fd >= 0)
        close(s->replaces_lock_fd);
    free(s->path);
    free(s->replaces);
    free(s->tmp_path);
    free(s);
}

cm_status cm_store_close(cm_store *s, char *msg, size_t msg_size)
{
    if (!s)
        return CM_OK;
    const cm_status st = close_db(s, msg, msg_size);
    if (s->tmp_path) { /* an unfinished replacement: the old file stays */
        unlink(s->tmp_path);
        remove_side_files(s->tmp_path);
    }
    free_store(s);
    return st;
}

bool cm_store_replacing(const cm_store *s) { return s && s->tmp_path; }

cm_status cm_store_finish(cm_store *s, char *msg, size_t msg_size)
{
    if (!s)
        return CM_OK;
    if (!s->tmp_path)
        return cm_store_close(s, msg, msg_size);
    cm_status st = s->failed ? cm_fail(CM_EIO, msg, msg_size,
                                       "a write to the new %s failed; the old file is unchanged",
                                       s->path)
                             : CM_OK;
    const cm_status closed = close_db(s, msg, msg_size);
    if (st == CM_OK)
        st = closed;
    if (st == CM_OK) {
        /* the old file's WAL must not be applied to the new one */
        remove_side_files(s->replaces);
        if (rename(s->tmp_path, s->replaces) != 0)
            st = cm_fail(CM_EIO, msg, msg_size, "cannot rename %s to %s: %s", s->tmp_path,
                         s->replaces, strerror(errno));
    }
    if (st != CM_OK) {
        unlink(s->tmp_path);
        remove_side_files(s->tmp_path);
    }
    free_store(s);
    return st;
}

void cm_store_get_stats(const cm_store *s, cm_store_stats *stats) { *stats = s->stats; }

/* ---- reading ---------------------------------------------------------- */










static cm_status shortest_params(char *params, size_t size, char *msg, size_t msg_size)
{
    char out[sizeof ((cm_store_info *)0)->params];
    if (size > sizeof out || !cm_json_numbers_shortest(params, out, size))
        return cm_fail(CM_EFORMAT, msg, msg_size, "its parameters '%.200s' are too long", params);
    memcpy(params, out, strlen(out) + 1);
    return CM_OK;
}

cm_status cm_store_read_info(cm_store *s, cm_store_info *info, char *msg, size_t msg_size)
{
    memset(info, 0, sizeof *info);
    info->version = s->version;
    sqlite3 *db = s->db;
    cm_status st = store_meta_text(db, "model", info->model, sizeof info->model, msg, msg_size);
    if (st == CM_OK)
        st = store_meta_text(db, "params", info->params, sizeof info->params, msg, msg_size);
    if (st == CM_OK) /* older files hold 17 digits; read them as printed now */
        st = shortest_params(info->params, sizeof info->params, msg, msg_size);
    if (st == CM_OK)
        st = store_meta_text(db, "command", info->command, sizeof info->command, msg, msg_size);
    if (st == CM_OK)
        st = store_meta_text(db, "plan", info->plan, sizeof info->plan, msg, msg_size);
    if (st == CM_OK)
        st = store_meta_text(db, "tool_version", info->tool_version, sizeof info->tool_version, msg,
                       msg_size);
    if (st == CM_OK) { /* only files of plugin models have these */
        store_read_text(db, "SELECT value FROM meta WHERE key='model_lib'", info->model_lib,
                  sizeof info->model_lib, NULL, 0);
        store_read_text(db, "SELECT value FROM meta WHERE key='model_lib_hash'", info->model_lib_hash,
                  sizeof info->model_lib_hash, NULL, 0);
    }
    if (st == CM_OK)
        st = store_read_lattice(db, &info->lattice, msg, msg_size);
    if (st == CM_OK)
        st = store_check_groups(s, msg, msg_size);
    if (st != CM_OK)
        return store_damaged(s, st, msg, msg_size);
    const int64_t regions = store_query_int(db, "SELECT COUNT(*) FROM regions");
    const int64_t cells = store_query_int(db, "SELECT IFNULL(SUM(cells), 0) FROM regions");
    const int64_t groups = store_query_int(db, "SELECT COUNT(*) FROM attractors");
    const int64_t pages = store_page_bytes(db);
    if (regions < 0 || cells < 0 || groups < 0 || pages < 0 || groups > CM_MAX_GROUPS)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is a damaged cellmap database (%s)", s->path,
                       sqlite3_errmsg(db));
    info->regions = (uint32_t)regions;
    info->cells = (uint64_t)cells;
    info->groups = (uint32_t)groups;
    info->page_bytes = (uint64_t)pages;
    char side[4200];
    struct stat sb;
    if (stat(s->path, &sb) == 0)
        info->file_bytes = (uint64_t)sb.st_size;
    snprintf(side, sizeof side, "%s-wal", s->path);
    if (stat(side, &sb) == 0)
        info->file_bytes += (uint64_t)sb.st_size;
    return CM_OK;
}

static cm_status check_note_key(const char *key, char *msg, size_t msg_size)
{
    if (strncmp(key, "note.", 5) != 0 || strlen(key) > 64)
        return cm_fail(CM_EINVAL, msg, msg_size, "note keys begin with \"note.\" (got '%s')", key);
    return CM_OK;
}

cm_status cm_store_set_note(cm_store *s, const char *key, const char *value, char *msg,
                            size_t msg_size)
{
    cm_status st = check_note_key(key, msg, msg_size);
    const int own = st == CM_OK && !s->in_transaction;
    if (st == CM_OK)
        st = store_begin(s, msg, msg_size);
    sqlite3_stmt *ins = NULL;
    if (st == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO meta(key, value) VALUES(?, ?)", -1, &ins,
                           NULL) != SQLITE_OK)
        st = store_db_error(s->db, "prepare note", msg, msg_size);
    if (st == CM_OK) {
        sqlite3_bind_text(ins, 1, key, -1, SQLITE_STATIC);
        sqlite3_bind_text(ins, 2, value, -1, SQLITE_STATIC);
        if (sqlite3_step(ins) != SQLITE_DONE)
            st = store_db_error(s->db, "write note", msg, msg_size);
    }
    sqlite3_finalize(ins);
    if (st == CM_OK && own && store_exec(s->db, "COMMIT") != SQLITE_OK)
        st = store_db_error(s->db, "commit note", msg, msg_size);
    if (st == CM_OK && own)
        s->in_transaction = 0;
    return st == CM_OK || st == CM_EINVAL ? st : store_abandon(s, st);
}

cm_status cm_store_get_note(cm_store *s, const char *key, char *out, size_t size, char *msg,
                            size_t msg_size)
{
    cm_status st = check_note_key(key, msg, msg_size);
    sqlite3_stmt *q = NULL;
    if (st != CM_OK)
        return st;
    if (sqlite3_prepare_v2(s->db, "SELECT value FROM meta WHERE key = ?", -1, &q, NULL) !=
        SQLITE_OK)
        return store_db_error(s->db, "prepare note", msg, msg_size);
    sqlite3_bind_text(q, 1, key, -1, SQLITE_STATIC);
    if (sqlite3_step(q) == SQLITE_ROW && sqlite3_column_text(q, 0))
        snprintf(out, size, "%s", (const char *)sqlite3_column_text(q, 0));
    else
        st = cm_fail(CM_ENOTFOUND, msg, msg_size, "%s has no %s", s->path, key);
    sqlite3_finalize(q);
    return st;
}

void cm_store_set_model(cm_store *s, const cm_model *model) { s->model = model; }
