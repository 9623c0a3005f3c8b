#include "cellmap/store.h"

#include "cellmap/classify.h"
#include "cellmap/codec.h"
#include "cellmap/grow.h"

#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Appends text to a fixed buffer, never overflowing. */
static void append(char *buf, size_t size, size_t *used, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void append(char *buf, size_t size, size_t *used, const char *fmt, ...)
{
    if (*used >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(buf + *used, size - *used, fmt, ap);
    va_end(ap);
    if (n > 0)
        *used += (size_t)n;
}

static void json_doubles(char *buf, size_t size, const double *v, int n)
{
    size_t used = 0;
    append(buf, size, &used, "[");
    for (int i = 0; i < n; i++)
        append(buf, size, &used, "%s%.17g", i ? "," : "", v[i]);
    append(buf, size, &used, "]");
}

static void json_ints(char *buf, size_t size, const int64_t *v, int n)
{
    size_t used = 0;
    append(buf, size, &used, "[");
    for (int i = 0; i < n; i++)
        append(buf, size, &used, "%s%lld", i ? "," : "", (long long)v[i]);
    append(buf, size, &used, "]");
}

void cm_params_json(const cm_params *p, char *buf, size_t size)
{
    size_t used = 0;
    append(buf, size, &used, "{");
    for (int i = 0; i < p->count; i++) {
        const cm_param_spec *s = &p->spec[i];
        const cm_param_value *v = &p->value[i];
        append(buf, size, &used, "%s\"%s\":", i ? "," : "", s->name);
        if (s->choices) {
            /* the k-th word of the choice list */
            const char *w = s->choices;
            for (int k = 0; k < (int)v->v[0] && w; k++)
                w = strchr(w, '|') ? strchr(w, '|') + 1 : NULL;
            const char *end = w ? strchr(w, '|') : NULL;
            append(buf, size, &used, "\"%.*s\"", w ? (int)(end ? (size_t)(end - w) : strlen(w)) : 0,
                   w ? w : "");
        } else if (s->max_count == 1) {
            append(buf, size, &used, "%.17g", v->v[0]);
        } else {
            char tmp[2048];
            json_doubles(tmp, sizeof tmp, v->v, v->count);
            append(buf, size, &used, "%s", tmp);
        }
    }
    append(buf, size, &used, "}");
}

static cm_status db_error(sqlite3 *db, const char *what, char *msg, size_t msg_size)
{
    return cm_fail(CM_EDB, msg, msg_size, "%s: %s", what, db ? sqlite3_errmsg(db) : "no database");
}

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

static const char *const schema_sql =
    "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);"
    "CREATE TABLE regions(id INTEGER PRIMARY KEY, lo TEXT NOT NULL, hi TEXT NOT NULL,"
    " cells INTEGER NOT NULL, exits INTEGER NOT NULL, own_groups INTEGER NOT NULL,"
    " status TEXT NOT NULL);"
    "CREATE TABLE pages(region INTEGER NOT NULL REFERENCES regions(id),"
    " first_cell INTEGER NOT NULL, cells INTEGER NOT NULL,"
    " image BLOB NOT NULL, grp BLOB NOT NULL, step BLOB NOT NULL,"
    " PRIMARY KEY(region, first_cell));"
    "CREATE TABLE exits(region INTEGER PRIMARY KEY REFERENCES regions(id),"
    " count INTEGER NOT NULL, targets BLOB NOT NULL);"
    "CREATE TABLE nodes(region INTEGER PRIMARY KEY REFERENCES regions(id),"
    " count INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE TABLE basins(grp INTEGER PRIMARY KEY, cells INTEGER NOT NULL);"
    "CREATE TABLE attractors(id INTEGER PRIMARY KEY, period INTEGER NOT NULL,"
    " centre TEXT NOT NULL, lo TEXT NOT NULL, hi TEXT NOT NULL, anchor TEXT NOT NULL,"
    " periodic_cells BLOB NOT NULL,"
    " kind TEXT NOT NULL DEFAULT 'attractor' CHECK(kind IN ('attractor', "
    "'sticking')));" GROUPS_VIEW_SQL("", "a.kind");

/* Version 2 had no kinds: every group of such a file is an attractor (no
 * model with rest states existed); read-only, a temporary view shadows the
 * old one. */
static const char *const shadow_v2_sql = GROUPS_VIEW_V3_SQL("TEMP ", "'attractor'");

/* Tables a file of this version (or of version 2 or 3) must have; their
 * absence means corruption. */
static const char *const check_sql =
    "SELECT (SELECT COUNT(*) FROM meta), (SELECT COUNT(*) FROM regions),"
    " (SELECT COUNT(*) FROM exits), (SELECT COUNT(*) FROM attractors),"
    " (SELECT COUNT(*) FROM nodes), (SELECT COUNT(*) FROM basins),"
    " (SELECT COUNT(*) FROM pages WHERE region = 1)";
static const char *const check_v3_sql =
    "SELECT (SELECT COUNT(*) FROM meta), (SELECT COUNT(*) FROM regions),"
    " (SELECT COUNT(*) FROM exits), (SELECT COUNT(*) FROM attractors),"
    " (SELECT COUNT(*) FROM region_groups), (SELECT COUNT(*) FROM pages WHERE region = 1)";

struct cm_store {
    sqlite3 *db;
    const cm_model *model; /* labels new groups (cm_store_set_model), may be NULL */
    char *path;
    int writable;
    int version; /* of the file: 2 and 3 are read (regions resolved, no node table) */
    int in_transaction;             /* evictions in a join write into it; the commit ends it */
    int failed;                     /* a write failed: the cluster and the file differ */
    unsigned char *blobs; /* a region's encoded pages, read or to write */
    uint64_t blobs_cap;
    int threads;     /* for encoding and decoding pages: the cluster's */
    cm_store_stats stats;
};

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int exec(sqlite3 *db, const char *sql) { return sqlite3_exec(db, sql, NULL, NULL, NULL); }

static cm_status read_text(sqlite3 *db, const char *sql, char *out, size_t size, char *msg,
                           size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    cm_status status = CM_EFORMAT;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW &&
        sqlite3_column_text(st, 0)) {
        snprintf(out, size, "%s", (const char *)sqlite3_column_text(st, 0));
        status = CM_OK;
    }
    sqlite3_finalize(st);
    return status == CM_OK ? CM_OK
                           : cm_fail(CM_EFORMAT, msg, msg_size, "corrupt database: %s failed", sql);
}

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
    int rc = sqlite3_prepare_v2(db, version >= 4 ? check_sql : check_v3_sql, -1, &st, NULL);
    if (rc == SQLITE_OK)
        rc = sqlite3_step(st) == SQLITE_ROW ? SQLITE_OK : SQLITE_CORRUPT;
    sqlite3_finalize(st);
    char result[64] = "ok";
    if (rc == SQLITE_OK && full)
        rc = read_text(db, "PRAGMA quick_check(1)", result, sizeof result, msg, msg_size) == CM_OK
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
        return cm_fail(CM_EIO, msg, msg_size, "%s does not exist or cannot be read", path);
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
static cm_status open_checked(const char *path, int full, int writable, sqlite3 **out, char *msg,
                              size_t msg_size)
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
        return open_checked(path, full, 1, out, msg, msg_size);
    }
    int version = CM_STORE_VERSION;
    if (st == CM_OK && pragma_int(db, "PRAGMA user_version", &version) != SQLITE_OK)
        st = db_error(db, "read the version", msg, msg_size);
    if (st == CM_OK && writable && version < CM_STORE_VERSION)
        st = cm_fail(CM_EFORMAT, msg, msg_size,
                     "%s has format version %d, which this cellmap reads but cannot extend "
                     "(version %d keeps regions unchanged and joins them through node tables): "
                     "render and export it as it is, or solve again with --db",
                     path, version, CM_STORE_VERSION);
    if (st == CM_OK && version == 2 && exec(db, shadow_v2_sql) != SQLITE_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "cannot read %s of format version 2: %s", path,
                     sqlite3_errmsg(db));
    if (st != CM_OK) {
        sqlite3_close(db);
        return st;
    }
    *out = db;
    return CM_OK;
}

