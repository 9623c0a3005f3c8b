/* The .cmdb store: codec round trips, paged clusters equal to in-memory
 * ones under any budget, reopening, and files that must be refused. */
#include <math.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/codec.h"
#include "cellmap/join.h"
#include "cellmap/outside.h"
#include "cellmap/store.h"
#include "check.h"
#include "shift_map.h"
#include "cmdb_hash.h"
#include "mix.h"
#include "models/registry.h"

static char *slurp(const char *path, long *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *size = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)*size + 1);
    if (fread(buf, 1, (size_t)*size, f) != (size_t)*size)
        *size = -1;
    fclose(f);
    return buf;
}

static int larger_basin_first(const void *a, const void *b)
{
    const cm_group_info *x = a, *y = b;
    if (x->basin_cells != y->basin_cells)
        return x->basin_cells > y->basin_cells ? -1 : 1;
    return x->id < y->id ? -1 : (x->id > y->id);
}

static int64_t sql_int(const char *path, const char *sql)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    int64_t v = -1;
    sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL);
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    return v;
}

static void sql_exec(const char *path, const char *sql)
{
    sqlite3 *db = NULL;
    sqlite3_open(path, &db);
    CHECK(sqlite3_exec(db, sql, NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(db);
}

static void test_codec(void)
{
    enum { N = 70000 };
    uint32_t *v = malloc(N * sizeof *v), *back = malloc(N * sizeof *back);
    int64_t *w = malloc(N * sizeof *w), *wback = malloc(N * sizeof *wback);
    unsigned char *scratch = malloc(8 * N), *out = malloc(cm_codec_bound(8 * N));
    for (uint32_t i = 0; i < N; i++) {
        v[i] = i % 7 == 0 ? 0xFFFFFFFFu : (uint32_t)(mix(i) % (N + 5)); /* marks, images */
        w[i] = (int64_t)mix(i + 1000) >> (i % 60);
    }
    size_t len = 0;
    CHECK(cm_codec_encode(v, N, 4, 123, scratch, out, cm_codec_bound(4 * N), &len) == CM_OK);
    CHECK(cm_codec_decode(out, len, N, 4, 123, scratch, back) == CM_OK);
    CHECK(memcmp(v, back, N * sizeof *v) == 0);
    /* a BLOB of another size, or damaged, is refused */
    CHECK(cm_codec_decode(out, len, N - 1, 4, 123, scratch, back) == CM_EFORMAT);
    out[len / 2] ^= 0x5A;
    out[len / 2 + 1] ^= 0xA5;
    const cm_status damaged = cm_codec_decode(out, len, N, 4, 123, scratch, back);
    CHECK(damaged == CM_EFORMAT);
    CHECK(cm_codec_decode(out, 3, N, 4, 123, scratch, back) == CM_EFORMAT);
    CHECK(cm_codec_encode(w, N, 8, -1, scratch, out, cm_codec_bound(8 * N), &len) == CM_OK);
    CHECK(cm_codec_decode(out, len, N, 8, -1, scratch, wback) == CM_OK);
    CHECK(memcmp(w, wback, N * sizeof *w) == 0);
    free(v);
    free(back);
    free(w);
    free(wback);
    free(scratch);
    free(out);
}

/* Fig. 4.16's map on 0..900 x 0..600 cells cut into 3 x 2 regions of two pages: groups
 * straddle borders and joins change older regions' pages. */
enum { NX = 900, NY = 600, TX = 3, TY = 2 };
static const cm_lattice lat416 = {2, {-13, -4}, {26.0 / 1300, 8.0 / 400}};

static void tiles(cm_box *boxes)
{
    for (int j = 0; j < TY; j++)
        for (int i = 0; i < TX; i++)
            boxes[j * TX + i] =
                (cm_box){2, {NX * i / TX, NY * j / TY}, {NX * (i + 1) / TX, NY * (j + 1) / TY}};
}

/* A pass over the exits of c (paged, every region saved) reserves room
 * in the budget, and the cluster evicts to make it. */
static void reserve_for_exits(cm_cluster *c)
{
    char msg[256];
    cm_exits x;
    CHECK(cm_cluster_exits(c, &x, msg, sizeof msg) == CM_OK);
    const uint64_t room = cm_cluster_exits_room(c);
    CHECK(x.nnodes > 0 && room == x.nnodes * CM_EXITS_PASS_BYTES);
    cm_exits_free(&x);
    const uint64_t held = c->mem_reserved, before = cm_cluster_resident_bytes(c);
    c->mem_reserved = held + room;
    cm_cluster_trim(c);
    const uint64_t after = cm_cluster_resident_bytes(c);
    CHECK(before == 0 || after < before); /* else the check below says little */
    CHECK(after + c->mem_reserved <= c->mem_budget + c->mem_budget / 4 ||
          (c->mem_reserved >= c->mem_budget && after <= c->mem_budget / 4));
    c->mem_reserved = held;
}

/* Bytes of c's resident node tables (only the clean ones, which a trim
 * may evict, with `clean`). */
static uint64_t table_bytes(const cm_cluster *c, bool clean)
{
    uint64_t bytes = 0;
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        if (cr->nodes && !(clean && cr->nodes_dirty))
            bytes += cr->r.nexits * sizeof(cm_node);
    }
    return bytes;
}

/* Node tables beyond their quarter of the budget stay while the cells
 * leave them room (cells and tables within the budget and its quarter),
 * and are shed once the cells do not (all but the changed ones, which a
 * trim keeps). Reads every table back; c's budget is as it was on
 * return. */
static void tables_use_free_room(cm_cluster *c)
{
    char msg[256];
    const uint64_t budget = c->mem_budget;
    for (uint32_t k = 0; k < c->nregions; k++) { /* every table resident */
        cm_node *nd;
        CHECK(cm_cluster_node_load(c, c->regions[k].node_base, &nd, msg, sizeof msg) == CM_OK ||
              c->regions[k].r.nexits == 0);
    }
    const uint64_t tables = table_bytes(c, false);
    const uint64_t cells = cm_cluster_resident_bytes(c) - tables + c->mem_reserved;
    /* a budget whose quarter the tables pass, with room for both */
    c->mem_budget = (cells + tables) * 4 / 5 + 1;
    CHECK(cells <= c->mem_budget && tables > c->mem_budget / 4); /* else the test says nothing */
    cm_cluster_trim(c);
    CHECK_INT(table_bytes(c, false), tables);
    /* cells that fill it: the tables go back to their quarter */
    c->mem_budget = cells;
    cm_cluster_trim(c);
    CHECK(table_bytes(c, false) <= c->mem_budget / 4 || table_bytes(c, true) == 0);
    CHECK(table_bytes(c, false) < tables);
    c->mem_budget = budget;
}

/* Solves the tiling into path (NULL: in memory only) under a budget of
 * `budget_regions` regions (0: none) with `threads` threads; returns the
 * flattened cluster in flat. */
static void solve_tiles(const cm_model *m, const char *path, int budget_regions, int threads,
                        int commit_each, cm_region *flat, cm_store_stats *stats)
{
    char msg[512];
    cm_box boxes[TX * TY], all = {2, {0, 0}, {NX, NY}};
    tiles(boxes);
    cm_cluster c;
    cm_cluster_init(&c, &lat416);
    c.threads = threads;
    cm_store *s = NULL;
    if (path) {
        const cm_store_meta meta = {m, &lat416, "test", "plan", "test", 0, NULL, NULL};
        CHECK(cm_store_create(path, &meta, &s, msg, sizeof msg) == CM_OK);
        cm_store_attach(s, &c);
        c.mem_budget = (uint64_t)budget_regions * 12 * cm_box_cells(&boxes[0]);
        c.mem_reserved = 4096; /* its owner's: the joins add theirs and give back only those */
    }
    const cm_scm_options opt = {.max_steps = 1, .threads = threads, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(&c, m, boxes, TX * TY, &opt,
                                 s && commit_each ? cm_store_commit_join : NULL, s, NULL, msg,
                                 sizeof msg) == CM_OK);
    CHECK(c.mem_reserved == (s ? 4096u : 0u));
    if (s && !commit_each) { /* one transaction: regions evicted before it were saved into it */
        CHECK(cm_store_commit(s, &c, msg, sizeof msg) == CM_OK);
        cm_cluster_trim(&c);
    }
    if (budget_regions) {
        CHECK(cm_cluster_resident_bytes(&c) <= c.mem_budget + c.mem_budget / 4);
        /* open lists went with their node tables (the same file below) */
        uint32_t lists_out = 0;
        for (uint32_t k = 0; k < c.nregions; k++)
            lists_out += (uint32_t)c.regions[k].open_paged;
        CHECK(lists_out > 0);
        reserve_for_exits(&c);
    }
    CHECK(cm_cluster_flatten(&c, &all, flat, msg, sizeof msg) == CM_OK);
    if (s) {
        cm_store_get_stats(s, stats);
        if (budget_regions) /* after the stats: it reads every table */
            tables_use_free_room(&c);
        CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    }
    cm_cluster_free(&c);
}

static int same_region(const cm_region *a, const cm_region *b)
{
    return a->ncells == b->ncells && a->ngroups == b->ngroups &&
           memcmp(a->image, b->image, 4 * a->ncells) == 0 &&
           memcmp(a->group, b->group, 4 * a->ncells) == 0 &&
           memcmp(a->step, b->step, 4 * a->ncells) == 0;
}

/* Cells scattered over every region, looked up at once under a budget of
 * one byte: their groups are the flattened cluster's, and the regions are
 * read about once each (one at a time, the lookups went back and forth). */
static void lookups_by_region(cm_store *s, cm_cluster *c, const cm_region *flat)
{
    enum { N = 6000 };
    char msg[256];
    int64_t *cells = malloc(2 * N * sizeof *cells);
    uint32_t *group = malloc(N * sizeof *group);
    for (int i = 0; i < N; i++) {
        cells[2 * i] = (int64_t)i * 149 % NX;
        cells[2 * i + 1] = (int64_t)i * 83 % NY;
    }
    cm_store_stats before, after;
    cm_store_get_stats(s, &before);
    CHECK(cm_cluster_cells_group(c, cells, N, group, msg, sizeof msg) == CM_OK);
    cm_store_get_stats(s, &after);
    /* each region once, and once more at most where a chain's cycle lies in
     * another region (its steps are counted there): 11 here; looked up one
     * at a time, in the given order, 3742 */
    CHECK(after.regions_read - before.regions_read <= 2 * TX * TY);
    int differ = 0;
    for (int i = 0; i < N; i++)
        differ += group[i] != flat->group[cm_box_index(&flat->box, cells + 2 * i)];
    CHECK_INT(differ, 0);
    free(cells);
    free(group);
}

static void test_budgets(const char *dir, const cm_model *m)
{
    enum { RUNS = 6, REF = RUNS }; /* flat[REF]: the cluster solved in memory */
    char path[RUNS][256];
    cm_region flat[RUNS + 1];
    cm_store_stats st[RUNS];
    const int budgets[RUNS] = {0, 4, 1, 0, 4, 1};
    const int threads[RUNS] = {2, 2, 2, 1, 1, 1};
    const int commit_each[RUNS] = {1, 1, 0, 1, 1, 0};
    solve_tiles(m, NULL, 0, 2, 1, &flat[REF], NULL);
    for (int k = 0; k < RUNS; k++) {
        snprintf(path[k], sizeof path[k], "%s/budget%d-%d.cmdb", dir, budgets[k], threads[k]);
        solve_tiles(m, path[k], budgets[k], threads[k], commit_each[k], &flat[k], &st[k]);
        CHECK(same_region(&flat[k], &flat[REF]));
    }
    /* unlimited never reads back; 4 and 1 regions do, the smaller more on
     * one thread (on two, what the second solves ahead of the joins, and
     * so the reads, depend on timing: 6 and 7 or 8 here, once not more in CI) */
    CHECK_INT(st[0].regions_read, 0);
    CHECK(st[1].regions_read > 0 && st[2].regions_read > 0);
    CHECK(st[4].regions_read > 0);
    CHECK(st[5].regions_read > st[4].regions_read);
    /* one region, one commit at the end: regions never saved are saved
     * into the transaction when they are evicted */
    CHECK_INT(st[0].regions_evicted, 0);
    CHECK(st[2].regions_evicted > 0);
    /* same files whatever the budget and the thread count */
    const uint64_t h = cmdb_content_hash(path[0]);
    for (int k = 1; k < RUNS; k++)
        CHECK(cmdb_content_hash(path[k]) == h);
    /* the bytes of the pages, kept in meta at every commit, are their sum */
    for (int k = 0; k < RUNS; k++) {
        const int64_t kept = sql_int(path[k], "SELECT value FROM meta WHERE key = 'page_bytes'");
        CHECK(kept > 0);
        CHECK_INT(kept, sql_int(path[k], "SELECT SUM(LENGTH(image) + LENGTH(grp) + "
                                         "LENGTH(step)) FROM pages"));
    }
    /* the groups view: every cell counted once; periodic cells are dim int64 each */
    CHECK_INT(sql_int(path[0], "SELECT SUM(basin_cells) FROM groups"), NX * NY);
    CHECK_INT(sql_int(path[0], "SELECT COUNT(*) FROM groups WHERE is_sink = 0"), flat[REF].ngroups);
    CHECK_INT(sql_int(path[0], "SELECT SUM(LENGTH(periodic_cells)) / 16 FROM attractors"),
              sql_int(path[0], "SELECT SUM(period) FROM attractors"));
    CHECK(sql_int(path[0], "SELECT COUNT(*) FROM pages") > TX * TY);

    /* reopened read-only, paged in on demand under a budget: the same cells */
    char msg[512];
    cm_store *s = NULL;
    cm_cluster c;
    cm_region back;
    const cm_box all = {2, {0, 0}, {NX, NY}};
    CHECK(cm_store_open(path[0], 0, &s, msg, sizeof msg) == CM_OK);
    CHECK(cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK);
    CHECK_INT(c.nregions, TX * TY);
    CHECK_INT(cm_cluster_resident_bytes(&c), 0);
    c.mem_budget = 1;
    CHECK(cm_cluster_flatten(&c, &all, &back, msg, sizeof msg) == CM_OK);
    CHECK(same_region(&back, &flat[REF]));
    lookups_by_region(s, &c, &flat[REF]);
    cm_store_info info;
    CHECK(cm_store_read_info(s, &info, msg, sizeof msg) == CM_OK);
    CHECK(strcmp(info.model, "microchaos-pd") == 0);
    CHECK_INT(info.regions, TX * TY);
    CHECK_INT(info.cells, NX * NY);
    CHECK_INT(info.groups, flat[REF].ngroups);
    CHECK(info.lattice.width[0] == lat416.width[0] && info.lattice.origin[1] == lat416.origin[1]);
    /* bytes per cell on disk, with compression */
    CHECK(info.page_bytes < 6 * (uint64_t)NX * NY);
    cm_group_info *g = calloc(info.groups + 1, sizeof *g),
                  *ref = calloc(info.groups + 1, sizeof *g);
    uint64_t sink = 0, ref_sink = 0;
    CHECK(cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg) == CM_OK);
    cm_scm_groups(&flat[REF], &lat416, ref, &ref_sink);
    CHECK_INT(sink, ref_sink);
    for (uint32_t k = 0; k < info.groups; k++)
        CHECK(memcmp(&g[k], &ref[k], sizeof g[k]) == 0);
    /* the largest groups: the first k of all of them sorted by cells, then id */
    qsort(g, info.groups, sizeof *g, larger_basin_first);
    cm_group_info *top = calloc(info.groups + 1, sizeof *top);
    const uint32_t ks[] = {1, 3, info.groups};
    for (int t = 0; t < 3; t++) {
        uint64_t top_sink = 0;
        CHECK(cm_store_largest_groups(s, top, ks[t], &top_sink, msg, sizeof msg) == CM_OK);
        CHECK_INT(top_sink, ref_sink);
        CHECK(memcmp(top, g, ks[t] * sizeof *g) == 0);
    }
    CHECK(info.groups > 3 && g[0].basin_cells > g[info.groups - 1].basin_cells);
    free(top);
    /* the regions' records without the cluster: the loaded regions' */
    cm_region *rec = calloc(info.regions + 1, sizeof *rec);
    CHECK(cm_store_regions(s, rec, info.regions, msg, sizeof msg) == CM_OK);
    for (uint32_t k = 0; k < info.regions; k++) {
        const cm_region *r = &c.regions[k].r;
        CHECK(memcmp(&rec[k].box, &r->box, sizeof r->box) == 0);
        CHECK_INT(rec[k].ncells, r->ncells);
        CHECK_INT(rec[k].nexits, r->nexits);
        CHECK_INT(rec[k].ngroups, r->ngroups);
        CHECK(rec[k].image == NULL && rec[k].exit_target == NULL);
        CHECK_INT(cm_region_bytes(&rec[k]), cm_region_bytes(r));
    }
    CHECK(cm_store_regions(s, rec, info.regions - 1, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "damaged") && strstr(msg, "more than"));
    CHECK(cm_store_regions(s, rec, info.regions + 1, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "damaged") && strstr(msg, "regions, not"));
    free(rec);
    free(g);
    free(ref);
    cm_region_free(&back);
    cm_cluster_free(&c);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    for (int k = 0; k <= REF; k++)
        cm_region_free(&flat[k]);
    for (int k = 1; k < RUNS; k++)
        if (!getenv("KEEP")) unlink(path[k]);
}

