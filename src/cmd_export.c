/* cellmap export: a .cmdb file's groups and cells as CSV, NumPy .npy or a
 * flat SQLite table, for users' own tools. Every output is written to a
 * temporary file and renamed when complete. */
#include <errno.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/output.h"
#include "src/args.h"
#include "src/outfile.h"
#include "src/commands.h"
#include "lib/attractor_report.h"
#include "src/attractor_opts.h"
#include "src/export_arrays.h"
#include "src/interrupt.h"
#include "src/progress.h"
#include "lib/project.h"

static const char export_help[] =
    "usage: cellmap export FILE.cmdb [--groups OUT.csv] [--cells OUT.csv|OUT.npy]\n"
    "                      [--flat OUT.sqlite] [--labels OUT.npy] [--steps OUT.npy]\n"
    "                      [--window X0:X1[,Y0:Y1...]] [--mem BYTES] [--quiet]\n\n"
    "Writes only complete files: Ctrl-C stops it and leaves no partial file (exit 130).\n\n"
    "  --groups OUT.csv    one row per group: id, period, basin_cells, is_sink (group 0),\n"
    "                      centre, bounds of the periodic cells' centres, anchor cell,\n"
    "                      kind (attractor, sticking zone or the sink), and the system's\n"
    "                      attractor its true orbit reaches (0: it diverges, -1: undecided)\n"
    "  --cells OUT         one row per computed cell: lattice indices ix, iv, ..., cell\n"
    "                      centre x, v, ... (i and the model's state names, as `cellmap\n"
    "                      models` lists them), grp, step, periodic, and the cell's\n"
    "                      attractor (as --labels gives it); CSV with a header, or .npy\n"
    "                      (a structured array with those fields, little-endian)\n"
    "  --flat OUT.sqlite   the same rows as a plain table cells(ix, iv, ..., x, v, ...,\n"
    "                      grp, step, periodic, attractor), with tables groups (as\n"
    "                      --groups, kind\n"
    "                      included), meta (source file, lattice origin and widths,\n"
    "                      state names) and indexes on cells(grp), the cells' indices\n"
    "                      and groups(kind)\n"
    "  --labels OUT.npy    the attractor of every cell as an n-D array: shape = cells per\n"
    "                      dimension (axis k = dimension k), C order, int32 (attractor ids\n"
    "                      from 1; 0 diverged; -2 outside: the sequence left the computed\n"
    "                      cells and its orbit did not come back (--outside-steps), or its\n"
    "                      group's true orbit was undecided; -1 not computed); OUT.json\n"
    "                      beside it holds the lattice, the box, the\n"
    "                      model and each attractor (kind, period, centre)\n"
    "  --by groups         --labels gives cell mapping's groups instead (0 the sink), and\n"
    "                      OUT.json each group (kind, period, centre, colour)\n"
    ATTRACTOR_OPTIONS_HELP
    "  --steps OUT.npy     the same array of step numbers (-1 not computed), with OUT.json\n"
    "  --window X0:X1,...  only cells whose centre lies in this box of state space (for\n"
    "                      --cells, --flat, --labels and --steps)\n"
    "  --mem BYTES         cell arrays to hold in memory while reading (default 256M)\n"
    "  --quiet             no progress line and no count of the cells written\n";

enum { SLAB_CELLS = 1 << 22 }; /* cells flattened at a time */

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

typedef struct export_args {
    const char *file, *groups, *cells, *flat, *window, *labels, *steps;
    uint64_t mem;
    bool quiet;
    int by;                   /* --by: --labels by attractors (default) or groups */
    cm_attractor_options att; /* --attractor-steps, --attractor-tol */
} export_args;

