/* cellmap/store_sql.c - the store files' shared helpers, the lowest of
 * them: SQL statements and queries, error messages, JSON number lists, the
 * transaction a write runs in, and checks of what a file says of itself.
 * store.c (files), store_pages.c (regions), store_commit.c (commits and
 * eviction), store_attractors.c and store_upgrade.c build on it; it calls
 * none of them. */
#include "cellmap/store_db.h"

#include "cellmap/classify.h"
#include "cellmap/clock.h"
#include "cellmap/numtext.h"
#include "cellmap/output.h"

#include <errno.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

void store_json_doubles(char *buf, size_t size, const double *v, int n)
{
    size_t used = 0;
    append(buf, size, &used, "[");
    char text[CM_NUM_TEXT];
    for (int i = 0; i < n; i++)
        append(buf, size, &used, "%s%s", i ? "," : "", cm_num_text(v[i], text));
    append(buf, size, &used, "]");
}

void store_json_ints(char *buf, size_t size, const int64_t *v, int n)
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
            char text[CM_NUM_TEXT];
            append(buf, size, &used, "%s", cm_num_text(v->v[0], text));
        } else {
            char tmp[2048];
            store_json_doubles(tmp, sizeof tmp, v->v, v->count);
            append(buf, size, &used, "%s", tmp);
        }
    }
    append(buf, size, &used, "}");
}

cm_status store_db_error(sqlite3 *db, const char *what, char *msg, size_t msg_size)
{
    const int code = db ? sqlite3_errcode(db) & 0xff : SQLITE_OK;
    if (code == SQLITE_FULL || code == SQLITE_IOERR || code == SQLITE_READONLY ||
        code == SQLITE_CANTOPEN) {
        /* the file system's reason, with the file and the fix */
        int err = sqlite3_system_errno(db);
        if (!err)
            err = code == SQLITE_FULL ? ENOSPC : code == SQLITE_READONLY ? EROFS : EIO;
        const char *file = sqlite3_db_filename(db, "main");
        char why[CM_OUTPUT_PATH_MAX + 256];
        cm_output_fail(file && *file ? file : "the database", err, why, sizeof why);
        return cm_fail(CM_EDB, msg, msg_size, "%s: %s", what, why);
    }
    return cm_fail(CM_EDB, msg, msg_size, "%s: %s", what, db ? sqlite3_errmsg(db) : "no database");
}

int store_exec(sqlite3 *db, const char *sql) { return sqlite3_exec(db, sql, NULL, NULL, NULL); }

