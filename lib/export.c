/* lib/export.c - a file's cells and groups for other tools (lib/export.h). */
#include "lib/export.h"

#include <errno.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/numtext.h"
#include "lib/json.h"
#include "lib/outfile.h"
#include "lib/parse.h"
#include "lib/project.h"
#include "render/palette.h"

enum { SLAB_CELLS = 1 << 22 }; /* cells flattened at a time */

/* What the arrays' sidecars say. */
typedef struct array_export {
    const char *labels, *steps; /* FILE.npy, or NULL */
    const char *source;         /* the .cmdb file, for the sidecar */
    const cm_store_info *info;
    const cm_group_info *groups; /* groups 1..ngroups */
    uint32_t ngroups;
    const char *const *names; /* the state coordinates' names */
    const cm_attractor_set *attractors; /* not NULL: labels by attractors */
    const cm_computed *computed;        /* where sink cells' sequences go beyond a slab */
} array_export;

/* ---- arrays ------------------------------------------------------------ */

void export_sidecar_path(const char *npy, char *out, size_t size)
{
    const size_t n = strlen(npy);
    const bool has_suffix = n > 4 && strcmp(npy + n - 4, ".npy") == 0;
    snprintf(out, size, "%.*s.json", (int)(has_suffix ? n - 4 : n), npy);
}

/* The .npy header (format 1.0): a dict padded with spaces to a multiple
 * of 64 bytes, then a newline. */
static bool array_npy_header(FILE *f, const cm_box *w)
{
    char header[512];
    int n = snprintf(header, sizeof header, "{'descr': '<i4', 'fortran_order': False, 'shape': (");
    for (int d = 0; d < w->dim; d++)
        n += snprintf(header + n, sizeof header - (size_t)n, "%lld,%s",
                      (long long)(w->hi[d] - w->lo[d]), d + 1 < w->dim ? " " : "");
    n += snprintf(header + n, sizeof header - (size_t)n, "), }");
    while ((10 + n + 1) % 64)
        header[n++] = ' ';
    header[n++] = '\n';
    const unsigned char magic[10] = {
        0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(n & 0xff), (unsigned char)(n >> 8)};
    return fwrite(magic, 1, 10, f) == 10 && fwrite(header, 1, (size_t)n, f) == (size_t)n;
}

static void put_i32(unsigned char *p, int32_t v)
{
    const uint32_t u = (uint32_t)v;
    for (int b = 0; b < 4; b++)
        p[b] = (unsigned char)(u >> (8 * b));
}

/* The slab's cells in C order (dimension 0 slowest): one int32 each, the
 * label of each cell (label[index] by attractors, else its group; -1 not
 * computed); in_window counts the cells of each group, by_label those of
 * each label (at label + 2: -2 and -1 first). */
static bool write_slab(const cm_region *flat, const int32_t *label, FILE *labels, FILE *steps,
                       uint64_t *in_window, uint64_t *by_label)
{
    const cm_box *b = &flat->box;
    const int dim = b->dim;
    int64_t n[CM_MAX_DIM], i[CM_MAX_DIM] = {0};
    for (int d = 0; d < dim; d++)
        n[d] = b->hi[d] - b->lo[d];
    const uint64_t cells = cm_box_cells(b);
    bool ok = true;
    for (uint64_t k = 0; k < cells && ok; k++) {
        uint64_t index = 0, stride = 1; /* the flat region has dimension 0 fastest */
        for (int d = 0; d < dim; d++) {
            index += (uint64_t)i[d] * stride;
            stride *= (uint64_t)n[d];
        }
        const uint32_t g = flat->group[index];
        unsigned char v[4];
        const int32_t l = label                ? label[index]
                          : g == CM_GROUP_NONE ? -1
                                               : (int32_t)g;
        if (g != CM_GROUP_NONE)
            in_window[g]++;
        by_label[l + 2]++;
        put_i32(v, l);
        ok = !labels || fwrite(v, 1, 4, labels) == 4;
        put_i32(v, g == CM_GROUP_NONE ? -1 : (int32_t)flat->step[index]);
        ok = ok && (!steps || fwrite(v, 1, 4, steps) == 4);
        for (int d = dim - 1; d >= 0; d--) { /* the next index in C order */
            if (++i[d] < n[d])
                break;
            i[d] = 0;
        }
    }
    return ok;
}

static void write_sidecar_groups(json *j, const array_export *x, const cm_lattice *lat,
                                 const uint64_t *in_window)
{
    uint8_t *classes = calloc((size_t)x->ngroups + 1, 1);
    if (classes)
        cm_palette_classes(NULL, x->groups, x->ngroups, lat, in_window + 1, 1, NULL, classes);
    json_array(j, "groups");
    for (uint32_t k = 0; k < x->ngroups; k++) {
        if (!in_window[k + 1])
            continue;
        const cm_group_info *g = &x->groups[k];
        json_object(j, NULL);
        json_group_fields(j, g, lat);
        json_uint(j, "in_view", in_window[k + 1]);
        if (classes) {
            const cm_rgb c = cm_class_colour(NULL, classes[k]);
            char hex[8];
            snprintf(hex, sizeof hex, "#%02x%02x%02x", c.r, c.g, c.b);
            json_str(j, "colour", hex);
        }
        json_object_end(j);
    }
    json_array_end(j);
    free(classes);
}

/* The attractors with cells in the window, as solve --json lists them,
 * with their cells in it. */
