#include "render/touching.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* A set of pairs by open addressing; UINT64_MAX marks a free slot (never a
 * pair: a < b). */
typedef struct pair_set {
    uint64_t *slot;
    size_t cap, n;
    bool failed; /* out of memory: the result is refused */
} pair_set;

static size_t slot_of(uint64_t key, size_t cap)
{
    key ^= key >> 31;
    key *= UINT64_C(0x9e3779b97f4a7c15);
    return (size_t)(key >> 17) & (cap - 1);
}

static bool set_grow(pair_set *s)
{
    const size_t cap = s->cap ? 2 * s->cap : 256;
    uint64_t *slot = malloc(cap * sizeof *slot);
    if (!slot)
        return false;
    memset(slot, 0xff, cap * sizeof *slot);
    for (size_t k = 0; k < s->cap; k++)
        if (s->slot[k] != UINT64_MAX) {
            size_t at = slot_of(s->slot[k], cap);
            while (slot[at] != UINT64_MAX)
                at = (at + 1) & (cap - 1);
            slot[at] = s->slot[k];
        }
    free(s->slot);
    s->slot = slot;
    s->cap = cap;
    return true;
}

static void set_add(pair_set *s, uint32_t a, uint32_t b)
{
    const uint64_t key = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
    if (s->failed)
        return;
    if (2 * (s->n + 1) > s->cap && !set_grow(s)) {
        s->failed = true;
        return;
    }
    size_t at = slot_of(key, s->cap);
    while (s->slot[at] != UINT64_MAX) {
        if (s->slot[at] == key)
            return;
        at = (at + 1) & (s->cap - 1);
    }
    s->slot[at] = key;
    s->n++;
}

/* Along a row: each run of one label touches the runs that start within
 * `reach` cells of its last cell. */
static void row_pairs(const uint32_t *row, uint64_t nx, uint32_t reach, pair_set *s)
{
    uint64_t start = 0;
    while (start < nx) {
        uint64_t end = start + 1; /* one past the run */
        while (end < nx && row[end] == row[start])
            end++;
        uint64_t next = end;
        while (next < nx && next - (end - 1) <= reach) {
            set_add(s, row[start], row[next]);
            const uint32_t l = row[next];
            while (next < nx && row[next] == l)
                next++;
        }
        start = end;
    }
}

static void column_pairs(const uint32_t *low, const uint32_t *high, uint64_t nx, pair_set *s)
{
    for (uint64_t i = 0; i < nx; i++)
        if (low[i] != high[i])
            set_add(s, low[i], high[i]);
}

static int compare_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

cm_status cm_touching_collect(const uint32_t *label, uint64_t nx, uint64_t ny, uint64_t row_stride,
                              uint32_t reach_x, uint32_t reach_y, cm_touching *out, char *msg,
                              size_t msg_size)
{
    memset(out, 0, sizeof *out);
    reach_x = reach_x ? reach_x : 1;
    reach_y = reach_y ? reach_y : 1;
    pair_set all = {0};
    bool failed = false;
#pragma omp parallel
    {
        pair_set mine = {0};
#pragma omp for schedule(static)
        for (uint64_t j = 0; j < ny; j++) {
            const uint32_t *row = label + j * row_stride;
            row_pairs(row, nx, reach_x, &mine);
            for (uint64_t e = 1; e <= reach_y && j + e < ny; e++)
                column_pairs(row, row + e * row_stride, nx, &mine);
        }
#pragma omp critical
        {
            failed = failed || mine.failed;
            for (size_t k = 0; k < mine.cap && !failed; k++)
                if (mine.slot[k] != UINT64_MAX)
                    set_add(&all, (uint32_t)(mine.slot[k] >> 32), (uint32_t)mine.slot[k]);
            failed = failed || all.failed;
        }
        free(mine.slot);
    }
    out->pair = failed ? NULL : malloc((all.n ? all.n : 1) * sizeof *out->pair);
    if (!out->pair) {
        free(all.slot);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the basins' neighbours");
    }
    for (size_t k = 0; k < all.cap; k++)
        if (all.slot[k] != UINT64_MAX)
            out->pair[out->n++] = all.slot[k];
    free(all.slot);
    qsort(out->pair, out->n, sizeof *out->pair, compare_u64);
    return CM_OK;
}

void cm_touching_free(cm_touching *t)
{
    free(t->pair);
    memset(t, 0, sizeof *t);
}

uint32_t cm_touching_reach(uint64_t cells, int pixels)
{
    if (pixels < 1 || cells <= (uint64_t)pixels)
        return 1;
    const uint64_t r = (cells + (uint64_t)pixels - 1) / (uint64_t)pixels;
    return r > UINT32_MAX ? UINT32_MAX : (uint32_t)r;
}
