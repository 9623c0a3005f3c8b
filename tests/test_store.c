#include <sqlite3.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/store.h"
#include "check.h"
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

static int sql_int(const char *path, const char *sql)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    int v = -1;
    sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL);
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int(st, 0);
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

/* A file that is refused must stay byte-identical. */
static void check_refused_untouched(const char *path, const cm_store_meta *meta,
                                    const cm_region *r, const cm_group_info *g)
{
    long before_size = 0, after_size = 0;
    char *before = slurp(path, &before_size);
    char msg[512] = "";
    CHECK(cm_store_check(path, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strlen(msg) > 10);
    CHECK(cm_store_save(path, meta, r, g, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "refusing") != NULL);
    char *after = slurp(path, &after_size);
    CHECK_INT(before_size, after_size);
    CHECK(before && after && memcmp(before, after, (size_t)before_size) == 0);
    free(before);
    free(after);
}

int main(void)
{
    char dir[] = "/tmp/cellmap-store-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256], foreign[256], junk[256], newer[256];
    snprintf(path, sizeof path, "%s/a.cmdb", dir);
    snprintf(foreign, sizeof foreign, "%s/foreign.sqlite", dir);
    snprintf(junk, sizeof junk, "%s/junk.cmdb", dir);
    snprintf(newer, sizeof newer, "%s/newer.cmdb", dir);

    cm_model m;
    char msg[512];
    CHECK(cm_model_create("microchaos-pd", NULL, 0, &m, msg, sizeof msg) == CM_OK);
    const cm_lattice lat = {2, {0, -40}, {0.5, 0.08}};
    const cm_box box = {2, {0, 0}, {300, 1000}}; /* several pages of 65536 cells */
    cm_region r;
    CHECK(cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK);
    const cm_scm_options opt = {1, 0, NULL, NULL, 0};
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(r.ngroups + 1, sizeof *g);
    cm_scm_groups(&r, &lat, g, NULL);
    const cm_store_meta meta = {&m, &lat, "cellmap solve (test)", "test", 0};

    CHECK(cm_store_save(path, &meta, &r, g, msg, sizeof msg) == CM_OK);
    CHECK(cm_store_check(path, msg, sizeof msg) == CM_OK);
    CHECK_INT(sql_int(path, "PRAGMA application_id"), CM_STORE_APP_ID);
    CHECK_INT(sql_int(path, "PRAGMA user_version"), CM_STORE_VERSION);
    CHECK_INT(sql_int(path, "SELECT count(*) FROM groups"), r.ngroups + 1);
    CHECK_INT(sql_int(path, "SELECT sum(basin_cells) FROM groups"), r.ncells);
    CHECK_INT(sql_int(path, "SELECT count(*) FROM pages"), (300 * 1000 + 65535) / 65536);
    CHECK_INT(sql_int(path, "SELECT sum(length(periodic_cells)) / 4 FROM groups"),
              sql_int(path, "SELECT sum(period) FROM groups WHERE is_sink = 0"));

    /* round trip, cell by cell */
    cm_lattice lat2;
    cm_region back;
    char name[64];
    CHECK(cm_store_load(path, &lat2, &back, name, sizeof name, msg, sizeof msg) == CM_OK);
    CHECK(strcmp(name, "microchaos-pd") == 0);
    CHECK_INT(lat2.dim, 2);
    CHECK(lat2.width[1] == lat.width[1] && lat2.origin[1] == lat.origin[1]);
    CHECK_INT(back.ncells, r.ncells);
    CHECK_INT(back.ngroups, r.ngroups);
    CHECK(memcmp(back.image, r.image, 4 * r.ncells) == 0);
    CHECK(memcmp(back.group, r.group, 4 * r.ncells) == 0);
    CHECK(memcmp(back.step, r.step, 4 * r.ncells) == 0);
    cm_region_free(&back);

    /* replacing an older cellmap database works and is atomic */
    CHECK(cm_store_save(path, &meta, &r, g, msg, sizeof msg) == CM_OK);

    /* a foreign SQLite file, random bytes, an empty file, a newer version */
    sql_exec(foreign, "CREATE TABLE t(x); INSERT INTO t VALUES(1);");
    check_refused_untouched(foreign, &meta, &r, g);
    FILE *f = fopen(junk, "wb");
    for (int i = 0; i < 5000; i++)
        fputc((i * 7919 + 13) & 0xff, f);
    fclose(f);
    check_refused_untouched(junk, &meta, &r, g);
    CHECK(cm_store_save(newer, &meta, &r, g, msg, sizeof msg) == CM_OK);
    sql_exec(newer, "PRAGMA user_version = 99");
    check_refused_untouched(newer, &meta, &r, g);
    CHECK(cm_store_check(newer, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "version 99") != NULL);

    /* truncated: half of a valid file */
    long size = 0;
    char *whole = slurp(path, &size);
    f = fopen(junk, "wb");
    fwrite(whole, 1, (size_t)size / 2, f);
    fclose(f);
    free(whole);
    cm_region tr;
    CHECK(cm_store_load(junk, &lat2, &tr, name, sizeof name, msg, sizeof msg) != CM_OK);

    free(g);
    cm_region_free(&r);
    cm_model_release(&m);
    unlink(path);
    unlink(foreign);
    unlink(junk);
    unlink(newer);
    rmdir(dir);
    CHECK_DONE();
}
