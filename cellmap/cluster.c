#include "cellmap/cluster.h"

#include "cellmap/grow.h"

#include <stdbool.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define NODE_BLOCK (UINT64_C(1) << CM_NODE_BLOCK_BITS)

/* An open node keeps its weight in its own record, in fields a link or a
 * final outcome fills later (saved as 0 while the node is open): dist the
 * low 32 bits, group the high ones, target the INDEXED flag (the node is in
 * its region's open list). When its node table is evicted, the weight and
 * the flag go beside the node's place in the open list (open_weight,
 * INDEXED as bit 63: 8 bytes a node), or to c->open for an open node the
 * list lacks, and come back with the table. */
#define INDEXED_FLAG 1u
#define INDEXED (UINT64_C(1) << 63)

static uint64_t weight_of(const cm_node *nd)
{
    return (uint64_t)nd->group << 32 | nd->dist;
}

static void set_weight(cm_node *nd, uint64_t w)
{
    nd->dist = (uint32_t)w;
    nd->group = (uint32_t)(w >> 32);
}

static int is_open(const cm_node *nd) { return nd->next == CM_NODE_OPEN && nd->up == CM_NODE_OPEN; }

void cm_cluster_init(cm_cluster *c, const cm_lattice *lat)
{
    memset(c, 0, sizeof *c);
    c->lat = *lat;
    c->keep_exits = 1;
}

int cm_cluster_threads(const cm_cluster *c)
{
#ifdef _OPENMP
    return c->threads > 0 ? c->threads : omp_get_max_threads();
#else
    (void)c;
    return 1;
#endif
}

void cm_cluster_free(cm_cluster *c)
{
    if (!c)
        return;
    for (uint32_t k = 0; k < c->nregions; k++) {
        cm_region_free(&c->regions[k].r);
        free(c->regions[k].nodes);
        free(c->regions[k].dirty_chunks);
        free(c->regions[k].open_local);
        free(c->regions[k].open_cells);
        free(c->regions[k].open_weight);
    }
    free(c->regions);
    cm_idmap_free(&c->open);
    free(c->node_blocks);
    free(c->node_bases);
    free(c->chain);
    free(c->basin);
    free(c->basin_dirty);
    free(c->new_periodic);
    free(c->big);
    cm_bricks_free(c->region_bricks);
    cm_bricks_free(c->escape_bricks);
    memset(c, 0, sizeof *c);
}

void cm_cluster_release_open(cm_cluster *c)
{
    for (uint32_t k = 0; k < c->nregions; k++) {
        cm_cluster_region *cr = &c->regions[k];
        free(cr->open_local);
        free(cr->open_cells);
        free(cr->open_weight);
        cr->open_local = NULL, cr->open_cells = NULL, cr->open_weight = NULL;
        cr->nopen = cr->open_cap = cr->open_stale = 0;
        cr->open_paged = 0;
    }
    cm_idmap_free(&c->open);
    cm_bricks_free(c->escape_bricks);
    c->escape_bricks = NULL;
    c->open_released = 1;
#ifdef __GLIBC__
    malloc_trim(0); /* the room is what the caller asked for */
#endif
}

/* ---- where cells and nodes are ------------------------------------------ */

int64_t cm_cluster_locate(const cm_cluster *c, const int64_t *cell, uint64_t *local)
{
    if (!c->region_bricks)
        return -1;
    int64_t key[CM_MAX_DIM];
    uint64_t n;
    cm_bricks_of(c->region_bricks, cell, key);
    const uint32_t *in_brick = cm_bricks_find(c->region_bricks, key, &n);
    for (uint64_t p = 0; p < n + c->nbig; p++) {
        const uint32_t k = p < n ? in_brick[p] : c->big[p - n];
        const cm_box *box = &c->regions[k].r.box;
        if (cm_box_contains(box, cell)) {
            *local = cm_box_index(box, cell);
            return k;
        }
    }
    return -1;
}

/* Calls found(user, k) for each region k that meets box, until it returns
 * true (then true): the regions of the bricks the box meets and the big
 * ones, or every region for a box of very many bricks. */
static bool find_regions_meeting(const cm_cluster *c, const cm_box *box,
                                 bool (*found)(void *user, uint32_t k), void *user)
{
    int64_t lo[CM_MAX_DIM], hi[CM_MAX_DIM], key[CM_MAX_DIM];
    cm_box both;
    if (!c->region_bricks || !cm_bricks_span(c->region_bricks, box, lo, hi)) {
        for (uint32_t k = 0; k < c->nregions; k++)
            if (cm_box_intersect(&c->regions[k].r.box, box, &both) && found(user, k))
                return true;
        return false;
    }
    for (uint64_t b = 0; b < c->nbig; b++)
        if (cm_box_intersect(&c->regions[c->big[b]].r.box, box, &both) && found(user, c->big[b]))
            return true;
    memcpy(key, lo, sizeof key);
    do {
        uint64_t n;
        const uint32_t *in_brick = cm_bricks_find(c->region_bricks, key, &n);
        for (uint64_t p = 0; p < n; p++)
            if (cm_box_intersect(&c->regions[in_brick[p]].r.box, box, &both) &&
                found(user, in_brick[p]))
                return true;
    } while (cm_index_next(c->lat.dim, lo, hi, key));
    return false;
}

/* Region k (the last) in the index of node blocks. */
static cm_status index_nodes(cm_cluster *c, uint32_t k)
{
    const uint64_t base = c->regions[k].node_base, end = base + c->regions[k].r.nexits;
    if (cm_grow((void **)&c->node_bases, &c->node_bases_cap, (uint64_t)k + 1,
                sizeof *c->node_bases) != CM_OK)
        return CM_ENOMEM;
    c->node_bases[k] = (uint32_t)base;
    const uint64_t first = (base + NODE_BLOCK - 1) >> CM_NODE_BLOCK_BITS;
    const uint64_t last = end > 0 ? (end - 1) >> CM_NODE_BLOCK_BITS : 0;
    if (end == base || first > last)
        return CM_OK;
    if (cm_grow((void **)&c->node_blocks, &c->node_blocks_cap, last + 1, sizeof *c->node_blocks) !=
        CM_OK)
        return CM_ENOMEM;
    for (uint64_t b = first; b <= last; b++)
        c->node_blocks[b] = k;
    return CM_OK;
}

/* A record of escape_bricks in a cluster that keeps no open lists
 * (keep_exits 0): an open node and its exit's target as an offset in the
 * brick (8 bytes, however many dimensions). With open lists, a record is
 * a region whose list holds open nodes leading into the brick (4 bytes a
 * region and brick, rather than 8 a node, which a long session gains by
 * the million): a take reads those lists. */
typedef struct escape_record {
    uint32_t node, offset;
} escape_record;

/* Resolution state from a node's saved fields. */
static void start_resolution(cm_node *nd)
{
    if (nd->next == CM_NODE_OPEN) {
        nd->up = CM_NODE_OPEN;
    } else if (nd->next == CM_NODE_FINAL) {
        nd->up = CM_NODE_FINAL;
        nd->up_dist = nd->dist;
    } else if (nd->next == CM_NODE_CYCLE) {
        nd->up = CM_NODE_CYCLE;
        nd->up_dist = 0;
    } else {
        nd->up = nd->next;
        nd->up_dist = nd->dist;
    }
}

cm_status cm_cluster_check_nodes(const cm_cluster *c, uint32_t k, const cm_node *nodes,
                                 uint32_t groups, char *msg, size_t msg_size)
{
    const cm_cluster_region *cr = &c->regions[k];
    for (uint64_t e = 0; e < cr->r.nexits; e++) {
        const cm_node *nd = &nodes[e];
        const bool known = nd->next == CM_NODE_FINAL || nd->next == CM_NODE_CYCLE;
        const bool linked = nd->next < CM_NODE_MAX;
        const bool bad_list = (nd->first_in != CM_NODE_OPEN && nd->first_in >= c->nnodes) ||
                              (nd->sibling != CM_NODE_OPEN && nd->sibling >= c->nnodes);
        if ((linked && (nd->next >= c->nnodes ||
                        nd->target >= c->regions[cm_cluster_node_region(c, nd->next)].r.ncells)) ||
            (!linked && !known && nd->next != CM_NODE_OPEN) || (known && nd->group > groups) ||
            (nd->next == CM_NODE_CYCLE && (nd->group == 0 || nd->dist >= cr->r.ncells)) ||
            nd->tree > cr->r.ncells || bad_list)
            return cm_fail(CM_EFORMAT, msg, msg_size, "node %llu of region %u is damaged",
                           (unsigned long long)e, k + 1);
    }
    return CM_OK;
}

/* Region k's open list, read back if it was paged out. The list was
 * saved without the nodes linked since, and its node table is out too:
 * every node it lists is open, its weight beside its place. */
static cm_status open_list(cm_cluster *c, uint32_t k, char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    cr->nodes_used = ++c->clock;
    if (!cr->open_paged)
        return CM_OK;
    uint32_t *local = NULL;
    uint64_t *weight = NULL, n = 0;
    int64_t *cells = NULL;
    cm_status st = c->open_in(c->pager, k, &local, &weight, &cells, &n, msg, msg_size);
    if (st == CM_OK && n != cr->nopen)
        st = cm_fail(CM_EFORMAT, msg, msg_size,
                     "region %u saved %llu open nodes where the cluster had %llu", k + 1,
                     (unsigned long long)n, (unsigned long long)cr->nopen);
    if (st != CM_OK) {
        free(local);
        free(weight);
        free(cells);
        return st;
    }
    for (uint64_t i = 0; i < n; i++)
        weight[i] |= INDEXED;
    cr->open_local = local;
    cr->open_weight = weight;
    cr->open_cells = cells;
    cr->open_cap = n;
    cr->open_stale = 0;
    cr->open_paged = 0;
    return CM_OK;
}

/* Whether region cr's open list may go once its node table is out: it is
 * saved as it stands (clean, and compacted, as a save leaves it). */
static bool open_list_saved(const cm_cluster *c, const cm_cluster_region *cr)
{
    return c->open_in && !cr->open_paged && !cr->open_dirty && !cr->open_stale;
}

static bool open_list_evictable(const cm_cluster *c, const cm_cluster_region *cr)
{
    return !cr->nodes && open_list_saved(c, cr);
}

static uint64_t open_list_bytes(const cm_cluster *c, const cm_cluster_region *cr)
{
    return cr->open_cap * (sizeof *cr->open_local + sizeof *cr->open_weight +
                           (uint64_t)c->lat.dim * sizeof *cr->open_cells);
}

static void evict_open_list(cm_cluster_region *cr)
{
    free(cr->open_local);
    free(cr->open_cells);
    free(cr->open_weight);
    cr->open_local = NULL, cr->open_cells = NULL, cr->open_weight = NULL;
    cr->open_cap = 0;
    cr->open_paged = 1;
}