/* A copy of `path` whose first page of region 1 holds a group no group of
 * the file (a valid zstd frame, so only the check of the groups read alone
 * finds it): reading its labels fails, naming the damage. */
static void damaged_group(const char *path, const cm_attractor_set *att, const int32_t *node_label,
                          const cm_box *window, int32_t *labels)
{
    char copy[300], cmd[700], msg[512];
    snprintf(copy, sizeof copy, "%s.damaged", path);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", path, copy);
    CHECK(system(cmd) == 0);
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    CHECK(sqlite3_open(copy, &db) == SQLITE_OK);
    CHECK(sqlite3_prepare_v2(db, "SELECT cells, grp FROM pages WHERE region = 1 AND "
                                 "first_cell = 0", -1, &st, NULL) == SQLITE_OK);
    CHECK(sqlite3_step(st) == SQLITE_ROW);
    const size_t n = (size_t)sqlite3_column_int64(st, 0);
    uint32_t *group = malloc(4 * n), *scratch = malloc(4 * n);
    void *blob = malloc(cm_codec_bound(4 * n));
    size_t len = 0;
    CHECK(cm_codec_decode(sqlite3_column_blob(st, 1), (size_t)sqlite3_column_bytes(st, 1), n, 4,
                          -1, scratch, group) == CM_OK);
    sqlite3_finalize(st);
    group[5] = 1000000; /* no group of the file, no node reference */
    CHECK(cm_codec_encode(group, n, 4, -1, scratch, blob, cm_codec_bound(4 * n), &len) == CM_OK);
    CHECK(sqlite3_prepare_v2(db, "UPDATE pages SET grp = ? WHERE region = 1 AND first_cell = 0",
                             -1, &st, NULL) == SQLITE_OK);
    sqlite3_bind_blob(st, 1, blob, (int)len, SQLITE_STATIC);
    CHECK(sqlite3_step(st) == SQLITE_DONE);
    sqlite3_finalize(st);
    sqlite3_close(db);
    cm_store *s = NULL;
    cm_cluster c;
    CHECK(cm_store_open(copy, 0, &s, msg, sizeof msg) == CM_OK);
    CHECK(cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK);
    c.mem_budget = 1;
    const cm_box first = {2, {0, 0}, {window->hi[0], window->hi[1]}};
    CHECK(cm_cluster_cell_labels(&c, att, node_label, &first, NULL, labels, msg, sizeof msg) ==
          CM_EFORMAT);
    CHECK(strstr(msg, "is damaged") && strstr(msg, "region 1, cell 5: its group is no group"));
    cm_cluster_free(&c);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    unlink(copy);
    free(group);
    free(scratch);
    free(blob);
}

