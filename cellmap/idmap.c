#include "cellmap/idmap.h"

#include <stdlib.h>
#include <string.h>

#define EMPTY UINT32_MAX

static uint64_t home(const cm_idmap *m, uint32_t key)
{
    return ((uint64_t)key * UINT64_C(0x9E3779B97F4A7C15)) >> 32 & (m->slots - 1);
}

void cm_idmap_free(cm_idmap *m)
{
    if (!m)
        return;
    free(m->keys);
    free(m->values);
    memset(m, 0, sizeof *m);
}

/* The slot holding key, or the empty slot where it would go. */
static uint64_t find(const cm_idmap *m, uint32_t key)
{
    uint64_t s = home(m, key);
    while (m->keys[s] != EMPTY && m->keys[s] != key)
        s = (s + 1) & (m->slots - 1);
    return s;
}

static cm_status grow(cm_idmap *m)
{
    const uint64_t slots = m->slots ? 2 * m->slots : 64;
    cm_idmap bigger = {malloc(slots * sizeof *m->keys), malloc(slots * sizeof *m->values), slots,
                       m->count};
    if (!bigger.keys || !bigger.values) {
        cm_idmap_free(&bigger);
        return CM_ENOMEM;
    }
    memset(bigger.keys, 0xFF, slots * sizeof *bigger.keys);
    for (uint64_t s = 0; s < m->slots; s++) {
        if (m->keys[s] == EMPTY)
            continue;
        const uint64_t t = find(&bigger, m->keys[s]);
        bigger.keys[t] = m->keys[s];
        bigger.values[t] = m->values[s];
    }
    cm_idmap_free(m);
    *m = bigger;
    return CM_OK;
}

cm_status cm_idmap_put(cm_idmap *m, uint32_t key, uint64_t value)
{
    if (key == EMPTY)
        return CM_EINVAL;
    if (2 * (m->count + 1) > m->slots && grow(m) != CM_OK)
        return CM_ENOMEM;
    const uint64_t s = find(m, key);
    if (m->keys[s] == EMPTY) {
        m->keys[s] = key;
        m->count++;
    }
    m->values[s] = value;
    return CM_OK;
}

uint64_t *cm_idmap_find(const cm_idmap *m, uint32_t key)
{
    if (m->count == 0 || key == EMPTY)
        return NULL;
    const uint64_t s = find(m, key);
    return m->keys[s] == EMPTY ? NULL : &m->values[s];
}

bool cm_idmap_get(const cm_idmap *m, uint32_t key, uint64_t *value)
{
    const uint64_t *v = cm_idmap_find(m, key);
    if (v && value)
        *value = *v;
    return v != NULL;
}

bool cm_idmap_remove(cm_idmap *m, uint32_t key, uint64_t *value)
{
    if (m->count == 0 || key == EMPTY)
        return false;
    uint64_t s = find(m, key);
    if (m->keys[s] == EMPTY)
        return false;
    if (value)
        *value = m->values[s];
    /* backward shift: move later entries of the probe run into the gap */
    for (uint64_t t = (s + 1) & (m->slots - 1); m->keys[t] != EMPTY; t = (t + 1) & (m->slots - 1)) {
        const uint64_t h = home(m, m->keys[t]);
        /* the entry at t may fill the gap at s if its home is not in (s, t] */
        const bool movable = s <= t ? (h <= s || h > t) : (h <= s && h > t);
        if (movable) {
            m->keys[s] = m->keys[t];
            m->values[s] = m->values[t];
            s = t;
        }
    }
    m->keys[s] = EMPTY;
    m->count--;
    return true;
}

uint64_t cm_idmap_bytes(const cm_idmap *m)
{
    return m->slots * (sizeof *m->keys + sizeof *m->values);
}