/* Region k's node table, read back if it was paged out. */
static cm_status node_table(cm_cluster *c, uint32_t k, cm_node **out, char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    cr->nodes_used = ++c->clock;
    if (!cr->nodes) {
        if (!c->nodes_in)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the nodes of region %u are paged out and there is no pager", k);
        cm_status st = open_list(c, k, msg, msg_size); /* it holds the open nodes' weights */
        if (st != CM_OK)
            return st;
        cr->nodes = calloc(cr->r.nexits + 1, sizeof *cr->nodes);
        if (!cr->nodes)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the nodes of region %u",
                           k);
        st = c->nodes_in(c->pager, k, cr->nodes, cr->r.nexits, msg, msg_size);
        if (st != CM_OK) {
            free(cr->nodes);
            cr->nodes = NULL;
            return st;
        }
        for (uint64_t e = 0; e < cr->r.nexits; e++) {
            cm_node *nd = &cr->nodes[e];
            uint64_t spilled;
            start_resolution(nd);
            if (is_open(nd) && cm_idmap_remove(&c->open, cr->node_base + (uint32_t)e, &spilled)) {
                set_weight(nd, spilled & ~INDEXED);
                nd->target = spilled & INDEXED ? INDEXED_FLAG : 0;
            }
        }
        for (uint64_t i = 0; i < cr->nopen; i++)
            if (cr->open_weight[i] & INDEXED) {
                cm_node *nd = &cr->nodes[cr->open_local[i]];
                set_weight(nd, cr->open_weight[i] & ~INDEXED);
                nd->target = INDEXED_FLAG;
            }
    }
    *out = cr->nodes;
    return CM_OK;
}

cm_status cm_cluster_node_load(cm_cluster *c, uint32_t id, cm_node **out, char *msg,
                               size_t msg_size)
{
    if (id >= c->nnodes)
        return cm_fail(CM_EFORMAT, msg, msg_size, "node %u is not in the cluster", id);
    const uint32_t k = cm_cluster_node_region(c, id);
    cm_node *table;
    cm_status st = node_table(c, k, &table, msg, msg_size);
    if (st == CM_OK)
        *out = &table[id - c->regions[k].node_base];
    return st;
}


/* Whether the node of entry i of region cr's open list is still open. */
static bool still_indexed(const cm_cluster_region *cr, uint64_t i)
{
    const uint32_t e = cr->open_local[i];
    if (cr->nodes)
        return is_open(&cr->nodes[e]) && (cr->nodes[e].target & INDEXED_FLAG);
    return cr->open_weight[i] & INDEXED;
}

/* The weight of entry i of region cr's open list, still open: in its
 * record while the node table is in memory, else beside its place. */
static uint64_t listed_weight(const cm_cluster_region *cr, uint64_t i)
{
    return cr->nodes ? weight_of(&cr->nodes[cr->open_local[i]]) : cr->open_weight[i] & ~INDEXED;
}

/* The place of exit e in region cr's open list (in memory), or nopen. */
static uint64_t listed_place(const cm_cluster_region *cr, uint32_t e)
{
    const uint64_t i = cm_first_not_below(cr->open_local, cr->nopen, e);
    return i < cr->nopen && cr->open_local[i] == e ? i : cr->nopen;
}

/* Entries of region cr's open list still open (known while it is paged out). */
static uint64_t live_open(const cm_cluster_region *cr) { return cr->nopen - cr->open_stale; }

/* Region cr's open list with room for cap nodes (at least nopen). */
static cm_status resize_open_list(const cm_cluster *c, cm_cluster_region *cr, uint64_t cap)
{
    const size_t dim = (size_t)c->lat.dim;
    uint32_t *local = realloc(cr->open_local, cap * sizeof *local);
    if (local)
        cr->open_local = local;
    int64_t *cells = local ? realloc(cr->open_cells, cap * dim * sizeof *cells) : NULL;
    if (cells)
        cr->open_cells = cells;
    uint64_t *weight = cells ? realloc(cr->open_weight, cap * sizeof *weight) : NULL;
    if (!weight)
        return CM_ENOMEM;
    cr->open_weight = weight;
    cr->open_cap = cap;
    return CM_OK;
}

/* Drops the nodes of region k's open list that are no longer open, and the
 * room they took. */
static void compact_open_list(cm_cluster *c, cm_cluster_region *cr)
{
    const size_t dim = (size_t)c->lat.dim;
    uint64_t kept = 0;
    for (uint64_t i = 0; i < cr->nopen; i++) {
        if (!still_indexed(cr, i))
            continue;
        cr->open_local[kept] = cr->open_local[i];
        cr->open_weight[kept] = cr->open_weight[i];
        memmove(cr->open_cells + kept * dim, cr->open_cells + i * dim, dim * sizeof *cr->open_cells);
        kept++;
    }
    cr->nopen = kept;
    cr->open_stale = 0;
    if (kept < cr->open_cap / 4) /* a failed shrink keeps the larger room */
        resize_open_list(c, cr, kept > 16 ? kept : 16);
}

/* The weight of open node id (0 if it is not open): from its record, its
 * place in the open list (which must be in memory) or c->open. */
static uint64_t open_weight(const cm_cluster *c, uint32_t id)
{
    const cm_cluster_region *cr = &c->regions[cm_cluster_node_region(c, id)];
    if (cr->nodes)
        return is_open(&cr->nodes[id - cr->node_base]) ? weight_of(&cr->nodes[id - cr->node_base])
                                                        : 0;
    const uint64_t i = listed_place(cr, id - cr->node_base);
    if (i < cr->nopen)
        return cr->open_weight[i] & INDEXED ? cr->open_weight[i] & ~INDEXED : 0;
    const uint64_t *v = cm_idmap_find(&c->open, id);
    return v ? *v & ~INDEXED : 0;
}

void cm_cluster_add_open_weight(cm_cluster *c, uint32_t id, cm_node *nd, uint64_t w)
{
    set_weight(nd, weight_of(nd) + w);
    if (c->keep_exits) /* its open record is to be saved again */
        c->regions[cm_cluster_node_region(c, id)].open_dirty = 1;
}

cm_status cm_cluster_take_open(cm_cluster *c, uint32_t id, cm_node *nd, uint64_t *w)
{
    *w = weight_of(nd);
    set_weight(nd, 0);
    if (!(nd->target & INDEXED_FLAG))
        return CM_OK;
    cm_cluster_region *cr = &c->regions[cm_cluster_node_region(c, id)];
    nd->target = 0;
    cr->open_dirty = 1;
    if (2 * ++cr->open_stale > cr->nopen)
        compact_open_list(c, cr);
    return CM_OK;
}

cm_status cm_cluster_open_nodes(cm_cluster *c, uint32_t k, uint32_t **local, uint64_t **weight,
                                int64_t **cells, uint64_t *n, char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    const size_t dim = (size_t)c->lat.dim;
    cm_status st = open_list(c, k, msg, msg_size); /* a save of every list reads them all */
    if (st != CM_OK)
        return st;
    compact_open_list(c, cr);
    const uint64_t kept = cr->nopen;
    *local = malloc((kept + 1) * sizeof **local);
    *weight = malloc((kept + 1) * sizeof **weight);
    *cells = malloc((kept + 1) * dim * sizeof **cells);
    if (!*local || !*weight || !*cells) {
        free(*local);
        free(*weight);
        free(*cells);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes of region %u",
                       k + 1);
    }
    for (uint64_t i = 0; i < kept; i++) { /* compacted: every entry is open */
        (*local)[i] = cr->open_local[i];
        (*weight)[i] = listed_weight(cr, i);
    }
    if (kept > 0)
        memcpy(*cells, cr->open_cells, kept * dim * sizeof **cells);
    *n = kept;
    return CM_OK;
}

cm_status cm_cluster_add_open(cm_cluster *c, uint32_t id, const int64_t *cell, uint64_t w)
{
    cm_cluster_region *cr = &c->regions[cm_cluster_node_region(c, id)];
    const size_t dim = (size_t)c->lat.dim;
    if (!c->keep_exits) { /* the weight only */
        if (cr->nodes)
            set_weight(&cr->nodes[id - cr->node_base], w);
        return cr->nodes || cm_idmap_put(&c->open, id, w) == CM_OK ? CM_OK : CM_ENOMEM;
    }
    if (cr->nopen == cr->open_cap &&
        resize_open_list(c, cr, cr->open_cap ? 2 * cr->open_cap : 16) != CM_OK)
        return CM_ENOMEM;
    if (cr->nodes) {
        set_weight(&cr->nodes[id - cr->node_base], w);
        cr->nodes[id - cr->node_base].target = INDEXED_FLAG;
    }
    cr->open_weight[cr->nopen] = w | INDEXED; /* back with the table, if it is paged out */
    cr->open_local[cr->nopen] = id - cr->node_base;
    memcpy(cr->open_cells + cr->nopen * dim, cell, dim * sizeof *cell);
    cr->nopen++;
    cr->open_dirty = 1;
    return CM_OK;
}

cm_status cm_cluster_index_escape(cm_cluster *c, uint32_t id, const int64_t *cell)
{
    if (!c->keep_exits) {
        const escape_record e = {id, cm_bricks_offset(c->escape_bricks, cell)};
        return cm_bricks_add(c->escape_bricks, cell, &e);
    }
    const uint32_t k = cm_cluster_node_region(c, id);
    int64_t key[CM_MAX_DIM];
    uint64_t n;
    cm_bricks_of(c->escape_bricks, cell, key);
    const uint32_t *listed = cm_bricks_find(c->escape_bricks, key, &n);
    if (n > 0 && listed[n - 1] == k) /* a region's nodes come in a row */
        return CM_OK;
    return cm_bricks_add(c->escape_bricks, cell, &k);
}

cm_status cm_cluster_add_escape(cm_cluster *c, uint32_t id, const int64_t *cell, uint64_t w)
{
    cm_status st = cm_cluster_index_escape(c, id, cell);
    return st == CM_OK ? cm_cluster_add_open(c, id, cell, w) : st;
}

typedef struct escape_visit {
    const cm_cluster *c;
    cm_escape_fn fn;
    void *user;
} escape_visit;

static void visit_escape(void *user, const int64_t *brick, const void *record)
{
    const escape_visit *v = user;
    const escape_record *e = record;
    int64_t cell[CM_MAX_DIM];
    cm_bricks_cell(v->c->escape_bricks, brick, e->offset, cell);
    v->fn(v->user, e->node, cell, open_weight(v->c, e->node));
}

/* The open nodes of region k's list, read back for the visit if it is out
 * (and let go again after). */