/* The part flattened with its cells' open nodes (cm_cluster_flatten_open)
 * is the part flattened alone, each cell's open node is the one
 * cm_cluster_cell_end gives, and the labels and exits found with them are
 * those found without (want, ws). Returns the cells that leave by an open
 * node. */
static uint64_t check_open_labels(cm_cluster *c, const cm_model *m, const cm_group_info *g,
                              const cm_region *part, const int32_t *want,
                              const cm_attractor_set *ws)
{
    char msg[512];
    cm_region flat;
    const uint64_t n = part->ncells;
    uint32_t *open = malloc(n * sizeof *open);
    int32_t *labels = malloc(n * sizeof *labels);
    CHECK(cm_cluster_flatten_open(c, &part->box, &flat, open, msg, sizeof msg) == CM_OK);
    CHECK(memcmp(flat.group, part->group, n * sizeof *flat.group) == 0);
    CHECK(memcmp(flat.step, part->step, n * sizeof *flat.step) == 0);
    CHECK(memcmp(flat.image, part->image, n * sizeof *flat.image) == 0);
    uint64_t wrong_open = 0, leaving = 0, *order = NULL;
    int64_t *cells = malloc(n * 2 * sizeof *cells);
    for (uint64_t i = 0; i < n; i++)
        cm_box_cell(&part->box, i, cells + 2 * i);
    /* region by region: in box order a paged cluster reads a region back
     * at every row's crossing (40 s of this test) */
    CHECK(cm_cluster_region_order(c, cells, n, &order) == CM_OK);
    for (uint64_t k = 0; k < n; k++) {
        const uint64_t i = order[k];
        uint32_t group, end;
        CHECK(cm_cluster_cell_end(c, cells + 2 * i, &group, &end, msg, sizeof msg) == CM_OK);
        wrong_open += end != open[i];
        leaving += open[i] != CM_NODE_OPEN;
    }
    free(order);
    free(cells);
    CHECK_INT(wrong_open, 0);
    cm_attractor_set s;
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &s, msg,
                             sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(m, c, &flat, open, NULL, NULL, &s, labels, msg, sizeof msg) ==
          CM_OK);
    CHECK(memcmp(labels, want, n * sizeof *labels) == 0);
    CHECK_INT(s.nexits, ws->nexits);
    CHECK(s.nexits == 0 ||
          memcmp(s.exit_cell, ws->exit_cell, s.nexits * c->lat.dim * sizeof *s.exit_cell) == 0);
    CHECK(s.nexits == 0 ||
          memcmp(s.exit_label, ws->exit_label, s.nexits * sizeof *s.exit_label) == 0);
    CHECK_INT(s.returned_cells, ws->returned_cells);
    CHECK_INT(s.outside_cells, ws->outside_cells);
    CHECK_INT(s.outside_steps_taken, ws->outside_steps_taken);
    /* on one thread the same: cells labelled and exits counted on every
     * thread (label_cells' walks, fates_of_cells) do not depend on how many */
    const cm_attractor_options one = {.threads = 1};
    cm_attractor_set s1;
    int32_t *alone = malloc(n * sizeof *alone);
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &s1, msg,
                             sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(m, c, &flat, open, &one, NULL, &s1, alone, msg, sizeof msg) ==
          CM_OK);
    CHECK(memcmp(alone, labels, n * sizeof *labels) == 0);
    CHECK_INT(s1.nexits, s.nexits);
    CHECK_INT(s1.returned_cells, s.returned_cells);
    CHECK_INT(s1.outside_cells, s.outside_cells);
    for (uint32_t a = 0; a < s1.n && a < s.n; a++)
        CHECK_INT(s1.a[a].basin_cells, s.a[a].basin_cells);
    cm_attractors_free(&s1);
    free(alone);
    cm_attractors_free(&s);
    cm_region_free(&flat);
    free(open);
    free(labels);
    return leaving;
}

