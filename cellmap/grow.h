/* cellmap/grow.h - growable arrays (the one place that doubles a buffer)
 * and arrays of per-thread records. */
#ifndef CM_GROW_H
#define CM_GROW_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/status.h"

/* Makes room for at least `need` items of `item_size` bytes in *items
 * (capacity *cap, doubled as needed, at least 16). On failure *items is
 * unchanged and CM_ENOMEM returned. */
static inline cm_status cm_grow(void **items, uint64_t *cap, uint64_t need, size_t item_size)
{
    if (need <= *cap)
        return CM_OK;
    uint64_t new_cap = *cap ? *cap : 16;
    while (new_cap < need)
        new_cap *= 2;
    if (new_cap > SIZE_MAX / item_size)
        return CM_ENOMEM;
    void *p = realloc(*items, (size_t)new_cap * item_size);
    if (!p)
        return CM_ENOMEM;
    *items = p;
    *cap = new_cap;
    return CM_OK;
}

/* Like cm_grow for a table indexed up to need - 1 whose *len entries are in
 * use: the new entries [*len, need) are zero and *len becomes need. */
static inline cm_status cm_grow_zeroed(void **items, uint64_t *cap, uint64_t *len, uint64_t need,
                                       size_t item_size)
{
    if (need <= *len)
        return CM_OK;
    if (cm_grow(items, cap, need, item_size) != CM_OK)
        return CM_ENOMEM;
    memset((char *)*items + *len * item_size, 0, (need - *len) * item_size);
    *len = need;
    return CM_OK;
}

/* A cache line. Records that threads update at every step of a loop start
 * on their own line (_Alignas(CM_CACHE_LINE) on their first member):
 * records of different threads sharing a line make each thread's writes
 * evict the line from the other's cache (false sharing). */
#define CM_CACHE_LINE 64

/* n zeroed records of `size` bytes (a multiple of CM_CACHE_LINE), the
 * first on a line of its own; free() frees them. NULL: out of memory. */
static inline void *cm_thread_records(size_t n, size_t size)
{
    if (n == 0 || size > SIZE_MAX / n)
        return NULL;
    void *p = aligned_alloc(CM_CACHE_LINE, n * size);
    if (p)
        memset(p, 0, n * size);
    return p;
}

#endif
