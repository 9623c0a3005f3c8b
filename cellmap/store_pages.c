/* cellmap/store_pages.c - a region in the file and back: its row, cell pages,
 * exit and node tables; the pager; loading a saved cluster. */
#include "cellmap/store_db.h"

#include "cellmap/clock.h"

#include "cellmap/classify.h"
#include "cellmap/codec.h"
#include "cellmap/grow.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Decodes the columns read into arrays (image, group, step), in parallel:
 * a region is up to 3 x 16 of them. */
static cm_status decode_columns(const cm_store *s, uint32_t *const arrays[3],
                                const column_ref *refs, uint64_t nrefs)
{
    int failed = 0;
#pragma omp parallel num_threads(s->threads) if (nrefs > 1)
    {
        unsigned char *scratch = malloc(4 * (size_t)CM_STORE_PAGE_CELLS);
        failed |= !scratch;
#pragma omp for schedule(dynamic, 1) reduction(| : failed)
        for (int64_t t = 0; t < (int64_t)nrefs; t++) {
            const column_ref *c = &refs[t];
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

/* Region k's pages (ncells cells) decoded into the arrays (image, group,
 * step) that are not NULL; the others' columns are not decoded. */
static cm_status read_columns(cm_store *s, uint32_t k, uint64_t ncells, uint32_t *const arrays[3],
                              char *msg, size_t msg_size)
{
    const uint64_t pages = npages(ncells);
    column_ref *refs = malloc((3 * pages + 1) * sizeof *refs);
    sqlite3_stmt *st = NULL;
    if (!refs)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading region %u", k + 1);
    if (sqlite3_prepare_v2(s->db,
                           "SELECT first_cell, cells, image, grp, step FROM pages WHERE region=? "
                           "ORDER BY first_cell",
                           -1, &st, NULL)) {
        free(refs);
        return store_db_error(s->db, "read pages", msg, msg_size);
    }
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    cm_status status = CM_OK;
    uint64_t seen = 0, nrefs = 0, used = 0;
    int rc;
    while (status == CM_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        const uint64_t first = (uint64_t)sqlite3_column_int64(st, 0);
        const uint64_t n = (uint64_t)sqlite3_column_int64(st, 1);
        if (first != seen || n == 0 || n > CM_STORE_PAGE_CELLS || first + n > ncells ||
            nrefs + 3 > 3 * pages) {
            status = CM_EFORMAT;
            break;
        }
        for (int col = 0; col < 3 && status == CM_OK; col++)
            if (arrays[col])
                status = keep_column(s, st, col, first, n, &used, &refs[nrefs++]);
        seen += n;
    }
    if (status == CM_OK && rc != SQLITE_DONE) {
        status = store_db_error(s->db, "read pages", msg, msg_size);
        sqlite3_finalize(st);
        free(refs);
        return status;
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != ncells)
        status = CM_EFORMAT;
    if (status == CM_OK)
        status = decode_columns(s, arrays, refs, nrefs);
    free(refs);
    if (status == CM_EFORMAT)
        return cm_fail(status, msg, msg_size,
                       "%s is damaged: the pages of region %u are incomplete or do not decode",
                       s->path, k + 1);
    return status == CM_OK
               ? CM_OK
               : cm_fail(status, msg, msg_size, "out of memory reading region %u", k + 1);
}

static cm_status read_pages(cm_store *s, uint32_t k, cm_region *r, char *msg, size_t msg_size)
{
    const size_t bytes = (size_t)r->ncells * sizeof(uint32_t);
    if (!(r->image = cm_cells_array(bytes)) || !(r->group = cm_cells_array(bytes)) ||
        !(r->step = cm_cells_array(bytes)))
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading region %u", k + 1);
    uint32_t *const arrays[3] = {r->image, r->group, r->step};
    return read_columns(s, k, r->ncells, arrays, msg, msg_size);
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
        status = store_db_error(s->db, "read exits", msg, msg_size);
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

/* Checks region k's cells as read (cm_region_check): pages that decode but
 * are damaged, or belong to another region, are found here. */
static cm_status check_cells(const cm_store *s, uint32_t k, const cm_region *r, char *msg,
                             size_t msg_size)
{
    char why[256];
    const uint32_t groups = s->cluster ? s->cluster->ngroups : 0;
    if (cm_region_check(r, groups, s->version >= 4, s->threads, why, sizeof why) == CM_OK)
        return CM_OK;
    return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: region %u, %s", s->path, k + 1,
                   why);
}

/* The pager of a region's groups alone (cm_groups_in_fn), checked. */
cm_status store_groups_in(void *user, uint32_t k, uint32_t *group, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = cm_seconds();
    const cm_region *r = &s->cluster->regions[k].r;
    uint32_t *const arrays[3] = {NULL, group, NULL};
    char why[256];
    cm_status st = read_columns(s, k, r->ncells, arrays, msg, msg_size);
    if (st == CM_OK && cm_groups_check(group, r->ncells, r->nexits, s->cluster->ngroups, why,
                                       sizeof why) != CM_OK)
        st = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: region %u, %s", s->path, k + 1,
                     why);
    s->stats.read_seconds += cm_seconds() - t0;
    return st;
}

/* The pager: reads region k's arrays and exit table back. */
cm_status store_page_in(void *user, uint32_t k, cm_region *r, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = cm_seconds();
    cm_status st = read_pages(s, k, r, msg, msg_size);
    if (st == CM_OK)
        st = read_exits(s, k, r->nexits, r->box.dim, &r->exit_target, msg, msg_size);
    if (st == CM_OK)
        st = check_cells(s, k, r, msg, msg_size);
    if (st != CM_OK) {
        free(r->image);
        free(r->group);
        free(r->step);
        r->image = r->group = r->step = NULL;
    }
    s->stats.regions_read++;
    s->stats.read_seconds += cm_seconds() - t0;
    return st;
}



static cm_status store_open_in(void *user, uint32_t k, uint32_t **local, uint64_t **weight,
                               int64_t **cells, uint64_t *n, char *msg, size_t msg_size);

void cm_store_attach(cm_store *s, cm_cluster *c)
{
    s->threads = cm_cluster_threads(c);
    s->cluster = c;
    c->page_in = store_page_in;
    c->page_out = s->writable ? store_page_out : NULL;
    c->nodes_in = store_nodes_in;
    c->groups_in = s->version >= 4 ? store_groups_in : NULL; /* node references since 4 */
    c->open_in = s->version >= 5 ? store_open_in : NULL; /* a table of open nodes since 5 */
    c->pager = s;
}

/* A region's bounds: whole numbers inside the world, lo < hi. */
static cm_status parse_box(const char *lo, const char *hi, int dim, cm_box *box)
{
    double l[CM_MAX_DIM], h[CM_MAX_DIM];
    if (!lo || !hi || store_parse_json_numbers(lo, l, CM_MAX_DIM) != dim ||
        store_parse_json_numbers(hi, h, CM_MAX_DIM) != dim)
        return CM_EFORMAT;
    box->dim = dim;
    const double limit = (double)CM_WORLD_LIMIT;
    for (int d = 0; d < dim; d++) {
        if (!(l[d] >= -limit && l[d] <= limit && h[d] >= -limit && h[d] <= limit) ||
            l[d] != floor(l[d]) || h[d] != floor(h[d]))
            return CM_EFORMAT;
        box->lo[d] = (int64_t)l[d];
        box->hi[d] = (int64_t)h[d];
        if (box->hi[d] <= box->lo[d])
            return CM_EFORMAT;
    }
    return CM_OK;
}

/* Decodes one row of node records (fields columns of n entries) into nodes. */
static cm_status decode_nodes(const void *blob, int len, uint64_t n, uint64_t fields,
                              cm_node *nodes)
{
    uint32_t *cols = malloc((fields * n + 1) * sizeof *cols);
    unsigned char *scratch = malloc(4 * (fields * n + 1));
    cm_status st = cols && scratch ? CM_OK : CM_ENOMEM;
    if (st == CM_OK && ((n > 0 && !blob) ||
                        (blob && cm_codec_decode(blob, (size_t)len, fields * n, 4, -1, scratch,
                                                 cols) != CM_OK)))
        st = CM_EFORMAT;
    for (uint64_t e = 0; st == CM_OK && e < n; e++)
        nodes[e] = (cm_node){.next = cols[e],
                             .dist = cols[n + e],
                             .group = cols[2 * n + e],
                             .target = cols[3 * n + e],
                             .tree = cols[4 * n + e],
                             .first_in = fields > 5 ? cols[5 * n + e] : CM_NODE_OPEN,
                             .sibling = fields > 5 ? cols[6 * n + e] : CM_NODE_OPEN};
    free(cols);
    free(scratch);
    return st;
}

/* Region k's n node records as saved into nodes[0..n): version 5's rows of
 * CM_NODE_CHUNK nodes, or version 4's one row. */
static cm_status read_nodes(cm_store *s, uint32_t k, uint64_t n, cm_node *nodes, char *msg,
                            size_t msg_size)
{
    if (s->version < 4) { /* regions of version 2 and 3 hold resolved cells: no node is referenced */
        for (uint64_t e = 0; e < n; e++)
            nodes[e] = (cm_node){.next = CM_NODE_FINAL, .dist = 1, .first_in = CM_NODE_OPEN,
                                 .sibling = CM_NODE_OPEN};
        return CM_OK;
    }
    const bool chunked = s->version >= 5;
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db,
                           chunked ? "SELECT first, count, data FROM nodes WHERE region=? ORDER BY "
                                     "first"
                                   : "SELECT 0, count, data FROM nodes WHERE region=?",
                           -1, &st, NULL))
        return store_db_error(s->db, "read nodes", msg, msg_size);
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    cm_status status = CM_OK;
    uint64_t seen = 0;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const int64_t first = sqlite3_column_int64(st, 0), count = sqlite3_column_int64(st, 1);
        const int len = sqlite3_column_bytes(st, 2);
        if (first != (int64_t)seen || count < 0 || (uint64_t)count > n - seen ||
            (chunked && count > CM_NODE_CHUNK))
            status = CM_EFORMAT;
        else
            status = decode_nodes(sqlite3_column_blob(st, 2), len, (uint64_t)count,
                                  chunked ? NODE_FIELDS : NODE_FIELDS_V4, nodes + seen);
        seen += status == CM_OK ? (uint64_t)count : 0;
        s->stats.bytes_read += (uint64_t)len;
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != n)
        status = CM_EFORMAT;
    if (status == CM_EFORMAT)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: nodes of region %u", s->path,
                       k + 1);
    return status == CM_OK ? CM_OK
                           : cm_fail(status, msg, msg_size, "out of memory for %llu nodes",
                                     (unsigned long long)n);
}