cm_status cm_store_check(const char *path, char *msg, size_t msg_size)
{
    sqlite3 *db = NULL;
    const cm_status st = open_checked(path, 0, 0, &db, msg, msg_size);
    sqlite3_close(db);
    return st;
}

static cm_status new_store(const char *path, sqlite3 *db, int writable, cm_store **out, char *msg,
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
    s->version = CM_STORE_VERSION;
    pragma_int(db, "PRAGMA user_version", &s->version);
    s->threads = 1;
    *out = s;
    return CM_OK;
}

static cm_status use_wal(sqlite3 *db, const char *path, char *msg, size_t msg_size)
{
    /* NORMAL: in WAL mode a commit survives the process being killed; only
     * an operating-system crash may lose the last commits, never consistency. */
    char mode[16] = "";
    if (read_text(db, "PRAGMA journal_mode=WAL", mode, sizeof mode, msg, msg_size) != CM_OK ||
        strcmp(mode, "wal") != 0 || exec(db, "PRAGMA synchronous=NORMAL") != SQLITE_OK)
        return cm_fail(CM_EDB, msg, msg_size, "cannot put %s in WAL mode: %s", path,
                       sqlite3_errmsg(db));
    return CM_OK;
}

static cm_status write_meta(sqlite3 *db, const cm_store_meta *meta, char *msg, size_t msg_size)
{
    char params[8192], origin[512], width[512], created[32], dim[8], page[16];
    const cm_lattice *lat = meta->lattice;
    cm_params_json(&meta->model->values, params, sizeof params);
    json_doubles(origin, sizeof origin, lat->origin, lat->dim);
    json_doubles(width, sizeof width, lat->width, lat->dim);
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
    };
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, "INSERT INTO meta(key, value) VALUES(?, ?)", -1, &st, NULL))
        return db_error(db, "prepare meta", msg, msg_size);
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        sqlite3_bind_text(st, 1, rows[i][0], -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, rows[i][1], -1, SQLITE_TRANSIENT);
        if (sqlite3_step(st) != SQLITE_DONE) {
            sqlite3_finalize(st);
            return db_error(db, "write meta", msg, msg_size);
        }
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    return CM_OK;
}

/* Checks that an existing file at path is a cellmap database (which a new
 * one may replace) and removes its WAL and shared-memory files. */
static cm_status prepare_replace(const char *path, char *msg, size_t msg_size)
{
    struct stat sb;
    if (stat(path, &sb) != 0)
        return CM_OK;
    char why[512];
    if (cm_store_check(path, why, sizeof why) != CM_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "refusing to overwrite %s: %s; choose another --db file", path, why);
    char side[4200];
    const char *suffixes[] = {"-wal", "-shm", "-journal"};
    for (int k = 0; k < 3; k++) {
        snprintf(side, sizeof side, "%s%s", path, suffixes[k]);
        unlink(side);
    }
    return CM_OK;
}

/* Writes the schema and metadata of an empty cluster to a new file. */
static cm_status write_empty(const char *path, const cm_store_meta *meta, char *msg,
                             size_t msg_size)
{
    sqlite3 *db = NULL;
    unlink(path);
    cm_status st = open_db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, &db, msg, msg_size);
    if (st != CM_OK)
        return st;
    char pragmas[128];
    snprintf(pragmas, sizeof pragmas, "PRAGMA application_id=%d; PRAGMA user_version=%d;",
             CM_STORE_APP_ID, CM_STORE_VERSION);
    if (exec(db, "BEGIN") != SQLITE_OK || exec(db, pragmas) != SQLITE_OK ||
        exec(db, schema_sql) != SQLITE_OK)
        st = db_error(db, "create schema", msg, msg_size);
    if (st == CM_OK)
        st = write_meta(db, meta, msg, msg_size);
    if (st == CM_OK && exec(db, "COMMIT") != SQLITE_OK)
        st = db_error(db, "commit", msg, msg_size);
    if (sqlite3_close(db) != SQLITE_OK && st == CM_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "closing %s failed", path);
    return st;
}

cm_status cm_store_create(const char *path, const cm_store_meta *meta, cm_store **out, char *msg,
                          size_t msg_size)
{
    *out = NULL;
    /* The empty database appears at path by a rename, so a process killed
     * now leaves either the old file or a complete empty cluster. */
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    cm_status st = prepare_replace(path, msg, msg_size);
    if (st == CM_OK)
        st = write_empty(tmp, meta, msg, msg_size);
    if (st == CM_OK && rename(tmp, path) != 0)
        st = cm_fail(CM_EIO, msg, msg_size, "cannot rename %s to %s", tmp, path);
    if (st != CM_OK) {
        unlink(tmp);
        return st;
    }
    return cm_store_open(path, 1, out, msg, msg_size);
}

