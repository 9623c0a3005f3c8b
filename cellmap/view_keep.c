/* cellmap/view_keep.c - a view's labels kept between views of a growing
 * cluster (cellmap/view_keep.h). */
#include "cellmap/view_keep.h"

#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/grow.h"
#include "cellmap/outside.h"

/* A key says where a sequence ends: below KEY_MOST a group (0: the
 * world's sink), KEY_EXIT | slot an exit cell, or one of the marks. */
#define KEY_EXIT UINT32_C(0x80000000)
#define KEY_UNCOMPUTED UINT32_C(0x3FFFFFFF) /* no region holds the cell */
#define KEY_OUTSIDE UINT32_C(0x3FFFFFFE)    /* an orbit still outside after its steps */
#define KEY_MOST UINT32_C(0x3FFFFFF0)       /* groups and slots below this */

static bool is_exit(uint32_t key) { return (key & KEY_EXIT) != 0; }
static uint32_t slot_of_key(uint32_t key) { return key & ~KEY_EXIT; }

/* What a slot knows of its exit cell. */
enum {
    SLOT_UNFOLLOWED, /* not computed; its orbit not followed (or no longer true) */
    SLOT_FOLLOWED,   /* not computed; next: the key its orbit's fate is */
    SLOT_COMPUTED,   /* computed now; its end not asked yet */
    SLOT_ENDED       /* computed; next: the key of its end */
};

struct cm_view_keep {
    int dim;
    uint32_t steps;   /* the budget the orbits were followed with */
    uint32_t regions; /* the cluster's regions seen */
    bool viewed;      /* box and key hold the last view */
    cm_box box;
    /* per cell of a view: the keys of the last view and the next, and
     * what a labelling hands out; kept, so that a view like the last
     * takes no fresh memory (which the kernel zeroes first) */
    uint32_t *key, *next_key;
    uint64_t key_cap, next_cap;
    int32_t *labels;
    uint32_t *shown_group, *shown_step;
    uint64_t out_cap; /* of labels and shown_* */
    /* exit slots */
    uint64_t n, cap;
    int64_t *cell;  /* dim words a slot */
    int64_t *span;  /* SLOT_FOLLOWED: the box of the cells its orbit visited, lo then hi */
    uint32_t *next; /* SLOT_FOLLOWED, SLOT_ENDED: see above */
    uint32_t *taken;
    uint8_t *state;
    uint8_t *reached; /* during a labelling: the view reaches the slot */
    /* the slots by cell, in tiles of TILE_CELLS cells (TILE_EDGE wide in
     * dimensions 0 and 1): neighbouring cells leave into neighbouring
     * exits, so that one tile serves lookups in a row, where a hash of
     * cells would miss the caches on each */
    uint32_t *tile_slot; /* TILE_CELLS per tile: slot + 1, 0 none */
    int64_t *tile_at;    /* dim words per tile: its place, in tiles */
    uint64_t ntiles, tiles_cap;
    uint32_t *hash; /* open addressing by tile: tile + 1, 0 empty; a power of 2 */
    uint64_t hash_size;
};

#define TILE_EDGE 8
#define TILE_CELLS 64

/* Box tests a sync of the slots may take before they are forgotten: about
 * the time of labelling a view of a million cells afresh. */
#define SYNC_MOST (UINT64_C(1) << 26)

cm_view_keep *cm_view_keep_new(void) { return calloc(1, sizeof(cm_view_keep)); }

static void forget_tiles(cm_view_keep *k)
{
    k->ntiles = 0;
    if (k->hash)
        memset(k->hash, 0, (size_t)k->hash_size * sizeof *k->hash);
}

static void forget_slots(cm_view_keep *k)
{
    k->n = 0;
    forget_tiles(k);
    if (k->reached)
        memset(k->reached, 0, (size_t)k->cap);
}

static void reset(cm_view_keep *k)
{
    forget_slots(k);
    k->viewed = false;
    k->regions = 0;
}

static void free_cells(cm_view_keep *k)
{
    free(k->key);
    free(k->next_key);
    free(k->labels);
    free(k->shown_group);
    free(k->shown_step);
    k->key = k->next_key = k->shown_group = k->shown_step = NULL;
    k->labels = NULL;
    k->key_cap = k->next_cap = k->out_cap = 0;
}

/* Room for a view of n cells: its keys, labels and shown cells (the last
 * view's keys stay). */
static cm_status cells_room(cm_view_keep *k, uint64_t n)
{
    const size_t bytes = ((size_t)n + 1) * sizeof(uint32_t);
    if (k->next_cap < n) {
        free(k->next_key);
        k->next_key = cm_cells_array(bytes);
        k->next_cap = k->next_key ? n : 0;
    }
    if (k->out_cap < n) {
        free(k->labels);
        free(k->shown_group);
        free(k->shown_step);
        k->labels = cm_cells_array(bytes);
        k->shown_group = cm_cells_array(bytes);
        k->shown_step = cm_cells_array(bytes);
        k->out_cap = k->labels && k->shown_group && k->shown_step ? n : 0;
    }
    return k->next_cap >= n && k->out_cap >= n ? CM_OK : CM_ENOMEM;
}