/* The pager of node tables (cm_nodes_in_fn). */
cm_status store_nodes_in(void *user, uint32_t k, cm_node *nodes, uint64_t n, char *msg,
                          size_t msg_size)
{
    cm_store *s = user;
    const double t0 = cm_seconds();
    cm_status st = read_nodes(s, k, n, nodes, msg, msg_size);
    char why[256];
    if (st == CM_OK && s->cluster &&
        cm_cluster_check_nodes(s->cluster, k, nodes, s->cluster->ngroups, why, sizeof why) != CM_OK)
        st = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: %s", s->path, why);
    s->stats.read_seconds += cm_seconds() - t0;
    return st;
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
        return store_db_error(s->db, "read groups", msg, msg_size);
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
    const char *why = NULL;
    if (sqlite3_column_int64(st, 0) != (sqlite3_int64)k + 1)
        why = "regions are not numbered 1..N";
    else if (parse_box((const char *)sqlite3_column_text(st, 1),
                       (const char *)sqlite3_column_text(st, 2), dim, &rec->box) != CM_OK)
        why = "its bounds are not whole numbers lo < hi inside the world";
    else if (rec->ncells != cm_box_cells(&rec->box) || rec->ncells > CM_REGION_MAX_CELLS)
        why = "its cell count is not its box's";
    else if (rec->nexits > rec->ncells)
        why = "it has more exits than cells";
    if (why)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: region %u: %s", s->path, k + 1,
                       why);
    return CM_OK;
}

