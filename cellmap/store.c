#include "cellmap/store.h"

#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *const schema_sql =
    "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);"
    "CREATE TABLE regions(id INTEGER PRIMARY KEY, lo TEXT NOT NULL, hi TEXT NOT NULL,"
    " cells INTEGER NOT NULL, status TEXT NOT NULL);"
    "CREATE TABLE pages(region INTEGER NOT NULL REFERENCES regions(id), first_cell INTEGER NOT "
    "NULL,"
    " cells INTEGER NOT NULL, image BLOB NOT NULL, grp BLOB NOT NULL, step BLOB NOT NULL,"
    " PRIMARY KEY(region, first_cell));"
    "CREATE TABLE groups(id INTEGER PRIMARY KEY, period INTEGER NOT NULL,"
    " basin_cells INTEGER NOT NULL, is_sink INTEGER NOT NULL, centre TEXT, lo TEXT, hi TEXT,"
    " anchor TEXT, periodic_cells BLOB);"
    "CREATE TABLE exits(region INTEGER NOT NULL, cell INTEGER NOT NULL, target TEXT NOT NULL,"
    " PRIMARY KEY(region, cell));";

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

/* Little-endian encoding, whatever the host's byte order. */
static void put_u32le(unsigned char *dst, const uint32_t *src, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        dst[4 * i] = (unsigned char)(src[i]);
        dst[4 * i + 1] = (unsigned char)(src[i] >> 8);
        dst[4 * i + 2] = (unsigned char)(src[i] >> 16);
        dst[4 * i + 3] = (unsigned char)(src[i] >> 24);
    }
}

static void get_u32le(uint32_t *dst, const unsigned char *src, size_t n)
{
    for (size_t i = 0; i < n; i++)
        dst[i] = (uint32_t)src[4 * i] | (uint32_t)src[4 * i + 1] << 8 |
                 (uint32_t)src[4 * i + 2] << 16 | (uint32_t)src[4 * i + 3] << 24;
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

/* Opens path read-only and checks application id and version. */
static cm_status open_checked(const char *path, sqlite3 **out, char *msg, size_t msg_size)
{
    sqlite3 *db = NULL;
    *out = NULL;
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
        cm_status st = cm_fail(CM_EIO, msg, msg_size, "cannot open %s: %s", path,
                               db ? sqlite3_errmsg(db) : "out of memory");
        sqlite3_close(db);
        return st;
    }
    int app = 0, version = 0;
    if (pragma_int(db, "PRAGMA application_id", &app) != SQLITE_OK ||
        pragma_int(db, "PRAGMA user_version", &version) != SQLITE_OK) {
        sqlite3_close(db);
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is not a cellmap database (not SQLite)",
                       path);
    }
    if (app != CM_STORE_APP_ID) {
        sqlite3_close(db);
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s is an SQLite file but not a cellmap database (application_id %d)",
                       path, app);
    }
    if (version > CM_STORE_VERSION || version < 1) {
        sqlite3_close(db);
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "%s has format version %d; this cellmap reads version %d (upgrade cellmap)",
                       path, version, CM_STORE_VERSION);
    }
    *out = db;
    return CM_OK;
}

cm_status cm_store_check(const char *path, char *msg, size_t msg_size)
{
    sqlite3 *db = NULL;
    cm_status st = open_checked(path, &db, msg, msg_size);
    sqlite3_close(db);
    return st;
}

static int exec(sqlite3 *db, const char *sql) { return sqlite3_exec(db, sql, NULL, NULL, NULL); }

