/* libFuzzer target: a valid .cmdb file (FUZZ_SEED_CMDB, a small split
 * cluster) whose rows the input changes, then read as every reader reads
 * it. SQLite keeps such a file sound, so this reaches what byte mutations
 * rarely do: plausible rows with damaged values, and pages that decode
 * (an "encoded" value is compressed as cellmap's pages are).
 *
 * Input: a sequence of changes, each
 *   table (1 byte), column (1), row (1), kind (1), length (1), value (length bytes)
 * kind % 5: 0 integer (8 bytes little-endian), 1 real (8 bytes), 2 text,
 * 3 blob, 4 the row's encoded BLOB decoded, the value's bytes written into
 * it at offset 4 * (its first byte), and encoded again (so that it decodes
 * as cellmap's pages, exits and nodes do, to damaged contents). */
#define _DEFAULT_SOURCE /* mkstemp */
#include <sqlite3.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>

#include "cellmap/codec.h"
#include "fuzz_read.h"

static const char *const tables[] = {"meta", "regions", "pages", "exits", "nodes", "open_nodes",
                                     "attractors", "basins"};
enum { NTABLES = sizeof tables / sizeof tables[0] };

static char path[64];

static void copy_seed(void)
{
    sqlite3 *src = NULL, *dst = NULL;
    if (sqlite3_open_v2(FUZZ_SEED_CMDB, &src, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK ||
        sqlite3_open(path, &dst) != SQLITE_OK)
        fuzz_fail("cannot open the seed file " FUZZ_SEED_CMDB);
    sqlite3_backup *b = sqlite3_backup_init(dst, "main", src, "main");
    if (!b || sqlite3_backup_step(b, -1) != SQLITE_DONE || sqlite3_backup_finish(b) != SQLITE_OK)
        fuzz_fail("cannot copy the seed file");
    sqlite3_close(src);
    sqlite3_close(dst);
}

/* The name of column k % (columns of the table), or NULL. */
static int column_name(sqlite3 *db, const char *table, unsigned k, char *out, size_t size)
{
    char sql[128];
    sqlite3_stmt *st = NULL;
    snprintf(sql, sizeof sql, "SELECT * FROM %s LIMIT 0", table);
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK)
        return 0;
    const int n = sqlite3_column_count(st);
    if (n > 0)
        snprintf(out, size, "%s", sqlite3_column_name(st, (int)(k % (unsigned)n)));
    sqlite3_finalize(st);
    return n > 0;
}

/* The value of a kind 4 change: the BLOB old (an encoded array of uint32
 * planes, as cellmap writes them) with v written into its decoded bytes. */
static void bind_reencoded(sqlite3_stmt *st, const void *old, int old_len, const uint8_t *v,
                           size_t len)
{
    const unsigned long long bytes = old ? ZSTD_getFrameContentSize(old, (size_t)old_len) : 0;
    const size_t n = bytes < (1u << 22) ? (size_t)bytes / 4 : 0;
    uint32_t *cells = malloc(4 * n + 4);
    unsigned char *scratch = malloc(4 * n + 4);
    const size_t cap = cm_codec_bound(4 * n + 4);
    unsigned char *out = malloc(cap);
    size_t out_len = 0;
    if (n && len > 1 && cells && scratch && out &&
        cm_codec_decode(old, (size_t)old_len, n, 4, -1, scratch, cells) == CM_OK) {
        const size_t at = 4 * (size_t)v[0] < 4 * n ? 4 * (size_t)v[0] : 0;
        const size_t copy = len - 1 < 4 * n - at ? len - 1 : 4 * n - at;
        memcpy((unsigned char *)cells + at, v + 1, copy);
        if (cm_codec_encode(cells, n, 4, -1, scratch, out, cap, &out_len) == CM_OK)
            sqlite3_bind_blob(st, 1, out, (int)out_len, SQLITE_TRANSIENT);
    }
    free(cells);
    free(scratch);
    free(out);
}

static void bind_value(sqlite3_stmt *st, unsigned kind, const uint8_t *v, size_t len,
                       const void *old, int old_len)
{
    uint64_t bits = 0;
    for (size_t b = 0; b < 8 && b < len; b++)
        bits |= (uint64_t)v[b] << (8 * b);
    switch (kind % 5) {
    case 0:
        sqlite3_bind_int64(st, 1, (sqlite3_int64)bits);
        break;
    case 1: {
        double x;
        memcpy(&x, &bits, sizeof x);
        sqlite3_bind_double(st, 1, x);
        break;
    }
    case 2:
        sqlite3_bind_text(st, 1, (const char *)v, (int)len, SQLITE_TRANSIENT);
        break;
    case 3:
        sqlite3_bind_blob(st, 1, v, (int)len, SQLITE_TRANSIENT);
        break;
    default:
        bind_reencoded(st, old, old_len, v, len);
    }
}

/* Applies one change; the old value is read first for kind 4. */
static void change_row(sqlite3 *db, const char *table, const char *column, unsigned row,
                       unsigned kind, const uint8_t *v, size_t len)
{
    char where[160], sql[320];
    snprintf(where, sizeof where,
             "WHERE rowid = (SELECT rowid FROM %s ORDER BY rowid LIMIT 1 OFFSET %u)", table, row);
    sqlite3_stmt *old = NULL, *st = NULL;
    const void *blob = NULL;
    int blob_len = 0;
    snprintf(sql, sizeof sql, "SELECT \"%s\" FROM %s %s", column, table, where);
    if (kind % 5 == 4 && sqlite3_prepare_v2(db, sql, -1, &old, NULL) == SQLITE_OK &&
        sqlite3_step(old) == SQLITE_ROW) {
        blob = sqlite3_column_blob(old, 0);
        blob_len = sqlite3_column_bytes(old, 0);
    }
    snprintf(sql, sizeof sql, "UPDATE %s SET \"%s\" = ?1 %s", table, column, where);
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK) {
        bind_value(st, kind, v, len, blob, blob_len);
        sqlite3_step(st); /* constraints may refuse it: then the file is as it was */
    }
    sqlite3_finalize(st);
    sqlite3_finalize(old);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_temp_path(path);
    copy_seed();
    sqlite3 *db = NULL;
    if (sqlite3_open(path, &db) != SQLITE_OK)
        fuzz_fail("cannot open the copy");
    size_t at = 0;
    while (at + 5 <= size) {
        const uint8_t *op = data + at;
        const size_t len = op[4] % 200 < size - at - 5 ? op[4] % 200 : size - at - 5;
        const char *table = tables[op[0] % NTABLES];
        char column[64];
        if (column_name(db, table, op[1], column, sizeof column))
            change_row(db, table, column, op[2], op[3], op + 5, len);
        at += 5 + len;
    }
    sqlite3_close(db);
    fuzz_read_file(path);
    return 0;
}