static cm_status visit_open_list(cm_cluster *c, uint32_t k, cm_escape_fn fn, void *user,
                                 char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    const bool was_paged = cr->open_paged;
    cm_status st = open_list(c, k, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < cr->nopen; i++)
        if (still_indexed(cr, i))
            fn(user, cr->node_base + cr->open_local[i], cr->open_cells + i * (uint64_t)c->lat.dim,
               listed_weight(cr, i));
    if (st == CM_OK && was_paged && open_list_evictable(c, cr))
        evict_open_list(cr);
    return st;
}

cm_status cm_cluster_each_escape(cm_cluster *c, cm_escape_fn fn, void *user, char *msg,
                                 size_t msg_size)
{
    if (c->open_released)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's open nodes were released: their exits are not known");
    if (!c->keep_exits) { /* no open lists: the index holds them all */
        escape_visit v = {c, fn, user};
        if (c->escape_bricks)
            cm_bricks_each(c->escape_bricks, visit_escape, &v);
        return CM_OK;
    }
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++)
        st = visit_open_list(c, k, fn, user, msg, msg_size);
    return st;
}

uint64_t cm_cluster_escape_count(const cm_cluster *c)
{
    uint64_t n = 0, records;
    if (c->open_released)
        return 0;
    const uint64_t bricks = c->escape_bricks ? cm_bricks_count(c->escape_bricks) : 0;
    for (uint64_t b = 0; !c->keep_exits && b < bricks; b++) {
        cm_bricks_find(c->escape_bricks, cm_bricks_key(c->escape_bricks, b), &records);
        n += records;
    }
    for (uint32_t k = 0; c->keep_exits && k < c->nregions; k++)
        n += live_open(&c->regions[k]);
    return n;
}

cm_status cm_cluster_open_target(cm_cluster *c, uint32_t id, int64_t *cell, bool *found,
                                 char *msg, size_t msg_size)
{
    const uint32_t k = cm_cluster_node_region(c, id);
    const cm_cluster_region *cr = &c->regions[k];
    *found = false;
    cm_status st = open_list(c, k, msg, msg_size);
    const uint64_t i = st == CM_OK ? listed_place(cr, id - cr->node_base) : cr->nopen;
    if (i < cr->nopen) {
        memcpy(cell, cr->open_cells + i * (uint64_t)c->lat.dim,
               (size_t)c->lat.dim * sizeof *cell);
        *found = true;
    }
    return st;
}

/* Moves the open nodes of brick `key` whose exits lead into box to out,
 * keeping the others in order: records are added in order of node id, so
 * every brick's list stays sorted. */
static cm_status take_from_brick(cm_cluster *c, const int64_t *key, const cm_box *box,
                                 cm_escape **out, uint64_t *n, uint64_t *cap)
{
    uint64_t count, kept = 0;
    escape_record *e = cm_bricks_find(c->escape_bricks, key, &count);
    for (uint64_t i = 0; i < count; i++) {
        int64_t cell[CM_MAX_DIM];
        cm_bricks_cell(c->escape_bricks, key, e[i].offset, cell);
        if (!cm_box_contains(box, cell)) {
            e[kept++] = e[i];
            continue;
        }
        if (cm_grow((void **)out, cap, *n + 1, sizeof **out) != CM_OK)
            return CM_ENOMEM;
        (*out)[(*n)++] = (cm_escape){e[i].node, (uint32_t)cm_box_index(box, cell)};
    }
    if (kept < count)
        cm_bricks_truncate(c->escape_bricks, key, kept);
    return CM_OK;
}

/* Sorts escapes by node id: LSD radix sort, 8 bits a pass. */
static cm_status sort_escapes(cm_escape *e, uint64_t n)
{
    cm_escape *tmp = malloc(n * sizeof *tmp);
    if (!tmp)
        return CM_ENOMEM;
    for (int shift = 0; shift < 32; shift += 8) {
        uint64_t start[257] = {0};
        for (uint64_t i = 0; i < n; i++)
            start[((e[i].node >> shift) & 0xFF) + 1]++;
        if (start[((e[0].node >> shift) & 0xFF) + 1] == n)
            continue; /* one bucket: nothing moves */
        for (int b = 0; b < 256; b++)
            start[b + 1] += start[b];
        for (uint64_t i = 0; i < n; i++)
            tmp[start[(e[i].node >> shift) & 0xFF]++] = e[i];
        memcpy(e, tmp, n * sizeof *e);
    }
    free(tmp);
    return CM_OK;
}

