/* The system's attractors in a .cmdb file (format version 7): tables
 * system_attractors (one row each, the footprint as a BLOB of little-endian
 * int64 cells, dim coordinates each, in box order), group_fates (each
 * group's attractor id, 0 when its true orbit diverges, -1 undecided) and
 * exit_fates (one row per fate of the exits, cellmap/outside.h: an
 * attractor id, 0 diverged, -2 outside, with its exit cells as a BLOB like
 * the footprints), and the options they were found with and the sink's
 * counts (meta 'attractor_options'). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "cellmap/store_db.h"

#define OPTIONS_KEY "attractor_options"

static void options_text(const cm_attractor_options *o, const cm_attractor_set *a, char *out,
                         size_t size)
{
    snprintf(out, size, "%u,%u,%u,%.17g,%.17g,%llu,%u,%llu,%llu,%llu,%llu", o->transient,
             o->record, o->max_steps, o->tol, o->match, (unsigned long long)a->steps,
             a->outside_steps, (unsigned long long)a->outside_steps_taken,
             (unsigned long long)a->sink_diverged_cells, (unsigned long long)a->outside_cells,
             (unsigned long long)a->returned_cells);
}

/* Exit cells per write into a label's blob: a buffer of 64 KiB in 2-D. */
#define FATES_CHUNK 4096

/* The exit cells of s labelled `label`, in box order, into the blob of its
 * exit_fates row: written in pieces through SQLite's blob I/O, so that
 * neither this nor SQLite holds a copy of them all (16 bytes an exit in
 * 2-D, a million exits and more on a long explore session's cluster). */
static cm_status write_fate_cells(cm_store *s, const cm_attractor_set *a, int dim, int64_t label,
                                  int64_t *buf, char *msg, size_t msg_size)
{
    sqlite3_blob *blob = NULL;
    if (sqlite3_blob_open(s->db, "main", "exit_fates", "cells", label, 1, &blob) != SQLITE_OK) {
        sqlite3_blob_close(blob);
        return store_db_error(s->db, "open the exits' fates", msg, msg_size);
    }
    const int cell_bytes = dim * (int)sizeof *buf;
    int n = 0, offset = 0, rc = SQLITE_OK;
    for (uint64_t e = 0; rc == SQLITE_OK && e < a->nexits; e++) {
        if (a->exit_label[e] != label)
            continue;
        memcpy(buf + (size_t)n++ * (size_t)dim, a->exit_cell + e * (uint64_t)dim,
               (size_t)cell_bytes);
        if (n == FATES_CHUNK) {
            rc = sqlite3_blob_write(blob, buf, n * cell_bytes, offset);
            offset += n * cell_bytes;
            n = 0;
        }
    }
    if (rc == SQLITE_OK && n > 0)
        rc = sqlite3_blob_write(blob, buf, n * cell_bytes, offset);
    if (sqlite3_blob_close(blob) != SQLITE_OK || rc != SQLITE_OK)
        return store_db_error(s->db, "write the exits' fates", msg, msg_size);
    return CM_OK;
}

/* Exit cells of s in box order, label by label: exit_fates' rows. */
static cm_status write_exit_fates(cm_store *s, const cm_attractor_set *a, int dim, char *msg,
                                  size_t msg_size)
{
    sqlite3_stmt *ins = NULL;
    int64_t *buf = malloc((size_t)FATES_CHUNK * (size_t)dim * sizeof *buf);
    /* exits per fate, label - CM_LABEL_OUTSIDE: counted in one pass */
    uint64_t *count = calloc((size_t)a->n + (size_t)(1 - CM_LABEL_OUTSIDE), sizeof *count);
    cm_status st = buf && count
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the exits");
    for (uint64_t e = 0; st == CM_OK && e < a->nexits; e++)
        if (a->exit_label[e] >= CM_LABEL_OUTSIDE && a->exit_label[e] <= (int64_t)a->n)
            count[a->exit_label[e] - CM_LABEL_OUTSIDE]++;
    if (st == CM_OK && (store_exec(s->db, "DELETE FROM exit_fates") != SQLITE_OK ||
                        sqlite3_prepare_v2(s->db, "INSERT INTO exit_fates VALUES(?, ?, ?)", -1,
                                           &ins, NULL) != SQLITE_OK))
        st = store_db_error(s->db, "prepare the exits' fates", msg, msg_size);
    for (int64_t label = CM_LABEL_OUTSIDE; st == CM_OK && label <= (int64_t)a->n; label++) {
        const uint64_t n = count[label - CM_LABEL_OUTSIDE];
        if (n == 0)
            continue;
        if (n * (uint64_t)dim * sizeof *buf > INT32_MAX) {
            st = cm_fail(CM_ETOOBIG, msg, msg_size,
                         "%llu exits of one fate are more than a file's value holds",
                         (unsigned long long)n);
            break;
        }
        sqlite3_bind_int64(ins, 1, label);
        sqlite3_bind_int64(ins, 2, (sqlite3_int64)n);
        sqlite3_bind_zeroblob(ins, 3, (int)(n * (uint64_t)dim * sizeof *buf));
        st = store_step_done(s->db, ins, "write the exits' fates", msg, msg_size);
        if (st == CM_OK)
            st = write_fate_cells(s, a, dim, label, buf, msg, msg_size);
    }
    sqlite3_finalize(ins);
    free(buf);
    free(count);
    return st;
}