static int ends_with(const char *s, const char *suffix)
{
    const size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* No output may replace the file exported (or its -wal, -shm), another
 * output, or an array's JSON sidecar. */
static int outputs_apart(const cli *c, const export_args *a)
{
    char labels_json[CM_OUTPUT_PATH_MAX], steps_json[CM_OUTPUT_PATH_MAX], why[2048];
    array_sidecar_path(a->labels ? a->labels : "", labels_json, sizeof labels_json);
    array_sidecar_path(a->steps ? a->steps : "", steps_json, sizeof steps_json);
    const cm_file_use files[] = {
        {a->file, "the database", false, true},
        {a->groups, "--groups", true, false},
        {a->cells, "--cells", true, false},
        {a->flat, "--flat", true, true},
        {a->labels, "--labels", true, false},
        {a->labels ? labels_json : NULL, "--labels' JSON", true, false},
        {a->steps, "--steps", true, false},
        {a->steps ? steps_json : NULL, "--steps' JSON", true, false},
    };
    if (cm_files_apart(files, sizeof files / sizeof *files, why, sizeof why) != CM_OK)
        return cli_usage_error(c, "%s", why);
    return EXIT_OK;
}

static int parse_export(cli *c, export_args *a)
{
    int err = 0;
    while (cli_next(c) && !err) {
        if (strcmp(c->opt, "--help") == 0) {
            fputs(export_help, stdout);
            return -1;
        } else if (cli_is(c, "--groups", true, &err)) {
            a->groups = c->value;
        } else if (cli_is(c, "--cells", true, &err)) {
            a->cells = c->value;
            if (a->cells && !ends_with(a->cells, ".csv") && !ends_with(a->cells, ".npy") &&
                !cm_output_names_stdout(a->cells))
                err = cli_usage_error(c, "--cells: '%s' must end in .csv or .npy (or be - for CSV "
                                         "on stdout)", a->cells);
        } else if (cli_is(c, "--flat", true, &err)) {
            a->flat = c->value;
        } else if (cli_is(c, "--labels", true, &err) || cli_is(c, "--steps", true, &err)) {
            const bool labels = strncmp(c->opt, "--labels", 8) == 0;
            if (c->value && !ends_with(c->value, ".npy"))
                err = cli_usage_error(c, "%s: '%s' must end in .npy (its JSON sidecar goes "
                                         "beside it)", labels ? "--labels" : "--steps", c->value);
            *(labels ? &a->labels : &a->steps) = c->value;
        } else if (cli_is(c, "--window", true, &err)) {
            a->window = c->value;
        } else if (by_option_take(c, &a->by, &err)) {
        } else if (attractor_options_take(c, &a->att, &err)) {
        } else if (cli_take_mem(c, &a->mem, &err)) {
        } else if (cli_is(c, "--quiet", false, &err)) {
            a->quiet = true;
        } else if (c->opt[0] != '-' && !a->file) {
            a->file = c->opt;
        } else {
            err = cli_stray(c);
        }
    }
    if (!err && !a->file)
        err = cli_usage_error(c, "which file? usage: cellmap export FILE.cmdb --cells OUT.csv");
    if (!err && !a->groups && !a->cells && !a->flat && !a->labels && !a->steps)
        err = cli_usage_error(c,
                              "nothing to export: add --groups, --cells, --flat, --labels or --steps");
    if (!err && a->window && !a->cells && !a->flat && !a->labels && !a->steps)
        err = cli_usage_error(c, "--window applies to --cells, --flat, --labels and --steps");
    const char *const outs[3] = {a->groups, a->cells, a->flat};
    int to_stdout = 0;
    for (int k = 0; k < 3; k++)
        to_stdout += outs[k] && cm_output_names_stdout(outs[k]);
    if (!err && to_stdout > 1)
        err = cli_usage_error(c, "only one of --groups, --cells and --flat can go to stdout");
    return err ? err : outputs_apart(c, a);
}

/* The cells whose centres lie in the window, within the cluster's bounds. */
static int window_box(const cli *c, const char *text, const cm_lattice *lat, cm_box *box)
{
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    if (!parse_ranges(text, lo, hi, &n, CM_MAX_DIM))
        return cli_usage_error(c, "--window: '%s' is not X0:X1[,Y0:Y1...] with X0 < X1", text);
    if (n != lat->dim)
        return cli_usage_error(c, "--window has %d range(s) but the lattice has dimension %d", n,
                               lat->dim);
    for (int d = 0; d < n; d++) {
        const double a = ceil((lo[d] - lat->origin[d]) / lat->width[d] - 0.5);
        const double b = floor((hi[d] - lat->origin[d]) / lat->width[d] - 0.5) + 1;
        const int64_t clo = box->lo[d], chi = box->hi[d];
        box->lo[d] = a > (double)clo ? (a < (double)chi ? (int64_t)a : chi) : clo;
        box->hi[d] = b < (double)chi ? (b > (double)box->lo[d] ? (int64_t)b : box->lo[d]) : chi;
        if (box->lo[d] >= box->hi[d]) /* nothing to write: said before any file is made */
            return cli_usage_error(
                c,
                "--window: '%s' holds no cell centre of the file in dimension %d (its cells "
                "are %.9g wide, their centres from %.9g to %.9g): widen the window",
                text, d + 1, lat->width[d],
                lat->origin[d] + ((double)clo + 0.5) * lat->width[d],
                lat->origin[d] + ((double)chi - 0.5) * lat->width[d]);
    }
    return EXIT_OK;
}

/* ---- outputs ---------------------------------------------------------- */

static int npy_header(cell_out *o, int dim)
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
        return npy_header(o, dim);
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

/* ---- what is exported ------------------------------------------------- */

static int export_groups(const char *path, const char *const *names, const cm_lattice *lat,
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
static cm_status export_cells(cm_cluster *c, const cm_box *window, const cm_attractor_set *att,
                              const cm_computed *computed, cell_out *outs, int nouts,
                              progress *pr, char *msg, size_t msg_size)
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
        int32_t *label = malloc((flat.ncells + 1) * sizeof *label);
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
        if (st == CM_OK && interrupt_requested())
            st = cm_fail(CM_ECANCELED, msg, msg_size,
                         "interrupted (Ctrl-C): --cells and --flat were not written");
        if (st != CM_OK)
            return st;
        progress_say(pr, done, NULL);
    }
    return CM_OK;
}