static int region_cmp(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The regions whose open lists lead into the bricks that meet box (every
 * region when it meets very many bricks), ascending, each once. */
static cm_status regions_toward(const cm_cluster *c, const cm_box *box, uint32_t **out,
                                uint64_t *n)
{
    int64_t lo[CM_MAX_DIM], hi[CM_MAX_DIM], key[CM_MAX_DIM];
    uint64_t cap = 0, count;
    *out = NULL;
    *n = 0;
    if (!cm_bricks_span(c->escape_bricks, box, lo, hi)) {
        if (cm_grow((void **)out, &cap, (uint64_t)c->nregions + 1, sizeof **out) != CM_OK)
            return CM_ENOMEM;
        for (uint32_t k = 0; k < c->nregions; k++)
            (*out)[(*n)++] = k;
        return CM_OK;
    }
    memcpy(key, lo, sizeof key);
    do {
        const uint32_t *k = cm_bricks_find(c->escape_bricks, key, &count);
        if (count && cm_grow((void **)out, &cap, *n + count, sizeof **out) != CM_OK)
            return CM_ENOMEM;
        if (count)
            memcpy(*out + *n, k, count * sizeof *k);
        *n += count;
    } while (cm_index_next(c->lat.dim, lo, hi, key));
    if (*n > 1)
        qsort(*out, *n, sizeof **out, region_cmp);
    uint64_t kept = 0;
    for (uint64_t i = 0; i < *n; i++)
        if (kept == 0 || (*out)[kept - 1] != (*out)[i])
            (*out)[kept++] = (*out)[i];
    *n = kept;
    return CM_OK;
}

/* The open nodes of region k's list whose exits lead into box. */
static cm_status take_listed(cm_cluster *c, uint32_t k, const cm_box *box, cm_escape **out,
                             uint64_t *n, uint64_t *cap, char *msg, size_t msg_size)
{
    const cm_cluster_region *cr = &c->regions[k];
    if (live_open(cr) == 0) /* nothing to take: a paged list is not read */
        return CM_OK;
    cm_status st = open_list(c, k, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < cr->nopen; i++) {
        const int64_t *cell = cr->open_cells + i * (uint64_t)c->lat.dim;
        if (!cm_box_contains(box, cell) || !still_indexed(cr, i))
            continue;
        if (cm_grow((void **)out, cap, *n + 1, sizeof **out) != CM_OK)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes");
        (*out)[(*n)++] = (cm_escape){cr->node_base + cr->open_local[i],
                                     (uint32_t)cm_box_index(box, cell)};
    }
    return st;
}

cm_status cm_cluster_take_escapes(cm_cluster *c, const cm_box *box, cm_escape **out, uint64_t *n,
                                  char *msg, size_t msg_size)
{
    int64_t lo[CM_MAX_DIM], hi[CM_MAX_DIM], key[CM_MAX_DIM];
    uint64_t cap = 0;
    cm_status st = CM_OK;
    *out = NULL;
    *n = 0;
    if (c->keep_exits) { /* regions ascending, each list in node order */
        uint32_t *regions;
        uint64_t nregions;
        if (regions_toward(c, box, &regions, &nregions) != CM_OK)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes");
        for (uint64_t i = 0; i < nregions && st == CM_OK; i++)
            st = take_listed(c, regions[i], box, out, n, &cap, msg, msg_size);
        free(regions);
        return st;
    }
    if (cm_bricks_span(c->escape_bricks, box, lo, hi)) {
        memcpy(key, lo, sizeof key);
        do
            st = take_from_brick(c, key, box, out, n, &cap);
        while (st == CM_OK && cm_index_next(c->lat.dim, lo, hi, key));
    } else { /* a box of very many bricks: look at the bricks there are */
        for (uint64_t b = 0; b < cm_bricks_count(c->escape_bricks) && st == CM_OK; b++)
            st = take_from_brick(c, cm_bricks_key(c->escape_bricks, b), box, out, n, &cap);
    }
    if (st == CM_OK && *n > 1)
        st = sort_escapes(*out, *n);
    return st == CM_OK ? CM_OK : cm_fail(st, msg, msg_size, "out of memory for the open nodes");
}

/* ---- resolution ----------------------------------------------------------- */

/* The end of node id's chain of up links: a node whose up is a mark. */
static cm_status chain_end(cm_cluster *c, uint32_t id, uint32_t *end, uint64_t *total, char *msg,
                           size_t msg_size)
{
    cm_node *nd = NULL;
    *total = 0;
    *end = id;
    /* a chain visits each node once at most: more hops mean a loop of links,
     * which only a damaged file holds */
    for (uint64_t hops = 0, y = id; hops <= c->nnodes; hops++, y = nd->up) {
        cm_status st = cm_cluster_node(c, (uint32_t)y, &nd, msg, msg_size);
        if (st != CM_OK)
            return st;
        if (nd->up >= CM_NODE_MAX) {
            *end = (uint32_t)y;
            return CM_OK;
        }
        *total += nd->up_dist;
    }
    return cm_fail(CM_EFORMAT, msg, msg_size, "the links from node %u form a loop", id);
}

static cm_status push_chain(cm_cluster *c, uint64_t *len, uint32_t id)
{
    if (cm_grow((void **)&c->chain, &c->chain_cap, *len + 1, sizeof *c->chain) != CM_OK)
        return CM_ENOMEM;
    c->chain[(*len)++] = id;
    return CM_OK;
}

/* Node id's chain ends on a straddling cycle: the steps of the nodes on its
 * chain of next links, back from a settled node or from the link into the
 * cycle's tree (counted through that tree's cells), become final. */
static cm_status settle(cm_cluster *c, uint32_t id, char *msg, size_t msg_size)
{
    uint64_t len = 0;
    cm_node *nd = NULL;
    cm_status st = CM_OK;
    for (uint32_t x = id; st == CM_OK; x = nd->next) {
        if (len > c->nnodes) /* a loop of links: a damaged file */
            return cm_fail(CM_EFORMAT, msg, msg_size, "the links from node %u form a loop", id);
        st = cm_cluster_node(c, x, &nd, msg, msg_size);
        if (st == CM_OK && (nd->up == CM_NODE_FINAL || nd->next == CM_NODE_CYCLE))
            break;
        if (st == CM_OK && nd->next >= CM_NODE_MAX)
            st = cm_fail(CM_EFORMAT, msg, msg_size, "node %u: a chain of links is broken", x);
        if (st == CM_OK && push_chain(c, &len, x) != CM_OK)
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory settling a chain of links");
    }
    while (st == CM_OK && len > 0) {
        const uint32_t p = c->chain[--len];
        cm_node *np, *nq;
        st = cm_cluster_node(c, p, &np, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_node(c, np->next, &nq, msg, msg_size);
        uint64_t steps = 0;
        if (st == CM_OK && nq->next == CM_NODE_CYCLE) {
            st = cm_cluster_into_cycle(c, np->next, np->target, &steps, msg, msg_size);
        } else if (st == CM_OK) {
            steps = (uint64_t)np->dist + nq->up_dist;
        }
        if (st == CM_OK && steps >= CM_STEP_ON_PATH)
            st = cm_fail(CM_ETOOBIG, msg, msg_size, "a step number overflows");
        if (st == CM_OK) {
            np->up = CM_NODE_FINAL;
            np->up_dist = (uint32_t)steps;
            np->group = nq->group;
        }
    }
    return st;
}

cm_status cm_cluster_resolve(cm_cluster *c, uint32_t id, uint32_t *group, uint32_t *step,
                             uint32_t *open, char *msg, size_t msg_size)
{
    uint32_t y;
    uint64_t total;
    cm_node *end, *nd;
    cm_status st = chain_end(c, id, &y, &total, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_node(c, y, &end, msg, msg_size);
    if (st == CM_OK && end->up == CM_NODE_CYCLE && y != id) {
        st = settle(c, id, msg, msg_size);
        if (st == CM_OK)
            st = chain_end(c, id, &y, &total, msg, msg_size);
        if (st == CM_OK)
            st = cm_cluster_node(c, y, &end, msg, msg_size);
    }
    if (st != CM_OK)
        return st;
    const bool open_end = end->up == CM_NODE_OPEN;
    const uint64_t last = end->up == CM_NODE_FINAL ? end->up_dist
                          : open_end               ? 1 /* an open node's image leaves */
                                                   : 0; /* a cycle node's cell is periodic */
    if (total + last >= CM_STEP_ON_PATH)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "a step number overflows");
    /* every node on the way now points at the end, or is final */
    uint64_t done = 0;
    for (uint32_t x = id; x != y && st == CM_OK;) {
        st = cm_cluster_node(c, x, &nd, msg, msg_size);
        if (st != CM_OK)
            break;
        const uint32_t next = nd->up, d = nd->up_dist;
        if (open_end) {
            nd->up = y;
            nd->up_dist = (uint32_t)(total - done);
        } else {
            nd->up = CM_NODE_FINAL;
            nd->group = end->group;
            nd->up_dist = (uint32_t)(total - done + last);
        }
        done += d;
        x = next;
    }
    *group = open_end ? 0 : end->group;
    *step = (uint32_t)(total + last);
    if (open)
        *open = open_end ? y : CM_NODE_OPEN;
    return st;
}

/* Steps from cell t of region r to a cycle that enters r's tree of a cycle
 * node at cell `entry` (the node's dist) and runs down the tree to the
 * node's cell (0 on it). r must be resident. */
static uint32_t cycle_steps(const cm_region *r, uint32_t entry, uint32_t t)
{
    const uint32_t *image = r->image, *step = r->step;
    uint32_t a = t, b = entry, da = step[a], db = step[b], count = 0;
    /* the cycle runs down the tree from its entry b to the node: t's chain
     * meets it where it meets b's chain */
    for (; da > db; da--, count++)
        a = image[a];
    for (; db > da; db--)
        b = image[b];
    for (; a != b; count++) {
        a = image[a];
        b = image[b];
    }
    return count;
}

cm_status cm_cluster_into_cycle(cm_cluster *c, uint32_t q, uint32_t t, uint64_t *steps,
                                char *msg, size_t msg_size)
{
    const uint32_t k = cm_cluster_node_region(c, q);
    cm_node *nq;
    cm_status st = cm_cluster_node(c, q, &nq, msg, msg_size);
    if (st == CM_OK)
        st = cm_cluster_acquire(c, k, msg, msg_size);
    if (st == CM_OK)
        *steps = 1 + (uint64_t)cycle_steps(&c->regions[k].r, nq->dist, t);
    return st;
}


/* ---- paging ----------------------------------------------------------- */

static int is_resident(const cm_cluster_region *cr) { return cr->r.group != NULL; }

static uint64_t node_table_bytes(const cm_cluster_region *cr)
{
    return cr->nodes ? cr->r.nexits * sizeof *cr->nodes : 0;
}

/* What the budget bounds: bytes of the resident cell arrays (and exit
 * tables), node tables, and open lists that can be paged (open_in). */
typedef struct held {
    uint64_t cells, tables, lists;
} held;

static held resident(const cm_cluster *c)
{
    held h = {0, 0, 0};
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        h.cells += is_resident(cr) ? cm_region_bytes(&cr->r) : 0;
        h.tables += node_table_bytes(cr);
        h.lists += c->open_in ? open_list_bytes(c, cr) : 0;
    }
    return h;
}

uint64_t cm_cluster_resident_bytes(const cm_cluster *c)
{
    const held h = resident(c);
    return h.cells + h.tables + h.lists;
}

uint64_t cm_cluster_bytes(const cm_cluster *c)
{
    uint64_t open_lists = 0; /* those not paged (no open_in) */
    for (uint32_t k = 0; k < c->nregions; k++)
        open_lists += c->open_in ? 0 : open_list_bytes(c, &c->regions[k]);
    return cm_cluster_resident_bytes(c) + open_lists + cm_idmap_bytes(&c->open) +
           c->basin_cap * (sizeof *c->basin + 1) + c->periodic_cap * sizeof *c->new_periodic +
           c->cap * sizeof *c->regions + cm_bricks_bytes(c->region_bricks) +
           cm_bricks_bytes(c->escape_bricks);
}

static void evict_cells(cm_cluster_region *cr)
{
    free(cr->r.image);
    free(cr->r.group);
    free(cr->r.step);
    free(cr->r.exit_target);
    cr->r.image = cr->r.group = cr->r.step = NULL;
    cr->r.exit_target = NULL;
}

/* How soon each region will be needed: the position among the first
 * upcoming boxes (c->upcoming) of the first one next to it (a cell apart at
 * most), where sequences leaving those boxes most likely land; UINT32_MAX
 * if none is. From the brick index: O(boxes looked at). */
#define LOOKAHEAD 4096
typedef struct use_mark {
    uint32_t *use, box;
} use_mark;

static bool mark_use(void *user, uint32_t k)
{
    const use_mark *m = user;
    m->use[k] = m->box; /* boxes go backwards: the first that needs it wins */
    return false;
}

static void next_uses(const cm_cluster *c, uint32_t *use)
{
    for (uint32_t k = 0; k < c->nregions; k++)
        use[k] = UINT32_MAX;
    const uint32_t n = c->nupcoming < LOOKAHEAD ? c->nupcoming : LOOKAHEAD;
    for (uint32_t i = n; i-- > 0;) {
        cm_box near = c->upcoming[i];
        for (int d = 0; d < near.dim; d++) {
            near.lo[d]--;
            near.hi[d]++;
        }
        use_mark m = {use, i};
        find_regions_meeting(c, &near, mark_use, &m);
    }
}

/* Something resident that can be evicted: region k's cells, its node
 * table, or its open list. */
enum { VICTIM_CELLS, VICTIM_TABLE, VICTIM_LIST };
typedef struct victim {
    uint32_t k;
    int kind;
    int unsaved;       /* cells never saved (evicting them saves them first) */
    uint32_t use;      /* next_uses */
    uint64_t last_used;
    uint64_t bytes;
} victim;

/* Saved before unsaved, then those the upcoming boxes need last, then the
 * least recently used; lists and node tables before cells on a tie (they
 * are read back in one piece). */
static int victim_cmp(const void *a, const void *b)
{
    const victim *x = a, *y = b;
    if (x->unsaved != y->unsaved)
        return x->unsaved - y->unsaved;
    if (x->use != y->use)
        return x->use > y->use ? -1 : 1;
    if (x->last_used != y->last_used)
        return x->last_used < y->last_used ? -1 : 1;
    if (x->kind != y->kind)
        return y->kind - x->kind;
    return (x->k > y->k) - (x->k < y->k);
}

/* The candidates for eviction, other than region `keep`'s cells, in the
 * order to evict them: cells (unsaved ones only with_unsaved), and when
 * `tables` (never while a join may hold node pointers) clean node tables
 * and the saved open lists of regions whose tables are out. */
static cm_status victims(const cm_cluster *c, int64_t keep, int with_unsaved, int tables,
                         victim **out, uint64_t *n)
{
    uint32_t *use = malloc(((size_t)c->nregions + 1) * sizeof *use);
    victim *v = malloc(((size_t)2 * c->nregions + 1) * sizeof *v);
    if (!use || !v) {
        free(use);
        free(v);
        return CM_ENOMEM;
    }
    next_uses(c, use);
    *n = 0;
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        if (is_resident(cr) && (int64_t)k != keep && !cr->pinned && (cr->written || with_unsaved))
            v[(*n)++] = (victim){k, VICTIM_CELLS, !cr->written, use[k], cr->last_used,
                                 cm_region_bytes(&cr->r)};
        if (tables && cr->nodes && !cr->nodes_dirty)
            v[(*n)++] = (victim){k, VICTIM_TABLE, 0, use[k], cr->nodes_used, node_table_bytes(cr)};
        else if (tables && open_list_evictable(c, cr) && cr->open_cap > 0)
            v[(*n)++] = (victim){k, VICTIM_LIST, 0, use[k], cr->nodes_used,
                                 open_list_bytes(c, cr)};
    }
    free(use);
    qsort(v, *n, sizeof *v, victim_cmp);
    *out = v;
    return CM_OK;
}

/* Before region cr's node table is evicted: its open nodes' weights and
 * flags beside their places in the open list, and those of open nodes it
 * lacks into c->open (all or none). */
static cm_status spill_open_weights(cm_cluster *c, cm_cluster_region *cr)
{
    for (uint64_t e = 0; e < cr->r.nexits; e++) {
        const cm_node *nd = &cr->nodes[e];
        if (is_open(nd) && !(nd->target & INDEXED_FLAG) &&
            cm_idmap_put(&c->open, cr->node_base + (uint32_t)e, weight_of(nd)) != CM_OK) {
            while (e-- > 0)
                cm_idmap_remove(&c->open, cr->node_base + (uint32_t)e, NULL);
            return CM_ENOMEM;
        }
    }
    for (uint64_t i = 0; i < cr->nopen; i++) {
        const cm_node *nd = &cr->nodes[cr->open_local[i]];
        cr->open_weight[i] = still_indexed(cr, i) ? weight_of(nd) | INDEXED : 0;
    }
    return CM_OK;
}

