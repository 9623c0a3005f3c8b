/* cellmap/store_commit.c - writing what joins changed: groups, basin counts,
 * node records and new regions, one transaction per commit. */
#include "cellmap/store_db.h"

#include "cellmap/clock.h"

#include "cellmap/codec.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The cell counts of the groups whose counts changed. */
static cm_status write_basins(cm_store *s, const cm_cluster *c, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO basins VALUES(?, ?)", -1, &st, NULL))
        return store_db_error(s->db, "prepare basins", msg, msg_size);
    cm_status status = CM_OK;
    for (uint32_t g = 1; status == CM_OK && g <= c->ngroups; g++) {
        if (!c->basin_dirty[g])
            continue;
        sqlite3_bind_int64(st, 1, g);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)c->basin[g]);
        status = store_step_done(s->db, st, "write basins", msg, msg_size);
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
    store_json_doubles(centre, sizeof centre, gi->centre, lat->dim);
    store_json_doubles(lo, sizeof lo, gi->lo, lat->dim);
    store_json_doubles(hi, sizeof hi, gi->hi, lat->dim);
    store_json_ints(anchor, sizeof anchor, gi->anchor, lat->dim);
    sqlite3_bind_int64(st, 1, gi->id);
    sqlite3_bind_int64(st, 2, gi->period);
    sqlite3_bind_text(st, 3, centre, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, lo, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 5, hi, -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 6, anchor, -1, SQLITE_TRANSIENT);
    sqlite3_bind_blob(st, 7, blob, (int)(n * (uint64_t)lat->dim * 8), SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 8, cm_group_kind_name(gi->kind), -1, SQLITE_STATIC);
    const cm_status status = store_step_done(s->db, st, "write group", msg, msg_size);
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
        status = store_db_error(s->db, "prepare groups", msg, msg_size);
    const cm_group_cell *cells = c->new_periodic;
    for (uint32_t g = 0; g < n && status == CM_OK; cells += groups[g++].period)
        status = insert_attractor(s, st, &c->lat, &groups[g], cells, msg, msg_size);
    sqlite3_finalize(st);
    free(groups);
    return status;
}

/* Region k's row of open_nodes: its open nodes as one encoded int64 array
 * of count * (2 + dim) values: the exits (local), their weights, then the
 * target cells (dim coordinates each). */
cm_status store_write_open_nodes(cm_store *s, cm_cluster *c, uint32_t k, char *msg,
                                 size_t msg_size)
{
    uint32_t *local;
    uint64_t *weight, n;
    int64_t *cells;
    s->cluster_written = 1;
    cm_status st = cm_cluster_open_nodes(c, k, &local, &weight, &cells, &n, msg, msg_size);
    if (st != CM_OK)
        return st;
    const size_t dim = (size_t)c->lat.dim, values = n * (2 + dim);
    int64_t *v = store_table_values(s, values * sizeof *v);
    const unsigned char *blob = NULL;
    size_t len = 0;
    st = v ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory writing open nodes");
    for (uint64_t i = 0; st == CM_OK && i < n; i++) {
        v[i] = local[i];
        v[n + i] = (int64_t)weight[i];
    }
    if (st == CM_OK) {
        memcpy(v + 2 * n, cells, n * dim * sizeof *v);
        if (store_encode(s, v, values, 8, &blob, &len) != CM_OK)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "encoding the open nodes of region %u", k + 1);
    }
    sqlite3_stmt *ins = NULL;
    if (st == CM_OK && sqlite3_prepare_v2(s->db, "INSERT OR REPLACE INTO open_nodes VALUES(?, ?, ?)",
                                          -1, &ins, NULL))
        st = store_db_error(s->db, "prepare open nodes", msg, msg_size);
    if (st == CM_OK) {
        sqlite3_bind_int64(ins, 1, (sqlite3_int64)k + 1);
        sqlite3_bind_int64(ins, 2, (sqlite3_int64)n);
        sqlite3_bind_blob(ins, 3, blob, (int)len, SQLITE_STATIC);
        st = store_step_done(s->db, ins, "write open nodes", msg, msg_size);
        s->stats.bytes_written += len;
    }
    sqlite3_finalize(ins);
    free(local);
    free(weight);
    free(cells);
    return st;
}

/* A region never saved: its row, exit table and pages. */

cm_status store_write_changes(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint32_t k = 0; st == CM_OK && k < c->nregions; k++)
        if (!c->regions[k].written)
            st = store_write_region(s, c, k, msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < c->nregions; k++)
        if (c->regions[k].nodes_dirty)
            st = store_write_nodes(s, c, k, msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < c->nregions; k++)
        if (c->regions[k].open_dirty)
            st = store_write_open_nodes(s, c, k, msg, msg_size);
    if (st == CM_OK)
        st = write_basins(s, c, msg, msg_size);
    if (st == CM_OK)
        st = write_new_groups(s, c, msg, msg_size);
    if (st == CM_OK) {
        char sql[96];
        snprintf(sql, sizeof sql, "UPDATE meta SET value = '%u' WHERE key = 'groups'", c->ngroups);
        if (store_exec(s->db, sql) != SQLITE_OK)
            st = store_db_error(s->db, "write meta", msg, msg_size);
    }
    return st;
}