cm_status store_read_text(sqlite3 *db, const char *sql, char *out, size_t size, char *msg,
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

/* Parses a JSON array of numbers written by this module. */
cm_status store_meta_text(sqlite3 *db, const char *key, char *out, size_t size, char *msg,
                           size_t msg_size)
{
    char sql[128];
    snprintf(sql, sizeof sql, "SELECT value FROM meta WHERE key='%s'", key);
    if (store_read_text(db, sql, out, size, NULL, 0) == CM_OK)
        return CM_OK;
    return cm_fail(CM_EFORMAT, msg, msg_size, "its meta table has no '%s'", key);
}

int64_t store_query_int(sqlite3 *db, const char *sql)
{
    sqlite3_stmt *st = NULL;
    int64_t v = -1;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return v;
}

int64_t store_page_bytes(sqlite3 *db)
{
    /* files written before the meta value existed are read page by page:
       a row per page, so a page of the file per row */
    char text[32], *end = NULL;
    if (store_read_text(db, "SELECT value FROM meta WHERE key='page_bytes'", text, sizeof text, NULL,
                  0) != CM_OK)
        return store_query_int(db, "SELECT IFNULL(SUM(LENGTH(image) + LENGTH(grp) + "
                                   "LENGTH(step)), 0) FROM pages");
    const long long bytes = strtoll(text, &end, 10);
    return end == text || *end || bytes < 0 ? -1 : bytes;
}

int store_parse_json_numbers(const char *text, double *out, int cap)
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

cm_status store_read_lattice(sqlite3 *db, cm_lattice *lat, char *msg, size_t msg_size)
{
    char text[1024];
    memset(lat, 0, sizeof *lat);
    cm_status st = store_meta_text(db, "lattice_origin", text, sizeof text, msg, msg_size);
    if (st != CM_OK)
        return st;
    lat->dim = store_parse_json_numbers(text, lat->origin, CM_MAX_DIM);
    if ((st = store_meta_text(db, "lattice_width", text, sizeof text, msg, msg_size)) != CM_OK)
        return st;
    if (lat->dim < 1 || store_parse_json_numbers(text, lat->width, CM_MAX_DIM) != lat->dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "its lattice is not a list of numbers");
    char why[256];
    if (cm_lattice_check(lat, why, sizeof why) != CM_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size, "its lattice: %s", why);
    return CM_OK;
}

cm_status store_use_wal(cm_store *s, char *msg, size_t msg_size)
{
    /* NORMAL: in WAL mode a commit survives the process being killed; only
     * an operating-system crash may lose the last commits, never consistency.
     * Entered at the first write, so that a file opened for writing and
     * refused (or left alone) stays byte-identical. */
    char mode[16] = "";
    if (s->wal)
        return CM_OK;
    if (store_read_text(s->db, "PRAGMA journal_mode=WAL", mode, sizeof mode, msg, msg_size) != CM_OK ||
        strcmp(mode, "wal") != 0 || store_exec(s->db, "PRAGMA synchronous=NORMAL") != SQLITE_OK)
        return cm_fail(CM_EDB, msg, msg_size, "cannot put %s in WAL mode: %s", s->path,
                       sqlite3_errmsg(s->db));
    s->wal = 1;
    return CM_OK;
}

cm_status store_damaged(const cm_store *s, cm_status st, char *msg, size_t msg_size)
{
    if (st != CM_EFORMAT || !msg || strstr(msg, s->path))
        return st;
    char detail[512];
    snprintf(detail, sizeof detail, "%s", msg);
    return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: %s", s->path, detail);
}

int64_t store_sink_cells(const cm_store *s)
{
    /* the groups view's first row; from version 4 on from the tables
       themselves, which spares every reader the view's machinery */
    return store_query_int(s->db, s->version >= 4
                                      ? "SELECT (SELECT IFNULL(SUM(cells), 0) FROM regions) -"
                                        " (SELECT IFNULL(SUM(cells), 0) FROM basins)"
                                      : "SELECT basin_cells FROM groups WHERE id = 0");
}

cm_status store_check_groups(const cm_store *s, char *msg, size_t msg_size)
{
    sqlite3 *db = s->db;
    const int64_t groups = store_query_int(db, "SELECT COUNT(*) FROM attractors");
    if (groups < 0 || groups > CM_MAX_GROUPS ||
        store_query_int(db, "SELECT IFNULL(MAX(id), 0) FROM attractors") != groups ||
        store_query_int(db, "SELECT COUNT(*) FROM attractors WHERE period < 1") != 0)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "its attractors are not numbered 1..N with periods of 1 or more");
    char text[32], *end = NULL;
    if (store_meta_text(db, "groups", text, sizeof text, NULL, 0) == CM_OK) {
        const long long said = strtoll(text, &end, 10);
        if (end == text || *end)
            return cm_fail(CM_EFORMAT, msg, msg_size, "its meta value 'groups' is not a number");
        if (said != groups)
            return cm_fail(CM_EFORMAT, msg, msg_size, "it says it holds %lld groups but has %lld",
                           said, (long long)groups);
    }
    if (s->version >= 4 &&
        store_query_int(db, "SELECT COUNT(*) FROM basins WHERE grp < 1 OR grp > "
                            "(SELECT COUNT(*) FROM attractors) OR cells < 0") != 0)
        return cm_fail(CM_EFORMAT, msg, msg_size, "its basins name groups it does not have");
    /* with no basin below 0 (version 4 on), only the sink can be */
    const bool negative =
        s->version >= 4 ? store_sink_cells(s) < 0
                        : store_query_int(db, "SELECT COUNT(*) FROM groups WHERE basin_cells < 0");
    if (negative)
        return cm_fail(CM_EFORMAT, msg, msg_size, "its basins hold more cells than its regions");
    return CM_OK;
}

cm_status store_step_done(sqlite3 *db, sqlite3_stmt *st, const char *what, char *msg,
                           size_t msg_size)
{
    const int rc = sqlite3_step(st);
    sqlite3_reset(st);
    return rc == SQLITE_DONE ? CM_OK : store_db_error(db, what, msg, msg_size);
}

cm_status store_begin(cm_store *s, char *msg, size_t msg_size)
{
    if (!s->writable)
        return cm_fail(CM_EINVAL, msg, msg_size, "%s is open read-only", s->path);
    if (s->failed)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "an earlier write to %s failed; reopen it (solve --resume) to go on",
                       s->path);
    if (!s->in_transaction) {
        const cm_status st = store_use_wal(s, msg, msg_size);
        if (st != CM_OK)
            return st;
        if (store_exec(s->db, "BEGIN IMMEDIATE") != SQLITE_OK)
            return store_db_error(s->db, "begin", msg, msg_size);
    }
    s->in_transaction = 1;
    return CM_OK;
}

/* Undoes the open transaction after a failed write. */
cm_status store_abandon(cm_store *s, cm_status st)
{
    if (s->in_transaction)
        store_exec(s->db, "ROLLBACK");
    s->in_transaction = 0;
    s->failed = 1;
    return st;
}