cm_status cm_store_open(const char *path, int writable, cm_store **out, char *msg, size_t msg_size)
{
    *out = NULL;
    sqlite3 *db = NULL;
    cm_status st = open_checked(path, writable, writable, &db, msg, msg_size);
    if (st == CM_OK && writable)
        st = use_wal(db, path, msg, msg_size);
    if (st != CM_OK) {
        sqlite3_close(db);
        return st;
    }
    return new_store(path, db, writable, out, msg, msg_size);
}

cm_status cm_store_close(cm_store *s, char *msg, size_t msg_size)
{
    if (!s)
        return CM_OK;
    cm_status st = CM_OK;
    if (s->in_transaction)
        exec(s->db, "ROLLBACK"); /* a join that did not finish */
    /* Back to one self-contained file for users and their sqlite3 shell. */
    if (s->writable && exec(s->db, "PRAGMA journal_mode=DELETE") != SQLITE_OK)
        st = db_error(s->db, "leave WAL mode", msg, msg_size);
    if (sqlite3_close(s->db) != SQLITE_OK && st == CM_OK)
        st = cm_fail(CM_EDB, msg, msg_size, "closing %s failed", s->path);
    free(s->path);
    free(s->blobs);
    free(s);
    return st;
}

void cm_store_get_stats(const cm_store *s, cm_store_stats *stats) { *stats = s->stats; }

/* ---- reading ---------------------------------------------------------- */

/* Parses a JSON array of numbers written by this module. */
static int parse_json_numbers(const char *text, double *out, int cap)
{
    int n = 0;
    const char *p = text ? strchr(text, '[') : NULL;
    if (!p)
        return -1;
    p++;
    while (*p && *p != ']' && n < cap) {
        char *end = NULL;
        out[n++] = strtod(p, &end);
        if (end == p)
            return -1;
        p = end;
        while (*p == ',' || *p == ' ')
            p++;
    }
    return *p == ']' ? n : -1;
}

static cm_status meta_text(sqlite3 *db, const char *key, char *out, size_t size, char *msg,
                           size_t msg_size)
{
    char sql[128];
    snprintf(sql, sizeof sql, "SELECT value FROM meta WHERE key='%s'", key);
    return read_text(db, sql, out, size, msg, msg_size);
}

static cm_status read_lattice(sqlite3 *db, cm_lattice *lat, char *msg, size_t msg_size)
{
    char text[1024];
    memset(lat, 0, sizeof *lat);
    cm_status st = meta_text(db, "lattice_origin", text, sizeof text, msg, msg_size);
    if (st != CM_OK)
        return st;
    lat->dim = parse_json_numbers(text, lat->origin, CM_MAX_DIM);
    if ((st = meta_text(db, "lattice_width", text, sizeof text, msg, msg_size)) != CM_OK)
        return st;
    if (lat->dim < 1 || parse_json_numbers(text, lat->width, CM_MAX_DIM) != lat->dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "corrupt lattice metadata");
    return cm_lattice_check(lat, msg, msg_size);
}

static int64_t query_int(sqlite3 *db, const char *sql)
{
    sqlite3_stmt *st = NULL;
    int64_t v = -1;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return v;
}