/* Frees every array: the keep is as new (slots are sized by dimension). */
static void empty(cm_view_keep *k)
{
    free_cells(k);
    free(k->cell);
    free(k->span);
    free(k->next);
    free(k->taken);
    free(k->state);
    free(k->reached);
    free(k->tile_slot);
    free(k->tile_at);
    free(k->hash);
    memset(k, 0, sizeof *k);
}

void cm_view_keep_free(cm_view_keep *k)
{
    if (!k)
        return;
    empty(k);
    free(k);
}

uint64_t cm_view_keep_bytes(const cm_view_keep *k)
{
    if (!k)
        return 0;
    const uint64_t per_slot = 3 * (uint64_t)k->dim * sizeof(int64_t) + 2 * sizeof(uint32_t) + 2;
    const uint64_t per_tile =
        TILE_CELLS * sizeof *k->tile_slot + (uint64_t)k->dim * sizeof(int64_t);
    return sizeof *k + (k->key_cap + k->next_cap + 3 * k->out_cap) * sizeof *k->key +
           k->cap * per_slot + k->tiles_cap * per_tile + k->hash_size * sizeof *k->hash;
}

/* ---- exit slots --------------------------------------------------------- */

/* The tile of cell (dim words) and the cell's place in it. */
static uint32_t tile_of(int dim, const int64_t *cell, int64_t *tile)
{
    uint32_t place = 0;
    for (int d = 0; d < dim; d++) {
        const int64_t edge = d > 1 ? 1 : dim == 1 ? TILE_CELLS : TILE_EDGE;
        tile[d] = (cell[d] >= 0 ? cell[d] : cell[d] - (edge - 1)) / edge; /* floor */
        place = d == 0 ? (uint32_t)(cell[0] - tile[0] * edge)
                : d == 1 ? place + (uint32_t)(cell[1] - tile[1] * edge) * TILE_EDGE
                         : place;
    }
    return place;
}

/* Where tile is in the hash, or the empty place it would take. */
static uint64_t hash_place(const cm_view_keep *k, const int64_t *tile)
{
    return cm_cell_table_place(k->hash, k->hash_size, k->tile_at, k->dim, tile);
}

static bool grow_array(void **a, uint64_t cap, size_t item)
{
    void *p = realloc(*a, (size_t)cap * item);
    if (p)
        *a = p;
    return p != NULL;
}

/* Room for one more tile, the hash at most half full. */
static cm_status tile_room(cm_view_keep *k)
{
    if (k->ntiles == k->tiles_cap) {
        const uint64_t cap = k->tiles_cap ? 2 * k->tiles_cap : 1024;
        if (!grow_array((void **)&k->tile_slot, cap, TILE_CELLS * sizeof *k->tile_slot) ||
            !grow_array((void **)&k->tile_at, cap, (size_t)k->dim * sizeof *k->tile_at))
            return CM_ENOMEM;
        k->tiles_cap = cap;
    }
    if (2 * (k->ntiles + 1) <= k->hash_size)
        return CM_OK;
    return cm_cell_table_rebuild(&k->hash, &k->hash_size, k->hash_size ? 2 * k->hash_size : 4096,
                                 k->tile_at, k->ntiles, k->dim);
}

/* Where the slot of cell is kept (its tile added when new); NULL when out
 * of memory. */
static uint32_t *slot_place(cm_view_keep *k, const int64_t *cell)
{
    int64_t tile[CM_MAX_DIM];
    const uint32_t place = tile_of(k->dim, cell, tile);
    uint64_t i = k->hash_size ? hash_place(k, tile) : 0;
    if (!k->hash_size || !k->hash[i]) {
        if (tile_room(k) != CM_OK)
            return NULL;
        const uint64_t t = k->ntiles++;
        memcpy(k->tile_at + t * (uint64_t)k->dim, tile, (size_t)k->dim * sizeof *tile);
        memset(k->tile_slot + t * TILE_CELLS, 0, TILE_CELLS * sizeof *k->tile_slot);
        i = hash_place(k, tile);
        k->hash[i] = (uint32_t)(t + 1);
    }
    return k->tile_slot + (uint64_t)(k->hash[i] - 1) * TILE_CELLS + place;
}