static const char regions_sql[] =
    "SELECT id, lo, hi, cells, exits, own_groups FROM regions ORDER BY id";

cm_status cm_store_regions(cm_store *s, cm_region *regions, uint32_t n, char *msg,
                           size_t msg_size)
{
    cm_lattice lat;
    cm_status status = store_read_lattice(s->db, &lat, msg, msg_size);
    sqlite3_stmt *st = NULL;
    if (status == CM_OK && sqlite3_prepare_v2(s->db, regions_sql, -1, &st, NULL))
        status = store_db_error(s->db, "read regions", msg, msg_size);
    uint32_t k = 0;
    int rc = SQLITE_DONE;
    while (status == CM_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (k == n) {
            status = cm_fail(CM_EFORMAT, msg, msg_size, "it holds more than %u regions", n);
            break;
        }
        status = region_record(s, st, k, lat.dim, &regions[k], msg, msg_size);
        k++;
    }
    if (status == CM_OK && rc != SQLITE_DONE)
        status = store_db_error(s->db, "read regions", msg, msg_size);
    else if (status == CM_OK && k != n)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "it holds %u regions, not %u", k, n);
    sqlite3_finalize(st);
    return store_damaged(s, status, msg, msg_size);
}

/* The regions' rows. Files of version 5 keep their node tables in the file
 * (read back on use); older ones give every node table and exit table
 * (into *exits), for cm_cluster_restored. */