static void write_sidecar_attractors(json *j, const array_export *x, const cm_lattice *lat,
                                     const uint64_t *in_window)
{
    const cm_attractor_set *s = x->attractors;
    json_array(j, "attractors");
    for (uint32_t k = 0; k < s->n; k++) {
        if (!in_window[s->a[k].id + 2])
            continue;
        const cm_attractor *a = &s->a[k];
        json_object(j, NULL);
        json_attractor_fields(j, a, lat);
        json_uint(j, "in_view", in_window[a->id + 2]);
        json_object_end(j);
    }
    json_array_end(j);
}

static cm_status write_sidecar(const char *npy, const char *kind, const array_export *x,
                               const cm_lattice *lat, const cm_box *w, const uint64_t *in_window,
                               const uint64_t *by_label, char *msg, size_t msg_size)
{
    const bool by_attractors = x->attractors && strcmp(kind, "labels") == 0;
    char path[CM_OUTPUT_PATH_MAX];
    export_sidecar_path(npy, path, sizeof path);
    outfile o;
    const cm_status st = outfile_begin(path, &o, msg, msg_size);
    if (st != CM_OK)
        return st;
    json j;
    json_begin(&j, o.f, "export");
    json_str(&j, "array", kind);
    json_str(&j, "file", npy);
    json_str(&j, "source", x->source);
    json_str(&j, "dtype", "<i4");
    json_str(&j, "order", "C");
    json_array(&j, "shape");
    for (int d = 0; d < w->dim; d++)
        json_int(&j, NULL, w->hi[d] - w->lo[d]);
    json_array_end(&j);
    json_array(&j, "axes"); /* axis k of the array is state dimension k */
    for (int d = 0; d < w->dim; d++)
        json_str(&j, NULL, x->names[d]);
    json_array_end(&j);
    json_array(&j, "first_cell");
    for (int d = 0; d < w->dim; d++)
        json_int(&j, NULL, w->lo[d]);
    json_array_end(&j);
    json_box(&j, "box", lat, w);
    json_lattice(&j, lat);
    json_str(&j, "model", x->info->model);
    json_raw(&j, "params", x->info->params);
    json_str(&j, "by", by_attractors ? "attractors" : "groups");
    json_object(&j, "values");
    json_str(&j, "-1", "not computed");
    if (by_attractors) {
        json_str(&j, "-2", "outside: the sequence left the computed cells, or its group's true "
                           "orbit was undecided");
        json_str(&j, "0", "diverged: its group's true orbit diverges");
        json_str(&j, "k", "attractor k");
    } else if (strcmp(kind, "labels") == 0) {
        json_str(&j, "0", "the sink (the sequence leaves the cluster)");
        json_str(&j, "k", "group k");
    } else {
        json_str(&j, "k", "steps to the group's periodic cells");
    }
    json_object_end(&j);
    if (by_attractors)
        write_sidecar_attractors(&j, x, lat, by_label);
    else
        write_sidecar_groups(&j, x, lat, in_window);
    json_end(&j);
    return outfile_end(&o, true, msg, msg_size);
}

/* ---- cells ------------------------------------------------------------- */

