/* cellmap/exit_memo.c - see exit_memo.h. */
#include "cellmap/exit_memo.h"

#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"

/* Entry i's words: the exit cell, the landing cell, the box's lo and hi
 * (dim each) from coord + i * 4 * dim. */
enum { KEY, LANDED, LO, HI, WORDS };

struct cm_exit_memo {
    int dim;          /* 0 until the first sync */
    uint32_t steps;   /* the budget the entries were followed with */
    uint32_t regions; /* the cluster's regions they know of */
    uint64_t n, cap;
    int64_t *coord;
    int32_t *how;
    uint32_t *taken;
    uint8_t *used;
    uint32_t *hash; /* entry + 1, 0 empty; hash_size a power of 2, at most half full */
    uint64_t hash_size;
};

cm_exit_memo *cm_exit_memo_new(void) { return calloc(1, sizeof(cm_exit_memo)); }

void cm_exit_memo_free(cm_exit_memo *memo)
{
    if (!memo)
        return;
    free(memo->coord);
    free(memo->how);
    free(memo->taken);
    free(memo->used);
    free(memo->hash);
    free(memo);
}

uint64_t cm_exit_memo_count(const cm_exit_memo *memo) { return memo ? memo->n : 0; }

uint64_t cm_exit_memo_bytes(const cm_exit_memo *memo)
{
    if (!memo)
        return 0;
    const uint64_t per = (uint64_t)WORDS * (uint64_t)memo->dim * sizeof *memo->coord +
                         sizeof *memo->how + sizeof *memo->taken + sizeof *memo->used;
    return memo->cap * per + memo->hash_size * sizeof *memo->hash;
}

static int64_t *word(const cm_exit_memo *memo, uint64_t i, int which)
{
    return memo->coord + (i * WORDS + (uint64_t)which) * (uint64_t)memo->dim;
}

/* Where cell's entry is in the hash, or the empty place it would take. */
static uint64_t hash_place(const cm_exit_memo *memo, const int64_t *cell)
{
    uint64_t i = cm_cell_hash(cell, memo->dim) & (memo->hash_size - 1);
    while (memo->hash[i] && !cm_cell_same(word(memo, memo->hash[i] - 1, KEY), cell, memo->dim))
        i = (i + 1) & (memo->hash_size - 1);
    return i;
}

/* The empty place a cell not in the hash takes: entries are distinct, so a
 * rehash compares no cells (each comparison is a cache miss). */
static uint64_t free_place(const cm_exit_memo *memo, const int64_t *cell)
{
    uint64_t i = cm_cell_hash(cell, memo->dim) & (memo->hash_size - 1);
    while (memo->hash[i])
        i = (i + 1) & (memo->hash_size - 1);
    return i;
}

static void rehash(cm_exit_memo *memo)
{
    if (memo->hash_size)
        memset(memo->hash, 0, (size_t)memo->hash_size * sizeof *memo->hash);
    for (uint64_t i = 0; i < memo->n; i++)
        memo->hash[free_place(memo, word(memo, i, KEY))] = (uint32_t)(i + 1);
}

/* Keeps the entries keep[i] says, in their order, and rehashes. */
static void compact(cm_exit_memo *memo, const uint8_t *keep)
{
    const uint64_t words = (uint64_t)WORDS * (uint64_t)memo->dim;
    uint64_t k = 0;
    for (uint64_t i = 0; i < memo->n; i++) {
        if (!keep[i])
            continue;
        if (k != i) {
            memmove(word(memo, k, KEY), word(memo, i, KEY), (size_t)words * sizeof *memo->coord);
            memo->how[k] = memo->how[i];
            memo->taken[k] = memo->taken[i];
            memo->used[k] = memo->used[i];
        }
        k++;
    }
    memo->n = k;
    rehash(memo);
}

/* Whether entry i's box meets the (half-open) box b. */
static bool box_meets(const cm_exit_memo *memo, uint64_t i, const cm_box *b)
{
    const int64_t *lo = word(memo, i, LO), *hi = word(memo, i, HI);
    for (int d = 0; d < memo->dim; d++)
        if (hi[d] < b->lo[d] || lo[d] >= b->hi[d])
            return false;
    return true;
}