static cm_status load_regions(cm_store *s, cm_cluster *c, int64_t ***exits, char *msg,
                              size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    uint64_t cap = 0;
    const bool tables = s->version < 5;
    if (sqlite3_prepare_v2(s->db, regions_sql, -1, &st, NULL))
        return store_db_error(s->db, "read regions", msg, msg_size);
    cm_status status = CM_OK;
    int rc;
    while (status == CM_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        cm_region rec;
        cm_node *nodes = NULL;
        int64_t *region_exits = NULL; /* the cluster's once restored (the caller frees them) */
        const uint32_t k = c->nregions;
        status = region_record(s, st, k, c->lat.dim, &rec, msg, msg_size);
        if (status == CM_OK && tables &&
            cm_grow((void **)exits, &cap, (uint64_t)k + 1, sizeof **exits))
            status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for region %u", k + 1);
        if (status == CM_OK && tables) {
            (*exits)[k] = NULL;
            status = read_exits(s, k, rec.nexits, c->lat.dim, &region_exits, msg, msg_size);
            nodes = status == CM_OK ? calloc(rec.nexits + 1, sizeof *nodes) : NULL;
            if (status == CM_OK && !nodes)
                status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for region %u", k + 1);
            if (status == CM_OK)
                status = read_nodes(s, k, rec.nexits, nodes, msg, msg_size);
        }
        if (status == CM_OK)
            status = cm_cluster_restore(c, &rec, nodes, msg, msg_size);
        if (c->nregions > k && tables)
            (*exits)[k] = region_exits;
        else
            free(region_exits);
        free(nodes);
    }
    if (status == CM_OK && rc != SQLITE_DONE)
        status = store_db_error(s->db, "read regions", msg, msg_size);
    sqlite3_finalize(st);
    return status;
}

/* Appends region k's saved open nodes (a row of open_nodes) to the arrays:
 * base plus their exits (base node_base: their node ids; 0: the exits). */
static cm_status read_open_row(cm_store *s, const cm_cluster *c, uint32_t k, uint32_t base,
                               int64_t count, const void *blob, int len, uint32_t **ids,
                               uint64_t **weights, int64_t **cells, uint64_t *n, uint64_t *cap)
{
    const cm_cluster_region *cr = &c->regions[k];
    const size_t dim = (size_t)c->lat.dim;
    if (count < 0 || (uint64_t)count > cr->r.nexits || !blob)
        return CM_EFORMAT;
    const uint64_t m = (uint64_t)count, values = m * (2 + dim);
    int64_t *v = malloc((values + 1) * sizeof *v);
    unsigned char *scratch = malloc(8 * (values + 1));
    cm_status st = v && scratch ? CM_OK : CM_ENOMEM;
    if (st == CM_OK && cm_codec_decode(blob, (size_t)len, values, 8, -1, scratch, v) != CM_OK)
        st = CM_EFORMAT;
    s->stats.bytes_read += (uint64_t)len;
    if (st == CM_OK && *n + m > *cap) {
        uint64_t want = *cap ? *cap : 64;
        while (want < *n + m)
            want *= 2;
        uint32_t *i2 = realloc(*ids, want * sizeof *i2);
        if (i2)
            *ids = i2;
        uint64_t *w2 = i2 ? realloc(*weights, want * sizeof *w2) : NULL;
        if (w2)
            *weights = w2;
        int64_t *c2 = w2 ? realloc(*cells, want * dim * sizeof *c2) : NULL;
        if (c2)
            *cells = c2;
        st = c2 ? CM_OK : CM_ENOMEM;
        if (c2)
            *cap = want;
    }
    for (uint64_t i = 0; st == CM_OK && i < m; i++) {
        if (v[i] < 0 || (uint64_t)v[i] >= cr->r.nexits || v[m + i] < 0 ||
            (i > 0 && v[i] <= v[i - 1])) {
            st = CM_EFORMAT;
            break;
        }
        (*ids)[*n + i] = base + (uint32_t)v[i];
        (*weights)[*n + i] = (uint64_t)v[m + i];
    }
    if (st == CM_OK && m > 0) {
        memcpy(*cells + *n * dim, v + 2 * m, m * dim * sizeof *v);
        *n += m;
    }
    free(v);
    free(scratch);
    return st;
}

/* The pager of open lists (cm_open_in_fn): region k's row of open_nodes
 * (none: no open node). */