static cm_status write_meta(sqlite3 *db, const cm_store_meta *meta, char *msg, size_t msg_size)
{
    char params[8192], origin[512], width[512], created[32], dim[8];
    const cm_lattice *lat = meta->lattice;
    cm_params_json(&meta->model->values, params, sizeof params);
    json_doubles(origin, sizeof origin, lat->origin, lat->dim);
    json_doubles(width, sizeof width, lat->width, lat->dim);
    snprintf(created, sizeof created, "%lld", meta->created);
    snprintf(dim, sizeof dim, "%d", lat->dim);
    const char *rows[][2] = {
        {"format", "cellmap cluster database"},
        {"tool_version", meta->tool_version ? meta->tool_version : ""},
        {"model", meta->model->name},
        {"params", params},
        {"dim", dim},
        {"lattice_origin", origin},
        {"lattice_width", width},
        {"command", meta->command ? meta->command : ""},
        {"created", created},
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

static cm_status write_pages(sqlite3 *db, const cm_region *r, char *msg, size_t msg_size)
{
    char lo[512], hi[512];
    json_ints(lo, sizeof lo, r->box.lo, r->box.dim);
    json_ints(hi, sizeof hi, r->box.hi, r->box.dim);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, "INSERT INTO regions VALUES(1, ?, ?, ?, 'solved')", -1, &st, NULL))
        return db_error(db, "prepare regions", msg, msg_size);
    sqlite3_bind_text(st, 1, lo, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 2, hi, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)r->ncells);
    const int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE)
        return db_error(db, "write region", msg, msg_size);
    unsigned char *buf = malloc(3 * 4 * (size_t)CM_STORE_PAGE_CELLS);
    if (!buf)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing pages");
    cm_status status = CM_OK;
    if (sqlite3_prepare_v2(db, "INSERT INTO pages VALUES(1, ?, ?, ?, ?, ?)", -1, &st, NULL))
        status = db_error(db, "prepare pages", msg, msg_size);
    for (uint64_t first = 0; status == CM_OK && first < r->ncells; first += CM_STORE_PAGE_CELLS) {
        const uint64_t n =
            r->ncells - first < CM_STORE_PAGE_CELLS ? r->ncells - first : CM_STORE_PAGE_CELLS;
        const uint32_t *arrays[3] = {r->image + first, r->group + first, r->step + first};
        sqlite3_bind_int64(st, 1, (sqlite3_int64)first);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)n);
        for (int a = 0; a < 3; a++) {
            put_u32le(buf + (size_t)a * 4 * CM_STORE_PAGE_CELLS, arrays[a], n);
            sqlite3_bind_blob(st, 3 + a, buf + (size_t)a * 4 * CM_STORE_PAGE_CELLS, (int)(4 * n),
                              SQLITE_STATIC);
        }
        if (sqlite3_step(st) != SQLITE_DONE)
            status = db_error(db, "write page", msg, msg_size);
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    free(buf);
    return status;
}

static cm_status write_groups(sqlite3 *db, const cm_region *r, const cm_lattice *lat,
                              const cm_group_info *groups, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    uint64_t sink = r->ncells;
    for (uint32_t k = 0; k < r->ngroups; k++)
        sink -= groups[k].basin_cells;
    if (sqlite3_prepare_v2(db, "INSERT INTO groups VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?)", -1, &st,
                           NULL))
        return db_error(db, "prepare groups", msg, msg_size);
    /* The sink: group 0, period 1, no periodic cells in the lattice. */
    sqlite3_bind_int(st, 1, 0);
    sqlite3_bind_int(st, 2, 1);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)sink);
    sqlite3_bind_int(st, 4, 1);
    for (int c = 5; c <= 9; c++)
        sqlite3_bind_null(st, c);
    cm_status status = sqlite3_step(st) == SQLITE_DONE ? CM_OK : db_error(db, "write sink", msg,
                                                                          msg_size);
    for (uint32_t k = 0; status == CM_OK && k < r->ngroups; k++) {
        const cm_group_info *g = &groups[k];
        char centre[512], lo[512], hi[512], anchor[512];
        json_doubles(centre, sizeof centre, g->centre, lat->dim);
        json_doubles(lo, sizeof lo, g->lo, lat->dim);
        json_doubles(hi, sizeof hi, g->hi, lat->dim);
        json_ints(anchor, sizeof anchor, g->anchor, lat->dim);
        sqlite3_reset(st);
        sqlite3_bind_int64(st, 1, g->id);
        sqlite3_bind_int64(st, 2, g->period);
        sqlite3_bind_int64(st, 3, (sqlite3_int64)g->basin_cells);
        sqlite3_bind_int(st, 4, 0);
        sqlite3_bind_text(st, 5, centre, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 6, lo, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 7, hi, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 8, anchor, -1, SQLITE_TRANSIENT);
        sqlite3_bind_null(st, 9);
        if (sqlite3_step(st) != SQLITE_DONE)
            status = db_error(db, "write group", msg, msg_size);
    }
    sqlite3_finalize(st);
    return status;
}

/* Periodic cells of every group as local indices (little-endian uint32),
 * one BLOB per group. */