/* Room for `need` slots. */
static cm_status slot_room(cm_view_keep *k, uint64_t need)
{
    if (need >= KEY_MOST)
        return CM_ETOOBIG;
    if (need <= k->cap)
        return CM_OK;
    const uint64_t cap = need > 2 * k->cap ? need : k->cap ? 2 * k->cap : 4096;
    const size_t d = (size_t)k->dim * sizeof(int64_t);
    if (!grow_array((void **)&k->cell, cap, d) || !grow_array((void **)&k->span, cap, 2 * d) ||
        !grow_array((void **)&k->next, cap, sizeof *k->next) ||
        !grow_array((void **)&k->taken, cap, sizeof *k->taken) ||
        !grow_array((void **)&k->state, cap, 1) || !grow_array((void **)&k->reached, cap, 1))
        return CM_ENOMEM;
    memset(k->reached + k->cap, 0, (size_t)(cap - k->cap));
    k->cap = cap;
    return CM_OK;
}

/* The key of exit cell `cell`, its slot added (unfollowed) when new. */
static cm_status exit_key(cm_view_keep *k, const int64_t *cell, uint32_t *key, char *msg,
                          size_t msg_size)
{
    uint32_t *at = slot_place(k, cell);
    if (at && *at) {
        *key = KEY_EXIT | (*at - 1);
        return CM_OK;
    }
    const cm_status st = at ? slot_room(k, k->n + 1) : CM_ENOMEM;
    if (st == CM_ETOOBIG)
        return cm_fail(st, msg, msg_size, "the view reaches more than %lu exits",
                       (unsigned long)KEY_MOST);
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "out of memory for the view's exits");
    const uint64_t s = k->n++;
    memcpy(k->cell + s * (uint64_t)k->dim, cell, (size_t)k->dim * sizeof *cell);
    k->state[s] = SLOT_UNFOLLOWED;
    k->next[s] = KEY_OUTSIDE;
    k->taken[s] = 0;
    k->reached[s] = 0;
    *at = (uint32_t)(s + 1);
    *key = KEY_EXIT | (uint32_t)s;
    return CM_OK;
}

/* The key of a computed cell's end, as the cluster resolves it: its group,
 * the world's sink, or the exit its open node leads to. */
static cm_status end_key(cm_view_keep *k, cm_cluster *c, uint32_t group, uint32_t open,
                         uint32_t *key, char *msg, size_t msg_size)
{
    if (group == CM_GROUP_NONE) {
        *key = KEY_UNCOMPUTED;
        return CM_OK;
    }
    if (group != 0) {
        *key = group;
        return group < KEY_MOST ? CM_OK
                                : cm_fail(CM_ETOOBIG, msg, msg_size, "more than %lu groups",
                                          (unsigned long)KEY_MOST);
    }
    if (open == CM_NODE_OPEN) {
        *key = 0;
        return CM_OK;
    }
    int64_t exit[CM_MAX_DIM];
    const cm_status st = cm_cluster_open_exit(c, open, exit, msg, msg_size);
    return st == CM_OK ? exit_key(k, exit, key, msg, msg_size) : st;
}

/* Slots whose exit cell a region added since the last labelling holds are
 * computed now; orbits whose boxes such a region meets are no longer true.
 * When that takes more work than labelling afresh (many regions added, as
 * an extension adds them), the slots are forgotten instead. */
static void sync_slots(cm_view_keep *k, const cm_cluster *c)
{
    const int dim = k->dim;
    if ((uint64_t)(c->nregions - k->regions) * k->n > SYNC_MOST)
        reset(k); /* the slots and the last view: every key is found afresh */
    for (uint32_t r = k->regions; r < c->nregions; r++) {
        const cm_box *b = &c->regions[r].r.box;
        for (uint64_t s = 0; s < k->n; s++) {
            if (k->state[s] >= SLOT_COMPUTED)
                continue;
            if (cm_box_contains(b, k->cell + s * (uint64_t)dim)) {
                k->state[s] = SLOT_COMPUTED;
                continue;
            }
            const int64_t *lo = k->span + s * 2 * (uint64_t)dim, *hi = lo + dim;
            bool meets = k->state[s] == SLOT_FOLLOWED;
            for (int d = 0; d < dim && meets; d++)
                meets = lo[d] < b->hi[d] && hi[d] >= b->lo[d];
            if (meets)
                k->state[s] = SLOT_UNFOLLOWED;
        }
    }
    k->regions = c->nregions;
}

/* ---- the view's cells ----------------------------------------------------- */

/* Grows part (empty: *empty) to hold b. */
static void add_to_part(cm_box *part, bool *empty, const cm_box *b)
{
    if (*empty)
        *part = *b;
    else
        cm_box_grow(part, b);
    *empty = false;
}

/* The part of box whose keys must be found afresh: where the last view did
 * not reach, and the regions added since (a bounding box; *empty when none). */