static cm_status store_open_in(void *user, uint32_t k, uint32_t **local, uint64_t **weight,
                               int64_t **cells, uint64_t *n, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = cm_seconds();
    uint64_t cap = 0;
    sqlite3_stmt *st = NULL;
    *local = NULL, *weight = NULL, *cells = NULL, *n = 0;
    if (sqlite3_prepare_v2(s->db, "SELECT count, data FROM open_nodes WHERE region = ?", -1, &st,
                           NULL))
        return store_db_error(s->db, "read open nodes", msg, msg_size);
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    const int rc = sqlite3_step(st);
    cm_status status = CM_OK;
    if (rc == SQLITE_ROW)
        status = read_open_row(s, s->cluster, k, 0,
                               sqlite3_column_int64(st, 0), sqlite3_column_blob(st, 1),
                               sqlite3_column_bytes(st, 1), local, weight, cells, n, &cap);
    else if (rc != SQLITE_DONE)
        status = store_db_error(s->db, "read open nodes", msg, msg_size);
    sqlite3_finalize(st);
    if (status == CM_EFORMAT)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: open nodes of region %u",
                         s->path, k + 1);
    else if (status == CM_ENOMEM)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes");
    if (status != CM_OK) {
        free(*local), free(*weight), free(*cells);
        *local = NULL, *weight = NULL, *cells = NULL, *n = 0;
    }
    s->stats.read_seconds += cm_seconds() - t0;
    return status;
}

/* The open nodes of a file of version 5 into the cluster. */
static cm_status load_open_nodes(cm_store *s, cm_cluster *c, uint32_t groups,
                                 const uint64_t *basin, char *msg, size_t msg_size)
{
    uint32_t *ids = NULL;
    uint64_t *weights = NULL, n = 0, cap = 0;
    int64_t *cells = NULL;
    sqlite3_stmt *st = NULL;
    cm_status status = cm_cluster_restored_open(c, groups, basin, msg, msg_size);
    if (status != CM_OK)
        return status;
    if (sqlite3_prepare_v2(s->db, "SELECT region, count, data FROM open_nodes ORDER BY region", -1,
                           &st, NULL))
        return store_db_error(s->db, "read open nodes", msg, msg_size);
    int64_t last = 0;
    char why[256] = "";
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const int64_t region = sqlite3_column_int64(st, 0);
        if (region <= last || region > (int64_t)c->nregions) {
            status = CM_EFORMAT;
            break;
        }
        last = region;
        n = 0; /* a row at a time: the rows of a long session hold millions */
        status = read_open_row(s, c, (uint32_t)(region - 1), c->regions[region - 1].node_base,
                               sqlite3_column_int64(st, 1), sqlite3_column_blob(st, 2),
                               sqlite3_column_bytes(st, 2), &ids, &weights, &cells, &n, &cap);
        if (status == CM_OK)
            status = cm_cluster_restored_escapes(c, ids, weights, cells, n, why, sizeof why);
    }
    sqlite3_finalize(st);
    if (status == CM_EFORMAT)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: open nodes of region %lld%s%s",
                         s->path, (long long)last, why[0] ? ": " : "", why);
    else if (status != CM_OK)
        status = cm_fail(status, msg, msg_size, "out of memory for the open nodes");
    free(ids);
    free(weights);
    free(cells);
    return status;
}

cm_status cm_store_load_cluster(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    cm_lattice lat;
    cm_status status = store_read_lattice(s->db, &lat, msg, msg_size);
    if (status != CM_OK)
        return status;
    cm_cluster_init(c, &lat);
    c->resolved_cells = s->version < 4;
    cm_store_attach(s, c);
    status = store_check_groups(s, msg, msg_size);
    if (status != CM_OK)
        return store_damaged(s, status, msg, msg_size);
    const int64_t groups = store_query_int(s->db, "SELECT COUNT(*) FROM attractors");
    int64_t **exits = NULL;
    uint64_t *basin = NULL;
    status = load_regions(s, c, &exits, msg, msg_size);
    if (status == CM_OK)
        status = read_basins(s, (uint32_t)groups, &basin, msg, msg_size);
    if (status == CM_OK && c->nregions > 0)
        status = s->version >= 5
                     ? load_open_nodes(s, c, (uint32_t)groups, basin, msg, msg_size)
                     : cm_cluster_restored(c, (uint32_t)groups, basin, exits, msg, msg_size);
    status = store_damaged(s, status, msg, msg_size);
    for (uint32_t k = 0; exits && k < c->nregions; k++)
        free(exits[k]);
    free(exits);
    free(basin);
    if (status == CM_OK)
        cm_cluster_saved(c);
    return status;
}