static cm_status write_periodic_cells(sqlite3 *db, const cm_region *r, const cm_group_info *groups,
                                      char *msg, size_t msg_size)
{
    uint64_t *offset = calloc((size_t)r->ngroups + 1, sizeof *offset);
    uint64_t total = 0;
    for (uint32_t k = 0; offset && k < r->ngroups; k++) {
        offset[k] = total;
        total += groups[k].period;
    }
    unsigned char *cells = offset ? malloc(4 * (total ? total : 1)) : NULL;
    if (!cells) {
        free(offset);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing periodic cells");
    }
    for (uint64_t i = 0; i < r->ncells; i++) {
        if (!cm_is_periodic(r, i))
            continue;
        const uint32_t idx = (uint32_t)i;
        put_u32le(cells + 4 * offset[r->group[i] - 1]++, &idx, 1);
    }
    sqlite3_stmt *st = NULL;
    cm_status status = CM_OK;
    if (sqlite3_prepare_v2(db, "UPDATE groups SET periodic_cells = ? WHERE id = ?", -1, &st, NULL))
        status = db_error(db, "prepare periodic cells", msg, msg_size);
    for (uint32_t k = 0; status == CM_OK && k < r->ngroups; k++) {
        /* offset[k] now points at the end of group k's cells */
        sqlite3_bind_blob(st, 1, cells + 4 * (offset[k] - groups[k].period),
                          (int)(4 * groups[k].period), SQLITE_STATIC);
        sqlite3_bind_int64(st, 2, groups[k].id);
        if (sqlite3_step(st) != SQLITE_DONE)
            status = db_error(db, "write periodic cells", msg, msg_size);
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    free(cells);
    free(offset);
    return status;
}

/* Refuses to replace an existing file that is not a cellmap database. */
static cm_status check_replaceable(const char *path, char *msg, size_t msg_size)
{
    struct stat sb;
    if (stat(path, &sb) != 0)
        return CM_OK;
    char why[512];
    if (cm_store_check(path, why, sizeof why) != CM_OK)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "refusing to overwrite %s: %s; choose another --db file", path, why);
    return CM_OK;
}

cm_status cm_store_save(const char *path, const cm_store_meta *meta, const cm_region *r,
                        const cm_group_info *groups, char *msg, size_t msg_size)
{
    cm_status status = check_replaceable(path, msg, msg_size);
    if (status != CM_OK)
        return status;
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    unlink(tmp);
    sqlite3 *db = NULL;
    if (sqlite3_open_v2(tmp, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, NULL) != SQLITE_OK) {
        status = cm_fail(CM_EIO, msg, msg_size, "cannot create %s: %s", tmp,
                         db ? sqlite3_errmsg(db) : "out of memory");
        sqlite3_close(db);
        return status;
    }
    char pragmas[128];
    snprintf(pragmas, sizeof pragmas, "PRAGMA application_id=%d; PRAGMA user_version=%d;",
             CM_STORE_APP_ID, CM_STORE_VERSION);
    if (exec(db, "BEGIN") != SQLITE_OK || exec(db, pragmas) != SQLITE_OK ||
        exec(db, schema_sql) != SQLITE_OK)
        status = db_error(db, "create schema", msg, msg_size);
    if (status == CM_OK)
        status = write_meta(db, meta, msg, msg_size);
    if (status == CM_OK)
        status = write_pages(db, r, msg, msg_size);
    if (status == CM_OK)
        status = write_groups(db, r, meta->lattice, groups, msg, msg_size);
    if (status == CM_OK)
        status = write_periodic_cells(db, r, groups, msg, msg_size);
    if (status == CM_OK && exec(db, "COMMIT") != SQLITE_OK)
        status = db_error(db, "commit", msg, msg_size);
    if (sqlite3_close(db) != SQLITE_OK && status == CM_OK)
        status = cm_fail(CM_EDB, msg, msg_size, "closing %s failed", tmp);
    if (status == CM_OK && rename(tmp, path) != 0)
        status = cm_fail(CM_EIO, msg, msg_size, "cannot rename %s to %s", tmp, path);
    if (status != CM_OK)
        unlink(tmp);
    return status;
}

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
    return n;
}

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
                           : cm_fail(CM_EFORMAT, msg, msg_size, "database lacks: %s", sql);
}

