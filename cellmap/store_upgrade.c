/* cellmap/store_upgrade.c - files of versions 2, 3 and 4 to version 5.
 *
 * Version 4 lacks only the table of open nodes: it is added from the
 * cluster as version 4 loads it. Versions 2 and 3 stored every region resolved: cells held cluster-wide
 * groups and steps, rewritten by every join. Version 4 keeps each region
 * as its own SCM left it and joins regions through node tables (so does 5). The saved
 * images and exit tables are all a join needs, so the upgrade classifies
 * each region again from its images (no model step is taken) and joins the
 * regions in their saved order, which numbers groups as the old joins did.
 * It then checks that the result is the file's, cell by cell (group and
 * step) and group by group (the `groups` view), before it replaces the
 * tables; anything else rolls the transaction back. */
#include "cellmap/store_db.h"

#include "cellmap/grow.h"
#include "cellmap/join.h"
#include "cellmap/numtext.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The `groups` view as text, to compare before and after. */
static cm_status groups_text(cm_store *s, char **out, char *msg, size_t msg_size)
{
    sqlite3_stmt *st = NULL;
    char *text = NULL;
    uint64_t len = 0, cap = 0;
    if (sqlite3_prepare_v2(s->db,
                           "SELECT id, period, basin_cells, centre, lo, hi, anchor, kind,"
                           " hex(periodic_cells) FROM groups ORDER BY id",
                           -1, &st, NULL))
        return store_db_error(s->db, "read groups", msg, msg_size);
    cm_status status = CM_OK;
    while (status == CM_OK && sqlite3_step(st) == SQLITE_ROW) {
        for (int col = 0; col < 9 && status == CM_OK; col++) {
            const char *v = (const char *)sqlite3_column_text(st, col);
            char shortest[1024]; /* older versions wrote 17 digits: compare values */
            if (v && v[0] == '[' && cm_json_numbers_shortest(v, shortest, sizeof shortest))
                v = shortest;
            const uint64_t n = (v ? strlen(v) : 0) + 1;
            if (cm_grow((void **)&text, &cap, len + n + 1, 1) != CM_OK) {
                status = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading groups");
                break;
            }
            memcpy(text + len, v ? v : "", n - 1);
            len += n;
            text[len - 1] = col == 8 ? '\n' : '|';
            text[len] = '\0';
        }
    }
    sqlite3_finalize(st);
    if (status != CM_OK) {
        free(text);
        return status;
    }
    *out = text ? text : strdup("");
    return *out ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory reading groups");
}

/* The saved regions joined again into c (in memory) from their images. */
static cm_status join_again(cm_store *s, const cm_cluster *saved, cm_cluster *c, char *msg,
                            size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < saved->nregions && st == CM_OK; k++) {
        cm_region r = saved->regions[k].r; /* the record: box, cells, exits */
        r.image = r.group = r.step = NULL;
        r.exit_target = NULL;
        st = store_page_in(s, k, &r, msg, msg_size);
        r.exits_recorded = 1;
        if (st == CM_OK)
            st = cm_scm_classify(&r, 0, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_join(c, &r, NULL, msg, msg_size);
        cm_region_free(&r);
    }
    return st;
}

/* Every cell of the joined cluster c has the group and step the file holds. */
static cm_status same_cells(cm_store *s, const cm_cluster *saved, cm_cluster *c, char *msg,
                            size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < saved->nregions && st == CM_OK; k++) {
        cm_region old = saved->regions[k].r, now;
        old.image = old.group = old.step = NULL;
        old.exit_target = NULL;
        memset(&now, 0, sizeof now);
        st = store_page_in(s, k, &old, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_flatten(c, &old.box, &now, msg, msg_size);
        for (uint64_t i = 0; st == CM_OK && i < old.ncells; i++)
            if (old.group[i] != now.group[i] || old.step[i] != now.step[i])
                st = cm_fail(CM_EFORMAT, msg, msg_size,
                             "cell %llu of region %u joins again as group %u step %u, the file "
                             "says group %u step %u",
                             (unsigned long long)i, k + 1, now.group[i], now.step[i],
                             old.group[i], old.step[i]);
        cm_region_free(&old);
        cm_region_free(&now);
    }
    return st;
}