cm_status cm_store_commit(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    if (c->open_released)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's open nodes were released (it is only read): nothing "
                       "of it is saved");
    const double t0 = cm_seconds();
    cm_status st = store_begin(s, msg, msg_size);
    if (st == CM_OK)
        st = store_write_changes(s, c, msg, msg_size);
    if (st == CM_OK && s->cluster_written)
        st = store_forget_attractors(s, msg, msg_size);
    if (st == CM_OK && store_exec(s->db, "COMMIT") != SQLITE_OK)
        st = store_db_error(s->db, "commit", msg, msg_size);
    if (st != CM_OK)
        return store_abandon(s, st);
    s->in_transaction = 0;
    s->cluster_written = 0;
    cm_cluster_saved(c); /* the file now holds everything */
    s->stats.commit_seconds += cm_seconds() - t0;
    return CM_OK;
}

cm_status cm_store_commit_join(void *store, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                               char *msg, size_t msg_size)
{
    (void)box;
    (void)stats;
    return cm_store_commit(store, c, msg, msg_size); /* the next join makes room */
}

/* Group row `st` (id, period, basin_cells, centre, lo, hi, anchor, kind)
 * into g. */
static cm_status group_row(const cm_store *s, sqlite3_stmt *st, const cm_lattice *lat,
                           cm_group_info *g, char *msg, size_t msg_size)
{
    const int64_t id = sqlite3_column_int64(st, 0);
    double anchor[CM_MAX_DIM];
    memset(g, 0, sizeof *g);
    g->id = (uint32_t)id;
    g->period = (uint32_t)sqlite3_column_int64(st, 1);
    g->basin_cells = (uint64_t)sqlite3_column_int64(st, 2);
    for (int col = 3; col <= 6; col++) {
        double *const out[] = {g->centre, g->lo, g->hi, anchor};
        if (store_parse_json_numbers((const char *)sqlite3_column_text(st, col), out[col - 3],
                                     CM_MAX_DIM) != lat->dim)
            return cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: group %lld", s->path,
                           (long long)id);
    }
    for (int d = 0; d < lat->dim; d++)
        g->anchor[d] = (int64_t)anchor[d];
    const unsigned char *kind = sqlite3_column_text(st, 7);
    g->kind = kind && strcmp((const char *)kind, cm_group_kind_name(CM_GROUP_STICKING)) == 0
                  ? CM_GROUP_STICKING
                  : CM_GROUP_ATTRACTOR;
    return CM_OK;
}

/* The n group rows `sql` gives (its ?1, if it has one: n) into groups, and
 * the sink's cells; in_id_order: the rows must be groups 1..n. */
static cm_status read_groups(cm_store *s, const char *sql, bool in_id_order, cm_group_info *groups,
                             uint32_t n, uint64_t *sink_cells, char *msg, size_t msg_size)
{
    cm_lattice lat;
    cm_status status = store_read_lattice(s->db, &lat, msg, msg_size);
    const int64_t sink = status == CM_OK ? store_sink_cells(s) : 0;
    if (status == CM_OK && sink < 0)
        status = cm_fail(CM_EFORMAT, msg, msg_size,
                         "%s is damaged: its basins hold more cells than its regions", s->path);
    *sink_cells = (uint64_t)(sink > 0 ? sink : 0);
    sqlite3_stmt *st = NULL;
    if (status == CM_OK && sqlite3_prepare_v2(s->db, sql, -1, &st, NULL))
        status = store_db_error(s->db, "read groups", msg, msg_size);
    if (st && sqlite3_bind_parameter_count(st) > 0)
        sqlite3_bind_int64(st, 1, n);
    uint32_t seen = 0;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        const int64_t id = sqlite3_column_int64(st, 0);
        if (seen == n || id < 1 || (in_id_order && id != (int64_t)seen + 1)) {
            status = cm_fail(CM_EFORMAT, msg, msg_size, "%s is damaged: group %lld", s->path,
                             (long long)id);
            break;
        }
        status = group_row(s, st, &lat, &groups[seen++], msg, msg_size);
    }
    sqlite3_finalize(st);
    if (status == CM_OK && seen != n)
        status = cm_fail(CM_EFORMAT, msg, msg_size, "%s holds %u groups, not %u", s->path, seen, n);
    return status;
}

/* From version 4 on, the groups view's rows of the attractors are read
 * straight from its tables: its ORDER BY over a UNION ALL sorts every row. */
cm_status cm_store_groups(cm_store *s, cm_group_info *groups, uint32_t n, uint64_t *sink_cells,
                          char *msg, size_t msg_size)
{
    const char *const sql =
        s->version >= 4
            ? "SELECT a.id, a.period, IFNULL((SELECT cells FROM basins WHERE grp = a.id), 0),"
              " a.centre, a.lo, a.hi, a.anchor, a.kind FROM attractors a ORDER BY a.id"
            : "SELECT id, period, basin_cells, centre, lo, hi, anchor, kind FROM groups "
              "WHERE id > 0 ORDER BY id";
    return read_groups(s, sql, true, groups, n, sink_cells, msg, msg_size);
}

cm_status cm_store_largest_groups(cm_store *s, cm_group_info *groups, uint32_t k,
                                  uint64_t *sink_cells, char *msg, size_t msg_size)
{
    const char *const sql =
        s->version >= 4
            ? "SELECT a.id, a.period, IFNULL(b.cells, 0) AS basin, a.centre, a.lo, a.hi,"
              " a.anchor, a.kind FROM attractors a LEFT JOIN basins b ON b.grp = a.id"
              " ORDER BY basin DESC, a.id LIMIT ?1"
            : "SELECT id, period, basin_cells, centre, lo, hi, anchor, kind FROM groups "
              "WHERE id > 0 ORDER BY basin_cells DESC, id LIMIT ?1";
    return read_groups(s, sql, false, groups, k, sink_cells, msg, msg_size);
}