cm_status cm_store_read_info(cm_store *s, cm_store_info *info, char *msg, size_t msg_size)
{
    memset(info, 0, sizeof *info);
    sqlite3 *db = s->db;
    cm_status st = meta_text(db, "model", info->model, sizeof info->model, msg, msg_size);
    if (st == CM_OK)
        st = meta_text(db, "params", info->params, sizeof info->params, msg, msg_size);
    if (st == CM_OK)
        st = meta_text(db, "command", info->command, sizeof info->command, msg, msg_size);
    if (st == CM_OK)
        st = meta_text(db, "plan", info->plan, sizeof info->plan, msg, msg_size);
    if (st == CM_OK)
        st = meta_text(db, "tool_version", info->tool_version, sizeof info->tool_version, msg,
                       msg_size);
    if (st == CM_OK)
        st = read_lattice(db, &info->lattice, msg, msg_size);
    if (st != CM_OK)
        return st;
    const int64_t regions = query_int(db, "SELECT COUNT(*) FROM regions");
    const int64_t cells = query_int(db, "SELECT IFNULL(SUM(cells), 0) FROM regions");
    const int64_t groups = query_int(db, "SELECT COUNT(*) FROM attractors");
    const int64_t pages = query_int(db, "SELECT IFNULL(SUM(LENGTH(image) + LENGTH(grp) + "
                                        "LENGTH(step)), 0) FROM pages");
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

static uint64_t npages(uint64_t ncells)
{
    return (ncells + CM_STORE_PAGE_CELLS - 1) / CM_STORE_PAGE_CELLS;
}

static uint64_t page_cells(uint64_t ncells, uint64_t page)
{
    const uint64_t first = page * CM_STORE_PAGE_CELLS;
    return ncells - first < CM_STORE_PAGE_CELLS ? ncells - first : CM_STORE_PAGE_CELLS;
}

/* A page's column as read: where its BLOB lies in s->blobs, where it goes. */
typedef struct column_ref {
    uint64_t offset, len, n, first;
    int col;
} column_ref;

/* Decodes the columns read, in parallel: a region is 3 x 16 of them. */
static cm_status decode_columns(const cm_store *s, cm_region *r, const column_ref *refs,
                                uint64_t nrefs)
{
    int failed = 0;
#pragma omp parallel num_threads(s->threads) if (nrefs > 1)
    {
        unsigned char *scratch = malloc(4 * (size_t)CM_STORE_PAGE_CELLS);
        failed |= !scratch;
#pragma omp for schedule(dynamic, 1) reduction(| : failed)
        for (int64_t t = 0; t < (int64_t)nrefs; t++) {
            const column_ref *c = &refs[t];
            uint32_t *const arrays[3] = {r->image, r->group, r->step};
            failed |= !scratch || cm_codec_decode(s->blobs + c->offset, c->len, c->n, 4,
                                                  c->col == 0 ? (int64_t)c->first : -1, scratch,
                                                  arrays[c->col] + c->first) != CM_OK;
        }
        free(scratch);
    }
    return failed ? CM_EFORMAT : CM_OK;
}

/* Copies column col's BLOB of the current row to s->blobs. */
static cm_status keep_column(cm_store *s, sqlite3_stmt *st, int col, uint64_t first, uint64_t n,
                             uint64_t *used, column_ref *ref)
{
    const void *blob = sqlite3_column_blob(st, 2 + col);
    const uint64_t len = (uint64_t)sqlite3_column_bytes(st, 2 + col);
    if (!blob || cm_grow((void **)&s->blobs, &s->blobs_cap, *used + len, sizeof *s->blobs) != CM_OK)
        return blob ? CM_ENOMEM : CM_EFORMAT;
    memcpy(s->blobs + *used, blob, len);
    *ref = (column_ref){*used, len, n, first, col};
    *used += len;
    s->stats.bytes_read += len;
    return CM_OK;
}

static cm_status read_pages(cm_store *s, uint32_t k, cm_region *r, char *msg, size_t msg_size)
{
    const uint64_t pages = npages(r->ncells);
    column_ref *refs = malloc((3 * pages + 1) * sizeof *refs);
    sqlite3_stmt *st = NULL;
    if (!refs)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading region %u", k + 1);
    if (sqlite3_prepare_v2(s->db,
                           "SELECT first_cell, cells, image, grp, step FROM pages WHERE region=? "
                           "ORDER BY first_cell",
                           -1, &st, NULL)) {
        free(refs);
        return db_error(s->db, "read pages", msg, msg_size);
    }
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    cm_status status = CM_OK;
    uint64_t seen = 0, nrefs = 0, used = 0;
    int rc;
    while (status == CM_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        const uint64_t first = (uint64_t)sqlite3_column_int64(st, 0);
        const uint64_t n = (uint64_t)sqlite3_column_int64(st, 1);
        if (first != seen || n == 0 || n > CM_STORE_PAGE_CELLS || first + n > r->ncells ||
            nrefs == 3 * pages) {
            status = CM_EFORMAT;
            break;
        }
        for (int col = 0; col < 3 && status == CM_OK; col++)
            status = keep_column(s, st, col, first, n, &used, &refs[nrefs++]);
        seen += n;
    }
    if (status == CM_OK && rc != SQLITE_DONE) {
        status = db_error(s->db, "read pages", msg, msg_size);
        sqlite3_finalize(st);
        free(refs);
        return status;
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != r->ncells)
        status = CM_EFORMAT;
    if (status == CM_OK)
        status = decode_columns(s, r, refs, nrefs);
    free(refs);
    if (status == CM_EFORMAT)
        return cm_fail(status, msg, msg_size,
                       "%s is damaged: the pages of region %u are incomplete or do not decode",
                       s->path, k + 1);
    return status == CM_OK
               ? CM_OK
               : cm_fail(status, msg, msg_size, "out of memory reading region %u", k + 1);
}

/* Region k's exit targets into a new array of nexits * dim cells. */
static cm_status read_exits(cm_store *s, uint32_t k, uint64_t nexits, int dim, int64_t **out,
                            char *msg, size_t msg_size)
{
    const uint64_t n = nexits * (uint64_t)dim;
    int64_t *targets = malloc((n + 1) * sizeof *targets);
    unsigned char *scratch = malloc(8 * (n + 1));
    sqlite3_stmt *st = NULL;
    cm_status status = CM_OK;
    if (!targets || !scratch)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                         (unsigned long long)nexits);
    else if (sqlite3_prepare_v2(s->db, "SELECT count, targets FROM exits WHERE region=?", -1, &st,
                                NULL))
        status = db_error(s->db, "read exits", msg, msg_size);
    if (status == CM_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
        const void *blob = NULL;
        int len = 0;
        if (sqlite3_step(st) == SQLITE_ROW && (uint64_t)sqlite3_column_int64(st, 0) == nexits) {
            blob = sqlite3_column_blob(st, 1);
            len = sqlite3_column_bytes(st, 1);
        }
        if (!blob || cm_codec_decode(blob, (size_t)len, n, 8, -1, scratch, targets) != CM_OK)
            status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: exits of region %u",
                             s->path, k + 1);
        s->stats.bytes_read += (uint64_t)len;
    }
    sqlite3_finalize(st);
    free(scratch);
    if (status != CM_OK) {
        free(targets);
        return status;
    }
    *out = targets;
    return CM_OK;
}

/* The pager: reads region k's arrays and exit table back. */
static cm_status page_in(void *user, uint32_t k, cm_region *r, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = seconds_now();
    const size_t bytes = (size_t)r->ncells * sizeof(uint32_t);
    r->image = malloc(bytes + 4);
    r->group = malloc(bytes + 4);
    r->step = malloc(bytes + 4);
    cm_status st = r->image && r->group && r->step
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading region %u", k);
    if (st == CM_OK)
        st = read_pages(s, k, r, msg, msg_size);
    if (st == CM_OK)
        st = read_exits(s, k, r->nexits, r->box.dim, &r->exit_target, msg, msg_size);
    if (st != CM_OK) {
        free(r->image);
        free(r->group);
        free(r->step);
        r->image = r->group = r->step = NULL;
    }
    s->stats.regions_read++;
    s->stats.read_seconds += seconds_now() - t0;
    return st;
}

static cm_status page_out(void *user, const cm_cluster *c, uint32_t k, char *msg, size_t msg_size);

void cm_store_attach(cm_store *s, cm_cluster *c)
{
    s->threads = cm_cluster_threads(c);
    c->page_in = page_in;
    c->page_out = s->writable ? page_out : NULL;
    c->pager = s;
}

static cm_status parse_box(const char *lo, const char *hi, int dim, cm_box *box)
{
    double l[CM_MAX_DIM], h[CM_MAX_DIM];
    if (!lo || !hi || parse_json_numbers(lo, l, CM_MAX_DIM) != dim ||
        parse_json_numbers(hi, h, CM_MAX_DIM) != dim)
        return CM_EFORMAT;
    box->dim = dim;
    for (int d = 0; d < dim; d++) {
        box->lo[d] = (int64_t)l[d];
        box->hi[d] = (int64_t)h[d];
        if (box->hi[d] <= box->lo[d])
            return CM_EFORMAT;
    }
    return CM_OK;
}

/* Node records as saved: five little-endian uint32 columns of n entries
 * (next, dist, group, target, tree), encoded as one BLOB. */
#define NODE_FIELDS 5