static int ends_with(const char *s, const char *suffix)
{
    const size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

typedef enum { OUT_CSV, OUT_NPY, OUT_SQLITE } out_kind;

/* One cells output being written. */
typedef struct cell_out {
    out_kind kind;
    const char *path;
    cm_output out; /* out.tmp is written, then moved to path */
    FILE *f;
    sqlite3 *db;
    sqlite3_stmt *insert;
    uint64_t rows;
    long shape_at; /* .npy: where the row count is written at the end */
    const char *const *names; /* the state coordinates' names */
    const char *source;       /* the .cmdb file exported */
    int dim;
} cell_out;

static int records_npy_header(cell_out *o, int dim)
{
    char descr[512];
    size_t used = 0;
    for (int d = 0; d < dim; d++)
        used +=
            (size_t)snprintf(descr + used, sizeof descr - used, "('i%s', '<i8'), ", o->names[d]);
    for (int d = 0; d < dim; d++)
        used +=
            (size_t)snprintf(descr + used, sizeof descr - used, "('%s', '<f8'), ", o->names[d]);
    snprintf(descr + used, sizeof descr - used,
             "('grp', '<u4'), ('step', '<u4'), ('periodic', '|u1'), ('attractor', '<i4')");
    char header[1024];
    int n = snprintf(header, sizeof header, "{'descr': [%s], 'fortran_order': False, 'shape': (",
                     descr);
    o->shape_at = 10 + n;
    n += snprintf(header + n, sizeof header - (size_t)n, "%20d,), }", 0);
    while ((10 + n + 1) % 64)
        header[n++] = ' ';
    header[n++] = '\n';
    const unsigned char magic[10] = {
        0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(n & 0xff), (unsigned char)(n >> 8)};
    return fwrite(magic, 1, 10, o->f) == 10 && fwrite(header, 1, (size_t)n, o->f) == (size_t)n;
}

/* "[v0,v1,...]", each number the shortest that reads back */
static void json_numbers_text(const double *v, int n, char *out, size_t size)
{
    size_t used = (size_t)snprintf(out, size, "[");
    for (int d = 0; d < n && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", d ? "," : "", CM_NUM(v[d]));
    if (used < size)
        snprintf(out + used, size - used, "]");
}

static int sqlite_begin(cell_out *o, int dim, const cm_store_info *info)
{
    char sql[1024];
    size_t used = (size_t)snprintf(sql, sizeof sql, "CREATE TABLE cells(");
    for (int d = 0; d < dim; d++)
        used += (size_t)snprintf(sql + used, sizeof sql - used, "i%s INTEGER, ", o->names[d]);
    for (int d = 0; d < dim; d++)
        used += (size_t)snprintf(sql + used, sizeof sql - used, "%s REAL, ", o->names[d]);
    snprintf(sql + used, sizeof sql - used,
             "grp INTEGER, step INTEGER, periodic INTEGER, attractor INTEGER);"
             "CREATE TABLE groups(id INTEGER PRIMARY KEY, period INTEGER, basin_cells INTEGER,"
             " is_sink INTEGER, centre TEXT, lo TEXT, hi TEXT, anchor TEXT, kind TEXT,"
             " attractor INTEGER);"
             "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT);");
    if (sqlite3_open(o->out.tmp, &o->db) != SQLITE_OK ||
        sqlite3_exec(o->db, "PRAGMA journal_mode=OFF; PRAGMA synchronous=OFF; BEGIN", NULL, NULL,
                     NULL) != SQLITE_OK ||
        sqlite3_exec(o->db, sql, NULL, NULL, NULL) != SQLITE_OK)
        return 0;
    sqlite3_stmt *st = NULL;
    char origin[CM_MAX_DIM * CM_NUM_TEXT + 8], width[CM_MAX_DIM * CM_NUM_TEXT + 8],
        state[CM_MAX_DIM * 32 + 8], dims[8];
    json_numbers_text(info->lattice.origin, dim, origin, sizeof origin);
    json_numbers_text(info->lattice.width, dim, width, sizeof width);
    size_t at = (size_t)snprintf(state, sizeof state, "[");
    for (int d = 0; d < dim && at < sizeof state; d++)
        at += (size_t)snprintf(state + at, sizeof state - at, "%s\"%s\"", d ? "," : "",
                               o->names[d]);
    if (at < sizeof state)
        snprintf(state + at, sizeof state - at, "]");
    snprintf(dims, sizeof dims, "%d", dim);
    /* what a reader needs to place a cell without the .cmdb: the cell
     * (i...) has centre origin + (i + 1/2) width */
    const char *rows[][2] = {{"model", info->model},          {"params", info->params},
                             {"command", info->command},      {"source", o->source},
                             {"dim", dims},                   {"state", state},
                             {"lattice_origin", origin},      {"lattice_width", width}};
    if (sqlite3_prepare_v2(o->db, "INSERT INTO meta VALUES(?, ?)", -1, &st, NULL) != SQLITE_OK)
        return 0;
    int ok = 1;
    for (size_t k = 0; k < sizeof rows / sizeof rows[0] && ok; k++) {
        sqlite3_bind_text(st, 1, rows[k][0], -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, rows[k][1], -1, SQLITE_STATIC);
        ok = sqlite3_step(st) == SQLITE_DONE;
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    used = (size_t)snprintf(sql, sizeof sql, "INSERT INTO cells VALUES(");
    for (int k = 0; k < 2 * dim + 4; k++)
        used += (size_t)snprintf(sql + used, sizeof sql - used, "%s?", k ? "," : "");
    snprintf(sql + used, sizeof sql - used, ")");
    return ok && sqlite3_prepare_v2(o->db, sql, -1, &o->insert, NULL) == SQLITE_OK;
}

/* Starts output o; on failure says why in msg. */
static int out_begin(cell_out *o, int dim, const cm_store_info *info, char *msg, size_t msg_size)
{
    if (cm_output_begin(&o->out, o->path, false, msg, msg_size) != CM_OK)
        return 0;
    snprintf(msg, msg_size, "cannot write %s", o->path);
    if (o->kind == OUT_SQLITE)
        return sqlite_begin(o, dim, info);
    if (!(o->f = fopen(o->out.tmp, "wb"))) {
        snprintf(msg, msg_size, "cannot write %s: %s", o->path, strerror(errno));
        return 0;
    }
    if (o->kind == OUT_NPY)
        return records_npy_header(o, dim);
    for (int d = 0; d < dim; d++)
        fprintf(o->f, "i%s,", o->names[d]);
    for (int d = 0; d < dim; d++)
        fprintf(o->f, "%s,", o->names[d]);
    return fprintf(o->f, "grp,step,periodic,attractor\n") > 0;
}

static int out_row(cell_out *o, int dim, const int64_t *cell, const double *x, uint32_t grp,
                   uint32_t step, int periodic, int32_t attractor)
{
    o->rows++;
    if (o->kind == OUT_CSV) {
        for (int d = 0; d < dim; d++)
            fprintf(o->f, "%lld,", (long long)cell[d]);
        for (int d = 0; d < dim; d++)
            fprintf(o->f, "%.17g,", x[d]);
        return fprintf(o->f, "%u,%u,%d,%d\n", grp, step, periodic, (int)attractor) > 0;
    }
    if (o->kind == OUT_NPY) {
        unsigned char row[CM_MAX_DIM * 16 + 13];
        size_t n = 0;
        for (int d = 0; d < dim; d++, n += 8)
            for (int b = 0; b < 8; b++)
                row[n + (size_t)b] = (unsigned char)((uint64_t)cell[d] >> (8 * b));
        for (int d = 0; d < dim; d++, n += 8) {
            uint64_t bits;
            memcpy(&bits, &x[d], 8);
            for (int b = 0; b < 8; b++)
                row[n + (size_t)b] = (unsigned char)(bits >> (8 * b));
        }
        const uint32_t u[2] = {grp, step};
        for (int k = 0; k < 2; k++, n += 4)
            for (int b = 0; b < 4; b++)
                row[n + (size_t)b] = (unsigned char)(u[k] >> (8 * b));
        row[n++] = (unsigned char)periodic;
        for (int b = 0; b < 4; b++)
            row[n++] = (unsigned char)((uint32_t)attractor >> (8 * b));
        return fwrite(row, 1, n, o->f) == n;
    }
    int col = 1;
    for (int d = 0; d < dim; d++)
        sqlite3_bind_int64(o->insert, col++, cell[d]);
    for (int d = 0; d < dim; d++)
        sqlite3_bind_double(o->insert, col++, x[d]);
    sqlite3_bind_int64(o->insert, col++, grp);
    sqlite3_bind_int64(o->insert, col++, step);
    sqlite3_bind_int(o->insert, col++, periodic);
    sqlite3_bind_int(o->insert, col, attractor);
    const int ok = sqlite3_step(o->insert) == SQLITE_DONE;
    sqlite3_reset(o->insert);
    return ok;
}

static int numbers_json(char *buf, size_t size, const double *v, int n)
{
    size_t used = (size_t)snprintf(buf, size, "[");
    for (int d = 0; d < n && used < size; d++)
        used += (size_t)snprintf(buf + used, size - used, "%s%.17g", d ? "," : "", v[d]);
    return snprintf(buf + used, used < size ? size - used : 0, "]") > 0;
}

static int sqlite_groups(cell_out *o, const cm_lattice *lat, const cm_group_info *g, uint32_t n,
                         uint64_t sink, const cm_attractor_set *att)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(o->db, "INSERT INTO groups VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", -1,
                           &st, NULL) != SQLITE_OK)
        return 0;
    int ok = 1;
    for (uint32_t k = 0; k <= n && ok; k++) {
        char centre[512], lo[512], hi[512], anchor[512];
        if (k == 0) {
            sqlite3_bind_int(st, 1, 0);
            sqlite3_bind_int(st, 2, 1);
            sqlite3_bind_int64(st, 3, (sqlite3_int64)sink);
            sqlite3_bind_int(st, 4, 1);
            for (int c = 5; c <= 8; c++)
                sqlite3_bind_null(st, c);
            sqlite3_bind_text(st, 9, "sink", -1, SQLITE_STATIC);
            sqlite3_bind_null(st, 10);
        } else {
            const cm_group_info *gi = &g[k - 1];
            double a[CM_MAX_DIM];
            for (int d = 0; d < lat->dim; d++)
                a[d] = (double)gi->anchor[d];
            numbers_json(centre, sizeof centre, gi->centre, lat->dim);
            numbers_json(lo, sizeof lo, gi->lo, lat->dim);
            numbers_json(hi, sizeof hi, gi->hi, lat->dim);
            numbers_json(anchor, sizeof anchor, a, lat->dim);
            sqlite3_bind_int64(st, 1, gi->id);
            sqlite3_bind_int64(st, 2, gi->period);
            sqlite3_bind_int64(st, 3, (sqlite3_int64)gi->basin_cells);
            sqlite3_bind_int(st, 4, 0);
            sqlite3_bind_text(st, 5, centre, -1, SQLITE_TRANSIENT);
            sqlite3_bind_text(st, 6, lo, -1, SQLITE_TRANSIENT);
            sqlite3_bind_text(st, 7, hi, -1, SQLITE_TRANSIENT);
            sqlite3_bind_text(st, 8, anchor, -1, SQLITE_TRANSIENT);
            sqlite3_bind_text(st, 9, cm_group_kind_name(gi->kind), -1, SQLITE_STATIC);
            sqlite3_bind_int64(st, 10, cm_attractor_fate(att, gi->id));
        }
        ok = sqlite3_step(st) == SQLITE_DONE;
        sqlite3_reset(st);
    }
    sqlite3_finalize(st);
    return ok;
}

/* Completes the output and moves it into place (cellmap/output.h); on
 * failure removes it and, if it was the first failure (ok), says why. */
/* Indexes for the obvious queries: the cells of a group, a cell by its
 * indices, and groups by kind. */
static int sqlite_indexes(cell_out *o)
{
    char sql[512];
    size_t used = (size_t)snprintf(sql, sizeof sql,
                                   "CREATE INDEX cells_grp ON cells(grp);"
                                   "CREATE INDEX groups_kind ON groups(kind);"
                                   "CREATE UNIQUE INDEX cells_cell ON cells(");
    for (int d = 0; d < o->dim && used < sizeof sql; d++)
        used += (size_t)snprintf(sql + used, sizeof sql - used, "%si%s", d ? "," : "", o->names[d]);
    if (used < sizeof sql)
        snprintf(sql + used, sizeof sql - used, ");");
    return sqlite3_exec(o->db, sql, NULL, NULL, NULL) == SQLITE_OK;
}

/* Why a write to o failed (err: errno of a stream's write): the file
 * system's reason, which SQLite keeps too (but for a full disk, which it
 * reports as SQLITE_FULL alone), with the fix, else SQLite's message. */
static void out_failed(const cell_out *o, int err, char *msg, size_t msg_size)
{
    const int sys = !o->db                                         ? err
                    : (sqlite3_errcode(o->db) & 0xff) == SQLITE_FULL ? ENOSPC
                                                                   : sqlite3_system_errno(o->db);
    if (sys || !o->db)
        cm_output_fail(o->path, sys ? sys : EIO, msg, msg_size);
    else
        snprintf(msg, msg_size, "cannot write %s: %s", o->path, sqlite3_errmsg(o->db));
}

static int out_end(cell_out *o, int ok, char *msg, size_t msg_size)
{
    const int was_ok = ok;
    if (o->kind == OUT_NPY && ok && o->f) {
        char shape[32];
        snprintf(shape, sizeof shape, "%20llu", (unsigned long long)o->rows);
        ok = fseek(o->f, o->shape_at, SEEK_SET) == 0 && fwrite(shape, 1, 20, o->f) == 20;
    }
    if (o->f) { /* the reason of a failure, unless an earlier one was given */
        char ignored[8];
        if (cm_output_close_stream(&o->out, o->f, ok ? msg : ignored,
                                   ok ? msg_size : sizeof ignored) != CM_OK)
            ok = 0;
        o->f = NULL;
    }
    if (o->db) {
        sqlite3_finalize(o->insert);
        if (ok && !sqlite_indexes(o))
            ok = 0, snprintf(msg, msg_size, "cannot index %s: %s", o->path, sqlite3_errmsg(o->db));
        if (ok && sqlite3_exec(o->db, "COMMIT", NULL, NULL, NULL) != SQLITE_OK)
            ok = 0, out_failed(o, 0, msg, msg_size);
        ok = (sqlite3_close(o->db) == SQLITE_OK) && ok;
        o->db = NULL;
    }
    if (was_ok && !ok && !strstr(msg, o->path))
        snprintf(msg, msg_size, "cannot complete %s", o->path);
    if (ok && cm_output_commit(&o->out, msg, msg_size) != CM_OK)
        ok = 0;
    cm_output_abandon(&o->out);
    return ok;
}

static int write_groups_csv(const char *path, const char *const *names, const cm_lattice *lat,
                         const cm_group_info *g, uint32_t n, uint64_t sink,
                         const cm_attractor_set *att, char *msg, size_t msg_size)
{
    cell_out o;
    memset(&o, 0, sizeof o);
    o.kind = OUT_CSV;
    o.path = path;
    o.names = names;
    if (cm_output_begin(&o.out, path, false, msg, msg_size) != CM_OK)
        return 0;
    if (!(o.f = fopen(o.out.tmp, "w"))) {
        snprintf(msg, msg_size, "cannot write %s: %s", path, strerror(errno));
        return 0;
    }
    const char *parts[] = {"centre_", "lo_", "hi_", "anchor_i"};
    fprintf(o.f, "id,period,basin_cells,is_sink");
    for (int p = 0; p < 4; p++)
        for (int d = 0; d < lat->dim; d++)
            fprintf(o.f, ",%s%s", parts[p], names[d]);
    fprintf(o.f, ",kind,attractor\n0,1,%llu,1", (unsigned long long)sink);
    for (int k = 0; k < 4 * lat->dim; k++)
        fprintf(o.f, ",");
    fprintf(o.f, ",sink,\n");
    for (uint32_t k = 0; k < n; k++) {
        fprintf(o.f, "%u,%u,%llu,0", g[k].id, g[k].period, (unsigned long long)g[k].basin_cells);
        const double *v[3] = {g[k].centre, g[k].lo, g[k].hi};
        for (int p = 0; p < 3; p++)
            for (int d = 0; d < lat->dim; d++)
                fprintf(o.f, ",%.17g", v[p][d]);
        for (int d = 0; d < lat->dim; d++)
            fprintf(o.f, ",%lld", (long long)g[k].anchor[d]);
        fprintf(o.f, ",%s,%lld\n", cm_group_kind_name(g[k].kind),
                (long long)cm_attractor_fate(att, g[k].id));
    }
    return out_end(&o, 1, msg, msg_size);
}

/* Walks the window in slabs along the last dimension, reading regions
 * back as needed, and writes every computed cell to each output. */
/* The rows of the window's cells, a slab at a time, each with its
 * attractor (cm_attractor_cell_labels over att and the cluster's exits). */
static cm_status write_rows(cm_cluster *c, const cm_box *window, const cm_attractor_set *att,
                            const cm_computed *computed, cell_out *outs, int nouts,
                            const work_hooks *hooks, char *msg, size_t msg_size)
{
    uint64_t done = 0;
    const int dim = c->lat.dim, last = dim - 1;
    const uint64_t row =
        cm_box_cells(window) /
        (uint64_t)(window->hi[last] - window->lo[last] ? window->hi[last] - window->lo[last] : 1);
    const int64_t step = row >= SLAB_CELLS ? 1 : (int64_t)(SLAB_CELLS / (row ? row : 1));
    for (int64_t at = window->lo[last]; at < window->hi[last]; at += step) {
        cm_box slab = *window;
        slab.lo[last] = at;
        slab.hi[last] = at + step < window->hi[last] ? at + step : window->hi[last];
        cm_region flat;
        cm_status st = cm_cluster_flatten(c, &slab, &flat, msg, msg_size);
        if (st != CM_OK)
            return st;
        int32_t *label = cm_cells_array((flat.ncells + 1) * sizeof *label);
        st = label ? cm_attractor_cell_labels(att, &flat, computed, label, msg, msg_size)
                   : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
        for (uint64_t i = 0; i < flat.ncells && st == CM_OK; i++) {
            if (flat.group[i] == CM_GROUP_NONE)
                continue;
            int64_t cell[CM_MAX_DIM];
            double x[CM_MAX_DIM];
            cm_box_cell(&slab, i, cell);
            cm_lattice_centre(&c->lat, cell, x);
            for (int k = 0; k < nouts && st == CM_OK; k++)
                if (!out_row(&outs[k], dim, cell, x, flat.group[i], flat.step[i],
                             cm_is_periodic(&flat, i), label[i])) {
                    out_failed(&outs[k], errno, msg, msg_size);
                    st = CM_EIO;
                }
        }
        done += flat.ncells;
        free(label);
        cm_region_free(&flat);
        const char *why = st == CM_OK ? work_stop(hooks) : NULL;
        if (why)
            st = cm_fail(CM_ECANCELED, msg, msg_size, "%s: the cells' table and flat database were not written",
                         why);
        if (st != CM_OK)
            return st;
        work_progress(hooks, done, NULL);
    }
    return CM_OK;
}

/* ---- the exporter ------------------------------------------------------ */

cm_status exporter_open(exporter *x, cm_store *s, const cm_store_info *info, cm_cluster *c,
                        const cm_box *window, const char *source, const cm_attractor_options *o,
                        char *msg, size_t msg_size)
{
    memset(x, 0, sizeof *x);
    if (c->nregions == 0) /* as project_open_records refuses a file */
        return cm_fail(CM_EINVAL, msg, msg_size, "%s holds no region yet", source);
    x->store = s;
    x->info = info;
    x->c = c;
    x->source = source;
    if (window)
        x->window = *window;
    else
        cm_cluster_bounds(c, &x->window);
    project_state_names(info, x->names);
    x->groups = calloc((size_t)info->groups + 1, sizeof *x->groups);
    if (!x->groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", info->groups);
    cm_status st = cm_store_groups(s, x->groups, info->groups, &x->sink, msg, msg_size);
    if (st != CM_OK)
        return st;
    char why[1024];
    st = file_attractors(s, info, NULL, c, &x->ends, x->groups, o, &x->att, why, sizeof why);
    if (st != CM_OK) /* nothing is written without them */
        cm_fail(st, msg, msg_size, "%s: %s", source, why);
    return st;
}

void exporter_close(exporter *x)
{
    cluster_ends_close(&x->ends);
    cm_attractors_free(&x->att);
    free(x->node_labels);
    x->node_labels = NULL;
    free(x->groups);
    x->groups = NULL;
}

/* The nodes' labels, made once. */
static cm_status node_labels(exporter *x, char *msg, size_t msg_size)
{
    return x->node_labels ? CM_OK
                          : cm_cluster_node_labels(x->c, &x->att, &x->node_labels, msg, msg_size);
}

cm_status exporter_labels_only(exporter *x, char *msg, size_t msg_size)
{
    if (x->c->resolved_cells || x->node_labels)
        return CM_OK;
    cm_status st = cm_node_labels_open(x->c, &x->att, &x->node_labels, msg, msg_size);
    if (st != CM_OK)
        return st;
    /* the open nodes have their exits' fates: what gave them goes */
    free(x->att.exit_cell);
    free(x->att.exit_label);
    x->att.exit_cell = NULL;
    x->att.exit_label = NULL;
    x->att.nexits = 0;
    cluster_ends_close(&x->ends);
    cm_cluster_release_open(x->c); /* cluster_ends_open refuses it from here on */
    st = cm_node_labels_settle(x->c, &x->att, x->node_labels, msg, msg_size);
    if (st != CM_OK) {
        free(x->node_labels);
        x->node_labels = NULL;
    }
    return st;
}

cm_status export_window(const cm_cluster *c, const char *text, cm_box *box, char *msg,
                        size_t msg_size)
{
    const cm_lattice *lat = &c->lat;
    cm_cluster_bounds(c, box);
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    if (!parse_ranges(text, lo, hi, &n, CM_MAX_DIM))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the window '%s' is not X0:X1[,Y0:Y1...] with X0 < X1", text);
    if (n != lat->dim)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the window has %d range(s) but the lattice has dimension %d", n, lat->dim);
    for (int d = 0; d < n; d++) {
        const double a = ceil((lo[d] - lat->origin[d]) / lat->width[d] - 0.5);
        const double b = floor((hi[d] - lat->origin[d]) / lat->width[d] - 0.5) + 1;
        const int64_t clo = box->lo[d], chi = box->hi[d];
        box->lo[d] = a > (double)clo ? (a < (double)chi ? (int64_t)a : chi) : clo;
        box->hi[d] = b < (double)chi ? (b > (double)box->lo[d] ? (int64_t)b : box->lo[d]) : chi;
        if (box->lo[d] >= box->hi[d]) /* nothing to write: said before any file is made */
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the window '%s' holds no cell centre of the file in dimension %d "
                           "(its cells are %.9g wide, their centres from %.9g to %.9g): widen "
                           "the window",
                           text, d + 1, lat->width[d],
                           lat->origin[d] + ((double)clo + 0.5) * lat->width[d],
                           lat->origin[d] + ((double)chi - 0.5) * lat->width[d]);
    }
    return CM_OK;
}

cm_status export_groups(const exporter *x, const char *path, char *msg, size_t msg_size)
{
    if (write_groups_csv(path, x->names, &x->c->lat, x->groups, x->info->groups, x->sink, &x->att,
                         msg, msg_size))
        return CM_OK;
    return CM_EIO;
}

cm_status export_groups_of_file(const char *file, const char *path,
                                const cm_attractor_options *o, char *msg, size_t msg_size)
{
    cm_store *s = NULL;
    cm_store_info info;
    cm_group_info *g = NULL;
    cm_attractor_set att;
    uint64_t sink = 0;
    memset(&att, 0, sizeof att);
    cm_status st = project_open_records(file, true, &s, &info, msg, msg_size);
    if (st == CM_OK && !(g = calloc((size_t)info.groups + 1, sizeof *g)))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", info.groups);
    if (st == CM_OK)
        st = cm_store_groups(s, g, info.groups, &sink, msg, msg_size);
    cm_status got = CM_ENOTFOUND;
    if (st == CM_OK && !attractor_options_given(o))
        got = cm_store_get_attractors(s, info.lattice.dim, info.groups, &att, NULL, msg, msg_size);
    st = got == CM_ENOTFOUND ? st : got;
    cm_store_snapshot_end(s);
    if (st == CM_OK && got == CM_ENOTFOUND)
        st = CM_ENOTFOUND; /* found from the cells: the cluster is needed */
    if (st == CM_OK) {
        const char *names[CM_MAX_DIM];
        project_state_names(&info, names);
        if (!write_groups_csv(path, names, &info.lattice, g, info.groups, sink, &att, msg,
                              msg_size))
            st = CM_EIO;
    }
    cm_attractors_free(&att);
    free(g);
    char ignored[256];
    cm_store_close(s, ignored, sizeof ignored);
    return st;
}

cm_status export_cells(exporter *x, const char *cells, const char *flat, const work_hooks *hooks,
                       uint64_t *rows, char *msg, size_t msg_size)
{
    cm_cluster *c = x->c;
    cell_out outs[2];
    int nouts = 0;
    memset(outs, 0, sizeof outs);
    *rows = 0;
    cluster_ends_lookup(&x->ends, c); /* the attractors know every exit's fate */
    for (int k = 0; k < 2; k++) {
        outs[k].names = x->names;
        outs[k].source = x->source;
        outs[k].dim = c->lat.dim;
    }
    if (cells) {
        outs[nouts].kind = ends_with(cells, ".npy") ? OUT_NPY : OUT_CSV;
        outs[nouts++].path = cells;
    }
    if (flat) {
        outs[nouts].kind = OUT_SQLITE;
        outs[nouts++].path = flat;
    }
    int ok = 1;
    for (int k = 0; k < nouts && ok; k++)
        ok = out_begin(&outs[k], c->lat.dim, x->info, msg, msg_size);
    if (ok && flat &&
        !sqlite_groups(&outs[nouts - 1], &c->lat, x->groups, x->info->groups, x->sink, &x->att))
        ok = 0, snprintf(msg, msg_size, "cannot write %.900s", flat);
    cm_status st = CM_OK;
    if (ok && nouts)
        ok = (st = write_rows(c, &x->window, &x->att, &x->ends.computed, outs, nouts, hooks, msg,
                              msg_size)) == CM_OK;
    for (int k = 0; k < nouts; k++)
        ok = out_end(&outs[k], ok, msg, msg_size) && ok;
    if (!ok)
        return st != CM_OK ? st : CM_EIO;
    *rows = nouts ? outs[0].rows : 0;
    return CM_OK;
}

/* Called with each slab of a window and its cells' labels by attractors
 * (NULL without attractors); false stops, the reason in msg. */
typedef bool (*slab_fn)(void *user, const cm_region *flat, const int32_t *label, char *msg,
                        size_t msg_size);

/* The window's cells a slab of about SLAB_CELLS at a time along dimension
 * 0 (the slowest in C order), labelled by att when not NULL; `what` says
 * what a stop request leaves undone. */
static cm_status each_slab(cm_cluster *c, const cm_box *window, const cm_attractor_set *att,
                           const cm_computed *computed, const work_hooks *hooks, const char *what,
                           slab_fn fn, void *user, char *msg, size_t msg_size)
{
    const uint64_t per_layer = cm_box_cells(window) / (uint64_t)(window->hi[0] - window->lo[0]);
    const int64_t layers = per_layer >= SLAB_CELLS ? 1 : (int64_t)(SLAB_CELLS / per_layer);
    uint64_t done = 0;
    cm_status st = CM_OK;
    msg[0] = '\0';
    for (int64_t at = window->lo[0]; at < window->hi[0] && st == CM_OK; at += layers) {
        cm_box slab = *window;
        slab.lo[0] = at;
        slab.hi[0] = at + layers < window->hi[0] ? at + layers : window->hi[0];
        cm_region flat;
        if ((st = cm_cluster_flatten(c, &slab, &flat, msg, msg_size)) != CM_OK)
            break;
        int32_t *label = att ? cm_cells_array((flat.ncells + 1) * sizeof *label) : NULL;
        if (att && !label)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
        else if (att)
            st = cm_attractor_cell_labels(att, &flat, computed, label, msg, msg_size);
        if (st == CM_OK && !fn(user, &flat, label, msg, msg_size))
            st = msg[0] ? CM_EIO : cm_fail(CM_EIO, msg, msg_size, "cannot write the arrays");
        free(label);
        done += flat.ncells;
        cm_region_free(&flat);
        const char *why = st == CM_OK ? work_stop(hooks) : NULL;
        if (why)
            st = cm_fail(CM_ECANCELED, msg, msg_size, "%s: %s", why, what);
        work_progress(hooks, done, NULL);
    }
    return st;
}

typedef struct slab_files {
    FILE *labels, *steps; /* either may be NULL */
    const array_export *x;
    uint64_t *in_window, *by_label;
} slab_files;

static bool write_files(void *user, const cm_region *flat, const int32_t *label, char *msg,
                        size_t msg_size)
{
    const slab_files *w = user;
    errno = 0;
    const bool ok = write_slab(flat, label, w->labels, w->steps, w->in_window, w->by_label);
    if (!ok) /* the file a write failed on, and why */
        cm_output_fail(w->labels && ferror(w->labels) ? w->x->labels : w->x->steps,
                       errno ? errno : EIO, msg, msg_size);
    return ok;
}

/* The strides of box's cells in C order (dimension 0 slowest), as the
 * labels arrays hold them. */
static void c_order_strides(const cm_box *box, int64_t *stride)
{
    stride[box->dim - 1] = 1;
    for (int d = box->dim - 2; d >= 0; d--)
        stride[d] = stride[d + 1] * (box->hi[d + 1] - box->lo[d + 1]);
}

typedef struct slab_memory {
    int32_t *labels;      /* the window's, C order */
    const cm_box *window;
} slab_memory;

static bool copy_slab(void *user, const cm_region *flat, const int32_t *label, char *msg,
                      size_t msg_size)
{
    (void)msg, (void)msg_size;
    const slab_memory *m = user;
    const cm_box *b = &flat->box, *w = m->window;
    int64_t stride[CM_MAX_DIM], i[CM_MAX_DIM] = {0};
    c_order_strides(w, stride);
    for (uint64_t k = 0; k < flat->ncells; k++) { /* the flat region has dimension 0 fastest */
        int64_t at = 0;
        for (int d = 0; d < w->dim; d++)
            at += (b->lo[d] + i[d] - w->lo[d]) * stride[d];
        const uint32_t g = flat->group[k];
        m->labels[at] = label ? label[k] : g == CM_GROUP_NONE ? -1 : (int32_t)g;
        for (int d = 0; d < w->dim && ++i[d] == b->hi[d] - b->lo[d]; d++)
            i[d] = 0;
    }
    return true;
}

cm_status export_labels(exporter *ex, const cm_box *box, int32_t *labels,
                        const work_hooks *hooks, char *msg, size_t msg_size)
{
    if (ex->c->resolved_cells) { /* sink sequences followed across regions */
        slab_memory m = {labels, box};
        cluster_ends_lookup(&ex->ends, ex->c);
        return each_slab(ex->c, box, &ex->att, &ex->ends.computed, hooks,
                         "the labels were not read", copy_slab, &m, msg, msg_size);
    }
    int64_t stride[CM_MAX_DIM];
    c_order_strides(box, stride);
    cm_status st = node_labels(ex, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_cell_labels(ex->c, &ex->att, ex->node_labels, box, stride, labels,
                                    msg, msg_size);
    work_progress(hooks, cm_box_cells(box), NULL);
    return st;
}

cm_status export_arrays(exporter *ex, const char *labels_path, const char *steps_path,
                        bool by_groups, const work_hooks *hooks, char *msg, size_t msg_size)
{
    cm_cluster *c = ex->c;
    const cm_box *window = &ex->window;
    cluster_ends_lookup(&ex->ends, c);
    const array_export arrays = {labels_path, steps_path, ex->source, ex->info, ex->groups,
                                 ex->info->groups, ex->names,
                                 labels_path && !by_groups ? &ex->att : NULL,
                                 &ex->ends.computed};
    const array_export *x = &arrays;
    outfile labels, steps;
    const bool has_labels = x->labels != NULL, has_steps = x->steps != NULL;
    const uint32_t labels_n = x->attractors ? x->attractors->n : x->ngroups;
    uint64_t *in_window = calloc((size_t)x->ngroups + 2, sizeof *in_window);
    uint64_t *by_label = calloc((size_t)labels_n + 3, sizeof *by_label);
    if (!in_window || !by_label) {
        free(in_window);
        free(by_label);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", x->ngroups);
    }
    cm_status st = has_labels ? outfile_begin(x->labels, &labels, msg, msg_size) : CM_OK;
    if (st == CM_OK && has_steps && (st = outfile_begin(x->steps, &steps, msg,
                                                        msg_size)) != CM_OK &&
        has_labels)
        outfile_end(&labels, false, (char[64]){0}, 64);
    if (st != CM_OK) {
        free(in_window);
        free(by_label);
        return st;
    }
    msg[0] = '\0';
    bool ok = (!has_labels || array_npy_header(labels.f, window)) &&
              (!has_steps || array_npy_header(steps.f, window));
    if (ok) {
        slab_files files = {has_labels ? labels.f : NULL, has_steps ? steps.f : NULL, x,
                            in_window, by_label};
        st = each_slab(ex->c, window, x->attractors, x->computed, hooks,
                       "the labels and steps arrays were not written", write_files, &files, msg,
                       msg_size);
        ok = st == CM_OK;
    }
    if (!ok && st == CM_OK)
        st = msg[0] ? CM_EIO : cm_fail(CM_EIO, msg, msg_size, "cannot write the arrays");
    /* the first failure's reason stays in msg; a close after it is silent */
    char later[1024];
    if (has_labels) {
        const cm_status end =
            outfile_end(&labels, ok, ok ? msg : later, ok ? msg_size : sizeof later);
        st = st == CM_OK ? end : st;
        ok = st == CM_OK;
    }
    if (has_steps) {
        const cm_status end =
            outfile_end(&steps, ok, ok ? msg : later, ok ? msg_size : sizeof later);
        st = st == CM_OK ? end : st;
        ok = st == CM_OK;
    }
    if (st == CM_OK && has_labels)
        st = write_sidecar(x->labels, "labels", x, &c->lat, window, in_window, by_label, msg,
                           msg_size);
    if (st == CM_OK && has_steps)
        st = write_sidecar(x->steps, "steps", x, &c->lat, window, in_window, by_label, msg,
                           msg_size);
    free(in_window);
    free(by_label);
    return st;
}