/* The old tables out, this version's in, written from c. */
static cm_status rewrite(cm_store *s, cm_cluster *c, char *msg, size_t msg_size)
{
    if (store_exec(s->db, "DROP VIEW IF EXISTS temp.groups; DROP VIEW main.groups;"
                          " DROP TABLE region_groups; DROP TABLE pages; DROP TABLE exits;"
                          " DROP TABLE attractors; DROP TABLE regions;") != SQLITE_OK ||
        store_exec(s->db, store_tables_sql) != SQLITE_OK ||
        store_exec(s->db, "INSERT OR REPLACE INTO meta(key, value) VALUES('page_bytes', '0')") !=
            SQLITE_OK)
        return store_db_error(s->db, "replace the tables", msg, msg_size);
    for (uint32_t k = 0; k < c->nregions; k++)
        c->regions[k].written = 0; /* all regions, nodes, counts and groups are unsaved */
    cm_status st = store_write_changes(s, c, msg, msg_size);
    s->cluster_written = 0; /* the same cluster, rewritten: its attractors hold */
    char pragma[64];
    snprintf(pragma, sizeof pragma, "PRAGMA user_version=%d", CM_STORE_VERSION);
    if (st == CM_OK && store_exec(s->db, pragma) != SQLITE_OK)
        st = store_db_error(s->db, "write the version", msg, msg_size);
    return st;
}

/* The upgrade of an open old file, in its transaction. */
static cm_status upgrade(cm_store *s, char *msg, size_t msg_size)
{
    cm_cluster saved, c;
    char *before = NULL, *after = NULL;
    memset(&c, 0, sizeof c);
    cm_status st = cm_store_load_cluster(s, &saved, msg, msg_size);
    if (st == CM_OK)
        cm_cluster_init(&c, &saved.lat);
    if (st == CM_OK)
        st = groups_text(s, &before, msg, msg_size);
    if (st == CM_OK)
        st = join_again(s, &saved, &c, msg, msg_size);
    if (st == CM_OK)
        st = same_cells(s, &saved, &c, msg, msg_size);
    if (st == CM_OK)
        st = rewrite(s, &c, msg, msg_size);
    if (st == CM_OK)
        st = groups_text(s, &after, msg, msg_size);
    if (st == CM_OK && strcmp(before, after) != 0)
        st = cm_fail(CM_EFORMAT, msg, msg_size, "its groups would change");
    free(before);
    free(after);
    cm_cluster_free(&saved);
    cm_cluster_free(&c);
    return st;
}

/* Version 4 kept no lists of the nodes linked into each node's tree: those
 * whose sequences still leave the cluster are listed now. */
static cm_status list_linked_in(cm_cluster *c, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++) {
        cm_cluster_region *cr = &c->regions[k];
        for (uint64_t e = 0; e < cr->r.nexits && st == CM_OK; e++) {
            const uint32_t id = cr->node_base + (uint32_t)e, m = cr->nodes[e].next;
            uint32_t g, step, open;
            cm_node *nm;
            if (m >= CM_NODE_MAX)
                continue;
            st = cm_cluster_resolve(c, id, &g, &step, &open, msg, msg_size);
            if (st == CM_OK && open != CM_NODE_OPEN &&
                (st = cm_cluster_node(c, m, &nm, msg, msg_size)) == CM_OK) {
                cr->nodes[e].sibling = nm->first_in;
                nm->first_in = id;
            }
        }
    }
    for (uint32_t k = 0; k < c->nregions; k++) { /* every table is written again, in version 5 */
        c->regions[k].nodes_dirty = 1;
        memset(c->regions[k].dirty_chunks, 1, c->regions[k].r.nexits / CM_NODE_CHUNK + 1);
    }
    return st;
}

/* Version 4 had everything but the open nodes, which it rebuilt from every
 * node table at each open, the lists of linked-in nodes and node rows by
 * chunks: they are written from the cluster loaded that way. */
