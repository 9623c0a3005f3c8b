#include "cellmap/bricks.h"

#include "cellmap/grow.h"

#include <stdlib.h>
#include <string.h>

typedef struct brick {
    int64_t key[CM_MAX_DIM];
    unsigned char *records;
    uint64_t n, cap;
} brick;

struct cm_bricks {
    int dim;
    int shift[CM_MAX_DIM];
    size_t record_size;
    brick *bricks; /* in order of first use */
    uint64_t nbricks, bricks_cap;
    uint32_t *slots; /* hash table: brick index + 1, 0 for an empty slot */
    uint64_t nslots; /* a power of two, at least twice nbricks */
};

cm_status cm_bricks_alloc(int dim, const int *shift, size_t record_size, cm_bricks **out)
{
    int bits = 0;
    for (int d = 0; d < dim; d++)
        bits += shift[d] >= 0 && shift[d] <= 31 ? shift[d] : 32;
    if (bits > 31) /* offsets must fit 31 bits */
        return CM_EINVAL;
    cm_bricks *b = calloc(1, sizeof *b);
    if (!b)
        return CM_ENOMEM;
    b->dim = dim;
    memcpy(b->shift, shift, (size_t)dim * sizeof *shift);
    b->record_size = record_size;
    *out = b;
    return CM_OK;
}

void cm_bricks_free(cm_bricks *b)
{
    if (!b)
        return;
    for (uint64_t i = 0; i < b->nbricks; i++)
        free(b->bricks[i].records);
    free(b->bricks);
    free(b->slots);
    free(b);
}

void cm_bricks_shift_for(const cm_box *box, int *shift)
{
    for (int d = 0; d < box->dim; d++) {
        const int64_t half = (box->hi[d] - box->lo[d]) / 2;
        int s = 0;
        while (s < 40 && ((int64_t)1 << (s + 1)) <= half)
            s++;
        shift[d] = s;
    }
}

void cm_bricks_of(const cm_bricks *b, const int64_t *cell, int64_t *key)
{
    for (int d = 0; d < b->dim; d++)
        key[d] = cell[d] >> b->shift[d]; /* arithmetic shift: floor for negative cells */
}

static uint64_t hash_key(const cm_bricks *b, const int64_t *key)
{
    uint64_t h = UINT64_C(0x9E3779B97F4A7C15);
    for (int d = 0; d < b->dim; d++) {
        h = (h ^ (uint64_t)key[d]) * UINT64_C(0xFF51AFD7ED558CCD);
        h ^= h >> 32;
    }
    return h;
}

static int same_key(const cm_bricks *b, const int64_t *x, const int64_t *y)
{
    for (int d = 0; d < b->dim; d++)
        if (x[d] != y[d])
            return 0;
    return 1;
}

/* The slot holding key, or the empty slot where it would go. */
static uint64_t probe(const cm_bricks *b, const int64_t *key)
{
    uint64_t s = hash_key(b, key) & (b->nslots - 1);
    while (b->slots[s] && !same_key(b, b->bricks[b->slots[s] - 1].key, key))
        s = (s + 1) & (b->nslots - 1);
    return s;
}

static cm_status rehash(cm_bricks *b)
{
    const uint64_t nslots = b->nslots ? 2 * b->nslots : 64;
    uint32_t *slots = calloc(nslots, sizeof *slots);
    if (!slots)
        return CM_ENOMEM;
    free(b->slots);
    b->slots = slots;
    b->nslots = nslots;
    for (uint64_t i = 0; i < b->nbricks; i++)
        b->slots[probe(b, b->bricks[i].key)] = (uint32_t)(i + 1);
    return CM_OK;
}

/* The brick with this key, made if need be (NULL: out of memory). */
static brick *get_brick(cm_bricks *b, const int64_t *key)
{
    if (2 * (b->nbricks + 1) > b->nslots && rehash(b) != CM_OK)
        return NULL;
    const uint64_t s = probe(b, key);
    if (b->slots[s])
        return &b->bricks[b->slots[s] - 1];
    if (b->nbricks >= UINT32_MAX - 1 ||
        cm_grow((void **)&b->bricks, &b->bricks_cap, b->nbricks + 1, sizeof *b->bricks) != CM_OK)
        return NULL;
    brick *br = &b->bricks[b->nbricks++];
    memset(br, 0, sizeof *br);
    memcpy(br->key, key, (size_t)b->dim * sizeof *key);
    b->slots[s] = (uint32_t)b->nbricks;
    return br;
}