static int run_export(const cli *cl, const export_args *a, cm_store *s, const cm_store_info *info,
                      cm_cluster *c)
{
    char msg[1024];
    cm_box window;
    cm_cluster_bounds(c, &window);
    if (a->window) {
        const int rc = window_box(cl, a->window, &c->lat, &window);
        if (rc != EXIT_OK)
            return rc;
    }
    cm_group_info *g = calloc((size_t)info->groups + 1, sizeof *g);
    uint64_t sink = 0;
    if (!g || cm_store_groups(s, g, info->groups, &sink, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "cellmap export: %s\n", g ? msg : "out of memory");
        free(g);
        return EXIT_FAIL;
    }
    const char *names[CM_MAX_DIM];
    project_state_names(info, names);
    int rc = EXIT_OK;
    cm_attractor_set att; /* the groups' attractors: stored, else found */
    memset(&att, 0, sizeof att);
    cluster_ends ends; /* the cluster's exits, for the attractors and the cells' labels */
    if (cluster_ends_open(&ends, c, msg, sizeof msg) != CM_OK ||
        file_attractors(s, info, NULL, &ends, g, &a->att, &att, msg, sizeof msg) !=
            CM_OK) { /* nothing is written without them */
        fprintf(stderr, "cellmap export: %s: %s\n", a->file, msg);
        cluster_ends_close(&ends);
        cm_attractors_free(&att);
        free(g);
        return EXIT_FAIL;
    }
    if (rc == EXIT_OK && a->groups &&
        !export_groups(a->groups, names, &c->lat, g, info->groups, sink, &att, msg, sizeof msg)) {
        fprintf(stderr, "cellmap export: %s\n", msg);
        rc = EXIT_FAIL;
    }
    cell_out outs[2];
    int nouts = 0;
    memset(outs, 0, sizeof outs);
    for (int k = 0; k < 2; k++) {
        outs[k].names = names;
        outs[k].source = a->file;
        outs[k].dim = c->lat.dim;
    }
    if (a->cells) {
        outs[nouts].kind = ends_with(a->cells, ".npy") ? OUT_NPY : OUT_CSV;
        outs[nouts++].path = a->cells;
    }
    if (a->flat) {
        outs[nouts].kind = OUT_SQLITE;
        outs[nouts++].path = a->flat;
    }
    int ok = 1;
    for (int k = 0; k < nouts && ok; k++)
        ok = out_begin(&outs[k], c->lat.dim, info, msg, sizeof msg);
    if (ok && a->flat && !sqlite_groups(&outs[nouts - 1], &c->lat, g, info->groups, sink, &att))
        ok = 0, snprintf(msg, sizeof msg, "cannot write %.900s", a->flat);
    progress pr;
    progress_start(&pr, "export", "cells", cm_box_cells(&window), a->quiet);
    interrupt_catch();
    cm_status st = CM_OK;
    if (ok && nouts)
        ok = (st = export_cells(c, &window, &att, &ends.computed, outs, nouts, &pr, msg,
                                sizeof msg)) == CM_OK;
    progress_end(&pr);
    for (int k = 0; k < nouts; k++)
        ok = out_end(&outs[k], ok, msg, sizeof msg) && ok;
    if (!ok) {
        fprintf(stderr, "cellmap export: %s\n", msg);
        rc = st == CM_ECANCELED ? EXIT_INTERRUPTED : EXIT_FAIL;
    } else if (nouts && !a->quiet) {
        fprintf(report_stream(a->groups, a->cells, a->flat), "exported %llu cells\n",
                (unsigned long long)outs[0].rows);
    }
    const bool by_attractors = a->labels && a->by == BY_ATTRACTORS;
    if (rc == EXIT_OK && (a->labels || a->steps)) {
        const array_export x = {a->labels, a->steps, a->file, info, g, info->groups, names,
                                by_attractors ? &att : NULL, &ends.computed};
        progress_start(&pr, "export", "cells", cm_box_cells(&window), a->quiet);
        if (!export_arrays(c, &window, &x, &pr))
            rc = interrupt_requested() ? EXIT_INTERRUPTED : EXIT_FAIL;
    }
    cluster_ends_close(&ends);
    cm_attractors_free(&att);
    free(g);
    return rc;
}