static cm_status add_open_nodes(cm_store *s, char *msg, size_t msg_size)
{
    cm_cluster c;
    cm_status st = cm_store_load_cluster(s, &c, msg, msg_size);
    if (st == CM_OK)
        st = list_linked_in(&c, msg, msg_size);
    if (st == CM_OK && store_exec(s->db, "DROP TABLE nodes;" NODES_TABLE_SQL OPEN_NODES_TABLE_SQL
                                             SYSTEM_ATTRACTORS_SQL) != SQLITE_OK)
        st = store_db_error(s->db, "add the open nodes", msg, msg_size);
    for (uint32_t k = 0; st == CM_OK && k < c.nregions; k++) {
        st = store_write_nodes(s, &c, k, msg, msg_size);
        if (st == CM_OK) /* a row for every region, as a solve writes them */
            st = store_write_open_nodes(s, &c, k, msg, msg_size);
    }
    char pragma[64];
    snprintf(pragma, sizeof pragma, "PRAGMA user_version=%d", CM_STORE_VERSION);
    if (st == CM_OK && store_exec(s->db, pragma) != SQLITE_OK)
        st = store_db_error(s->db, "write the version", msg, msg_size);
    cm_cluster_free(&c);
    return st;
}

/* Version 5 had everything but the system's attractors: their tables come
 * empty, and the solve or session that upgraded the file fills them. */
static cm_status add_system_attractors(cm_store *s, char *msg, size_t msg_size)
{
    char sql[1024];
    snprintf(sql, sizeof sql, "%s PRAGMA user_version=%d;", SYSTEM_ATTRACTORS_SQL,
             CM_STORE_VERSION);
    return store_exec(s->db, sql) == SQLITE_OK
               ? CM_OK
               : store_db_error(s->db, "add the attractors' tables", msg, msg_size);
}

/* Version 6's attractors were found without following the orbits that
 * leave the computed cells: they go (the solve or session that upgraded
 * the file finds them again), and the table of exits' fates comes. */
static cm_status add_exit_fates(cm_store *s, char *msg, size_t msg_size)
{
    char sql[1024];
    snprintf(sql, sizeof sql,
             "DELETE FROM system_attractors; DELETE FROM group_fates;"
             " DELETE FROM meta WHERE key = 'attractor_options'; %s PRAGMA user_version=%d;",
             EXIT_FATES_SQL, CM_STORE_VERSION);
    return store_exec(s->db, sql) == SQLITE_OK
               ? CM_OK
               : store_db_error(s->db, "add the exits' fates", msg, msg_size);
}

cm_status cm_store_upgrade(const char *path, const cm_model *model, int *upgraded, char *msg,
                           size_t msg_size)
{
    *upgraded = 0;
    sqlite3 *db = NULL;
    cm_store *s = NULL;
    cm_status st = store_open_checked(path, 1, 1, 1, &db, msg, msg_size);
    if (st == CM_OK)
        st = store_new(path, db, 1, &s, msg, msg_size);
    if (st != CM_OK || s->version >= CM_STORE_VERSION) {
        char ignored[64];
        cm_store_close(s, ignored, sizeof ignored);
        return st;
    }
    const int from = s->version;
    s->model = model;
    char why[1024] = "";
    /* one transaction in the rollback journal, not WAL mode: a refused
     * upgrade leaves the file byte-identical */
    if (store_exec(s->db, "BEGIN IMMEDIATE") != SQLITE_OK)
        st = store_db_error(s->db, "begin", why, sizeof why);
    s->in_transaction = st == CM_OK;
    if (st == CM_OK)
        st = from == 6   ? add_exit_fates(s, why, sizeof why)
             : from == 5 ? add_system_attractors(s, why, sizeof why)
             : from == 4 ? add_open_nodes(s, why, sizeof why)
                         : upgrade(s, why, sizeof why);
    if (st == CM_OK && store_exec(s->db, "COMMIT") != SQLITE_OK)
        st = store_db_error(s->db, "commit", why, sizeof why);
    if (st != CM_OK) {
        store_exec(s->db, "ROLLBACK");
        s->in_transaction = 0;
        cm_fail(st, msg, msg_size,
                "%s has format version %d and could not be upgraded to version %d (%s); the "
                "file is unchanged: render and export it as it is, or solve again with --db",
                path, from, CM_STORE_VERSION, why);
    }
    s->in_transaction = 0;
    char ignored[64];
    cm_store_close(s, ignored, sizeof ignored);
    *upgraded = st == CM_OK;
    return st;
}
