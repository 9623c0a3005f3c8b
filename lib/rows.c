/* lib/rows.c - growing arrays of rows (lib/rows.h). */
#include "lib/rows.h"

#include <stdlib.h>
#include <string.h>

bool rows_room(void **p, size_t *cap, size_t n, size_t size)
{
    if (n < *cap)
        return true;
    const size_t grown = *cap ? 2 * *cap : 64;
    void *q = realloc(*p, grown * size);
    if (!q)
        return false;
    *p = q;
    *cap = grown;
    return true;
}

void rows_reverse(void *base, size_t from, size_t n, size_t size)
{
    unsigned char *b = base, t[1024];
    for (size_t i = from, j = n; i + 1 < j; i++, j--) {
        unsigned char *x = b + i * size, *y = b + (j - 1) * size;
        for (size_t k = 0; k < size; k += sizeof t) { /* in pieces of t */
            const size_t len = size - k < sizeof t ? size - k : sizeof t;
            memcpy(t, x + k, len);
            memcpy(x + k, y + k, len);
            memcpy(y + k, t, len);
        }
    }
}
