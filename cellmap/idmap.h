/* cellmap/idmap.h - a hash map from 32-bit ids to 64-bit values (the
 * cluster keeps in one the weights of the open nodes whose node tables
 * paging dropped).
 *
 * Open addressing with linear probing and backward-shift deletion, so no
 * tombstones: a map of n entries holds at most 2n slots after growth. Not
 * thread-safe; cm_idmap_free is NULL-safe. Id UINT32_MAX cannot be a key. */
#ifndef CM_IDMAP_H
#define CM_IDMAP_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/status.h"

typedef struct cm_idmap {
    uint32_t *keys;  /* UINT32_MAX: an empty slot */
    uint64_t *values;
    uint64_t slots;  /* a power of two, or 0 */
    uint64_t count;
} cm_idmap;

void cm_idmap_free(cm_idmap *m);

/* Sets the value of key (adding it if need be). */
cm_status cm_idmap_put(cm_idmap *m, uint32_t key, uint64_t value);

/* The value of key, in place (valid until the map changes), or NULL. */
uint64_t *cm_idmap_find(const cm_idmap *m, uint32_t key);

/* Whether key is there, and its value into *value (may be NULL). */
bool cm_idmap_get(const cm_idmap *m, uint32_t key, uint64_t *value);

/* Removes key; whether it was there, and its value into *value (may be NULL). */
bool cm_idmap_remove(cm_idmap *m, uint32_t key, uint64_t *value);

/* Bytes held. */
uint64_t cm_idmap_bytes(const cm_idmap *m);

#endif