/* Whether node tables of table_bytes must shrink beside `cells` bytes of
 * cells: beyond their quarter of the budget, unless the cells leave them
 * room (the two within the budget and its quarter). */
static bool tables_over(const cm_cluster *c, uint64_t cells, uint64_t table_bytes)
{
    const uint64_t table_budget = c->mem_budget / 4;
    return table_bytes > table_budget && cells + table_bytes > c->mem_budget + table_budget;
}

/* Evicts until `extra` more bytes of cells fit the budget, and (with
 * `tables`) the node tables fit a quarter of it or the room the cells
 * leave (tables_over) and the open lists that can be paged another quarter
 * (a table goes for its list too; see victims). Region `keep` stays; a
 * region being joined (`joining`, or -1) is not counted. */
static cm_status shed(cm_cluster *c, int64_t keep, int64_t joining, uint64_t extra, int tables,
                      char *msg, size_t msg_size)
{
    if (!c->page_in || c->mem_budget == 0)
        return CM_OK;
    held h = resident(c);
    uint64_t cells = h.cells + extra + c->mem_reserved, table_bytes = h.tables;
    if (joining >= 0 && is_resident(&c->regions[joining]))
        cells -= cm_region_bytes(&c->regions[joining].r);
    tables = tables && (tables_over(c, cells, table_bytes) || h.lists > c->mem_budget / 4);
    if (cells <= c->mem_budget && !tables)
        return CM_OK;
    victim *v = NULL;
    uint64_t n = 0;
    const int with_unsaved = c->page_out != NULL && keep >= 0;
    if (victims(c, keep, with_unsaved, tables, &v, &n) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory choosing what to page out");
    cm_status st = CM_OK;
    for (uint64_t i = 0; i < n && st == CM_OK; i++) {
        cm_cluster_region *cr = &c->regions[v[i].k];
        const bool lists_over = h.lists > c->mem_budget / 4;
        if (v[i].kind == VICTIM_TABLE &&
            (tables_over(c, cells, table_bytes) || (lists_over && open_list_saved(c, cr)))) {
            if (spill_open_weights(c, cr) != CM_OK)
                continue; /* the table stays */
            free(cr->nodes);
            cr->nodes = NULL;
            table_bytes -= v[i].bytes;
            c->evicted_since_trim += v[i].bytes;
        }
        if ((v[i].kind == VICTIM_TABLE || v[i].kind == VICTIM_LIST) && lists_over &&
            open_list_evictable(c, cr)) {
            h.lists -= open_list_bytes(c, cr);
            c->evicted_since_trim += open_list_bytes(c, cr);
            evict_open_list(cr);
        } else if (v[i].kind == VICTIM_CELLS && cells > c->mem_budget) {
            if (!cr->written)
                st = c->page_out(c->pager, c, v[i].k, msg, msg_size);
            if (st != CM_OK)
                break;
            cr->written = 1;
            evict_cells(cr);
            cells -= v[i].bytes;
            c->evicted_since_trim += v[i].bytes;
        }
    }
    free(v);
#ifdef __GLIBC__
    /* evicted arrays leave holes in the heap rather than free memory: give
     * the room back now and then (it costs a walk of the heap) */
    if (c->evicted_since_trim > c->mem_budget / 4) {
        malloc_trim(0);
        c->evicted_since_trim = 0;
    }
#endif
    return st;
}

cm_status cm_cluster_acquire(cm_cluster *c, uint32_t k, char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    cr->last_used = ++c->clock;
    if (is_resident(cr))
        return CM_OK;
    if (!c->page_in)
        return cm_fail(CM_EINVAL, msg, msg_size, "region %u is paged out and there is no pager", k);
    cm_status st = shed(c, k, -1, cm_region_bytes(&cr->r), 0, msg, msg_size);
    if (st == CM_OK)
        st = c->page_in(c->pager, k, &cr->r, msg, msg_size);
    if (st == CM_OK && !is_resident(cr))
        st = cm_fail(CM_EIO, msg, msg_size, "region %u was not read back", k);
    return st;
}

void cm_cluster_trim(cm_cluster *c)
{
    char ignored[64];
    shed(c, -1, -1, 0, 1, ignored, sizeof ignored);
}

void cm_cluster_trim_joining(cm_cluster *c, uint32_t joining)
{
    char ignored[64];
    shed(c, joining, joining, 0, 1, ignored, sizeof ignored);
}

void cm_cluster_saved(cm_cluster *c)
{
    for (uint32_t k = 0; k < c->nregions; k++) {
        cm_cluster_region *cr = &c->regions[k];
        if (cr->nodes_dirty)
            memset(cr->dirty_chunks, 0, cr->r.nexits / CM_NODE_CHUNK + 1);
        cr->written = 1;
        cr->nodes_dirty = cr->open_dirty = 0;
    }
    if (c->basin_dirty)
        memset(c->basin_dirty, 0, (size_t)c->ngroups + 1);
    c->nnew_periodic = 0;
    c->saved_groups = c->ngroups;
}

uint64_t cm_cluster_sink_cells(const cm_cluster *c)
{
    uint64_t in_groups = 0;
    for (uint32_t g = 1; g <= c->ngroups; g++)
        in_groups += c->basin[g];
    return c->cells - in_groups;
}

void cm_cluster_bounds(const cm_cluster *c, cm_box *box)
{
    if (c->nregions == 0) { /* an empty box */
        memset(box, 0, sizeof *box);
        box->dim = c->lat.dim;
        return;
    }
    *box = c->regions[0].r.box;
    for (uint32_t k = 1; k < c->nregions; k++)
        cm_box_grow(box, &c->regions[k].r.box);
}

/* ---- adding regions -------------------------------------------------------- */

static bool take_first(void *user, uint32_t k)
{
    *(int64_t *)user = k;
    return true;
}

/* A region that shares cells with box, or -1. */
static int64_t overlapping_region(const cm_cluster *c, const cm_box *box)
{
    int64_t k = -1;
    find_regions_meeting(c, box, take_first, &k);
    return k;
}

static cm_status check_region(const cm_cluster *c, const cm_box *box, uint64_t nexits,
                              uint32_t ngroups, char *msg, size_t msg_size)
{
    if (box->dim != c->lat.dim)
        return cm_fail(CM_EINVAL, msg, msg_size, "region of %d dimensions, lattice of %d",
                       box->dim, c->lat.dim);
    if (c->nregions == UINT32_MAX - 1)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many regions in one cluster");
    if (c->ngroups > CM_MAX_GROUPS - ngroups)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many periodic groups in one cluster");
    if (c->nnodes + nexits >= CM_NODE_MAX)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many exits in one cluster");
    const int64_t k = overlapping_region(c, box);
    if (k >= 0)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the new region overlaps region %u of the cluster; regions of a "
                       "cluster must not share cells",
                       (unsigned)k);
    return CM_OK;
}

/* Room for a region, its nodes and its groups; the brick maps on the first. */
static cm_status make_space(cm_cluster *c, const cm_box *box, uint32_t ngroups)
{
    if (!c->region_bricks) {
        int shift[CM_MAX_DIM];
        cm_bricks_shift_for(box, shift);
        if (cm_bricks_alloc(c->lat.dim, shift, sizeof(uint32_t), &c->region_bricks) != CM_OK ||
            cm_bricks_alloc(c->lat.dim, shift,
                            c->keep_exits ? sizeof(uint32_t) : sizeof(escape_record),
                            &c->escape_bricks) != CM_OK)
            return CM_ENOMEM;
    }
    const uint64_t groups = (uint64_t)c->ngroups + ngroups + 1, had = c->basin_cap;
    if (cm_grow((void **)&c->regions, &c->cap, c->nregions + 1, sizeof *c->regions) != CM_OK ||
        cm_grow((void **)&c->basin, &c->basin_cap, groups, sizeof *c->basin) != CM_OK)
        return CM_ENOMEM;
    uint8_t *dirty = realloc(c->basin_dirty, c->basin_cap);
    if (!dirty)
        return CM_ENOMEM;
    c->basin_dirty = dirty;
    memset(c->basin + had, 0, (c->basin_cap - had) * sizeof *c->basin);
    memset(c->basin_dirty + had, 0, c->basin_cap - had);
    return CM_OK;
}

cm_status cm_cluster_new_group(cm_cluster *c, uint32_t *g)
{
    if (c->ngroups >= CM_MAX_GROUPS)
        return CM_ETOOBIG;
    if (make_space(c, &c->regions[0].r.box, 1) != CM_OK)
        return CM_ENOMEM;
    *g = ++c->ngroups;
    c->basin[*g] = 0;
    c->basin_dirty[*g] = 1;
    return CM_OK;
}

/* Indexes region k by the bricks it meets (or as a big one). */
static cm_status index_region(cm_cluster *c, uint32_t k)
{
    cm_status st = cm_bricks_add_box(c->region_bricks, &c->regions[k].r.box, &k);
    if (st != CM_ETOOBIG)
        return st;
    if (cm_grow((void **)&c->big, &c->big_cap, c->nbig + 1, sizeof *c->big) != CM_OK)
        return CM_ENOMEM;
    c->big[c->nbig++] = k;
    return CM_OK;
}

/* Region k's node table from its nodes as saved (next, dist, group,
 * target, tree). */
static cm_status init_nodes(cm_cluster *c, cm_cluster_region *cr, const cm_node *saved)
{
    const uint64_t n = cr->r.nexits;
    cr->nodes = calloc(n + 1, sizeof *cr->nodes);
    if (!cr->nodes)
        return CM_ENOMEM;
    for (uint64_t e = 0; e < n; e++) {
        cr->nodes[e] = saved[e];
        start_resolution(&cr->nodes[e]);
    }
    c->nnodes += n;
    return CM_OK;
}

/* A node table of r's exits, every node open, trees not counted. */
static cm_node *open_nodes(const cm_region *r)
{
    /* every record is written below: fresh memory, in huge pages if big */
    cm_node *nodes = cm_cells_array((r->nexits + 1) * sizeof *nodes);
    if (!nodes)
        return NULL;
    memset(&nodes[r->nexits], 0, sizeof *nodes);
    for (uint64_t e = 0; e < r->nexits; e++)
        nodes[e] = (cm_node){.next = CM_NODE_OPEN, .up = CM_NODE_OPEN, .first_in = CM_NODE_OPEN,
                             .sibling = CM_NODE_OPEN};
    return nodes;
}

cm_status cm_region_nodes(const cm_region *r, cm_node **out)
{
    cm_node *nodes = open_nodes(r);
    if (!nodes)
        return CM_ENOMEM;
    for (uint64_t i = 0; i < r->ncells; i++)
        if (cm_is_node_ref(r->group[i]))
            nodes[r->group[i] & ~CM_NODE_REF].tree++;
    for (uint64_t e = 0; e < r->nexits; e++)
        set_weight(&nodes[e], nodes[e].tree); /* open: its own tree leaves */
    *out = nodes;
    return CM_OK;
}