static cm_status read_nodes(cm_store *s, uint32_t k, uint64_t n, cm_node **out, char *msg,
                            size_t msg_size)
{
    cm_node *nodes = calloc(n + 1, sizeof *nodes);
    uint32_t *cols = malloc((NODE_FIELDS * n + 1) * sizeof *cols);
    unsigned char *scratch = malloc(4 * (NODE_FIELDS * n + 1));
    sqlite3_stmt *st = NULL;
    cm_status status = nodes && cols && scratch
                           ? CM_OK
                           : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu nodes",
                                     (unsigned long long)n);
    if (status == CM_OK && s->version < 4) {
        /* regions of version 2 and 3 hold resolved cells: no node is referenced */
        for (uint64_t e = 0; e < n; e++)
            nodes[e] = (cm_node){.next = CM_NODE_FINAL, .dist = 1};
    } else if (status == CM_OK) {
        if (sqlite3_prepare_v2(s->db, "SELECT count, data FROM nodes WHERE region=?", -1, &st,
                               NULL))
            status = db_error(s->db, "read nodes", msg, msg_size);
        const void *blob = NULL;
        int len = 0;
        if (status == CM_OK) {
            sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
            if (sqlite3_step(st) == SQLITE_ROW && (uint64_t)sqlite3_column_int64(st, 0) == n) {
                blob = sqlite3_column_blob(st, 1);
                len = sqlite3_column_bytes(st, 1);
            }
            if ((n > 0 && !blob) || (blob && cm_codec_decode(blob, (size_t)len, NODE_FIELDS * n,
                                                             4, -1, scratch, cols) != CM_OK))
                status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: nodes of region %u",
                                 s->path, k + 1);
            s->stats.bytes_read += (uint64_t)len;
        }
        for (uint64_t e = 0; status == CM_OK && e < n; e++)
            nodes[e] = (cm_node){.next = cols[e],
                                 .dist = cols[n + e],
                                 .group = cols[2 * n + e],
                                 .target = cols[3 * n + e],
                                 .tree = cols[4 * n + e]};
    }
    sqlite3_finalize(st);
    free(cols);
    free(scratch);
    if (status != CM_OK) {
        free(nodes);
        return status;
    }
    *out = nodes;
    return CM_OK;
}

/* Cells per group 1..groups from the groups view (every version has it). */
static cm_status read_basins(cm_store *s, uint32_t groups, uint64_t **out, char *msg,
                             size_t msg_size)
{
    uint64_t *basin = calloc((size_t)groups + 1, sizeof *basin);
    sqlite3_stmt *st = NULL;
    if (!basin)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", groups);
    if (sqlite3_prepare_v2(s->db, "SELECT id, basin_cells FROM groups WHERE id > 0", -1, &st,
                           NULL)) {
        free(basin);
        return db_error(s->db, "read groups", msg, msg_size);
    }
    cm_status status = CM_OK;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const int64_t id = sqlite3_column_int64(st, 0), cells = sqlite3_column_int64(st, 1);
        if (id < 1 || id > groups || cells < 0)
            status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: group %lld", s->path,
                             (long long)id);
        else
            basin[id] = (uint64_t)cells;
    }
    sqlite3_finalize(st);
    if (status != CM_OK) {
        free(basin);
        return status;
    }
    *out = basin;
    return CM_OK;
}

/* Region row k into rec, checked. */
static cm_status region_record(const cm_store *s, sqlite3_stmt *st, uint32_t k, int dim,
                               cm_region *rec, char *msg, size_t msg_size)
{
    memset(rec, 0, sizeof *rec);
    rec->ncells = (uint64_t)sqlite3_column_int64(st, 3);
    rec->nexits = (uint64_t)sqlite3_column_int64(st, 4);
    rec->ngroups = (uint32_t)sqlite3_column_int64(st, 5);
    if (sqlite3_column_int64(st, 0) != (sqlite3_int64)k + 1 ||
        parse_box((const char *)sqlite3_column_text(st, 1),
                  (const char *)sqlite3_column_text(st, 2), dim, &rec->box) != CM_OK ||
        rec->ncells != cm_box_cells(&rec->box) || rec->ncells > CM_REGION_MAX_CELLS ||
        rec->nexits > rec->ncells)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: region %u", s->path, k + 1);
    return CM_OK;
}

static cm_status load_regions(cm_store *s, cm_cluster *c, int64_t ***exits, char *msg,
                              size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    uint64_t cap = 0;
    if (sqlite3_prepare_v2(s->db,
                           "SELECT id, lo, hi, cells, exits, own_groups FROM regions ORDER BY id",
                           -1, &st, NULL))
        return db_error(s->db, "read regions", msg, msg_size);
    cm_status status = CM_OK;
    int rc;
    while (status == CM_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        cm_region rec;
        cm_node *nodes = NULL;
        const uint32_t k = c->nregions;
        status = region_record(s, st, k, c->lat.dim, &rec, msg, msg_size);
        if (status == CM_OK && cm_grow((void **)exits, &cap, (uint64_t)k + 1, sizeof **exits))
            status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for region %u", k + 1);
        if (status == CM_OK) {
            (*exits)[k] = NULL;
            status = read_exits(s, k, rec.nexits, c->lat.dim, &(*exits)[k], msg, msg_size);
        }
        if (status == CM_OK)
            status = read_nodes(s, k, rec.nexits, &nodes, msg, msg_size);
        if (status == CM_OK)
            status = cm_cluster_restore(c, &rec, nodes, msg, msg_size);
        free(nodes);
    }
    if (status == CM_OK && rc != SQLITE_DONE)
        status = db_error(s->db, "read regions", msg, msg_size);
    sqlite3_finalize(st);
    return status;
}

cm_status cm_store_load_cluster(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    cm_lattice lat;
    cm_status status = read_lattice(s->db, &lat, msg, msg_size);
    if (status != CM_OK)
        return status;
    cm_cluster_init(c, &lat);
    cm_store_attach(s, c);
    const int64_t groups = query_int(s->db, "SELECT COUNT(*) FROM attractors");
    if (groups < 0 || groups > CM_MAX_GROUPS ||
        query_int(s->db, "SELECT IFNULL(MAX(id), 0) FROM attractors") != groups)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: attractors", s->path);
    int64_t **exits = NULL;
    uint64_t *basin = NULL;
    status = load_regions(s, c, &exits, msg, msg_size);
    if (status == CM_OK)
        status = read_basins(s, (uint32_t)groups, &basin, msg, msg_size);
    if (status == CM_OK && c->nregions > 0)
        status = cm_cluster_restored(c, (uint32_t)groups, basin, exits, msg, msg_size);
    if (status == CM_EFORMAT && !strstr(msg, s->path)) {
        char detail[256];
        snprintf(detail, sizeof detail, "%s", msg);
        cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: %s", s->path, detail);
    }
    for (uint32_t k = 0; exits && k < c->nregions; k++)
        free(exits[k]);
    free(exits);
    free(basin);
    if (status == CM_OK)
        cm_cluster_saved(c);
    return status;
}

