/* lib/rows.h - the growing arrays in which the analysis drivers collect
 * the rows of a branch, and the reversal that puts a branch followed
 * downwards in order. */
#ifndef CM_LIB_ROWS_H
#define CM_LIB_ROWS_H

#include <stdbool.h>
#include <stddef.h>

/* Room for entry n (entries of size bytes) in *p of capacity *cap,
 * doubling it when full; false when out of memory (*p unchanged). */
bool rows_room(void **p, size_t *cap, size_t n, size_t size);

/* Entries from..n-1 of base in reverse order. */
void rows_reverse(void *base, size_t from, size_t n, size_t size);

#endif