void cm_region_trees(const cm_region *r, uint32_t *tree)
{
    memset(tree, 0, r->nexits * sizeof *tree);
    for (uint64_t i = 0; i < r->ncells; i++)
        if (cm_is_node_ref(r->group[i]))
            tree[r->group[i] & ~CM_NODE_REF]++;
}

cm_status cm_region_nodes_of_trees(const cm_region *r, const uint32_t *tree, cm_node **out)
{
    cm_node *nodes = open_nodes(r);
    if (!nodes)
        return CM_ENOMEM;
    for (uint64_t e = 0; e < r->nexits; e++) {
        nodes[e].tree = tree[e];
        set_weight(&nodes[e], tree[e]);
    }
    *out = nodes;
    return CM_OK;
}

static cm_status note_periodic(cm_cluster *c, uint32_t group, const cm_box *box, uint64_t i)
{
    if (cm_grow((void **)&c->new_periodic, &c->periodic_cap, c->nnew_periodic + 1,
                sizeof *c->new_periodic) != CM_OK)
        return CM_ENOMEM;
    cm_group_cell *pc = &c->new_periodic[c->nnew_periodic++];
    memset(pc, 0, sizeof *pc);
    pc->group = group;
    cm_box_cell(box, i, pc->cell);
    return CM_OK;
}

cm_status cm_cluster_note_periodic(cm_cluster *c, uint32_t g, uint32_t k, uint64_t local)
{
    return note_periodic(c, g, &c->regions[k].r.box, local);
}

/* The new region's own groups take ids from base + 1: one pass that also
 * counts the cells of each group and notes the periodic cells. */
static cm_status take_cells(cm_cluster *c, cm_region *r, uint32_t base)
{
    uint32_t *group = r->group;
    const uint32_t *step = r->step;
    uint64_t *basin = c->basin;
    for (uint64_t i = 0; i < r->ncells; i++) {
        const uint32_t g = group[i];
        if (g != 0 && !cm_is_node_ref(g)) {
            group[i] = g + base;
            basin[g + base]++;
            if (step[i] == 0 && note_periodic(c, g + base, &r->box, i) != CM_OK)
                return CM_ENOMEM;
        }
    }
    for (uint32_t g = 1; g <= r->ngroups; g++)
        c->basin_dirty[base + g] = 1;
    return CM_OK;
}