cm_status store_insert_region(cm_store *s, uint32_t k, const cm_region *r, char *msg,
                               size_t msg_size)
{
    char lo[512], hi[512];
    store_json_ints(lo, sizeof lo, r->box.lo, r->box.dim);
    store_json_ints(hi, sizeof hi, r->box.hi, r->box.dim);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db, "INSERT INTO regions VALUES(?, ?, ?, ?, ?, ?, 'joined')",
                           -1, &st, NULL))
        return store_db_error(s->db, "prepare regions", msg, msg_size);
    sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
    sqlite3_bind_text(st, 2, lo, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, hi, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 4, (sqlite3_int64)r->ncells);
    sqlite3_bind_int64(st, 5, (sqlite3_int64)r->nexits);
    sqlite3_bind_int64(st, 6, (sqlite3_int64)r->ngroups);
    cm_status status = store_step_done(s->db, st, "write region", msg, msg_size);
    sqlite3_finalize(st);
    if (status != CM_OK)
        return status;
    /* the exit table: nexits * dim little-endian int64 cell coordinates */
    const uint64_t n = r->nexits * (uint64_t)r->box.dim;
    const unsigned char *out = NULL;
    size_t len = 0;
    if (store_encode(s, r->exit_target, n, 8, &out, &len) != CM_OK)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing exits");
    if (status == CM_OK &&
        sqlite3_prepare_v2(s->db, "INSERT INTO exits VALUES(?, ?, ?)", -1, &st, NULL))
        status = store_db_error(s->db, "prepare exits", msg, msg_size);
    if (status == CM_OK) {
        sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)r->nexits);
        sqlite3_bind_blob(st, 3, out, (int)len, SQLITE_STATIC);
        status = store_step_done(s->db, st, "write exits", msg, msg_size);
        sqlite3_finalize(st);
        s->stats.bytes_written += len;
    }
    return status;
}

/* Pages encoded at once: 8 x 3 columns of up to cm_codec_bound(256 KiB). */
#define WRITE_BATCH 8

/* At least `threads` page encoders in s. */
static cm_status ensure_encoders(cm_store *s, int threads)
{
    if (s->n_encoders >= threads)
        return CM_OK;
    store_encoder *e = realloc(s->encoders, (size_t)threads * sizeof *e);
    if (!e)
        return CM_ENOMEM;
    s->encoders = e;
    for (; s->n_encoders < threads; s->n_encoders++) {
        store_encoder *n = &e[s->n_encoders];
        n->ctx = NULL;
        n->scratch = malloc(4 * (size_t)CM_STORE_PAGE_CELLS);
        if (!n->scratch || cm_codec_ctx_new(&n->ctx) != CM_OK) {
            free(n->scratch);
            cm_codec_ctx_free(n->ctx);
            return CM_ENOMEM;
        }
    }
    return CM_OK;
}

void store_free_encoders(cm_store *s)
{
    for (int k = 0; k < s->n_encoders; k++) {
        cm_codec_ctx_free(s->encoders[k].ctx);
        free(s->encoders[k].scratch);
    }
    free(s->encoders);
    free(s->table_values);
    free(s->table_scratch);
    free(s->table_blob);
    s->encoders = NULL;
    s->n_encoders = 0;
    s->table_values = s->table_scratch = s->table_blob = NULL;
    s->table_values_cap = s->table_scratch_cap = s->table_blob_cap = 0;
}

void *store_table_values(cm_store *s, size_t bytes)
{
    return cm_grow((void **)&s->table_values, &s->table_values_cap, bytes + 1, 1) == CM_OK
               ? s->table_values
               : NULL;
}

cm_status store_encode(cm_store *s, const void *v, size_t n, int width, const unsigned char **blob,
                       size_t *len)
{
    const size_t bytes = (size_t)width * (n + 1), bound = cm_codec_bound(bytes);
    if (ensure_encoders(s, 1) != CM_OK ||
        cm_grow((void **)&s->table_scratch, &s->table_scratch_cap, bytes, 1) != CM_OK ||
        cm_grow((void **)&s->table_blob, &s->table_blob_cap, bound, 1) != CM_OK)
        return CM_ENOMEM;
    *blob = s->table_blob;
    return cm_codec_encode_with(s->encoders[0].ctx, v, n, width, -1, s->table_scratch,
                                s->table_blob, bound, len);
}

/* Encodes the three columns (image, grp, step) of pages first .. first +
 * n - 1 into s->blobs, part bytes apart, in parallel; lens[t] is task t's
 * size (task t: page t / 3, column t % 3). An encoder's output does not
 * depend on what it encoded before: the bytes are the same whichever thread
 * encodes a page. */