static cm_status add_to(cm_bricks *b, const int64_t *key, const void *record)
{
    brick *br = get_brick(b, key);
    if (!br || cm_grow((void **)&br->records, &br->cap, br->n + 1, b->record_size) != CM_OK)
        return CM_ENOMEM;
    memcpy(br->records + br->n++ * b->record_size, record, b->record_size);
    return CM_OK;
}

cm_status cm_bricks_add(cm_bricks *b, const int64_t *cell, const void *record)
{
    int64_t key[CM_MAX_DIM];
    cm_bricks_of(b, cell, key);
    return add_to(b, key, record);
}

bool cm_bricks_span(const cm_bricks *b, const cm_box *box, int64_t *lo, int64_t *hi)
{
    int64_t last[CM_MAX_DIM];
    for (int d = 0; d < b->dim; d++)
        last[d] = box->hi[d] - 1;
    cm_bricks_of(b, box->lo, lo);
    cm_bricks_of(b, last, hi);
    uint64_t span = 1;
    for (int d = 0; d < b->dim; d++) {
        span *= (uint64_t)(hi[d] - lo[d] + 1);
        if (span > CM_BRICKS_MAX_SPAN)
            return false;
    }
    return true;
}

uint64_t cm_bricks_count(const cm_bricks *b) { return b->nbricks; }

const int64_t *cm_bricks_key(const cm_bricks *b, uint64_t i) { return b->bricks[i].key; }

cm_status cm_bricks_add_box(cm_bricks *b, const cm_box *box, const void *record)
{
    int64_t lo[CM_MAX_DIM], hi[CM_MAX_DIM], key[CM_MAX_DIM];
    if (!cm_bricks_span(b, box, lo, hi))
        return CM_ETOOBIG;
    memcpy(key, lo, sizeof key);
    cm_status st = CM_OK;
    do
        st = add_to(b, key, record);
    while (st == CM_OK && cm_index_next(b->dim, lo, hi, key));
    return st;
}

void *cm_bricks_find(const cm_bricks *b, const int64_t *key, uint64_t *n)
{
    *n = 0;
    if (!b->nslots)
        return NULL;
    const uint64_t s = probe(b, key);
    if (!b->slots[s])
        return NULL;
    const brick *br = &b->bricks[b->slots[s] - 1];
    *n = br->n;
    return br->n ? br->records : NULL;
}

void cm_bricks_truncate(cm_bricks *b, const int64_t *key, uint64_t n)
{
    brick *br = &b->bricks[b->slots[probe(b, key)] - 1];
    if (n < br->n)
        br->n = n;
    if (br->n < br->cap / 4 && br->cap > 16) { /* give back what a drained brick held */
        const uint64_t cap = br->n > 16 ? br->n : 16;
        unsigned char *records = realloc(br->records, cap * b->record_size);
        if (records) {
            br->records = records;
            br->cap = cap;
        }
    }
}

uint32_t cm_bricks_offset(const cm_bricks *b, const int64_t *cell)
{
    uint64_t offset = 0;
    for (int d = b->dim - 1; d >= 0; d--)
        offset = (offset << b->shift[d]) |
                 ((uint64_t)cell[d] & ((UINT64_C(1) << b->shift[d]) - 1));
    return (uint32_t)offset;
}

void cm_bricks_cell(const cm_bricks *b, const int64_t *brick, uint32_t offset, int64_t *cell)
{
    for (int d = 0; d < b->dim; d++) {
        cell[d] = (brick[d] * ((int64_t)1 << b->shift[d])) +
                  (int64_t)(offset & ((UINT32_C(1) << b->shift[d]) - 1));
        offset >>= b->shift[d];
    }
}

void cm_bricks_each(const cm_bricks *b,
                    void (*fn)(void *user, const int64_t *brick, const void *record), void *user)
{
    for (uint64_t i = 0; i < b->nbricks; i++)
        for (uint64_t r = 0; r < b->bricks[i].n; r++)
            fn(user, b->bricks[i].key, b->bricks[i].records + r * b->record_size);
}

uint64_t cm_bricks_bytes(const cm_bricks *b)
{
    if (!b)
        return 0;
    uint64_t bytes = sizeof *b + b->nslots * sizeof *b->slots + b->bricks_cap * sizeof *b->bricks;
    for (uint64_t i = 0; i < b->nbricks; i++)
        bytes += b->bricks[i].cap * b->record_size;
    return bytes;
}