cm_status cm_cluster_add_region(cm_cluster *c, cm_region *r, cm_node *nodes, char *msg,
                                size_t msg_size)
{
    if (c->open_released) {
        free(nodes);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's open nodes were released (it is only read): no region "
                       "can join it");
    }
    if (!r->exits_recorded) {
        free(nodes);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the region was solved without record_exits; its exits cannot be "
                       "followed into the cluster");
    }
    cm_status st = check_region(c, &r->box, r->nexits, r->ngroups, msg, msg_size);
    if (st == CM_OK && make_space(c, &r->box, r->ngroups) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a region");
    if (st == CM_OK && !nodes && cm_region_nodes(r, &nodes) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the nodes of a region");
    if (st != CM_OK) {
        free(nodes);
        return st;
    }
    const uint32_t k = c->nregions, base = c->ngroups;
    cm_cluster_region *cr = &c->regions[k];
    memset(cr, 0, sizeof *cr);
    cr->node_base = (uint32_t)c->nnodes;
    cr->r.nexits = r->nexits;
    cr->dirty_chunks = calloc(r->nexits / CM_NODE_CHUNK + 1, 1);
    if (!cr->dirty_chunks) {
        free(nodes);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the nodes of a region");
    }
    cr->nodes = nodes;
    memset(cr->dirty_chunks, 1, r->nexits / CM_NODE_CHUNK + 1); /* every chunk is to be saved */
    c->nnodes += r->nexits;
    if (take_cells(c, r, base) != CM_OK) {
        free(cr->nodes);
        free(cr->dirty_chunks);
        c->nnodes -= r->nexits;
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the periodic cells");
    }
    cr->r = *r;
    memset(r, 0, sizeof *r);
    cr->nodes_dirty = 1;
    cr->last_used = ++c->clock;
    c->nregions++;
    c->ngroups += cr->r.ngroups;
    c->cells += cr->r.ncells;
    if (index_region(c, k) != CM_OK || index_nodes(c, k) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the region index");
    return CM_OK;
}

cm_status cm_cluster_restore(cm_cluster *c, const cm_region *record, const cm_node *nodes,
                             char *msg, size_t msg_size)
{
    cm_status st = check_region(c, &record->box, record->nexits, 0, msg, msg_size);
    if (st == CM_OK && make_space(c, &record->box, 0) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a region");
    if (st != CM_OK)
        return st;
    const uint32_t k = c->nregions++;
    cm_cluster_region *cr = &c->regions[k];
    memset(cr, 0, sizeof *cr);
    cr->r.box = record->box;
    cr->r.ncells = record->ncells;
    cr->r.nexits = record->nexits;
    cr->r.ngroups = record->ngroups;
    cr->r.exits_recorded = 1;
    cr->node_base = (uint32_t)c->nnodes;
    cr->written = 1;
    cr->dirty_chunks = calloc(record->nexits / CM_NODE_CHUNK + 1, 1);
    if (!cr->dirty_chunks)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the nodes of a region");
    if (!nodes)
        c->nnodes += record->nexits; /* the table stays in the file until it is used */
    else if (init_nodes(c, cr, nodes) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the nodes of a region");
    c->cells += record->ncells;
    return index_region(c, k) == CM_OK && index_nodes(c, k) == CM_OK
               ? CM_OK
               : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the region index");
}

/* The weights of the open nodes: the trees of the nodes whose chains end there. */
static cm_status weigh_open_nodes(cm_cluster *c, char *msg, size_t msg_size)
{
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        for (uint64_t e = 0; e < cr->r.nexits; e++) {
            uint32_t y;
            uint64_t total;
            cm_node *end;
            cm_status st = chain_end(c, cr->node_base + (uint32_t)e, &y, &total, msg, msg_size);
            if (st == CM_OK)
                st = cm_cluster_node(c, y, &end, msg, msg_size);
            if (st != CM_OK)
                return st;
            if (end->up != CM_NODE_OPEN)
                continue;
            set_weight(end, weight_of(end) + cr->nodes[e].tree);
        }
    }
    return CM_OK;
}

cm_status cm_cluster_restored(cm_cluster *c, uint32_t groups, const uint64_t *basin,
                              int64_t *const *exits, char *msg, size_t msg_size)
{
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_status st =
            cm_cluster_check_nodes(c, k, c->regions[k].nodes, groups, msg, msg_size);
        if (st != CM_OK)
            return st;
    }
    if (make_space(c, &c->regions[0].r.box, groups) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", groups);
    c->ngroups = groups;
    memcpy(c->basin + 1, basin + 1, (size_t)groups * sizeof *basin);
    cm_status st = weigh_open_nodes(c, msg, msg_size);
    if (st != CM_OK)
        return st;
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        for (uint64_t e = 0; e < cr->r.nexits; e++)
            if (cr->nodes[e].next == CM_NODE_OPEN &&
                cm_cluster_add_escape(c, cr->node_base + (uint32_t)e,
                                      exits[k] + e * (uint64_t)c->lat.dim,
                                      open_weight(c, cr->node_base + (uint32_t)e)) !=
                    CM_OK)
                return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the exit index");
    }
    c->saved_groups = groups;
    return CM_OK;
}

cm_status cm_cluster_restored_open(cm_cluster *c, uint32_t groups, const uint64_t *basin,
                                   char *msg, size_t msg_size)
{
    if (make_space(c, &c->regions[0].r.box, groups) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", groups);
    c->ngroups = groups;
    memcpy(c->basin + 1, basin + 1, (size_t)groups * sizeof *basin);
    for (uint32_t k = 0; c->open_in && k < c->nregions; k++)
        c->regions[k].open_paged = 1; /* in the file until used */
    c->saved_groups = groups;
    return CM_OK;
}

cm_status cm_cluster_restored_escapes(cm_cluster *c, const uint32_t *ids, const uint64_t *weights,
                                      const int64_t *cells, uint64_t n, char *msg,
                                      size_t msg_size)
{
    for (uint64_t i = 0; i < n; i++) {
        if (ids[i] >= c->nnodes || (i > 0 && ids[i] <= ids[i - 1]))
            return cm_fail(CM_EFORMAT, msg, msg_size, "the open nodes are damaged (node %u)",
                           ids[i]);
        const int64_t *cell = cells + i * (uint64_t)c->lat.dim;
        cm_status st = CM_OK;
        if (c->open_in) { /* indexed; the list is counted, and read on use */
            st = cm_cluster_index_escape(c, ids[i], cell);
            c->regions[cm_cluster_node_region(c, ids[i])].nopen++;
        } else {
            st = cm_cluster_add_escape(c, ids[i], cell, weights[i]);
        }
        if (st != CM_OK)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes");
    }
    return CM_OK;
}

/* ---- group summaries --------------------------------------------------- */

/* Group first, then box order; unused coordinates are zero, so comparing
 * all CM_MAX_DIM of them is box order in any dimension. */
static int periodic_cell_cmp(const void *a, const void *b)
{
    const cm_group_cell *x = a, *y = b;
    if (x->group != y->group)
        return x->group < y->group ? -1 : 1;
    return cm_cell_less(x->cell, y->cell, CM_MAX_DIM)   ? -1
           : cm_cell_less(y->cell, x->cell, CM_MAX_DIM) ? 1
                                                        : 0;
}

cm_status cm_cluster_describe_new(cm_cluster *c, const cm_model *model, cm_group_info *groups,
                                  char *msg, size_t msg_size)
{
    cm_group_cell *cells = c->new_periodic;
    const uint64_t n = c->nnew_periodic;
    const uint32_t first = c->saved_groups + 1;
    if (n > 1)
        qsort(cells, n, sizeof *cells, periodic_cell_cmp);
    for (uint32_t g = first; g <= c->ngroups; g++) {
        cm_group_info *gi = &groups[g - first];
        memset(gi, 0, sizeof *gi);
        gi->id = g;
        gi->basin_cells = c->basin[g];
        gi->kind = model && model->at_rest ? CM_GROUP_STICKING : CM_GROUP_ATTRACTOR;
    }
    for (uint64_t i = 0; i < n; i++) {
        const uint32_t g = cells[i].group;
        if (g < first || g > c->ngroups)
            return cm_fail(CM_EINVAL, msg, msg_size, "periodic cell of unknown group %u", g);
        cm_group_info *gi = &groups[g - first];
        if (gi->kind == CM_GROUP_STICKING && !cm_cell_at_rest(model, &c->lat, cells[i].cell))
            gi->kind = CM_GROUP_ATTRACTOR;
        cm_group_add_periodic(gi, &c->lat, cells[i].cell);
    }
    for (uint32_t g = first; g <= c->ngroups; g++) {
        if (groups[g - first].period == 0)
            return cm_fail(CM_EINVAL, msg, msg_size, "group %u has no periodic cell", g);
        cm_group_finish(&groups[g - first], c->lat.dim);
    }
    return CM_OK;
}

/* ---- readers ---------------------------------------------------------- */

/* Where region r's cells lie in a flat box `out`: what flat_image needs,
 * worked out once per region (every cell of a view is mapped). */
typedef struct image_map {
    const cm_region *r;
    int dim;
    uint32_t side[CM_MAX_DIM];    /* the region's sides (its cells fit 32 bits) */
    int64_t shift[CM_MAX_DIM];    /* r's lo less out's lo */
    int64_t lo[CM_MAX_DIM];       /* out's lo */
    int64_t out_side[CM_MAX_DIM]; /* out's sides */
} image_map;

static image_map image_map_of(const cm_region *r, const cm_box *out)
{
    image_map im = {.r = r, .dim = out->dim};
    for (int d = 0; d < out->dim; d++) {
        im.side[d] = (uint32_t)(r->box.hi[d] - r->box.lo[d]);
        im.shift[d] = r->box.lo[d] - out->lo[d];
        im.lo[d] = out->lo[d];
        im.out_side[d] = out->hi[d] - out->lo[d];
    }
    return im;
}

/* The index in out of the cell at offsets o[d] from out's lo, or
 * CM_IMAGE_EXIT beyond out. */
static uint32_t out_index(const image_map *im, const int64_t *o)
{
    uint64_t index = 0;
    for (int d = im->dim - 1; d >= 0; d--) {
        if (o[d] < 0 || o[d] >= im->out_side[d])
            return CM_IMAGE_EXIT;
        index = index * (uint64_t)im->out_side[d] + (uint64_t)o[d];
    }
    return (uint32_t)index;
}

/* Image of cell i of the region as an index of out, or CM_IMAGE_EXIT
 * beyond it. */
static uint32_t flat_image(const image_map *im, uint64_t i)
{
    const cm_region *r = im->r;
    const uint32_t v = r->image[i];
    int64_t o[CM_MAX_DIM];
    if (v < r->ncells) {
        uint32_t rest = v; /* 32-bit divisions: a region's cells fit */
        for (int d = 0; d + 1 < im->dim; d++) {
            o[d] = (int64_t)(rest % im->side[d]) + im->shift[d];
            rest /= im->side[d];
        }
        o[im->dim - 1] = (int64_t)rest + im->shift[im->dim - 1];
        return out_index(im, o);
    }
    const int64_t e = cm_image_exit_index(v);
    if (e < 0)
        return CM_IMAGE_SINK;
    if (!r->exit_target)
        return CM_IMAGE_EXIT; /* a cluster that kept no exit table (keep_exits 0) */
    const int64_t *cell = cm_region_exit(r, (uint64_t)e);
    for (int d = 0; d < im->dim; d++)
        o[d] = cell[d] - im->lo[d];
    return out_index(im, o);
}

/* What a region's nodes resolve to, for copying its cells: group and step
 * of each node's cell, and whether it is on a straddling cycle. */
typedef struct node_values {
    const cm_node *nodes; /* the region's; NULL: the region has no node references */
    const uint32_t *group, *step;
    const uint8_t *cycle;
    const uint32_t *open; /* the open node each node's sequence leaves by; NULL: not asked */
} node_values;

/* Group and step of cell i of r. */
static void resolved_cell(const cm_region *r, uint64_t i, const node_values *nv, uint32_t *group,
                          uint32_t *step)
{
    const uint32_t g = r->group[i];
    if (!nv->nodes || !cm_is_node_ref(g)) {
        *group = g;
        *step = r->step[i];
        return;
    }
    const uint32_t e = g & ~CM_NODE_REF;
    *group = nv->group[e];
    *step = nv->cycle[e] ? cycle_steps(r, nv->nodes[e].dist, (uint32_t)i)
                         : nv->step[e] + r->step[i] - 1;
}

/* The open node cell i of r leaves the cluster by (CM_NODE_OPEN: none). */
static uint32_t open_of_cell(const cm_region *r, uint64_t i, const node_values *nv)
{
    const uint32_t g = r->group[i];
    return cm_is_node_ref(g) ? nv->open[g & ~CM_NODE_REF] : CM_NODE_OPEN;
}

/* Copies the cells of region r inside `both` (their intersection) into
 * out (and their open nodes into open, unless NULL), one row along
 * dimension 0 at a time: rows are contiguous in both. */
static void flatten_part(const cm_region *r, const node_values *nv, const cm_box *both,
                         cm_region *out, uint32_t *open, int threads)
{
    const int64_t width = both->hi[0] - both->lo[0];
    const int64_t rows = (int64_t)(cm_box_cells(both) / (uint64_t)width);
    const image_map im = image_map_of(r, &out->box);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t q = 0; q < rows; q++) {
        int64_t cell[CM_MAX_DIM];
        cm_box row = *both;
        row.hi[0] = row.lo[0] + 1;
        cm_box_cell(&row, (uint64_t)q, cell);
        const uint64_t from = cm_box_index(&r->box, cell), to = cm_box_index(&out->box, cell);
        for (int64_t i = 0; i < width; i++) {
            resolved_cell(r, from + (uint64_t)i, nv, &out->group[to + (uint64_t)i],
                          &out->step[to + (uint64_t)i]);
            out->image[to + (uint64_t)i] = flat_image(&im, from + (uint64_t)i);
        }
        for (int64_t i = 0; open && i < width; i++)
            open[to + (uint64_t)i] = nv->nodes ? open_of_cell(r, from + (uint64_t)i, nv)
                                               : CM_NODE_OPEN;
    }
}

cm_status cm_flat_alloc(const cm_box *box, uint32_t ngroups, cm_region *out, char *msg,
                        size_t msg_size)
{
    cm_status st = cm_region_alloc(out, box, msg, msg_size);
    if (st != CM_OK)
        return st;
    out->ngroups = ngroups;
    for (uint64_t i = 0; i < out->ncells; i++) {
        out->image[i] = CM_IMAGE_SINK;
        out->group[i] = CM_GROUP_NONE;
        out->step[i] = 0;
    }
    return CM_OK;
}

void cm_flat_copy(const cm_region *r, cm_region *out)
{
    cm_box both;
    const node_values none = {NULL, NULL, NULL, NULL, NULL};
    if (cm_box_intersect(&r->box, &out->box, &both))
        flatten_part(r, &none, &both, out, NULL, 1);
}

cm_status cm_cluster_cell_end(cm_cluster *c, const int64_t *cell, uint32_t *group,
                              uint32_t *open, char *msg, size_t msg_size)
{
    uint64_t local;
    const int64_t k = cm_cluster_locate(c, cell, &local);
    *group = CM_GROUP_NONE;
    *open = CM_NODE_OPEN;
    if (k < 0)
        return CM_OK;
    cm_status st = cm_cluster_acquire(c, (uint32_t)k, msg, msg_size);
    if (st != CM_OK)
        return st;
    const uint32_t g = c->regions[k].r.group[local];
    if (!cm_is_node_ref(g)) {
        *group = g;
        return CM_OK;
    }
    uint32_t step;
    return cm_cluster_resolve(c, c->regions[k].node_base + (g & ~CM_NODE_REF), group, &step, open,
                              msg, msg_size);
}

cm_status cm_cluster_region_order(const cm_cluster *c, const int64_t *cells, uint64_t n,
                                  uint64_t **order)
{
    const int dim = c->lat.dim;
    uint64_t *start = calloc((size_t)c->nregions + 2, sizeof *start);
    uint32_t *region = malloc(((size_t)n + 1) * sizeof *region);
    *order = malloc(((size_t)n + 1) * sizeof **order);
    if (!start || !region || !*order) {
        free(start);
        free(region);
        free(*order);
        *order = NULL;
        return CM_ENOMEM;
    }
    for (uint64_t i = 0; i < n; i++) {
        uint64_t local;
        const int64_t k = cm_cluster_locate(c, cells + i * (uint64_t)dim, &local);
        region[i] = k < 0 ? c->nregions : (uint32_t)k; /* none: last */
        start[region[i] + 1]++;
    }
    for (uint32_t k = 0; k <= c->nregions; k++)
        start[k + 1] += start[k];
    for (uint64_t i = 0; i < n; i++)
        (*order)[start[region[i]]++] = i;
    free(start);
    free(region);
    return CM_OK;
}

/* The lookups of cm_cluster_cells_group, shedding every `trim_every`
 * lookups (0: never). */
static cm_status cells_group(cm_cluster *c, const int64_t *cells, uint64_t n, uint32_t *group,
                             uint64_t trim_every, char *msg, size_t msg_size)
{
    uint64_t *order = NULL;
    if (cm_cluster_region_order(c, cells, n, &order) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory ordering %llu cells",
                       (unsigned long long)n);
    cm_status st = CM_OK;
    for (uint64_t i = 0; i < n && st == CM_OK; i++) {
        if (trim_every && i % trim_every == trim_every - 1)
            cm_cluster_trim(c); /* between lookups: no node is held */
        uint32_t open;
        const uint64_t j = order[i];
        st = cm_cluster_cell_end(c, cells + j * (uint64_t)c->lat.dim, &group[j], &open, msg,
                                 msg_size);
    }
    free(order);
    return st;
}

cm_status cm_cluster_cells_group(void *cluster, const int64_t *cells, uint64_t n,
                                 uint32_t *group, char *msg, size_t msg_size)
{
    return cells_group(cluster, cells, n, group, 0, msg, msg_size);
}

cm_status cm_cluster_cells_group_shedding(void *cluster, const int64_t *cells, uint64_t n,
                                          uint32_t *group, char *msg, size_t msg_size)
{
    return cells_group(cluster, cells, n, group, 1024, msg, msg_size);
}

/* ---- resolved nodes kept between flattens ----------------------------- */

/* Per-node arrays: what a region's nodes resolve to (a flatten without a
 * cache reuses one set, for the largest region read so far). */
typedef struct node_arrays {
    uint32_t *group, *step, *open;
    uint8_t *cycle;
    uint64_t cap;
} node_arrays;

static void node_arrays_free(node_arrays *a)
{
    free(a->group);
    free(a->step);
    free(a->open);
    free(a->cycle);
    memset(a, 0, sizeof *a);
}

static cm_status node_arrays_room(node_arrays *a, uint64_t n, bool with_open)
{
    if (n <= a->cap)
        return CM_OK;
    node_arrays_free(a);
    a->group = malloc(n * sizeof *a->group);
    a->step = malloc(n * sizeof *a->step);
    a->open = with_open ? malloc(n * sizeof *a->open) : NULL;
    a->cycle = malloc(n);
    a->cap = n;
    return a->group && a->step && a->cycle && (a->open || !with_open) ? CM_OK : CM_ENOMEM;
}

/* What open nodes met by one flatten resolve to now (direct mapped by id;
 * CM_NODE_OPEN, never a node's id, marks a free slot). */
#define ENDS_SEEN 65536

/* A node's outcome now: its group, its cell's step, the open node its
 * chains leave by (itself while it is open); step ON_CYCLE: it is on a
 * straddling cycle. */
typedef struct end_now {
    uint32_t id, group, step, open;
} end_now;
#define ON_CYCLE UINT32_MAX

struct cm_resolve_cache {
    node_arrays *region; /* by region index (cap 0: nothing kept) */
    uint32_t nregions;
    end_now seen[ENDS_SEEN];
};

cm_resolve_cache *cm_resolve_cache_new(void) { return calloc(1, sizeof(cm_resolve_cache)); }

static void cache_empty(cm_resolve_cache *cache)
{
    for (uint32_t k = 0; k < cache->nregions; k++)
        node_arrays_free(&cache->region[k]);
    free(cache->region);
    cache->region = NULL;
    cache->nregions = 0;
}

uint64_t cm_resolve_cache_bytes(const cm_resolve_cache *cache)
{
    if (!cache)
        return 0;
    uint64_t bytes = sizeof *cache + (uint64_t)cache->nregions * sizeof *cache->region;
    for (uint32_t k = 0; k < cache->nregions; k++) /* group, step, open and cycle a node */
        bytes += cache->region[k].cap * (3 * sizeof(uint32_t) + 1);
    return bytes;
}

void cm_resolve_cache_free(cm_resolve_cache *cache)
{
    if (!cache)
        return;
    cache_empty(cache);
    free(cache);
}

/* An entry for every region of c, and no open node remembered. */
static cm_status cache_room(cm_resolve_cache *cache, const cm_cluster *c)
{
    for (uint32_t i = 0; i < ENDS_SEEN; i++)
        cache->seen[i].id = CM_NODE_OPEN;
    if (cache->nregions > c->nregions) /* another cluster */
        cache_empty(cache);
    if (cache->nregions == c->nregions)
        return CM_OK;
    node_arrays *region = realloc(cache->region, (size_t)c->nregions * sizeof *region);
    if (!region)
        return CM_ENOMEM;
    memset(region + cache->nregions, 0, (size_t)(c->nregions - cache->nregions) * sizeof *region);
    cache->region = region;
    cache->nregions = c->nregions;
    return CM_OK;
}

/* What node id, open when its outcomes were kept, resolves to now. */
static cm_status end_of(cm_cluster *c, cm_resolve_cache *cache, uint32_t id, const end_now **out,
                        char *msg, size_t msg_size)
{
    end_now *seen = &cache->seen[(id * UINT32_C(2654435761)) >> 16]; /* 16 bits: ENDS_SEEN */
    *out = seen;
    if (seen->id == id)
        return CM_OK;
    cm_node *nd;
    cm_status st = cm_cluster_node(c, id, &nd, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (is_open(nd)) {
        *seen = (end_now){id, 0, 1, id};
        return CM_OK;
    }
    if (nd->next == CM_NODE_CYCLE) {
        *seen = (end_now){id, 0, ON_CYCLE, CM_NODE_OPEN};
        return CM_OK;
    }
    end_now now = {id, 0, 0, 0};
    st = cm_cluster_resolve(c, id, &now.group, &now.step, &now.open, msg, msg_size);
    if (st == CM_OK)
        *seen = now;
    return st;
}

/* Resolves node e of region k (its table `nodes`) into entry e of the arrays. */
static cm_status resolve_node(cm_cluster *c, uint32_t k, const cm_node *nodes, uint64_t e,
                              uint32_t *group, uint32_t *step, uint8_t *cycle, uint32_t *open,
                              char *msg, size_t msg_size)
{
    cycle[e] = nodes[e].next == CM_NODE_CYCLE;
    return cm_cluster_resolve(c, c->regions[k].node_base + (uint32_t)e, &group[e], &step[e],
                              open ? &open[e] : NULL, msg, msg_size);
}

/* Resolves region k's nodes into the arrays (of the region's nexits; open
 * may be NULL). */
static cm_status resolve_region_nodes(cm_cluster *c, uint32_t k, uint32_t *group, uint32_t *step,
                                      uint8_t *cycle, uint32_t *open, char *msg, size_t msg_size)
{
    cm_node *nodes;
    cm_status st = node_table(c, k, &nodes, msg, msg_size);
    for (uint64_t e = 0; e < c->regions[k].r.nexits && st == CM_OK; e++)
        st = resolve_node(c, k, nodes, e, group, step, cycle, open, msg, msg_size);
    return st;
}

/* Region k's entry of the cache, up to date: resolved afresh when new, else
 * only the nodes whose chains ended on an open node linked since. */
static cm_status kept_nodes(cm_cluster *c, uint32_t k, cm_resolve_cache *cache, char *msg,
                            size_t msg_size)
{
    node_arrays *rn = &cache->region[k];
    const uint64_t n = c->regions[k].r.nexits;
    if (rn->cap == 0) {
        cm_status st = node_arrays_room(rn, n + 1, true) == CM_OK
                           ? resolve_region_nodes(c, k, rn->group, rn->step, rn->cycle, rn->open,
                                                  msg, msg_size)
                           : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory resolving nodes");
        if (st != CM_OK)
            node_arrays_free(rn);
        return st;
    }
    /* A node whose chain ended on open node x (open[e] == x, step[e] the
     * steps to x's cell plus one) now ends where x does, x's step on: the
     * chain to x is fixed. Unless x is on a straddling cycle, and so maybe
     * the node too, whose steps then count differently. */
    cm_node *nodes;
    cm_status st = node_table(c, k, &nodes, msg, msg_size); /* flatten_part reads it too */
    for (uint64_t e = 0; e < n && st == CM_OK; e++) {
        if (rn->open[e] == CM_NODE_OPEN)
            continue; /* a final outcome */
        const end_now *x;
        st = end_of(c, cache, rn->open[e], &x, msg, msg_size);
        if (st != CM_OK || x->open == rn->open[e])
            continue; /* still open */
        const uint64_t step = (uint64_t)rn->step[e] - 1 + x->step;
        if (x->step != ON_CYCLE && step < CM_STEP_ON_PATH) {
            rn->group[e] = x->group;
            rn->step[e] = (uint32_t)step;
            rn->open[e] = x->open;
        } else {
            st = resolve_node(c, k, nodes, e, rn->group, rn->step, rn->cycle, rn->open, msg,
                              msg_size);
        }
    }
    return st;
}

/* cm_cluster_flatten_progress, with the open nodes of the cells into open
 * unless NULL, through cache unless NULL. */
static cm_status flatten(cm_cluster *c, const cm_box *box, cm_region *out, uint32_t *open,
                         cm_resolve_cache *cache, cm_progress_fn progress, void *user, char *msg,
                         size_t msg_size)
{
    const double total = (double)cm_box_cells(box);
    uint64_t done = 0;
    /* Regions are disjoint: when they cover the box, every cell is copied,
     * and filling the arrays first would only write them twice. */
    uint64_t covered = 0;
    for (uint32_t k = 0; k < c->nregions; k++) {
        cm_box both;
        covered += cm_box_intersect(&c->regions[k].r.box, box, &both) ? cm_box_cells(&both) : 0;
    }
    cm_status st = covered == cm_box_cells(box) ? cm_region_alloc(out, box, msg, msg_size)
                                               : cm_flat_alloc(box, c->ngroups, out, msg, msg_size);
    out->ngroups = c->ngroups;
    _Static_assert(CM_NODE_OPEN == UINT32_MAX, "open cells are filled bytewise");
    if (st == CM_OK && open && covered < out->ncells)
        memset(open, 0xFF, (size_t)out->ncells * sizeof *open);
    if (st == CM_OK && cache && cache_room(cache, c) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory resolving nodes");
    node_arrays a;
    memset(&a, 0, sizeof a);
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++) {
        cm_box both;
        if (!cm_box_intersect(&c->regions[k].r.box, box, &both)) {
            if (cache)
                node_arrays_free(&cache->region[k]);
            continue;
        }
        /* nodes first: settling one can read other regions back */
        if (cache) {
            st = kept_nodes(c, k, cache, msg, msg_size);
        } else if (node_arrays_room(&a, c->regions[k].r.nexits + 1, open != NULL) != CM_OK) {
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory resolving nodes");
        } else {
            st = resolve_region_nodes(c, k, a.group, a.step, a.cycle, a.open, msg, msg_size);
        }
        if (st == CM_OK)
            st = cm_cluster_acquire(c, k, msg, msg_size);
        const node_arrays *rn = cache ? &cache->region[k] : &a;
        const node_values nv = {c->regions[k].nodes, rn->group, rn->step, rn->cycle, rn->open};
        if (st == CM_OK)
            flatten_part(&c->regions[k].r, &nv, &both, out, open, cm_cluster_threads(c));
        cm_cluster_trim(c);
        done += cm_box_cells(&both);
        if (st == CM_OK && progress && progress(user, "cells", total > 0 ? done / total : 1))
            st = cm_fail(CM_ECANCELED, msg, msg_size, "interrupted");
    }
    node_arrays_free(&a);
    if (st != CM_OK && cache)
        cache_empty(cache);
    if (st != CM_OK)
        cm_region_free(out);
    return st;
}

cm_status cm_cluster_flatten(cm_cluster *c, const cm_box *box, cm_region *out, char *msg,
                             size_t msg_size)
{
    return flatten(c, box, out, NULL, NULL, NULL, NULL, msg, msg_size);
}

cm_status cm_cluster_flatten_open(cm_cluster *c, const cm_box *box, cm_region *out,
                                  uint32_t *open, char *msg, size_t msg_size)
{
    return flatten(c, box, out, open, NULL, NULL, NULL, msg, msg_size);
}

cm_status cm_cluster_flatten_cached(cm_cluster *c, const cm_box *box, cm_resolve_cache *cache,
                                    cm_region *out, uint32_t *open, char *msg, size_t msg_size)
{
    return flatten(c, box, out, open, cache, NULL, NULL, msg, msg_size);
}

cm_status cm_cluster_flatten_progress(cm_cluster *c, const cm_box *box, cm_region *out,
                                      cm_progress_fn progress, void *user, char *msg,
                                      size_t msg_size)
{
    return flatten(c, box, out, NULL, NULL, progress, user, msg, msg_size);
}
