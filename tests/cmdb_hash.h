/* tests/cmdb_hash.h - a hash of every row of a .cmdb file's cluster
 * (regions, pages, exits, node tables, group counts, open nodes, attractors, metadata but
 * the command line): equal hashes, equal clusters. */
#ifndef CM_TESTS_CMDB_HASH_H
#define CM_TESTS_CMDB_HASH_H

#include <sqlite3.h>

#include "check.h"
#include "mix.h"

static inline uint64_t cmdb_content_hash(const char *path)
{
    static const char *const queries[] = {
        "SELECT * FROM regions ORDER BY id",
        "SELECT * FROM pages ORDER BY region, first_cell",
        "SELECT * FROM exits ORDER BY region",
        "SELECT * FROM nodes ORDER BY region, first",
        "SELECT * FROM basins ORDER BY grp",
        "SELECT * FROM open_nodes ORDER BY region",
        "SELECT * FROM attractors ORDER BY id",
        "SELECT * FROM meta WHERE key NOT IN ('command') ORDER BY key"};
    sqlite3 *db = NULL;
    uint64_t h = 1;
    CHECK(sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK);
    for (size_t q = 0; q < sizeof queries / sizeof queries[0]; q++) {
        sqlite3_stmt *st = NULL;
        CHECK(sqlite3_prepare_v2(db, queries[q], -1, &st, NULL) == SQLITE_OK);
        while (sqlite3_step(st) == SQLITE_ROW)
            for (int c = 0; c < sqlite3_column_count(st); c++) {
                const unsigned char *p = sqlite3_column_blob(st, c);
                const int n = sqlite3_column_bytes(st, c);
                for (int i = 0; i < n; i++)
                    h = mix(h ^ p[i]);
                h = mix(h + (uint64_t)n);
            }
        sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return h;
}

#endif