static void fresh_part(const cm_view_keep *k, const cm_cluster *c, uint32_t added_from,
                       const cm_box *box, cm_box *part, bool *empty)
{
    cm_box shared;
    *empty = true;
    if (!k->viewed || !cm_box_intersect(box, &k->box, &shared)) {
        add_to_part(part, empty, box);
        return;
    }
    for (int d = 0; d < box->dim; d++) { /* the slabs of box outside shared, dimension by dim. */
        cm_box below = *box, above = *box;
        below.hi[d] = shared.lo[d];
        above.lo[d] = shared.hi[d];
        if (box->lo[d] < shared.lo[d])
            add_to_part(part, empty, &below);
        if (shared.hi[d] < box->hi[d])
            add_to_part(part, empty, &above);
    }
    for (uint32_t r = added_from; r < c->nregions; r++) {
        cm_box met;
        if (cm_box_intersect(&c->regions[r].r.box, box, &met))
            add_to_part(part, empty, &met);
    }
}

/* Marks the slot of an exit key reached (relaxed: threads mark the same
 * slots, with the same value). */
static void mark_reached(uint8_t *reached, uint32_t key)
{
    if (is_exit(key))
        __atomic_store_n(&reached[slot_of_key(key)], 1, __ATOMIC_RELAXED);
}

/* Copies a row of width keys and marks the slots they reach. */
static void copy_keys(uint32_t *to, const uint32_t *from, int64_t width, uint8_t *reached)
{
    for (int64_t i = 0; i < width; i++) {
        to[i] = from[i];
        mark_reached(reached, to[i]);
    }
}

/* Copies the keys of the cells box shares with the last view, row by row
 * along dimension 0 (rows are contiguous in both), and marks the slots
 * they reach. */
static void copy_shared(cm_view_keep *k, const cm_box *box, uint32_t *key, int threads)
{
    cm_box shared;
    if (!k->viewed || !cm_box_intersect(box, &k->box, &shared))
        return;
    const int64_t width = shared.hi[0] - shared.lo[0];
    const int64_t rows = (int64_t)(cm_box_cells(&shared) / (uint64_t)width);
    uint8_t *reached = k->reached;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t q = 0; q < rows; q++) {
        int64_t cell[CM_MAX_DIM];
        cm_box row = shared;
        row.hi[0] = row.lo[0] + 1;
        cm_box_cell(&row, (uint64_t)q, cell);
        copy_keys(key + cm_box_index(box, cell), k->key + cm_box_index(&k->box, cell), width,
                  reached);
    }
}

/* Open node ids remembered with their keys (direct-mapped: the cells of
 * one tree, which share an open node, lie together). */
#define OPEN_CACHE 4096

/* While fresh_keys works: the key of the cell's image, in the part. */
#define KEY_WALK UINT32_C(0x3FFFFFFD)

/* The keys of the part's cells (flat, with the open nodes its cells leave
 * by) into pk, where they need no walk: a group's cell its group, a sink
 * cell that leaves the part its exit (the cell's image, or its open
 * node's exit), and KEY_WALK for a sink cell whose image is a computed
 * cell of the part. */
static cm_status first_keys(cm_view_keep *k, cm_cluster *c, const cm_region *flat,
                            const uint32_t *open, uint32_t *pk, char *msg, size_t msg_size)
{
    uint32_t cached_open[OPEN_CACHE], cached_key[OPEN_CACHE];
    memset(cached_open, 0xFF, sizeof cached_open); /* CM_NODE_OPEN */
    cm_status st = CM_OK;
    for (uint64_t j = 0; j < flat->ncells && st == CM_OK; j++) {
        const uint32_t g = flat->group[j], id = open[j], image = flat->image[j];
        if (g != 0 || id == CM_NODE_OPEN) {
            st = end_key(k, c, g, id, &pk[j], msg, msg_size);
        } else if (image < flat->ncells && flat->group[image] != CM_GROUP_NONE) {
            pk[j] = KEY_WALK;
        } else if (image < flat->ncells) { /* into an uncomputed cell: that is its exit */
            int64_t exit[CM_MAX_DIM];
            cm_box_cell(&flat->box, image, exit);
            st = exit_key(k, exit, &pk[j], msg, msg_size);
        } else {
            const uint32_t at = (id * UINT32_C(2654435761)) >> 20; /* 12 bits: OPEN_CACHE */
            if (cached_open[at] != id) {
                st = end_key(k, c, g, id, &cached_key[at], msg, msg_size);
                cached_open[at] = id;
            }
            pk[j] = cached_key[at];
        }
    }
    return st;
}

/* Every KEY_WALK cell of the part takes the key of the first cell its
 * sequence reaches that has one, as do the cells on the way. */
static void walk_keys(const cm_region *flat, uint32_t *pk)
{
    for (uint64_t j = 0; j < flat->ncells; j++) {
        if (pk[j] != KEY_WALK)
            continue;
        uint64_t end = j;
        while (pk[end] == KEY_WALK)
            end = flat->image[end];
        for (uint64_t i = j; i != end; i = flat->image[i])
            pk[i] = pk[end];
    }
}