void cm_exit_memo_sync(cm_exit_memo *memo, const cm_cluster *c, uint32_t steps)
{
    if (memo->dim != c->lat.dim || memo->steps != steps || c->nregions < memo->regions) {
        memo->n = 0;
        rehash(memo);
        memo->dim = c->lat.dim;
        memo->steps = steps;
        memo->regions = 0;
    }
    /* used[] doubles as the keep flags here, and is cleared after */
    for (uint64_t i = 0; i < memo->n; i++)
        memo->used[i] = 1;
    bool dropped = false;
    for (uint32_t k = memo->regions; k < c->nregions; k++)
        for (uint64_t i = 0; i < memo->n; i++)
            if (memo->used[i] && box_meets(memo, i, &c->regions[k].r.box)) {
                memo->used[i] = 0;
                dropped = true;
            }
    if (dropped)
        compact(memo, memo->used);
    if (memo->n)
        memset(memo->used, 0, (size_t)memo->n);
    memo->regions = c->nregions;
}

bool cm_exit_memo_find(cm_exit_memo *memo, const int64_t *cell, cm_exit_fate *out)
{
    if (memo->n == 0)
        return false;
    const uint32_t at = memo->hash[hash_place(memo, cell)];
    if (!at)
        return false;
    const uint64_t i = at - 1;
    const size_t bytes = (size_t)memo->dim * sizeof *cell;
    memo->used[i] = 1;
    out->how = memo->how[i];
    out->taken = memo->taken[i];
    memcpy(out->cell, word(memo, i, LANDED), bytes);
    memcpy(out->lo, word(memo, i, LO), bytes);
    memcpy(out->hi, word(memo, i, HI), bytes);
    return true;
}

/* Room for one more entry, with the hash at most half full. */
static cm_status room(cm_exit_memo *memo)
{
    if (memo->n >= UINT32_MAX - 1)
        return CM_ENOMEM;
    if (memo->n == memo->cap) {
        const uint64_t cap = memo->cap ? 2 * memo->cap : 1024;
        const size_t words = (size_t)WORDS * (size_t)memo->dim;
        int64_t *coord = realloc(memo->coord, (size_t)cap * words * sizeof *coord);
        memo->coord = coord ? coord : memo->coord;
        int32_t *how = coord ? realloc(memo->how, (size_t)cap * sizeof *how) : NULL;
        memo->how = how ? how : memo->how;
        uint32_t *taken = how ? realloc(memo->taken, (size_t)cap * sizeof *taken) : NULL;
        memo->taken = taken ? taken : memo->taken;
        uint8_t *used = taken ? realloc(memo->used, (size_t)cap) : NULL;
        memo->used = used ? used : memo->used;
        if (!used)
            return CM_ENOMEM; /* what grew holds the old entries and is kept */
        memo->cap = cap;
    }
    if (2 * (memo->n + 1) <= memo->hash_size)
        return CM_OK;
    const uint64_t size = memo->hash_size ? 2 * memo->hash_size : 2048;
    uint32_t *hash = malloc((size_t)size * sizeof *hash);
    if (!hash)
        return CM_ENOMEM;
    free(memo->hash);
    memo->hash = hash;
    memo->hash_size = size;
    rehash(memo);
    return CM_OK;
}

cm_status cm_exit_memo_put(cm_exit_memo *memo, const int64_t *cell, const cm_exit_fate *f)
{
    if (memo->dim == 0)
        return CM_EINVAL; /* never synced: no dimension */
    const cm_status st = room(memo);
    if (st != CM_OK)
        return st;
    const uint64_t place = hash_place(memo, cell);
    const uint64_t i = memo->hash[place] ? memo->hash[place] - 1 : memo->n++;
    const size_t bytes = (size_t)memo->dim * sizeof *cell;
    memo->hash[place] = (uint32_t)(i + 1);
    memcpy(word(memo, i, KEY), cell, bytes);
    memcpy(word(memo, i, LANDED), f->cell, bytes);
    memcpy(word(memo, i, LO), f->lo, bytes);
    memcpy(word(memo, i, HI), f->hi, bytes);
    memo->how[i] = f->how;
    memo->taken[i] = f->taken;
    memo->used[i] = 1;
    return CM_OK;
}

void cm_exit_memo_keep_used(cm_exit_memo *memo)
{
    if (memo->n)
        compact(memo, memo->used);
}