static cm_status encode_batch(cm_store *s, const cm_region *r, uint64_t first, int n, size_t part,
                              size_t *lens)
{
    const int tasks = 3 * n, threads = s->threads > 0 ? s->threads : 1;
    if (ensure_encoders(s, threads) != CM_OK)
        return CM_ENOMEM;
    int failed = 0;
#pragma omp parallel num_threads(threads) if (tasks > 1) reduction(| : failed)
    {
        const store_encoder *e = &s->encoders[omp_get_thread_num()];
#pragma omp for schedule(dynamic, 1)
        for (int t = 0; t < tasks; t++) {
            const uint64_t page = first + (uint64_t)(t / 3), cell = page * CM_STORE_PAGE_CELLS;
            const int col = t % 3;
            const uint32_t *const arrays[3] = {r->image, r->group, r->step};
            failed |= cm_codec_encode_with(e->ctx, arrays[col] + cell, page_cells(r->ncells, page),
                                           4, col == 0 ? (int64_t)cell : -1, e->scratch,
                                           s->blobs + (size_t)t * part, part, &lens[t]) != CM_OK;
        }
    }
    return failed ? CM_ENOMEM : CM_OK;
}

/* Adds a region's page bytes to the meta value 'page_bytes', in the
 * transaction that writes the pages. Files made before the value existed
 * have none and get none: a sum of only the later pages would be wrong. */
static cm_status add_page_bytes(cm_store *s, uint64_t bytes, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db,
                           "UPDATE meta SET value = CAST(value AS INTEGER) + ? "
                           "WHERE key = 'page_bytes'",
                           -1, &st, NULL))
        return store_db_error(s->db, "prepare page bytes", msg, msg_size);
    sqlite3_bind_int64(st, 1, (sqlite3_int64)bytes);
    const cm_status status = store_step_done(s->db, st, "write page bytes", msg, msg_size);
    sqlite3_finalize(st);
    return status;
}

/* Writes all of region k's pages, once: a region never changes. Pages are
 * encoded in parallel a batch at a time and written in order. */
cm_status store_write_pages(cm_store *s, uint32_t k, const cm_region *r, char *msg,
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
        return store_db_error(s->db, "prepare pages", msg, msg_size);
    cm_status status = CM_OK;
    uint64_t bytes = 0;
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
                s->stats.page_bytes_written += lens[t];
                bytes += lens[t];
            }
            status = store_step_done(s->db, st, "write page", msg, msg_size);
            s->stats.pages_written++;
        }
    }
    sqlite3_finalize(st);
    return status == CM_OK ? add_page_bytes(s, bytes, msg, msg_size) : status;
}

/* Node chunks encoded at once. */
#define NODE_BATCH 16

/* The NODE_FIELDS columns of nodes[0..n) into cols (n values each). Only
 * the fields that say what a node's exit leads to are saved: a final group
 * is kept for final and cycle nodes only, so the file does not depend on
 * what readers resolved. */
static void node_columns(const cm_node *nodes, uint64_t n, uint32_t *cols)
{
    for (uint64_t e = 0; e < n; e++) {
        const cm_node *nd = &nodes[e];
        const int known = nd->next == CM_NODE_FINAL || nd->next == CM_NODE_CYCLE;
        cols[e] = nd->next;
        cols[n + e] = nd->next == CM_NODE_OPEN ? 0 : nd->dist;
        cols[2 * n + e] = known ? nd->group : 0;
        cols[3 * n + e] = nd->next == CM_NODE_OPEN ? 0 : nd->target;
        cols[4 * n + e] = nd->tree;
        cols[5 * n + e] = nd->first_in;
        cols[6 * n + e] = nd->sibling;
    }
}

/* Nodes of the chunk that starts at node `first` of region cr. */
static uint64_t chunk_nodes(const cm_cluster_region *cr, uint64_t first)
{
    return cr->r.nexits - first < CM_NODE_CHUNK ? cr->r.nexits - first : CM_NODE_CHUNK;
}

/* Encodes the chunks of cr's nodes that start at first[0..n) into
 * s->blobs, part bytes apart, in parallel (lens[j]: chunk j's size). As
 * for pages, the bytes do not depend on which thread encodes a chunk. */