/* ---- writing ---------------------------------------------------------- */

static cm_status step_done(sqlite3 *db, sqlite3_stmt *st, const char *what, char *msg,
                           size_t msg_size)
{
    const int rc = sqlite3_step(st);
    sqlite3_reset(st);
    return rc == SQLITE_DONE ? CM_OK : db_error(db, what, msg, msg_size);
}

static cm_status insert_region(cm_store *s, uint32_t k, const cm_region *r, char *msg,
                               size_t msg_size)
{
    char lo[512], hi[512];
    json_ints(lo, sizeof lo, r->box.lo, r->box.dim);
    json_ints(hi, sizeof hi, r->box.hi, r->box.dim);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db, "INSERT INTO regions VALUES(?, ?, ?, ?, ?, ?, 'joined')",
                           -1, &st, NULL))
        return db_error(s->db, "prepare regions", msg, msg_size);
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    sqlite3_bind_text(st, 2, lo, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, hi, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 4, (sqlite3_int64)r->ncells);
    sqlite3_bind_int64(st, 5, (sqlite3_int64)r->nexits);
    sqlite3_bind_int64(st, 6, (sqlite3_int64)r->ngroups);
    cm_status status = step_done(s->db, st, "write region", msg, msg_size);
    sqlite3_finalize(st);
    if (status != CM_OK)
        return status;
    /* the exit table: nexits * dim little-endian int64 cell coordinates */
    const uint64_t n = r->nexits * (uint64_t)r->box.dim;
    unsigned char *scratch = malloc(8 * (n + 1)), *out = malloc(cm_codec_bound(8 * (n + 1)));
    size_t len = 0;
    if (!scratch || !out ||
        cm_codec_encode(r->exit_target, n, 8, -1, scratch, out, cm_codec_bound(8 * (n + 1)),
                        &len) != CM_OK)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing exits");
    if (status == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT INTO exits VALUES(?, ?, ?)", -1, &st, NULL))
        status = db_error(s->db, "prepare exits", msg, msg_size);
    if (status == CM_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)r->nexits);
        sqlite3_bind_blob(st, 3, out, (int)len, SQLITE_STATIC);
        status = step_done(s->db, st, "write exits", msg, msg_size);
        sqlite3_finalize(st);
        s->stats.bytes_written += len;
    }
    free(scratch);
    free(out);
    return status;
}

/* Pages encoded at once: 8 x 3 columns of up to cm_codec_bound(256 KiB). */
#define WRITE_BATCH 8

/* Encodes the three columns (image, grp, step) of pages first .. first +
 * n - 1 into s->blobs, part bytes apart, in parallel; lens[t] is task t's
 * size (task t: page t / 3, column t % 3). */
static cm_status encode_batch(cm_store *s, const cm_region *r, uint64_t first, int n, size_t part,
                              size_t *lens)
{
    int failed = 0;
    const int tasks = 3 * n;
#pragma omp parallel num_threads(s->threads) if (tasks > 1)
    {
        unsigned char *scratch = malloc(4 * (size_t)CM_STORE_PAGE_CELLS);
        failed |= !scratch;
#pragma omp for schedule(dynamic, 1) reduction(| : failed)
        for (int t = 0; t < tasks; t++) {
            const uint64_t page = first + (uint64_t)(t / 3), cell = page * CM_STORE_PAGE_CELLS;
            const int col = t % 3;
            const uint32_t *const arrays[3] = {r->image, r->group, r->step};
            failed |= !scratch ||
                      cm_codec_encode(arrays[col] + cell, page_cells(r->ncells, page), 4,
                                      col == 0 ? (int64_t)cell : -1, scratch,
                                      s->blobs + (size_t)t * part, part, &lens[t]) != CM_OK;
        }
        free(scratch);
    }
    return failed ? CM_ENOMEM : CM_OK;
}

/* Writes all of region k's pages, once: a region never changes. Pages are
 * encoded in parallel a batch at a time and written in order. */