/* export --groups alone: the groups are records, so the cluster (its node
 * tables, open nodes) is not loaded, as for info. */
/* The records-only path cannot find attractors a file does not store. */
enum { NEEDS_CLUSTER = -2 };

static int export_groups_only(const export_args *a)
{
    cm_store *s = NULL;
    cm_store_info info;
    cm_group_info *g = NULL;
    cm_attractor_set att;
    uint64_t sink = 0;
    char msg[1024];
    memset(&att, 0, sizeof att);
    cm_status st = project_open_records(a->file, true, &s, &info, msg, sizeof msg);
    if (st == CM_OK && !(g = calloc((size_t)info.groups + 1, sizeof *g)))
        st = cm_fail(CM_ENOMEM, msg, sizeof msg, "out of memory for %u groups", info.groups);
    if (st == CM_OK)
        st = cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg);
    cm_status got = CM_ENOTFOUND;
    if (st == CM_OK && !attractor_options_given(&a->att))
        got = cm_store_get_attractors(s, info.lattice.dim, info.groups, &att, NULL, msg,
                                      sizeof msg);
    st = got == CM_ENOTFOUND ? st : got;
    cm_store_snapshot_end(s);
    int rc = st == CM_OK ? EXIT_OK : EXIT_FAIL;
    if (st == CM_OK && got == CM_ENOTFOUND)
        rc = NEEDS_CLUSTER; /* found from the cells: the full path */
    if (rc == EXIT_OK) {
        const char *names[CM_MAX_DIM];
        project_state_names(&info, names);
        if (!export_groups(a->groups, names, &info.lattice, g, info.groups, sink, &att, msg,
                           sizeof msg))
            rc = EXIT_FAIL;
    }
    if (rc == EXIT_FAIL)
        fprintf(stderr, "cellmap export: %s\n", msg);
    cm_attractors_free(&att);
    free(g);
    cm_store_close(s, msg, sizeof msg);
    return rc;
}

int cmd_export(int argc, char **argv)
{
    cli c = {"export", argc, argv, 0, NULL, NULL};
    export_args a;
    memset(&a, 0, sizeof a);
    a.mem = UINT64_C(256) << 20;
    const int rc = parse_export(&c, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    const char *const outs[] = {a.groups, a.cells, a.flat, a.labels, a.steps};
    int werr = cli_input_check("export", a.file);
    if (werr == EXIT_OK)
        werr = outfiles_check("export", outs, 5);
    if (werr != EXIT_OK)
        return werr;
    if (a.groups && !a.cells && !a.flat && !a.labels && !a.steps && !a.window) {
        const int only = export_groups_only(&a);
        if (only != NEEDS_CLUSTER)
            return only;
    }
    cm_store *s = NULL;
    cm_store_info info;
    cm_cluster cl;
    if (cli_open_read("export", a.file, a.mem, &s, &info, &cl) != EXIT_OK)
        return EXIT_FAIL;
    const int result = run_export(&c, &a, s, &info, &cl);
    project_close(s, &cl);
    return result;
}