static cm_status read_lattice(sqlite3 *db, cm_lattice *lat, cm_box *box, char *msg,
                              size_t msg_size)
{
    char text[1024];
    double v[CM_MAX_DIM];
    cm_status st;
    memset(lat, 0, sizeof *lat);
    memset(box, 0, sizeof *box);
    if ((st = read_text(db, "SELECT value FROM meta WHERE key='lattice_origin'", text, sizeof text,
                        msg, msg_size)) != CM_OK)
        return st;
    lat->dim = parse_json_numbers(text, lat->origin, CM_MAX_DIM);
    if ((st = read_text(db, "SELECT value FROM meta WHERE key='lattice_width'", text, sizeof text,
                        msg, msg_size)) != CM_OK)
        return st;
    if (parse_json_numbers(text, lat->width, CM_MAX_DIM) != lat->dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "corrupt lattice metadata");
    box->dim = lat->dim;
    if ((st = read_text(db, "SELECT lo FROM regions WHERE id=1", text, sizeof text, msg,
                        msg_size)) != CM_OK)
        return st;
    if (parse_json_numbers(text, v, CM_MAX_DIM) != lat->dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "corrupt region box");
    for (int d = 0; d < lat->dim; d++)
        box->lo[d] = (int64_t)v[d];
    if ((st = read_text(db, "SELECT hi FROM regions WHERE id=1", text, sizeof text, msg,
                        msg_size)) != CM_OK)
        return st;
    if (parse_json_numbers(text, v, CM_MAX_DIM) != lat->dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "corrupt region box");
    for (int d = 0; d < lat->dim; d++)
        box->hi[d] = (int64_t)v[d];
    return cm_lattice_check(lat, msg, msg_size);
}

static cm_status read_pages(sqlite3 *db, cm_region *r, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    uint64_t seen = 0;
    if (sqlite3_prepare_v2(db,
                           "SELECT first_cell, cells, image, grp, step FROM pages WHERE region=1 "
                           "ORDER BY first_cell",
                           -1, &st, NULL))
        return db_error(db, "read pages", msg, msg_size);
    cm_status status = CM_OK;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const uint64_t first = (uint64_t)sqlite3_column_int64(st, 0);
        const uint64_t n = (uint64_t)sqlite3_column_int64(st, 1);
        uint32_t *arrays[3] = {r->image, r->group, r->step};
        if (first != seen || n == 0 || first + n > r->ncells) {
            status = cm_fail(CM_EFORMAT, msg, msg_size, "corrupt page table at cell %llu",
                             (unsigned long long)first);
            break;
        }
        for (int a = 0; a < 3 && status == CM_OK; a++) {
            const void *blob = sqlite3_column_blob(st, 2 + a);
            if ((uint64_t)sqlite3_column_bytes(st, 2 + a) != 4 * n || !blob)
                status = cm_fail(CM_EFORMAT, msg, msg_size, "corrupt page blob");
            else
                get_u32le(arrays[a] + first, blob, n);
        }
        seen += n;
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != r->ncells)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "pages cover %llu of %llu cells",
                         (unsigned long long)seen, (unsigned long long)r->ncells);
    return status;
}

cm_status cm_store_load(const char *path, cm_lattice *lat, cm_region *r, char *model_name,
                        size_t name_size, char *msg, size_t msg_size)
{
    sqlite3 *db = NULL;
    cm_box box;
    memset(r, 0, sizeof *r);
    cm_status st = open_checked(path, &db, msg, msg_size);
    if (st == CM_OK)
        st = read_text(db, "SELECT value FROM meta WHERE key='model'", model_name, name_size, msg,
                       msg_size);
    if (st == CM_OK)
        st = read_lattice(db, lat, &box, msg, msg_size);
    if (st == CM_OK)
        st = cm_region_alloc(r, &box, msg, msg_size);
    if (st == CM_OK)
        st = read_pages(db, r, msg, msg_size);
    if (st == CM_OK) {
        uint32_t max_group = 0;
        for (uint64_t i = 0; i < r->ncells; i++)
            if (r->group[i] != CM_GROUP_NONE && r->group[i] > max_group)
                max_group = r->group[i];
        r->ngroups = max_group;
    }
    if (st != CM_OK)
        cm_region_free(r);
    sqlite3_close(db);
    return st;
}