/* The keys of the cells of part (in box), from the cluster flattened
 * afresh there; the slots they reach marked. */
static cm_status fresh_keys(cm_view_keep *k, cm_cluster *c, cm_resolve_cache *cache,
                            const cm_box *part, const cm_box *box, uint32_t *key, char *msg,
                            size_t msg_size)
{
    cm_region flat;
    memset(&flat, 0, sizeof flat);
    const uint64_t n = cm_box_cells(part);
    uint32_t *open = cm_cells_array(((size_t)n + 1) * sizeof *open);
    uint32_t *pk = cm_cells_array(((size_t)n + 1) * sizeof *pk);
    cm_status st = open && pk
                       ? cm_cluster_flatten_cached(c, part, cache, &flat, open, msg, msg_size)
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's cells");
    if (st == CM_OK)
        st = first_keys(k, c, &flat, open, pk, msg, msg_size);
    if (st == CM_OK)
        walk_keys(&flat, pk);
    const int64_t width = part->hi[0] - part->lo[0];
    const uint64_t rows = st == CM_OK ? n / (uint64_t)width : 0;
    for (uint64_t q = 0; q < rows; q++) { /* rows are contiguous in both */
        int64_t cell[CM_MAX_DIM];
        cm_box_cell(part, q * (uint64_t)width, cell);
        copy_keys(key + cm_box_index(box, cell), pk + q * (uint64_t)width, width, k->reached);
    }
    cm_region_free(&flat);
    free(open);
    free(pk);
    return st;
}

/* ---- the exits the view reaches ------------------------------------------- */

/* The slots reached, in the order they were reached. */
typedef struct reach_list {
    uint64_t *slot;
    uint64_t n, cap;
} reach_list;

static cm_status list_add(reach_list *l, uint64_t slot)
{
    if (cm_grow((void **)&l->slot, &l->cap, l->n + 1, sizeof *l->slot) != CM_OK)
        return CM_ENOMEM;
    l->slot[l->n++] = slot;
    return CM_OK;
}

/* Lists slot as reached, unless it is already. */
static cm_status reach(cm_view_keep *k, reach_list *l, uint32_t slot)
{
    if (k->reached[slot])
        return CM_OK;
    k->reached[slot] = 1;
    return list_add(l, slot);
}

/* The slots the view's cells reach (marked as their keys were found), in
 * slot order. */
static cm_status reached_slots(const cm_view_keep *k, reach_list *l)
{
    cm_status st = CM_OK;
    for (uint64_t s = 0; s < k->n && st == CM_OK; s++)
        if (k->reached[s])
            st = list_add(l, s);
    return st;
}

/* The keys of n computed cells (dim words each): the view's keys for its
 * cells, else the cluster's ends, looked up region by region. */
static cm_status keys_of_cells(cm_view_keep *k, cm_cluster *c, const cm_box *box,
                               const uint32_t *view_key, const int64_t *cells, uint64_t n,
                               uint32_t *out, char *msg, size_t msg_size)
{
    uint64_t *order = NULL;
    cm_status st = cm_cluster_region_order(c, cells, n, &order) == CM_OK
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    for (uint64_t i = 0; st == CM_OK && i < n; i++) {
        const int64_t *cell = cells + order[i] * (uint64_t)k->dim;
        if (cm_box_contains(box, cell)) {
            out[order[i]] = view_key[cm_box_index(box, cell)];
            continue;
        }
        uint32_t g, open;
        st = cm_cluster_cell_end(c, cell, &g, &open, msg, msg_size);
        if (st == CM_OK)
            st = end_key(k, c, g, open, &out[order[i]], msg, msg_size);
    }
    free(order);
    return st;
}

/* Brings the slots l->slot[from..to) up to date: the ends of exits that
 * are computed now, and the orbits of the others not followed (or no
 * longer true). */