/* The labels of a flattened part that follows only the exits its cells
 * reach (cm_cluster_view_labels) are the cluster-wide ones (want, of the
 * box all), cell by cell; for the whole box its counts are the
 * cluster's too; and so are they with the cells' open nodes given
 * (check_open_labels, whose count it adds to *leaving). Returns the exits
 * it followed. */
static uint64_t check_view_labels(cm_cluster *c, const cm_model *m, const cm_group_info *g,
                                  const cm_attractor_set *full, const cm_box *all,
                                  const int32_t *want, const cm_box *view, uint64_t *leaving)
{
    char msg[512];
    cm_region part;
    CHECK(cm_cluster_flatten(c, view, &part, msg, sizeof msg) == CM_OK);
    cm_attractor_set vs;
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &vs, msg,
                             sizeof msg) == CM_OK);
    int32_t *labels = malloc(part.ncells * sizeof *labels);
    const cm_status vst = cm_cluster_view_labels(m, c, &part, NULL, NULL, NULL, &vs, labels, msg, sizeof msg);
    if (vst != CM_OK)
        fprintf(stderr, "view labels: %s\n", msg);
    CHECK(vst == CM_OK);
    uint64_t differ = 0;
    for (uint64_t i = 0; i < part.ncells; i++) {
        int64_t cell[2];
        cm_box_cell(view, i, cell);
        differ += labels[i] != want[cm_box_index(all, cell)];
    }
    CHECK_INT(differ, 0);
    CHECK(vs.nexits <= full->nexits && vs.n == full->n);
    if (view->lo[0] == all->lo[0] && view->lo[1] == all->lo[1] && view->hi[0] == all->hi[0] &&
        view->hi[1] == all->hi[1]) {
        CHECK_INT(vs.nexits, full->nexits);
        CHECK_INT(vs.returned_cells, full->returned_cells);
        CHECK_INT(vs.outside_cells, full->outside_cells);
        for (uint32_t a = 0; a < vs.n; a++)
            CHECK_INT(vs.a[a].basin_cells, full->a[a].basin_cells);
    }
    const uint64_t followed = vs.nexits;
    *leaving += check_open_labels(c, m, g, &part, labels, &vs);
    free(labels);
    cm_attractors_free(&vs);
    cm_region_free(&part);
    return followed;
}

/* Three regions apart, A = 0..10, B = 20..30 and C = 40..50 (x, cells of
 * width 1, four rows): A's sequences leave through exits whose orbits land
 * in B's sink cells, which leave through exits whose orbits land on C's
 * fixed points. A view of A alone must follow B's exits too, which none of
 * its cells reaches, to find its cells' attractors (one per row). */