static cm_status write_rows(cm_store *s, const cm_attractor_set *a, int dim, char *msg,
                            size_t msg_size)
{
    sqlite3_stmt *ins = NULL, *fate = NULL;
    cm_status st = CM_OK;
    if (store_exec(s->db, "DELETE FROM system_attractors; DELETE FROM group_fates;") != SQLITE_OK ||
        sqlite3_prepare_v2(s->db,
                           "INSERT INTO system_attractors VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                           -1, &ins, NULL) != SQLITE_OK ||
        sqlite3_prepare_v2(s->db, "INSERT INTO group_fates VALUES(?, ?)", -1, &fate, NULL) !=
            SQLITE_OK)
        st = store_db_error(s->db, "prepare the attractors", msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < a->n; k++) {
        const cm_attractor *at = &a->a[k];
        char centre[CM_MAX_DIM * 32], lo[CM_MAX_DIM * 32], hi[CM_MAX_DIM * 32], anchor[CM_MAX_DIM * 24];
        store_json_doubles(centre, sizeof centre, at->centre, dim);
        store_json_doubles(lo, sizeof lo, at->lo, dim);
        store_json_doubles(hi, sizeof hi, at->hi, dim);
        store_json_ints(anchor, sizeof anchor, at->anchor, dim);
        const uint64_t from = a->footprint_at[k], cells = a->footprint_at[k + 1] - from;
        sqlite3_bind_int64(ins, 1, at->id);
        sqlite3_bind_text(ins, 2, cm_attractor_kind_name(at->kind), -1, SQLITE_STATIC);
        if (at->kind == CM_ATTRACTOR_APERIODIC)
            sqlite3_bind_null(ins, 3);
        else
            sqlite3_bind_int64(ins, 3, at->period);
        sqlite3_bind_int64(ins, 4, (sqlite3_int64)at->basin_cells);
        sqlite3_bind_int64(ins, 5, at->groups);
        sqlite3_bind_text(ins, 6, centre, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(ins, 7, lo, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(ins, 8, hi, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(ins, 9, anchor, -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(ins, 10, (sqlite3_int64)cells);
        sqlite3_bind_blob64(ins, 11, a->footprint + from * dim, cells * dim * sizeof *a->footprint,
                            SQLITE_STATIC); /* x86-64 and arm64: little-endian in memory */
        st = store_step_done(s->db, ins, "write an attractor", msg, msg_size);
    }
    for (uint32_t g = 1; st == CM_OK && g <= a->ngroups; g++) {
        sqlite3_bind_int64(fate, 1, g);
        sqlite3_bind_int64(fate, 2, cm_attractor_fate(a, g));
        st = store_step_done(s->db, fate, "write a group's attractor", msg, msg_size);
    }
    sqlite3_finalize(ins);
    sqlite3_finalize(fate);
    return st;
}

cm_status cm_store_put_attractors(cm_store *s, const cm_attractor_set *a,
                                  const cm_attractor_options *o, int dim, char *msg,
                                  size_t msg_size)
{
    const int own = !s->in_transaction;
    cm_status st = store_begin(s, msg, msg_size);
    if (st == CM_OK)
        st = write_rows(s, a, dim, msg, msg_size);
    if (st == CM_OK)
        st = write_exit_fates(s, a, dim, msg, msg_size);
    char text[512];
    options_text(o, a, text, sizeof text);
    sqlite3_stmt *meta = NULL;
    if (st == CM_OK && sqlite3_prepare_v2(s->db,
                                          "INSERT OR REPLACE INTO meta(key, value) VALUES('" OPTIONS_KEY
                                          "', ?)",
                                          -1, &meta, NULL) != SQLITE_OK)
        st = store_db_error(s->db, "prepare the attractor options", msg, msg_size);
    if (st == CM_OK) {
        sqlite3_bind_text(meta, 1, text, -1, SQLITE_STATIC);
        st = store_step_done(s->db, meta, "write the attractor options", msg, msg_size);
    }
    sqlite3_finalize(meta);
    if (st == CM_OK && own && store_exec(s->db, "COMMIT") != SQLITE_OK)
        st = store_db_error(s->db, "commit the attractors", msg, msg_size);
    if (st == CM_OK && own)
        s->in_transaction = 0;
    return st == CM_OK ? st : store_abandon(s, st);
}

cm_status store_forget_attractors(cm_store *s, char *msg, size_t msg_size)
{
    if (s->version < 7)
        return CM_OK;
    if (store_exec(s->db, "DELETE FROM system_attractors; DELETE FROM group_fates; "
                          "DELETE FROM exit_fates; DELETE FROM meta WHERE key = '" OPTIONS_KEY
                          "'") != SQLITE_OK)
        return store_db_error(s->db, "forget the attractors", msg, msg_size);
    return CM_OK;
}

/* The options of the stored attractors and the sink's counts into a;
 * CM_ENOTFOUND if none are stored (a file of version 6 or older, or a
 * solve interrupted before them). */
static cm_status stored_options(cm_store *s, cm_attractor_options *o, cm_attractor_set *a)
{
    if (s->version < 7)
        return CM_ENOTFOUND;
    sqlite3_stmt *q = NULL;
    cm_status st = CM_ENOTFOUND;
    if (sqlite3_prepare_v2(s->db, "SELECT value FROM meta WHERE key = '" OPTIONS_KEY "'", -1, &q,
                           NULL) == SQLITE_OK &&
        sqlite3_step(q) == SQLITE_ROW && sqlite3_column_text(q, 0)) {
        unsigned long long n[5] = {0};
        memset(o, 0, sizeof *o);
        st = sscanf((const char *)sqlite3_column_text(q, 0),
                    "%u,%u,%u,%lg,%lg,%llu,%u,%llu,%llu,%llu,%llu", &o->transient, &o->record,
                    &o->max_steps, &o->tol, &o->match, &n[0], &a->outside_steps, &n[1], &n[2],
                    &n[3], &n[4]) == 11
                 ? CM_OK
                 : CM_EFORMAT;
        o->outside = a->outside_steps ? a->outside_steps : CM_OUTSIDE_OFF;
        a->steps = n[0];
        a->outside_steps_taken = n[1];
        a->sink_diverged_cells = n[2];
        a->outside_cells = n[3];
        a->returned_cells = n[4];
    }
    sqlite3_finalize(q);
    return st;
}

static cm_status read_attractors(cm_store *s, int dim, cm_attractor_set *a, char *msg,
                                 size_t msg_size)
{
    /* sized by the bytes the footprints hold, not by what the rows say (a
     * damaged count must not ask for memory the file does not have) */
    const int64_t n = store_query_int(s->db, "SELECT COUNT(*) FROM system_attractors");
    const int64_t bytes = store_query_int(s->db, "SELECT IFNULL(SUM(LENGTH(footprint)), 0) FROM "
                                                 "system_attractors");
    const int64_t cells = bytes / (int64_t)(dim * sizeof *a->footprint);
    if (n < 0 || bytes < 0 || n > UINT32_MAX)
        return cm_fail(CM_EFORMAT, msg, msg_size, "its attractors cannot be read");
    a->n = (uint32_t)n;
    a->a = calloc((size_t)n + 1, sizeof *a->a);
    a->footprint_at = calloc((size_t)n + 2, sizeof *a->footprint_at);
    a->footprint = malloc(((size_t)cells + 1) * dim * sizeof *a->footprint);
    if (!a->a || !a->footprint_at || !a->footprint)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %lld attractors",
                       (long long)n);
    sqlite3_stmt *q = NULL;
    cm_status st = CM_OK;
    if (sqlite3_prepare_v2(s->db,
                           "SELECT id, kind, period, basin_cells, groups, centre, lo, hi, anchor,"
                           " footprint_cells, footprint FROM system_attractors ORDER BY id",
                           -1, &q, NULL) != SQLITE_OK)
        st = store_db_error(s->db, "read the attractors", msg, msg_size);
    uint32_t k = 0;
    for (; st == CM_OK && sqlite3_step(q) == SQLITE_ROW; k++) {
        cm_attractor *at = &a->a[k];
        const char *kind = (const char *)sqlite3_column_text(q, 1);
        double v[3][CM_MAX_DIM], anchor[CM_MAX_DIM];
        const uint64_t fp = (uint64_t)sqlite3_column_int64(q, 9);
        const int bytes = sqlite3_column_bytes(q, 10);
        at->id = (uint32_t)sqlite3_column_int64(q, 0);
        at->kind = kind && strcmp(kind, "aperiodic") == 0  ? CM_ATTRACTOR_APERIODIC
                   : kind && strcmp(kind, "sticking") == 0 ? CM_ATTRACTOR_STICKING
                                                           : CM_ATTRACTOR_PERIODIC;
        at->period = (uint32_t)sqlite3_column_int64(q, 2);
        at->basin_cells = (uint64_t)sqlite3_column_int64(q, 3);
        at->groups = (uint32_t)sqlite3_column_int64(q, 4);
        at->footprint_cells = fp;
        bool ok = at->id == k + 1 && kind && fp >= 1 &&
                  a->footprint_at[k] + fp <= (uint64_t)cells &&
                  (uint64_t)bytes == fp * (uint64_t)dim * sizeof *a->footprint;
        for (int c = 0; c < 3 && ok; c++)
            ok = store_parse_json_numbers((const char *)sqlite3_column_text(q, 5 + c), v[c],
                                          CM_MAX_DIM) == dim;
        ok = ok && store_parse_json_numbers((const char *)sqlite3_column_text(q, 8), anchor,
                                            CM_MAX_DIM) == dim;
        if (!ok) {
            st = cm_fail(CM_EFORMAT, msg, msg_size, "its attractor %u is damaged", k + 1);
            break;
        }
        for (int d = 0; d < dim; d++) {
            at->centre[d] = v[0][d];
            at->lo[d] = v[1][d];
            at->hi[d] = v[2][d];
            at->anchor[d] = (int64_t)anchor[d];
        }
        memcpy(a->footprint + a->footprint_at[k] * dim, sqlite3_column_blob(q, 10),
               (size_t)bytes);
        a->footprint_at[k + 1] = a->footprint_at[k] + fp;
        a->merged += at->groups > 0 ? at->groups - 1 : 0;
    }
    sqlite3_finalize(q);
    if (st == CM_OK && k != a->n)
        st = cm_fail(CM_EFORMAT, msg, msg_size, "its attractors cannot be read");
    return st;
}

static cm_status read_fates(cm_store *s, cm_attractor_set *a, char *msg, size_t msg_size)
{
    sqlite3_stmt *q = NULL;
    cm_status st = CM_OK;
    for (uint32_t g = 0; g <= a->ngroups; g++)
        a->of_group[g] = CM_FATE_UNRESOLVED;
    a->of_group[0] = CM_FATE_DIVERGED;
    if (sqlite3_prepare_v2(s->db,
                           "SELECT f.grp, f.attractor, IFNULL(b.cells, 0) FROM group_fates f"
                           " LEFT JOIN basins b ON b.grp = f.grp",
                           -1, &q, NULL) != SQLITE_OK)
        st = store_db_error(s->db, "read the groups' attractors", msg, msg_size);
    uint32_t rows = 0;
    while (st == CM_OK && sqlite3_step(q) == SQLITE_ROW) {
        const int64_t g = sqlite3_column_int64(q, 0), f = sqlite3_column_int64(q, 1);
        const int64_t cells = sqlite3_column_int64(q, 2);
        if (g < 1 || g > a->ngroups || f < -1 || f > a->n || cells < 0) {
            st = cm_fail(CM_EFORMAT, msg, msg_size, "the attractor of its group %lld is damaged",
                         (long long)g);
            break;
        }
        a->of_group[g] = f < 0 ? CM_FATE_UNRESOLVED : (uint32_t)f;
        a->diverged_groups += f == 0;
        a->unresolved_groups += f < 0;
        a->diverged_cells += f == 0 ? (uint64_t)cells : 0;
        a->unresolved_cells += f < 0 ? (uint64_t)cells : 0;
        rows++;
    }
    sqlite3_finalize(q);
    if (st == CM_OK && rows != a->ngroups)
        st = cm_fail(CM_EFORMAT, msg, msg_size,
                     "it holds the attractors of %u groups, not of its %u", rows, a->ngroups);
    return st;
}

/* A row of exit_fates as read: its fate, and its cells' place among all
 * the rows' cells (in box order within the row, as written). */
typedef struct fate_row {
    int32_t label;
    uint64_t first, end;
} fate_row;

/* The rows' checks that need no cell: fate, count and size. */
static bool fate_row_ok(const cm_attractor_set *a, int dim, int64_t label, int64_t count,
                        uint64_t size)
{
    return label >= CM_LABEL_OUTSIDE && label != CM_LABEL_UNCOMPUTED && label <= a->n &&
           count >= 1 && size == (uint64_t)count * (uint64_t)dim * sizeof(int64_t);
}

/* Row heads as a binary heap, the least cell on top. */
static bool head_less(const fate_row *r, const int64_t *cells, int dim, uint32_t x, uint32_t y)
{
    return cm_cell_less(cells + r[x].first * (uint64_t)dim, cells + r[y].first * (uint64_t)dim,
                        dim);
}

static void sift_down(const fate_row *r, const int64_t *cells, int dim, uint32_t *heap,
                      uint32_t n, uint32_t i)
{
    for (;;) {
        uint32_t least = i;
        const uint32_t l = 2 * i + 1, rr = l + 1;
        if (l < n && head_less(r, cells, dim, heap[l], heap[least]))
            least = l;
        if (rr < n && head_less(r, cells, dim, heap[rr], heap[least]))
            least = rr;
        if (least == i)
            return;
        const uint32_t t = heap[i];
        heap[i] = heap[least];
        heap[least] = t;
        i = least;
    }
}

/* The rows' cells merged into a's exits in box order (each row is in box
 * order): false when the merge is not strictly ascending, as when a row is
 * not in order or two rows share a cell (damage). */
static bool merge_rows(fate_row *r, uint32_t nrows, const int64_t *cells, int dim,
                       cm_attractor_set *a)
{
    const size_t bytes = (size_t)dim * sizeof *cells;
    uint32_t *heap = malloc(((size_t)nrows + 1) * sizeof *heap), n = nrows;
    if (!heap)
        return false;
    for (uint32_t k = 0; k < nrows; k++)
        heap[k] = k;
    for (uint32_t k = nrows / 2; k-- > 0;)
        sift_down(r, cells, dim, heap, n, k);
    uint64_t out = 0;
    bool ok = true;
    while (n > 0 && ok) {
        fate_row *top = &r[heap[0]];
        const int64_t *cell = cells + top->first * (uint64_t)dim;
        ok = out == 0 || cm_cell_less(a->exit_cell + (out - 1) * (uint64_t)dim, cell, dim);
        memcpy(a->exit_cell + out * (uint64_t)dim, cell, bytes);
        a->exit_label[out++] = top->label;
        if (++top->first == top->end)
            heap[0] = heap[--n];
        sift_down(r, cells, dim, heap, n, 0);
    }
    free(heap);
    a->nexits = out;
    return ok;
}

/* The exits' fates into a (a->n attractors read), merged into box order. */
static cm_status read_exit_fates(cm_store *s, int dim, cm_attractor_set *a, char *msg,
                                 size_t msg_size)
{
    const int64_t bytes = store_query_int(s->db, "SELECT IFNULL(SUM(LENGTH(cells)), 0) FROM "
                                                 "exit_fates");
    const uint64_t cells = bytes > 0 ? (uint64_t)bytes / (dim * sizeof(int64_t)) : 0;
    int64_t *raw = malloc(((size_t)cells + 1) * dim * sizeof *raw);
    a->exit_cell = malloc(((size_t)cells + 1) * dim * sizeof *a->exit_cell);
    a->exit_label = malloc(((size_t)cells + 1) * sizeof *a->exit_label);
    fate_row *rows = NULL;
    uint64_t nrows = 0, rows_cap = 0, n = 0;
    if (bytes < 0 || !raw || !a->exit_cell || !a->exit_label) {
        free(raw);
        return bytes < 0 ? cm_fail(CM_EFORMAT, msg, msg_size, "its exits' fates cannot be read")
                         : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                                   (unsigned long long)cells);
    }
    sqlite3_stmt *q = NULL;
    cm_status st = CM_OK;
    if (sqlite3_prepare_v2(s->db, "SELECT attractor, exits, cells FROM exit_fates", -1, &q,
                           NULL) != SQLITE_OK)
        st = store_db_error(s->db, "read the exits' fates", msg, msg_size);
    while (st == CM_OK && sqlite3_step(q) == SQLITE_ROW) {
        const int64_t label = sqlite3_column_int64(q, 0), count = sqlite3_column_int64(q, 1);
        const int64_t *blob = sqlite3_column_blob(q, 2);
        const uint64_t size = (uint64_t)sqlite3_column_bytes(q, 2);
        if (!fate_row_ok(a, dim, label, count, size) || n + (uint64_t)count > cells) {
            st = cm_fail(CM_EFORMAT, msg, msg_size, "its exits' fates are damaged");
            break;
        }
        if (cm_grow((void **)&rows, &rows_cap, nrows + 1, sizeof *rows) != CM_OK) {
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the exits' fates");
            break;
        }
        memcpy(raw + n * (uint64_t)dim, blob, size);
        rows[nrows++] = (fate_row){(int32_t)label, n, n + (uint64_t)count};
        n += (uint64_t)count;
    }
    sqlite3_finalize(q);
    if (st == CM_OK && (n != cells || !merge_rows(rows, (uint32_t)nrows, raw, dim, a)))
        st = cm_fail(CM_EFORMAT, msg, msg_size, "its exits' fates are damaged");
    free(rows);
    free(raw);
    return st;
}

/* exit_fates' rows checked as read_exit_fates checks them, but by their
 * sizes: no cell is read (the order and the overlap of the cells are not
 * checked). */
static cm_status check_exit_fates(cm_store *s, int dim, const cm_attractor_set *a, char *msg,
                                  size_t msg_size)
{
    sqlite3_stmt *q = NULL;
    cm_status st = CM_OK;
    if (sqlite3_prepare_v2(s->db, "SELECT attractor, exits, LENGTH(cells) FROM exit_fates", -1,
                           &q, NULL) != SQLITE_OK)
        st = store_db_error(s->db, "read the exits' fates", msg, msg_size);
    while (st == CM_OK && sqlite3_step(q) == SQLITE_ROW)
        if (!fate_row_ok(a, dim, sqlite3_column_int64(q, 0), sqlite3_column_int64(q, 1),
                         (uint64_t)sqlite3_column_int64(q, 2)))
            st = cm_fail(CM_EFORMAT, msg, msg_size, "its exits' fates are damaged");
    sqlite3_finalize(q);
    return st;
}

/* cm_store_get_attractors, the exits' cells read or only checked by size. */
static cm_status get_attractors(cm_store *s, int dim, uint32_t ngroups, bool exits,
                                cm_attractor_set *a, cm_attractor_options *o, char *msg,
                                size_t msg_size)
{
    memset(a, 0, sizeof *a);
    cm_attractor_options stored;
    cm_status st = stored_options(s, &stored, a);
    if (st == CM_ENOTFOUND)
        return st;
    if (st != CM_OK)
        return store_damaged(s, cm_fail(CM_EFORMAT, msg, msg_size,
                                        "its attractor options are damaged"),
                             msg, msg_size);
    a->ngroups = ngroups;
    a->of_group = calloc((size_t)ngroups + 1, sizeof *a->of_group);
    st = a->of_group ? read_attractors(s, dim, a, msg, msg_size)
                     : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", ngroups);
    if (st == CM_OK)
        st = read_fates(s, a, msg, msg_size);
    if (st == CM_OK)
        st = exits ? read_exit_fates(s, dim, a, msg, msg_size)
                   : check_exit_fates(s, dim, a, msg, msg_size);
    if (st != CM_OK) {
        cm_attractors_free(a);
        return store_damaged(s, st, msg, msg_size);
    }
    if (o)
        *o = stored;
    return CM_OK;
}

cm_status cm_store_get_attractors(cm_store *s, int dim, uint32_t ngroups, cm_attractor_set *a,
                                  cm_attractor_options *o, char *msg, size_t msg_size)
{
    return get_attractors(s, dim, ngroups, true, a, o, msg, msg_size);
}

cm_status cm_store_check_attractors(cm_store *s, int dim, uint32_t ngroups, char *msg,
                                    size_t msg_size)
{
    cm_attractor_set a;
    const cm_status st = get_attractors(s, dim, ngroups, false, &a, NULL, msg, msg_size);
    if (st == CM_OK)
        cm_attractors_free(&a);
    return st;
}