static cm_status update_slots(cm_view_keep *k, const cm_model *m, cm_cluster *c,
                              const cm_box *box, const uint32_t *view_key, const reach_list *l,
                              uint64_t from, uint64_t to, int threads, char *msg, size_t msg_size)
{
    const int dim = k->dim;
    const size_t bytes = (size_t)dim * sizeof(int64_t);
    uint64_t n = 0;
    for (uint64_t i = from; i < to; i++)
        n += k->state[l->slot[i]] == SLOT_UNFOLLOWED || k->state[l->slot[i]] == SLOT_COMPUTED;
    if (n == 0)
        return CM_OK;
    /* slots arrays may move as keys add slots: copied out first */
    uint64_t *which = malloc((size_t)n * sizeof *which);
    int64_t *cell = malloc((size_t)n * bytes), *ask = malloc((size_t)n * bytes);
    int64_t *span = malloc((size_t)n * 2 * bytes);
    cm_followed *f = malloc((size_t)n * sizeof *f);
    uint32_t *got = malloc((size_t)n * sizeof *got);
    uint64_t *asked = malloc((size_t)n * sizeof *asked);
    cm_status st = which && cell && ask && span && f && got && asked
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    uint64_t nfollow = 0, nask = 0;
    for (uint64_t i = from; st == CM_OK && i < to; i++) { /* the orbits first, then the computed */
        const uint64_t s = l->slot[i];
        if (k->state[s] == SLOT_UNFOLLOWED) {
            which[nfollow] = s;
            memcpy(cell + nfollow++ * (uint64_t)dim, k->cell + s * (uint64_t)dim, bytes);
        }
    }
    uint64_t taken = 0;
    cm_cluster_cells cc = {c, NULL, NULL};
    const cm_computed computed = cm_cluster_computed(&cc);
    if (st == CM_OK && nfollow)
        st = cm_exits_follow(m, &c->lat, &computed, cell, nfollow, k->steps, threads, f, span,
                             &taken, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < nfollow; i++) {
        const uint64_t s = which[i];
        k->state[s] = SLOT_FOLLOWED;
        k->taken[s] = f[i].taken;
        memcpy(k->span + s * 2 * (uint64_t)dim, span + i * 2 * (uint64_t)dim, 2 * bytes);
        k->next[s] = f[i].how == CM_FOLLOW_DIVERGED ? 0 : KEY_OUTSIDE;
        if (f[i].how == CM_FOLLOW_RETURNED) {
            asked[nask] = s;
            memcpy(ask + nask++ * (uint64_t)dim, f[i].cell, bytes);
        }
    }
    for (uint64_t i = from; st == CM_OK && i < to; i++) {
        const uint64_t s = l->slot[i];
        if (k->state[s] == SLOT_COMPUTED) {
            k->state[s] = SLOT_ENDED;
            asked[nask] = s;
            memcpy(ask + nask++ * (uint64_t)dim, k->cell + s * (uint64_t)dim, bytes);
        }
    }
    if (st == CM_OK)
        st = keys_of_cells(k, c, box, view_key, ask, nask, got, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < nask; i++)
        k->next[asked[i]] = got[i];
    free(which);
    free(cell);
    free(ask);
    free(span);
    free(f);
    free(got);
    free(asked);
    return st;
}

/* Every slot the view reaches, and those their orbits and ends reach in
 * turn, up to date, in rounds. */
static cm_status update_reached(cm_view_keep *k, const cm_model *m, cm_cluster *c,
                                const cm_box *box, const uint32_t *view_key, reach_list *l,
                                int threads, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint64_t from = 0; st == CM_OK && from < l->n;) {
        const uint64_t to = l->n;
        st = update_slots(k, m, c, box, view_key, l, from, to, threads, msg, msg_size);
        for (uint64_t i = from; st == CM_OK && i < to; i++) {
            const uint32_t next = k->next[l->slot[i]];
            if (is_exit(next) && reach(k, l, slot_of_key(next)) != CM_OK)
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
        }
        from = to;
    }
    return st;
}

/* ---- labels ----------------------------------------------------------------- */

#define LABEL_PENDING INT32_MIN
#define LABEL_WALKING (INT32_MIN + 1)

/* The label of a key that names no exit. */
static int32_t key_label(const cm_attractor_set *s, uint32_t key)
{
    return key == 0                ? CM_LABEL_DIVERGED
           : key == KEY_OUTSIDE    ? CM_LABEL_OUTSIDE
           : key == KEY_UNCOMPUTED ? CM_LABEL_UNCOMPUTED
                                   : cm_attractor_label(s, key);
}

/* A computed slot's end, through the ends of computed slots in turn (an
 * uncomputed exit or no exit); the chain shortened to it. */
static uint32_t end_of_slot(cm_view_keep *k, uint32_t slot)
{
    uint32_t key = KEY_EXIT | slot;
    while (is_exit(key) && k->state[slot_of_key(key)] == SLOT_ENDED)
        key = k->next[slot_of_key(key)];
    for (uint32_t s = slot; k->state[s] == SLOT_ENDED && k->next[s] != key;) {
        const uint32_t next = k->next[s];
        k->next[s] = key;
        if (!is_exit(next))
            break;
        s = slot_of_key(next);
    }
    return key;
}

/* label[s] for the reached slots: the label their chains of orbits and
 * ends settle on; a chain that comes back on itself is outside (as
 * cm_cluster_view_labels settles them). */