static void test_view_closure(void)
{
    char msg[512];
    const cm_model m = {.name = "shift", .dim = 2, .step = shift_step};
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    const cm_box boxes[3] = {{2, {0, 0}, {10, 4}}, {2, {20, 0}, {30, 4}}, {2, {40, 0}, {50, 4}}};
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    const cm_scm_options opt = {.max_steps = 1, .threads = 1, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(&c, &m, boxes, 3, &opt, NULL, NULL, NULL, msg, sizeof msg) ==
          CM_OK);
    cm_group_info *g = calloc(c.ngroups + 1, sizeof *g);
    CHECK(cm_cluster_describe_new(&c, &m, g, msg, sizeof msg) == CM_OK);
    cm_exits x;
    CHECK(cm_cluster_exits(&c, &x, msg, sizeof msg) == CM_OK);
    cm_cluster_cells cc = {&c, &x, NULL};
    cm_attractor_set full, view;
    CHECK(cm_cluster_attractors(&m, &cc, g, NULL, &full, msg, sizeof msg) == CM_OK);
    CHECK_INT(full.n, 4);
    cm_region a;
    CHECK(cm_cluster_flatten(&c, &boxes[0], &a, msg, sizeof msg) == CM_OK);
    int32_t want[40], got[40];
    const cm_computed cells = cm_cluster_computed(&cc);
    CHECK(cm_attractor_cell_labels(&full, &a, &cells, want, msg, sizeof msg) == CM_OK);
    CHECK(cm_attractors_find(&m, &lat, g, c.ngroups, cm_cluster_cells_group, &c, NULL, &view, msg,
                             sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(&m, &c, &a, NULL, NULL, NULL, &view, got, msg, sizeof msg) == CM_OK);
    for (int i = 0; i < 40; i++)
        CHECK_INT(got[i], want[i]);
    for (int row = 0; row < 4; row++) /* every cell of a row: the row's fixed point */
        for (int i = 0; i < 10; i++)
            CHECK(want[row * 10 + i] > 0 && want[row * 10 + i] == want[row * 10]);
    CHECK(want[0] != want[10]);
    /* A's cells reach its 20 exit cells (x 10..14), whose orbits land in
     * B's sink cells, which leave through B's 20 (x 30..34) */
    CHECK_INT(view.nexits, 40);
    cm_region_free(&a);
    cm_attractors_free(&full);
    cm_attractors_free(&view);
    cm_exits_free(&x);
    free(g);
    cm_cluster_free(&c);
}

/* A cluster's pager that counts the regions it reads back. */
typedef struct counted_pager {
    cm_page_in_fn page_in;
    cm_nodes_in_fn nodes_in;
    cm_groups_in_fn groups_in;
    cm_open_in_fn open_in;
    void *pager;
    uint64_t reads, open_reads;
} counted_pager;

static cm_status counted_page_in(void *user, uint32_t region, cm_region *r, char *msg,
                                 size_t msg_size)
{
    counted_pager *p = user;
    p->reads++;
    return p->page_in(p->pager, region, r, msg, msg_size);
}

static cm_status counted_nodes_in(void *user, uint32_t region, cm_node *nodes, uint64_t n,
                                  char *msg, size_t msg_size)
{
    const counted_pager *p = user;
    return p->nodes_in(p->pager, region, nodes, n, msg, msg_size);
}

static cm_status counted_groups_in(void *user, uint32_t region, uint32_t *group, char *msg,
                                   size_t msg_size)
{
    counted_pager *p = user;
    p->reads++;
    return p->groups_in(p->pager, region, group, msg, msg_size);
}

static cm_status counted_open_in(void *user, uint32_t region, uint32_t **local,
                                 uint64_t **weight, int64_t **cells, uint64_t *n, char *msg,
                                 size_t msg_size)
{
    counted_pager *p = user;
    p->open_reads++;
    return p->open_in(p->pager, region, local, weight, cells, n, msg, msg_size);
}

/* c's pager counted by p (the cluster is read-only from here: no page_out) */
static void count_reads(cm_cluster *c, counted_pager *p)
{
    *p = (counted_pager){c->page_in, c->nodes_in, c->groups_in, c->open_in, c->pager, 0, 0};
    c->page_in = counted_page_in;
    c->nodes_in = counted_nodes_in;
    c->groups_in = c->groups_in ? counted_groups_in : NULL;
    c->open_in = c->open_in ? counted_open_in : NULL;
    c->page_out = NULL;
    c->pager = p;
}

/* HOPS regions of 10 x HOP_ROWS cells in a row, 10 cells apart; x moves
 * 5 right up to the last region, where every cell is a fixed point. Each
 * region's sequences leave into the gap after it, whose orbits return to
 * the next region's cells: in the exits' order (rows first) the returned
 * cells hop from region to region. */
enum { HOPS = 8, HOP_ROWS = 20 };

static int hop_step(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = x[0] < 20 * (HOPS - 1) ? x[0] + 5 : x[0];
    y[1] = x[1];
    return CM_STEP_OK;
}

/* HOPS regions of model m (hop_step or a variant) solved into a new file
 * at path, c attached to *s: the file's groups (*g, the caller's to free)
 * and the attractors of the cluster in memory (*want). */
static void hops_solved(const char *path, const cm_model *m, cm_cluster *c, cm_store **s,
                        cm_group_info **g, cm_attractor_set *want)
{
    char msg[512];
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    cm_box boxes[HOPS];
    for (int k = 0; k < HOPS; k++)
        boxes[k] = (cm_box){2, {20 * k, 0}, {20 * k + 10, HOP_ROWS}};
    cm_cluster_init(c, &lat);
    const cm_store_meta meta = {m, &lat, "test", "plan", "test", 0, NULL, NULL};
    CHECK(cm_store_create(path, &meta, s, msg, sizeof msg) == CM_OK);
    cm_store_attach(*s, c);
    const cm_scm_options opt = {.max_steps = 1, .threads = 1, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(c, m, boxes, HOPS, &opt, cm_store_commit_join, *s, NULL, msg,
                                 sizeof msg) == CM_OK);
    *g = calloc(c->ngroups + 1, sizeof **g);
    uint64_t sink = 0;
    CHECK(cm_store_groups(*s, *g, c->ngroups, &sink, msg, sizeof msg) == CM_OK);
    cm_exits x;
    CHECK(cm_cluster_exits(c, &x, msg, sizeof msg) == CM_OK);
    cm_cluster_cells cc = {c, &x, NULL};
    CHECK(cm_cluster_attractors(m, &cc, *g, NULL, want, msg, sizeof msg) == CM_OK);
    cm_exits_free(&x);
}

/* The attractors of a paged cluster, under a budget of one byte, are those
 * of the same cluster in memory, and finding them reads each region back
 * twice at most: the ends of the returned orbits are asked region by
 * region (asked in the exits' order, they read one region per hop). */
static void test_returned_reads(const char *dir)
{
    char msg[512], path[256];
    snprintf(path, sizeof path, "%s/hops.cmdb", dir);
    const cm_model m = {.name = "hops", .dim = 2, .step = hop_step};
    cm_cluster c;
    cm_store *s = NULL;
    cm_group_info *g = NULL;
    cm_attractor_set want, got;
    hops_solved(path, &m, &c, &s, &g, &want);
    cm_cluster_free(&c);
    CHECK(cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK);
    c.mem_budget = 1;
    counted_pager counted;
    count_reads(&c, &counted);
    cm_exits x;
    CHECK(cm_cluster_exits(&c, &x, msg, sizeof msg) == CM_OK);
    /* the open lists stay in the file until read, one at a time, and go again */
    CHECK_INT(counted.open_reads, HOPS);
    for (uint32_t k = 0; k < c.nregions; k++)
        CHECK(c.regions[k].open_paged);
    cm_cluster_cells cc = {&c, &x, NULL};
    CHECK(cm_cluster_attractors(&m, &cc, g, NULL, &got, msg, sizeof msg) == CM_OK);
    /* not vacuous: every region's exits return, into the next region */
    CHECK_INT(got.nexits, (HOPS - 1) * 5 * HOP_ROWS);
    CHECK_INT(got.returned_cells, want.returned_cells);
    CHECK(got.returned_cells > 0);
    CHECK_INT(got.n, want.n);
    CHECK_INT(want.nexits, got.nexits);
    for (uint64_t e = 0; e < got.nexits; e++)
        CHECK_INT(got.exit_label[e], want.exit_label[e]);
    CHECK(counted.reads <= 2 * HOPS); /* 144 when asked in the exits' order */
    cm_attractors_free(&want);
    cm_attractors_free(&got);
    cm_exits_free(&x);
    free(g);
    cm_cluster_free(&c);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    unlink(path);
}

/* The labels a paged cluster gives region by region from its node labels
 * (cm_cluster_cell_labels) are those of its flattened cells
 * (cm_attractor_cell_labels), cell by cell, for the whole box in either
 * order and for a window across regions, under a budget of one byte. */
static void test_cell_labels(const char *path, const cm_model *m)
{
    char msg[512];
    cm_store *s = NULL;
    cm_cluster c;
    CHECK(cm_store_open(path, 0, &s, msg, sizeof msg) == CM_OK);
    CHECK(cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK);
    c.mem_budget = 1;
    cm_store_info info;
    CHECK(cm_store_read_info(s, &info, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(info.groups + 1, sizeof *g);
    uint64_t sink = 0;
    CHECK(cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg) == CM_OK);
    cm_exits x;
    CHECK(cm_cluster_exits(&c, &x, msg, sizeof msg) == CM_OK);
    cm_cluster_cells cc = {&c, &x, NULL};
    cm_attractor_set att;
    CHECK(cm_cluster_attractors(m, &cc, g, NULL, &att, msg, sizeof msg) == CM_OK);
    int32_t *node_label = NULL;
    CHECK(cm_cluster_node_labels(&c, &att, &node_label, msg, sizeof msg) == CM_OK);

    const cm_box all = {2, {0, 0}, {NX, NY}}, window = {2, {250, 170}, {731, 433}};
    cm_region flat;
    CHECK(cm_cluster_flatten(&c, &all, &flat, msg, sizeof msg) == CM_OK);
    const cm_computed cells = cm_cluster_computed(&cc);
    int32_t *want = malloc(flat.ncells * sizeof *want), *got = malloc(flat.ncells * sizeof *got);
    CHECK(cm_attractor_cell_labels(&att, &flat, &cells, want, msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_cell_labels(&c, &att, node_label, &all, NULL, got, msg, sizeof msg) == CM_OK);
    uint64_t differ = 0, returned = 0, outside = 0, attractors = 0;
    for (uint64_t i = 0; i < flat.ncells; i++) {
        differ += got[i] != want[i];
        returned += flat.group[i] == 0 && want[i] > 0;
        outside += flat.group[i] == 0 && want[i] == CM_LABEL_OUTSIDE;
        attractors += want[i] > 0;
    }
    CHECK_INT(differ, 0);
    /* not vacuous: sink cells labelled by their exits' fates, both kinds */
    CHECK(attractors > 0 && returned > 0 && outside > 0);
    { /* ends read from the open lists, without the listing: the same labels (every
       * cell but a frame, whose sequences leave through the frame) */
        const cm_box inner = {2, {1, 1}, {NX - 1, NY - 1}};
        cm_region part;
        CHECK(cm_cluster_flatten(&c, &inner, &part, msg, sizeof msg) == CM_OK);
        cm_cluster_cells by_lists = {&c, NULL, NULL};
        const cm_computed listed = cm_cluster_computed(&by_lists);
        int32_t *a = malloc(part.ncells * sizeof *a), *b = malloc(part.ncells * sizeof *b);
        CHECK(cm_attractor_cell_labels(&att, &part, &cells, a, msg, sizeof msg) == CM_OK);
        CHECK(cm_attractor_cell_labels(&att, &part, &listed, b, msg, sizeof msg) == CM_OK);
        uint64_t differ_lists = 0, by_exits = 0;
        for (uint64_t i = 0; i < part.ncells; i++) {
            differ_lists += a[i] != b[i];
            by_exits += part.group[i] == 0 && a[i] > 0; /* returned: an exit's fate */
        }
        CHECK_INT(differ_lists, 0);
        CHECK(by_exits > 0);
        free(a);
        free(b);
        cm_region_free(&part);
    }
    const int64_t ww = window.hi[1] - window.lo[1];
    const int64_t c_order[2] = {ww, 1}; /* dimension 0 slowest */
    CHECK(cm_cluster_cell_labels(&c, &att, node_label, &window, c_order, got, msg, sizeof msg) ==
          CM_OK);
    differ = 0;
    for (int64_t i = window.lo[0]; i < window.hi[0]; i++)
        for (int64_t j = window.lo[1]; j < window.hi[1]; j++) {
            const int64_t cell[2] = {i, j};
            differ += got[(i - window.lo[0]) * ww + (j - window.lo[1])] !=
                      want[cm_box_index(&all, cell)];
        }
    CHECK_INT(differ, 0);
    /* the view's own labels: the whole box, the window, and random boxes
     * (some within one region, most across several) */
    uint64_t leaving = 0;
    uint64_t followed = check_view_labels(&c, m, g, &att, &all, want, &all, &leaving);
    CHECK(check_view_labels(&c, m, g, &att, &all, want, &window, &leaving) < followed);
    uint64_t seed = 12345;
    for (int k = 0; k < 12; k++) {
        cm_box b = {2, {0, 0}, {1, 1}};
        for (int d = 0; d < 2; d++) {
            const int64_t side = d == 0 ? NX : NY;
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            const int64_t lo = (int64_t)((seed >> 33) % (uint64_t)side);
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            b.lo[d] = lo;
            b.hi[d] = lo + 1 + (int64_t)((seed >> 33) % (uint64_t)(side - lo));
        }
        check_view_labels(&c, m, g, &att, &all, want, &b, &leaving);
    }
    CHECK(leaving > 0); /* not vacuous: cells whose ends the open nodes give */
    damaged_group(path, &att, node_label, &window, got);
    fprintf(stderr,
            "cell labels: %llu cells agree; %llu in basins, of the sink's %llu returned, %llu "
            "outside; a view of the whole box follows %llu exits; %llu view cells leave by "
            "open nodes\n",
            (unsigned long long)flat.ncells, (unsigned long long)attractors,
            (unsigned long long)returned, (unsigned long long)outside,
            (unsigned long long)followed, (unsigned long long)leaving);
    free(want);
    free(got);
    free(node_label);
    free(g);
    cm_region_free(&flat);
    cm_attractors_free(&att);
    cm_exits_free(&x);
    cm_cluster_free(&c);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
}

/* The labels of one view with the memo of followed exits and the cells'
 * open nodes, and without either: the same cells, and the same exits with
 * the same fates and counts. Returns the cells in attractors' basins. */
static uint64_t check_memo_labels(cm_cluster *c, const cm_model *m, const cm_group_info *g,
                              cm_exit_memo *memo, const cm_box *view)
{
    char msg[512];
    cm_region part;
    uint32_t *open = malloc(cm_box_cells(view) * sizeof *open);
    CHECK(cm_cluster_flatten_open(c, view, &part, open, msg, sizeof msg) == CM_OK);
    cm_attractor_set with, without;
    int32_t *a = malloc(part.ncells * sizeof *a), *b = malloc(part.ncells * sizeof *b);
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &with,
                             msg, sizeof msg) == CM_OK);
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &without,
                             msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(m, c, &part, open, NULL, memo, &with, a, msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(m, c, &part, NULL, NULL, NULL, &without, b, msg, sizeof msg) == CM_OK);
    uint64_t differ = 0, in_basins = 0;
    for (uint64_t i = 0; i < part.ncells; i++) {
        differ += a[i] != b[i];
        in_basins += b[i] > 0;
    }
    CHECK_INT(differ, 0);
    CHECK_INT(with.nexits, without.nexits);
    CHECK(with.nexits == 0 ||
          memcmp(with.exit_cell, without.exit_cell, with.nexits * 2 * sizeof *with.exit_cell) == 0);
    CHECK(with.nexits == 0 ||
          memcmp(with.exit_label, without.exit_label, with.nexits * sizeof *with.exit_label) == 0);
    CHECK_INT(with.returned_cells, without.returned_cells);
    CHECK_INT(with.outside_cells, without.outside_cells);
    CHECK_INT(with.outside_steps_taken, without.outside_steps_taken);
    free(a);
    free(b);
    free(open);
    cm_attractors_free(&with);
    cm_attractors_free(&without);
    cm_region_free(&part);
    return in_basins;
}

/* Solves box into c, then labels each view with and without the memo
 * (check_memo_labels); adds the memo's entries kept across the join to
 * *kept, those it dropped to *dropped. Returns the cells of the views in
 * attractors' basins. */
static uint64_t grow_and_check(cm_cluster *c, const cm_model *m, cm_exit_memo *memo,
                               const cm_box *box, const cm_box *views, int nviews,
                               uint64_t *kept, uint64_t *dropped)
{
    char msg[512];
    const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(c, m, box, 1, &opt, NULL, NULL, NULL, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(c->ngroups + 1, sizeof *g);
    CHECK(cm_cluster_describe_new(c, m, g, msg, sizeof msg) == CM_OK);
    cm_attractor_options defaults;
    cm_attractor_defaults(m, NULL, &defaults);
    const uint64_t before = cm_exit_memo_count(memo);
    cm_exit_memo_sync(memo, c, defaults.outside); /* the budget cm_cluster_view_labels uses */
    *kept += cm_exit_memo_count(memo);
    *dropped += before - cm_exit_memo_count(memo);
    uint64_t in_basins = 0;
    for (int v = 0; v < nviews; v++)
        in_basins += check_memo_labels(c, m, g, memo, &views[v]);
    free(g);
    return in_basins;
}

/* hop_step, but orbits in the upper rows' gaps have no image: their exits
 * diverge, the lower rows' return (two fates). */
static int hop_split_step(const cm_model *m, const double *x, double *y)
{
    const bool gap = fmod(x[0], 20.0) >= 10.0;
    return gap && x[1] >= HOP_ROWS / 2 ? CM_STEP_NO_IMAGE : hop_step(m, x, y);
}

/* A file's exits' fates read back are the set that was written (rows of
 * one fate each, merged into box order); a row out of order, or two rows
 * sharing a cell, is damage; checking without the cells sees sizes only. */
static void test_exit_fates_rows(const char *dir)
{
    char msg[512], path[256];
    snprintf(path, sizeof path, "%s/fates.cmdb", dir);
    const cm_model m = {.name = "hops", .dim = 2, .step = hop_split_step};
    cm_cluster c;
    cm_store *s = NULL;
    cm_group_info *g = NULL;
    cm_attractor_set want, got;
    hops_solved(path, &m, &c, &s, &g, &want);
    cm_attractor_options used;
    cm_attractor_defaults(&m, NULL, &used);
    CHECK(cm_store_put_attractors(s, &want, &used, 2, msg, sizeof msg) == CM_OK);
    CHECK(cm_store_get_attractors(s, 2, c.ngroups, &got, NULL, msg, sizeof msg) == CM_OK);
    CHECK(want.nexits > 100); /* not vacuous: exits of more than one fate */
    CHECK(sql_int(path, "SELECT COUNT(*) FROM exit_fates") >= 2);
    CHECK_INT(got.nexits, want.nexits);
    CHECK(memcmp(got.exit_cell, want.exit_cell, 2 * sizeof(int64_t) * want.nexits) == 0);
    CHECK(memcmp(got.exit_label, want.exit_label, sizeof(int32_t) * want.nexits) == 0);
    cm_attractors_free(&got);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    const char *const damage[] = {
        /* a row's first two cells swapped */
        "UPDATE exit_fates SET cells = CAST(substr(cells, 17, 16) || substr(cells, 1, 16) || "
        "substr(cells, 33) AS BLOB) WHERE attractor = (SELECT MIN(attractor) FROM exit_fates "
        "WHERE exits > 1)",
        /* the last row's cells also in the first's */
        "UPDATE exit_fates SET cells = (SELECT cells FROM exit_fates ORDER BY attractor DESC "
        "LIMIT 1), exits = (SELECT exits FROM exit_fates ORDER BY attractor DESC LIMIT 1) "
        "WHERE attractor = (SELECT MIN(attractor) FROM exit_fates)",
        /* a count that its cells do not fill */
        "UPDATE exit_fates SET exits = exits + 1 WHERE attractor = (SELECT MIN(attractor) FROM "
        "exit_fates)"};
    for (int d = 0; d < 3; d++) {
        char copy[300];
        snprintf(copy, sizeof copy, "%s/fates-%d.cmdb", dir, d);
        char cmd[700];
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", path, copy);
        CHECK(system(cmd) == 0);
        sql_exec(copy, damage[d]);
        CHECK(cm_store_open(copy, 0, &s, msg, sizeof msg) == CM_OK);
        CHECK_INT(cm_store_check_attractors(s, 2, c.ngroups, msg, sizeof msg),
                  (d < 2 ? CM_OK : CM_EFORMAT));
        CHECK(cm_store_get_attractors(s, 2, c.ngroups, &got, NULL, msg, sizeof msg) ==
              CM_EFORMAT);
        CHECK(strstr(msg, "exits' fates are damaged") != NULL);
        cm_store_close(s, msg, sizeof msg);
        unlink(copy);
    }
    cm_attractors_free(&want);
    free(g);
    cm_cluster_free(&c);
    unlink(path);
}

/* The memo of followed exits (cellmap/exit_memo.h) as a cluster grows by
 * one region at a time, labels with it against labels without it:
 *  - the shift map: A's exits' orbits stay outside until C is solved, then
 *    land on C's fixed points, so an entry the join does not drop gives A
 *    wrong labels (A's cells must then be in attractors);
 *  - Fig. 4.16's map (sink cells that return and that stay outside), its
 *    six tiles in a scattered order, each labelled with the view of the
 *    whole box, of the new tile and of the tiles left of it.
 * Not vacuous: entries survive joins (and are found again), and joins drop
 * entries whose orbits the new region meets. */
static void test_exit_memo(const cm_model *m)
{
    uint64_t kept = 0, dropped = 0;
    const cm_model shift = {.name = "shift", .dim = 2, .step = shift_step};
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    const cm_box a = {2, {0, 0}, {10, 4}}, b = {2, {20, 0}, {30, 4}}, cbox = {2, {40, 0}, {50, 4}};
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    cm_exit_memo *memo = cm_exit_memo_new();
    CHECK(memo != NULL);
    CHECK_INT(grow_and_check(&c, &shift, memo, &a, &a, 1, &kept, &dropped), 0); /* outside */
    CHECK(cm_exit_memo_count(memo) > 0);
    CHECK_INT(grow_and_check(&c, &shift, memo, &cbox, &a, 1, &kept, &dropped), 40);
    CHECK_INT(grow_and_check(&c, &shift, memo, &b, &a, 1, &kept, &dropped), 40);
    cm_cluster_free(&c);
    cm_exit_memo_free(memo);

    cm_box boxes[TX * TY];
    tiles(boxes);
    cm_cluster_init(&c, &lat416);
    memo = cm_exit_memo_new();
    CHECK(memo != NULL);
    const int order[TX * TY] = {4, 0, 5, 2, 1, 3};
    for (int j = 0; j < TX * TY; j++) {
        const cm_box *box = &boxes[order[j]];
        cm_box views[3] = {{2, {0, 0}, {NX, NY}}, *box, *box};
        views[2].lo[0] = 0;
        views[2].hi[0] = box->lo[0] > 0 ? box->lo[0] : box->hi[0];
        grow_and_check(&c, m, memo, box, views, 3, &kept, &dropped);
    }
    CHECK(kept > 0 && dropped > 0);
    fprintf(stderr, "exit memo: %llu entries kept across joins, %llu dropped by them\n",
            (unsigned long long)kept, (unsigned long long)dropped);
    cm_exit_memo_free(memo);
    cm_cluster_free(&c);
}

/* A refused file stays byte-identical, whatever tries to use it. */
static void check_refused_untouched(const char *path, const cm_model *m, const char *why)
{
    long before_size = 0, after_size = 0;
    char *before = slurp(path, &before_size);
    char msg[512] = "";
    cm_store *s = NULL;
    CHECK(cm_store_check(path, msg, sizeof msg) == CM_EFORMAT);
    if (!strstr(msg, why))
        fprintf(stderr, "expected '%s' in: %s\n", why, msg);
    CHECK(strstr(msg, why) != NULL);
    CHECK(cm_store_open(path, 1, &s, msg, sizeof msg) == CM_EFORMAT);
    CHECK(s == NULL);
    CHECK(strstr(msg, why) != NULL);
    CHECK(cm_store_open(path, 0, &s, msg, sizeof msg) == CM_EFORMAT);
    const cm_store_meta meta = {m, &lat416, "test", "plan", "test", 0, NULL, NULL};
    CHECK(cm_store_create(path, &meta, &s, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "refusing") != NULL);
    char *after = slurp(path, &after_size);
    CHECK_INT(before_size, after_size);
    CHECK(before && after && memcmp(before, after, (size_t)before_size) == 0);
    free(before);
    free(after);
}

static void test_refused(const char *dir, const char *good, const cm_model *m)
{
    char path[256];
    snprintf(path, sizeof path, "%s/foreign.sqlite", dir);
    sql_exec(path, "CREATE TABLE t(x); INSERT INTO t VALUES(1);");
    check_refused_untouched(path, m, "not a cellmap database (application_id 0)");
    unlink(path);

    snprintf(path, sizeof path, "%s/random.cmdb", dir);
    FILE *f = fopen(path, "wb");
    for (int i = 0; i < 50000; i++)
        fputc((int)(mix((uint64_t)i) & 0xff), f);
    fclose(f);
    check_refused_untouched(path, m, "not a cellmap database");
    unlink(path);

    long size = 0;
    char *whole = slurp(good, &size);
    snprintf(path, sizeof path, "%s/truncated.cmdb", dir);
    f = fopen(path, "wb");
    fwrite(whole, 1, (size_t)size / 2, f);
    fclose(f);
    check_refused_untouched(path, m, "damaged");
    unlink(path);

    /* basins of more cells than the regions hold: the sink would be negative */
    snprintf(path, sizeof path, "%s/oversized-basin.cmdb", dir);
    f = fopen(path, "wb");
    fwrite(whole, 1, (size_t)size, f);
    fclose(f);
    sql_exec(path, "UPDATE basins SET cells = cells + (SELECT SUM(cells) FROM regions) + 1 "
                   "WHERE grp = 1");
    char msg[512];
    cm_store *s = NULL;
    CHECK(cm_store_open(path, 0, &s, msg, sizeof msg) == CM_OK);
    cm_store_info info;
    CHECK(cm_store_read_info(s, &info, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "basins hold more cells than its regions") != NULL);
    cm_group_info *g = calloc(info.groups + 1, sizeof *g);
    uint64_t sink = 0;
    CHECK(cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "basins hold more cells than its regions") != NULL);
    free(g);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    unlink(path);

    snprintf(path, sizeof path, "%s/newer.cmdb", dir);
    f = fopen(path, "wb");
    fwrite(whole, 1, (size_t)size, f);
    fclose(f);
    sql_exec(path, "PRAGMA user_version = 99");
    check_refused_untouched(path, m, "version 99, newer");
    sql_exec(path, "PRAGMA user_version = 1");
    check_refused_untouched(path, m, "cannot be migrated");
    unlink(path);
    free(whole);
}

int main(void)
{
    char dir[] = "/tmp/cellmap-store-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    cm_model m;
    char msg[512];
    const char *const params[] = {"alpha=0.8,beta=0.3,P=0.7,D=0.6"};
    CHECK(cm_model_create("microchaos-pd", params, 1, &m, msg, sizeof msg) == CM_OK);
    test_codec();
    test_view_closure();
    test_budgets(dir, &m);
    char good[256];
    snprintf(good, sizeof good, "%s/budget0-2.cmdb", dir);
    test_cell_labels(good, &m);
    test_returned_reads(dir);
    test_exit_fates_rows(dir);
    test_exit_memo(&m);
    test_refused(dir, good, &m);
    unlink(good);
    rmdir(dir);
    cm_model_release(&m);
    CHECK_DONE();
}