static cm_status encode_node_chunks(cm_store *s, const cm_cluster_region *cr,
                                    const uint64_t *first, int n, size_t part, size_t *lens)
{
    const int threads = s->threads > 0 ? s->threads : 1;
    if (ensure_encoders(s, threads) != CM_OK)
        return CM_ENOMEM;
    int failed = 0;
#pragma omp parallel num_threads(threads) if (n > 1) reduction(| : failed)
    {
        const store_encoder *e = &s->encoders[omp_get_thread_num()];
        uint32_t *cols = malloc(NODE_FIELDS * CM_NODE_CHUNK * sizeof *cols);
        failed |= !cols;
#pragma omp for schedule(dynamic, 1)
        for (int j = 0; j < n; j++) {
            const uint64_t count = chunk_nodes(cr, first[j]);
            if (!cols)
                continue;
            node_columns(cr->nodes + first[j], count, cols);
            failed |= cm_codec_encode_with(e->ctx, cols, NODE_FIELDS * count, 4, -1, e->scratch,
                                           s->blobs + (size_t)j * part, part, &lens[j]) != CM_OK;
        }
        free(cols);
    }
    return failed ? CM_ENOMEM : CM_OK;
}

/* Region k's node records that changed: each chunk of CM_NODE_CHUNK nodes
 * with a changed record, as one row (NODE_FIELDS columns, node_columns),
 * encoded NODE_BATCH chunks at a time in parallel and written in order. */
cm_status store_write_nodes(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                            size_t msg_size)
{
    _Static_assert(NODE_FIELDS * CM_NODE_CHUNK <= CM_STORE_PAGE_CELLS,
                   "a chunk's columns fit an encoder's scratch");
    const cm_cluster_region *cr = &c->regions[k];
    const size_t part = cm_codec_bound(4 * (NODE_FIELDS * (size_t)CM_NODE_CHUNK + 1));
    s->cluster_written = 1;
    uint64_t first[NODE_BATCH];
    size_t lens[NODE_BATCH];
    sqlite3_stmt *st = NULL;
    cm_status status = CM_OK;
    if (cm_grow((void **)&s->blobs, &s->blobs_cap, (uint64_t)NODE_BATCH * part, 1) != CM_OK)
        status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing nodes");
    else if (sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO nodes VALUES(?, ?, ?, ?)", -1, &st,
                                NULL))
        status = store_db_error(s->db, "prepare nodes", msg, msg_size);
    for (uint64_t next = 0; status == CM_OK && next < cr->r.nexits;) {
        int n = 0;
        for (; n < NODE_BATCH && next < cr->r.nexits; next += CM_NODE_CHUNK)
            if (cr->dirty_chunks[next / CM_NODE_CHUNK])
                first[n++] = next;
        if (n > 0 && encode_node_chunks(s, cr, first, n, part, lens) != CM_OK)
            status = cm_fail(CM_ENOMEM, msg, msg_size, "encoding the nodes of region %u", k + 1);
        for (int j = 0; status == CM_OK && j < n; j++) {
            sqlite3_bind_int64(st, 1, (sqlite3_int64)k + 1);
            sqlite3_bind_int64(st, 2, (sqlite3_int64)first[j]);
            sqlite3_bind_int64(st, 3, (sqlite3_int64)chunk_nodes(cr, first[j]));
            sqlite3_bind_blob(st, 4, s->blobs + (size_t)j * part, (int)lens[j], SQLITE_STATIC);
            status = store_step_done(s->db, st, "write nodes", msg, msg_size);
            s->stats.bytes_written += lens[j];
            s->stats.node_tables_written++;
        }
    }
    sqlite3_finalize(st);
    return status;
}

/* Region k's row, exits and pages (a region saved whole). */
cm_status store_write_region(cm_store *s, const cm_cluster *c, uint32_t k, char *msg,
                             size_t msg_size)
{
    const cm_region *r = &c->regions[k].r;
    if (!r->group)
        return cm_fail(CM_EINVAL, msg, msg_size, "region %u is unsaved but paged out", k);
    s->cluster_written = 1;
    cm_status st = store_insert_region(s, k, r, msg, msg_size);
    if (st == CM_OK)
        st = store_write_pages(s, k, r, msg, msg_size);
    s->stats.regions_written++;
    return st;
}

/* The pager's other half: saves a dirty region about to be evicted, in the
 * transaction the next commit ends (a kill before it undoes the write). */
cm_status store_page_out(void *user, const cm_cluster *c, uint32_t k, char *msg, size_t msg_size)
{
    cm_store *s = user;
    const double t0 = cm_seconds();
    cm_status st = store_begin(s, msg, msg_size);
    if (st == CM_OK)
        st = store_write_region(s, c, k, msg, msg_size);
    s->stats.regions_evicted++;
    s->stats.evict_seconds += cm_seconds() - t0;
    return st == CM_OK ? CM_OK : store_abandon(s, st);
}