static void settle_slots(const cm_view_keep *k, const cm_attractor_set *s, const reach_list *l,
                         int32_t *label)
{
    for (uint64_t i = 0; i < l->n; i++)
        label[l->slot[i]] = LABEL_PENDING;
    for (uint64_t i = 0; i < l->n; i++) {
        uint32_t j = (uint32_t)l->slot[i];
        int32_t v;
        for (;;) {
            if (label[j] != LABEL_PENDING) {
                v = label[j] == LABEL_WALKING ? CM_LABEL_OUTSIDE : label[j];
                break;
            }
            label[j] = LABEL_WALKING;
            if (!is_exit(k->next[j])) {
                v = key_label(s, k->next[j]);
                break;
            }
            j = slot_of_key(k->next[j]);
        }
        for (uint32_t t = (uint32_t)l->slot[i]; label[t] == LABEL_WALKING;) {
            label[t] = v;
            if (!is_exit(k->next[t]))
                break;
            t = slot_of_key(k->next[t]);
        }
    }
}

/* Each cell's label and what a figure reads of it (cm_view_keep_labels);
 * end[s] is the end of each reached slot (end_of_slot), fate[s] its label.
 * A cell whose exit is computed now takes its end as its key, so that
 * computed slots are left to be dropped.
 * The cells that leave by an exit are counted in s by their exit's fate,
 * as cm_cluster_view_labels counts its exits' weights: each thread counts
 * into its own array, summed after. */
static cm_status label_cells(cm_attractor_set *s, uint32_t *key, uint64_t ncells,
                             const uint32_t *end, const int32_t *fate, int threads,
                             int32_t *labels, cm_region *shown)
{
    const uint32_t na = s->n;
    uint64_t *basin = calloc((size_t)threads * (na + 1) + 1, sizeof *basin);
    if (!basin)
        return CM_ENOMEM;
    uint64_t diverged = 0, outside = 0, returned = 0;
#pragma omp parallel num_threads(threads) reduction(+ : diverged, outside, returned)
    {
        uint64_t *mine = basin + (uint64_t)omp_get_thread_num() * (na + 1);
#pragma omp for schedule(static)
        for (int64_t i = 0; i < (int64_t)ncells; i++) {
            uint32_t kk = key[i];
            shown->group[i] = 0;
            shown->step[i] = 1;
            if (is_exit(kk) && end[slot_of_key(kk)] != kk)
                key[i] = kk = end[slot_of_key(kk)];
            if (!is_exit(kk)) {
                labels[i] = key_label(s, kk);
                continue;
            }
            const int32_t v = fate[slot_of_key(kk)];
            labels[i] = v;
            if (v > 0 && (uint32_t)v <= na) {
                mine[v]++;
                returned++;
            } else if (v == CM_LABEL_DIVERGED) {
                diverged++;
            } else {
                outside++;
            }
        }
    }
    s->sink_diverged_cells = diverged;
    s->outside_cells = outside;
    s->returned_cells = returned;
    for (int t = 0; t < threads; t++)
        for (uint32_t a = 1; a <= na; a++)
            s->a[a - 1].basin_cells += basin[(uint64_t)t * (na + 1) + a];
    free(basin);
    return CM_OK;
}

/* ---- the labelling -------------------------------------------------------- */

/* Drops the slots the view does not reach when they outnumber those it
 * does (the reached ones keep their order); clears the marks. */
static cm_status forget_unreached(cm_view_keep *k, const reach_list *l, uint32_t *key,
                                  uint64_t ncells, int threads)
{
    if (k->n <= 2 * l->n + 65536) {
        for (uint64_t i = 0; i < l->n; i++)
            k->reached[l->slot[i]] = 0;
        return CM_OK;
    }
    uint32_t *to = malloc((size_t)k->n * sizeof *to);
    if (!to)
        return CM_ENOMEM;
    const int dim = k->dim;
    const size_t bytes = (size_t)dim * sizeof(int64_t);
    uint64_t kept = 0;
    for (uint64_t s = 0; s < k->n; s++) {
        if (!k->reached[s])
            continue;
        to[s] = (uint32_t)kept;
        memmove(k->cell + kept * (uint64_t)dim, k->cell + s * (uint64_t)dim, bytes);
        memmove(k->span + kept * 2 * (uint64_t)dim, k->span + s * 2 * (uint64_t)dim, 2 * bytes);
        k->next[kept] = k->next[s];
        k->taken[kept] = k->taken[s];
        k->state[kept] = k->state[s];
        k->reached[s] = 0;
        kept++;
    }
    for (uint64_t s = 0; s < kept; s++) /* a reached slot's next exit is reached */
        if (is_exit(k->next[s]))
            k->next[s] = KEY_EXIT | to[slot_of_key(k->next[s])];
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t i = 0; i < (int64_t)ncells; i++)
        if (is_exit(key[i]))
            key[i] = KEY_EXIT | to[slot_of_key(key[i])];
    free(to);
    k->n = kept;
    forget_tiles(k);
    for (uint64_t s = 0; s < kept; s++) {
        uint32_t *at = slot_place(k, k->cell + s * (uint64_t)dim);
        if (!at)
            return CM_ENOMEM;
        *at = (uint32_t)(s + 1);
    }
    return CM_OK;
}