static cm_status write_pages(cm_store *s, uint32_t k, const cm_region *r, char *msg,
                             size_t msg_size)
{
    const uint64_t pages = npages(r->ncells);
    const size_t part = cm_codec_bound(4 * (size_t)CM_STORE_PAGE_CELLS);
    size_t lens[WRITE_BATCH * 3];
    sqlite3_stmt *st = NULL;
    if (cm_grow((void **)&s->blobs, &s->blobs_cap, (uint64_t)WRITE_BATCH * 3 * part, 1) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing region %u", k + 1);
    if (sqlite3_prepare_v2(s->db, "INSERT INTO pages VALUES(?1, ?2, ?3, ?4, ?5, ?6)", -1, &st,
                           NULL))
        return db_error(s->db, "prepare pages", msg, msg_size);
    cm_status status = CM_OK;
    for (uint64_t b = 0; status == CM_OK && b < pages; b += WRITE_BATCH) {
        const int batch = (int)(pages - b < WRITE_BATCH ? pages - b : WRITE_BATCH);
        if (encode_batch(s, r, b, batch, part, lens) != CM_OK)
            status = cm_fail(CM_ENOMEM, msg, msg_size, "encoding a page of region %u", k + 1);
        for (int p = 0; status == CM_OK && p < batch; p++) {
            const uint64_t page = b + (uint64_t)p;
            sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
            sqlite3_bind_int64(st, 2, (sqlite3_int64)(page * CM_STORE_PAGE_CELLS));
            sqlite3_bind_int64(st, 3, (sqlite3_int64)page_cells(r->ncells, page));
            for (int c = 0; c < 3; c++) {
                const int t = p * 3 + c;
                sqlite3_bind_blob(st, 4 + c, s->blobs + (size_t)t * part, (int)lens[t],
                                  SQLITE_STATIC);
                s->stats.bytes_written += lens[t];
            }
            status = step_done(s->db, st, "write page", msg, msg_size);
            s->stats.pages_written++;
        }
    }
    sqlite3_finalize(st);
    return status;
}

/* Replaces region k's node records (five columns, see read_nodes). Only the
 * fields that say what a node's exit leads to are saved: a final group is
 * kept for final and cycle nodes only, so the file does not depend on what
 * readers resolved. */
static cm_status write_nodes(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                             size_t msg_size)
{
    const cm_cluster_region *cr = &c->regions[k];
    const uint64_t n = cr->r.nexits;
    uint32_t *cols = malloc((NODE_FIELDS * n + 1) * sizeof *cols);
    unsigned char *scratch = malloc(4 * (NODE_FIELDS * n + 1));
    const size_t bound = cm_codec_bound(4 * (NODE_FIELDS * n + 1));
    unsigned char *blob = malloc(bound);
    size_t len = 0;
    cm_status status = CM_OK;
    if (!cols || !scratch || !blob)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing nodes");
    for (uint64_t e = 0; status == CM_OK && e < n; e++) {
        const cm_node *nd = &c->nodes[cr->node_base + e];
        const int known = nd->next == CM_NODE_FINAL || nd->next == CM_NODE_CYCLE;
        cols[e] = nd->next;
        cols[n + e] = nd->next == CM_NODE_OPEN ? 0 : nd->dist;
        cols[2 * n + e] = known ? nd->group : 0;
        cols[3 * n + e] = nd->next == CM_NODE_OPEN ? 0 : nd->target;
        cols[4 * n + e] = nd->tree;
    }
    if (status == CM_OK &&
        cm_codec_encode(cols, NODE_FIELDS * n, 4, -1, scratch, blob, bound, &len) != CM_OK)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "encoding the nodes of region %u", k + 1);
    sqlite3_stmt *st = NULL;
    if (status == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO nodes VALUES(?, ?, ?)", -1, &st, NULL))
        status = db_error(s->db, "prepare nodes", msg, msg_size);
    if (status == CM_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)n);
        sqlite3_bind_blob(st, 3, blob, (int)len, SQLITE_STATIC);
        status = step_done(s->db, st, "write nodes", msg, msg_size);
        s->stats.bytes_written += len;
        s->stats.node_tables_written++;
    }
    sqlite3_finalize(st);
    free(cols);
    free(scratch);
    free(blob);
    return status;
}

/* The cell counts of the groups whose counts changed. */
static cm_status write_basins(cm_store *s, const cm_cluster *c, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO basins VALUES(?, ?)", -1, &st, NULL))
        return db_error(s->db, "prepare basins", msg, msg_size);
    cm_status status = CM_OK;
    for (uint32_t g = 1; status == CM_OK && g <= c->ngroups; g++) {
        if (!c->basin_dirty[g])
            continue;
        sqlite3_bind_int64(st, 1, g);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)c->basin[g]);
        status = step_done(s->db, st, "write basins", msg, msg_size);
    }
    sqlite3_finalize(st);
    return status;
}

static cm_status insert_attractor(cm_store *s, sqlite3_stmt *st, const cm_lattice *lat,
                                  const cm_group_info *gi, const cm_group_cell *cells,
                                  char *msg, size_t msg_size)
{
    const uint64_t n = gi->period;
    unsigned char *blob = malloc(n * (size_t)lat->dim * 8);
    if (!blob)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing groups");
    for (uint64_t i = 0; i < n; i++)
        for (int d = 0; d < lat->dim; d++) {
            const uint64_t v = (uint64_t)cells[i].cell[d];
            for (int b = 0; b < 8; b++)
                blob[(i * (uint64_t)lat->dim + (uint64_t)d) * 8 + (uint64_t)b] =
                    (unsigned char)(v >> (8 * b));
        }
    char centre[512], lo[512], hi[512], anchor[512];
    json_doubles(centre, sizeof centre, gi->centre, lat->dim);
    json_doubles(lo, sizeof lo, gi->lo, lat->dim);
    json_doubles(hi, sizeof hi, gi->hi, lat->dim);
    json_ints(anchor, sizeof anchor, gi->anchor, lat->dim);
    sqlite3_bind_int64(st, 1, gi->id);
    sqlite3_bind_int64(st, 2, gi->period);
    sqlite3_bind_text(st, 3, centre, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, lo, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 5, hi, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 6, anchor, -1, SQLITE_TRANSIENT);
    sqlite3_bind_blob(st, 7, blob, (int)(n * (uint64_t)lat->dim * 8), SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 8, cm_group_kind_name(gi->kind), -1, SQLITE_STATIC);
    const cm_status status = step_done(s->db, st, "write group", msg, msg_size);
    free(blob);
    return status;
}

/* Rows of `attractors` for the groups made since the last commit, from
 * the periodic cells the cluster noted (in the order the cluster sorts
 * them, whatever the order they were found in). */
static cm_status write_new_groups(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    const uint32_t n = c->ngroups - c->saved_groups;
    if (n == 0)
        return CM_OK;
    cm_group_info *groups = malloc((size_t)n * sizeof *groups);
    if (!groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", n);
    cm_status status = cm_cluster_describe_new(c, s->model, groups, msg, msg_size);
    sqlite3_stmt *st = NULL;
    if (status == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT INTO attractors VALUES(?, ?, ?, ?, ?, ?, ?, ?)", -1, &st,
                           NULL))
        status = db_error(s->db, "prepare groups", msg, msg_size);
    const cm_group_cell *cells = c->new_periodic;
    for (uint32_t g = 0; g < n && status == CM_OK; cells += groups[g++].period)
        status = insert_attractor(s, st, &c->lat, &groups[g], cells, msg, msg_size);
    sqlite3_finalize(st);
    free(groups);
    return status;
}

/* A region never saved: its row, exit table and pages. */
static cm_status write_region(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                              size_t msg_size)
{
    const cm_region *r = &c->regions[k].r;
    if (!r->group)
        return cm_fail(CM_EINVAL, msg, msg_size, "region %u is unsaved but paged out", k);
    cm_status st = insert_region(s, k, r, msg, msg_size);
    if (st == CM_OK)
        st = write_pages(s, k, r, msg, msg_size);
    s->stats.regions_written++;
    return st;
}