/* The keys of box's cells into key: those of the last view where it
 * shares cells that no region added since holds, the others afresh. */
static cm_status view_keys(cm_view_keep *k, cm_cluster *c, cm_resolve_cache *cache,
                           uint32_t added_from, const cm_box *box, uint32_t *key, int threads,
                           char *msg, size_t msg_size)
{
    cm_box part;
    bool none;
    fresh_part(k, c, added_from, box, &part, &none);
    if (!none && 2 * cm_box_cells(&part) > cm_box_cells(box))
        part = *box; /* mostly new: no copying first */
    else
        copy_shared(k, box, key, threads);
    return none ? CM_OK : fresh_keys(k, c, cache, &part, box, key, msg, msg_size);
}

/* The ends and fates of the reached slots, the cells' labels and counts. */
static cm_status labels_of_keys(cm_view_keep *k, cm_attractor_set *s, const reach_list *l,
                                uint32_t *key, uint64_t ncells, int threads,
                                int32_t *labels, cm_region *shown)
{
    uint32_t *end = malloc(((size_t)k->n + 1) * sizeof *end);
    int32_t *fate = malloc(((size_t)k->n + 1) * sizeof *fate);
    cm_status st = end && fate ? CM_OK : CM_ENOMEM;
    uint64_t taken = 0;
    for (uint64_t i = 0; st == CM_OK && i < l->n; i++) {
        const uint32_t slot = (uint32_t)l->slot[i];
        const bool computed = k->state[slot] == SLOT_ENDED;
        end[slot] = computed ? end_of_slot(k, slot) : KEY_EXIT | slot;
        taken += computed ? 0 : k->taken[slot];
    }
    if (st == CM_OK) {
        settle_slots(k, s, l, fate);
        st = label_cells(s, key, ncells, end, fate, threads, labels, shown);
    }
    s->outside_steps = k->steps;
    s->outside_steps_taken = taken;
    free(end);
    free(fate);
    return st;
}

cm_status cm_view_keep_labels(cm_view_keep *k, const cm_model *m, cm_cluster *c,
                              cm_resolve_cache *cache, const cm_box *box,
                              const cm_attractor_options *opt, cm_attractor_set *s,
                              int32_t **labels, cm_region *shown, char *msg, size_t msg_size)
{
    memset(shown, 0, sizeof *shown);
    *labels = NULL;
    if (c->resolved_cells || c->open_released || !c->keep_exits)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster does not know its exits (an old file, or released)");
    if (box->dim != c->lat.dim)
        return cm_fail(CM_EINVAL, msg, msg_size, "a box of %d dimensions for a lattice of %d",
                       box->dim, c->lat.dim);
    const uint32_t steps = cm_outside_budget(m, opt);
    const int threads = opt && opt->threads > 0 ? opt->threads : omp_get_max_threads();
    if (k->dim != c->lat.dim)
        empty(k); /* reset too: a keep as new */
    else if (k->steps != steps || c->nregions < k->regions)
        reset(k);
    k->dim = c->lat.dim;
    k->steps = steps;
    const uint32_t added_from = k->regions;
    sync_slots(k, c);
    const uint64_t ncells = cm_box_cells(box);
    reach_list l = {NULL, 0, 0};
    cm_status st = cells_room(k, ncells) == CM_OK
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's cells");
    uint32_t *key = k->next_key;
    shown->group = k->shown_group;
    shown->step = k->shown_step;
    shown->box = *box;
    shown->ncells = ncells;
    shown->ngroups = c->ngroups;
    if (st == CM_OK)
        st = view_keys(k, c, cache, added_from, box, key, threads, msg, msg_size);
    if (st == CM_OK && reached_slots(k, &l) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    if (st == CM_OK)
        st = update_reached(k, m, c, box, key, &l, threads, msg, msg_size);
    if (st == CM_OK && labels_of_keys(k, s, &l, key, ncells, threads, k->labels, shown) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's labels");
    if (st == CM_OK && forget_unreached(k, &l, key, ncells, threads) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    free(l.slot);
    free(s->exit_cell);
    free(s->exit_label);
    s->exit_cell = NULL;
    s->exit_label = NULL;
    s->nexits = 0;
    if (st != CM_OK) {
        reset(k);
        free_cells(k);
        memset(shown, 0, sizeof *shown);
        return st;
    }
    k->next_key = k->key; /* the last view's keys: room for the next */
    k->key = key;
    const uint64_t cap = k->next_cap;
    k->next_cap = k->key_cap;
    k->key_cap = cap;
    k->box = *box;
    k->viewed = true;
    *labels = k->labels;
    return CM_OK;
}