static cm_status begin(cm_store *s, char *msg, size_t msg_size)
{
    if (!s->writable)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s is open read-only", s->path);
    if (s->failed)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "an earlier write to %s failed; reopen it (solve --resume) to go on",
                       s->path);
    if (!s->in_transaction && exec(s->db, "BEGIN IMMEDIATE") != SQLITE_OK)
        return db_error(s->db, "begin", msg, msg_size);
    s->in_transaction = 1;
    return CM_OK;
}

/* Undoes the open transaction after a failed write. */
static cm_status abandon(cm_store *s, cm_status st)
{
    if (s->in_transaction)
        exec(s->db, "ROLLBACK");
    s->in_transaction = 0;
    s->failed = 1;
    return st;
}

/* The pager's other half: saves a dirty region about to be evicted, in the
 * transaction the next commit ends (a kill before it undoes the write). */
static cm_status page_out(void *user, const cm_cluster *c, uint32_t k, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = seconds_now();
    cm_status st = begin(s, msg, msg_size);
    if (st == CM_OK)
        st = write_region(s, c, k, msg, msg_size);
    s->stats.regions_evicted++;
    s->stats.evict_seconds += seconds_now() - t0;
    return st == CM_OK ? CM_OK : abandon(s, st);
}

cm_status cm_store_commit(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    const double t0 = seconds_now();
    cm_status st = begin(s, msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < c->nregions; k++)
        if (!c->regions[k].written)
            st = write_region(s, c, k, msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < c->nregions; k++)
        if (c->regions[k].nodes_dirty)
            st = write_nodes(s, c, k, msg, msg_size);
    if (st == CM_OK)
        st = write_basins(s, c, msg, msg_size);
    if (st == CM_OK)
        st = write_new_groups(s, c, msg, msg_size);
    if (st == CM_OK) {
        char sql[96];
        snprintf(sql, sizeof sql, "UPDATE meta SET value = '%u' WHERE key = 'groups'", c->ngroups);
        if (exec(s->db, sql) != SQLITE_OK)
            st = db_error(s->db, "write meta", msg, msg_size);
    }
    if (st == CM_OK && exec(s->db, "COMMIT") != SQLITE_OK)
        st = db_error(s->db, "commit", msg, msg_size);
    if (st != CM_OK)
        return abandon(s, st);
    s->in_transaction = 0;
    cm_cluster_saved(c); /* the file now holds everything */
    s->stats.commit_seconds += seconds_now() - t0;
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
        st = begin(s, msg, msg_size);
    sqlite3_stmt *ins = NULL;
    if (st == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO meta(key, value) VALUES(?, ?)", -1, &ins,
                           NULL) != SQLITE_OK)
        st = db_error(s->db, "prepare note", msg, msg_size);
    if (st == CM_OK) {
        sqlite3_bind_text(ins, 1, key, -1, SQLITE_STATIC);
        sqlite3_bind_text(ins, 2, value, -1, SQLITE_STATIC);
        if (sqlite3_step(ins) != SQLITE_DONE)
            st = db_error(s->db, "write note", msg, msg_size);
    }
    sqlite3_finalize(ins);
    if (st == CM_OK && own && exec(s->db, "COMMIT") != SQLITE_OK)
        st = db_error(s->db, "commit note", msg, msg_size);
    if (st == CM_OK && own)
        s->in_transaction = 0;
    return st == CM_OK || st == CM_EINVAL ? st : abandon(s, st);
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
        return db_error(s->db, "prepare note", msg, msg_size);
    sqlite3_bind_text(q, 1, key, -1, SQLITE_STATIC);
    if (sqlite3_step(q) == SQLITE_ROW && sqlite3_column_text(q, 0))
        snprintf(out, size, "%s", (const char *)sqlite3_column_text(q, 0));
    else
        st = cm_fail(CM_ENOTFOUND, msg, msg_size, "%s has no %s", s->path, key);
    sqlite3_finalize(q);
    return st;
}

cm_status cm_store_commit_join(void *store, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                               char *msg, size_t msg_size)
{
    (void)box;
    (void)stats;
    const cm_status st = cm_store_commit(store, c, msg, msg_size);
    cm_cluster_trim(c);
    return st;
}

void cm_store_set_model(cm_store *s, const cm_model *model) { s->model = model; }

cm_status cm_store_groups(cm_store *s, cm_group_info *groups, uint32_t n, uint64_t *sink_cells,
                          char *msg, size_t msg_size)
{
    cm_lattice lat;
    cm_status status = read_lattice(s->db, &lat, msg, msg_size);
    sqlite3_stmt *st = NULL;
    if (status == CM_OK &&
        sqlite3_prepare_v2(
            s->db,
            "SELECT id, period, basin_cells, centre, lo, hi, anchor, kind FROM groups "
            "ORDER BY id",
            -1, &st, NULL))
        status = db_error(s->db, "read groups", msg, msg_size);
    uint32_t seen = 0;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const int64_t id = sqlite3_column_int64(st, 0);
        if (id == 0) {
            *sink_cells = (uint64_t)sqlite3_column_int64(st, 2);
            continue;
        }
        double anchor[CM_MAX_DIM];
        cm_group_info *g = &groups[seen];
        memset(g, 0, sizeof *g);
        g->id = (uint32_t)id;
        g->period = (uint32_t)sqlite3_column_int64(st, 1);
        g->basin_cells = (uint64_t)sqlite3_column_int64(st, 2);
        if (id != (int64_t)seen + 1 || seen >= n ||
            parse_json_numbers((const char *)sqlite3_column_text(st, 3), g->centre, CM_MAX_DIM) !=
                lat.dim ||
            parse_json_numbers((const char *)sqlite3_column_text(st, 4), g->lo, CM_MAX_DIM) !=
                lat.dim ||
            parse_json_numbers((const char *)sqlite3_column_text(st, 5), g->hi, CM_MAX_DIM) !=
                lat.dim ||
            parse_json_numbers((const char *)sqlite3_column_text(st, 6), anchor, CM_MAX_DIM) !=
                lat.dim) {
            status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: group %lld", s->path,
                             (long long)id);
            break;
        }
        for (int d = 0; d < lat.dim; d++)
            g->anchor[d] = (int64_t)anchor[d];
        const unsigned char *kind = sqlite3_column_text(st, 7);
        g->kind = kind && strcmp((const char *)kind, cm_group_kind_name(CM_GROUP_STICKING)) == 0
                      ? CM_GROUP_STICKING
                      : CM_GROUP_ATTRACTOR;
        seen++;
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != n)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "%s holds %u groups, not %u", s->path, seen, n);
    return status;
}
