#include "cellmap/resolve.h"

#include "cellmap/classify.h"
#include "cellmap/grow.h"

#include <string.h>

/* step[] of a sink cell that is being resolved: this flag plus its old step
 * number. Cells without the flag hold final values. */
#define PENDING CM_STEP_ON_PATH
#define NO_NODE UINT32_MAX
#define NO_REGION UINT32_MAX
/* A region with fewer sink cells is resolved on one thread. */
#define PARALLEL_MIN_CELLS 65536

enum node_state {
    NODE_NEW,        /* linked, not yet resolved */
    NODE_ON_WALK,    /* on the current walk; step holds the position */
    NODE_DONE,       /* group and step final */
    NODE_CYCLE,      /* on a cycle across borders: step 0 */
    NODE_CYCLE_BOUND /* leads into such a cycle; step still to count */
};

/* A sink cell whose image leaves its region: the root of a tree of sink cells. */
typedef struct node {
    uint32_t region, cell;
    uint32_t target_region, target_cell; /* where the image lies, or NO_REGION */
    uint32_t next;                       /* the node whose tree the image lies in, or NO_NODE */
    uint32_t dist;                       /* steps from this cell to next's cell */
    uint32_t old_step;                   /* before the join */
    uint32_t group, step;
    uint32_t state; /* enum node_state */
} node;

/* A region's sink cells in order of their old step number. */
typedef struct step_order {
    uint32_t *cells;
    uint32_t *start; /* cells of step s: cells[start[s] .. start[s + 1]) */
    uint64_t nsteps;
} step_order;

typedef struct u32_stack {
    uint32_t *v;
    uint64_t len, cap;
} u32_stack;

/* group[] and step[] of an entry cell after pass 1 */
typedef struct entry_value {
    uint32_t group, step;
} entry_value;

/* A cell of a cycle that crosses region borders, and its new group. */
typedef struct cycle_cell {
    uint32_t region, cell, group;
} cycle_cell;

typedef struct resolver {
    cm_cluster *c;
    const uint8_t *affected;
    int threads;
    int first_pass;        /* pass 1 makes the nodes; pass 2 finds them again */
    step_order order;      /* of the region being ordered */
    entry_value **entries; /* per affected region, of its entries after pass 1 */
    uint32_t *node_base;   /* per affected region, the id of its first node */
    uint64_t *marked_at;   /* per region: read_at + 1 while pass 1's marks stay */
    cycle_cell *cycles;    /* ascending by region and cell once walked */
    uint64_t ncycles, cycles_cap;
    node *nodes;
    uint64_t nnodes, nodes_cap;
    u32_stack walk;  /* nodes of a walk */
    u32_stack chain; /* cells of a chain in one region */
    char *msg;       /* why a region could not be read back or saved */
    size_t msg_size;
} resolver;

/* Makes region k resident. Other regions may be evicted: the resolver
 * holds one region's arrays at a time. */
static cm_status acquire(const resolver *rs, uint32_t k)
{
    return cm_cluster_acquire(rs->c, k, rs->msg, rs->msg_size);
}

/* a + b as a step number, or CM_ETOOBIG */
static cm_status add_steps(uint32_t a, uint32_t b, uint32_t *sum)
{
    if ((uint64_t)a + b >= PENDING)
        return CM_ETOOBIG;
    *sum = a + b;
    return CM_OK;
}

static cm_status push(u32_stack *stack, uint32_t value)
{
    if (cm_grow((void **)&stack->v, &stack->cap, stack->len + 1, sizeof *stack->v) != CM_OK)
        return CM_ENOMEM;
    stack->v[stack->len++] = value;
    return CM_OK;
}

/* The sink cells of one part of a region, counted by step number. */
typedef struct part_count {
    uint32_t *count; /* then the next position in cells[] of each step */
    uint64_t nsteps, cap;
    uint64_t nodes, sink;
    uint32_t node_base; /* id of the part's first node */
    int failed;
} part_count;

/* Counts the part's sink cells by step number and flags them PENDING. */
static void count_part(cm_region *r, uint64_t lo, uint64_t hi, part_count *pc)
{
    const uint32_t *group = r->group, *image = r->image;
    uint32_t *step = r->step;
    const uint64_t n = r->ncells;
    uint64_t nodes = 0, sink = 0;
    for (uint64_t i = lo; i < hi; i++) {
        if (group[i] != 0)
            continue;
        const uint32_t s = step[i];
        if (s >= pc->nsteps && cm_grow_zeroed((void **)&pc->count, &pc->cap, &pc->nsteps,
                                              (uint64_t)s + 1, sizeof *pc->count) != CM_OK) {
            pc->failed = 1;
            break;
        }
        pc->count[s]++;
        step[i] = s | PENDING;
        nodes += image[i] >= n;
        sink++;
    }
    pc->nodes = nodes;
    pc->sink = sink;
}

/* Bucket beginnings for all parts together, in part order within a step
 * (so the order is that of one sequential pass), and node ids per part. */
static cm_status plan_parts(resolver *rs, uint32_t k, step_order *o, part_count *parts, int nparts)
{
    uint64_t nsteps = 0, nodes = rs->first_pass ? rs->nnodes : rs->node_base[k];
    rs->node_base[k] = (uint32_t)nodes;
    for (int t = 0; t < nparts; t++) {
        if (parts[t].failed)
            return CM_ENOMEM;
        nsteps = parts[t].nsteps > nsteps ? parts[t].nsteps : nsteps;
        parts[t].node_base = (uint32_t)nodes;
        nodes += parts[t].nodes;
        if (nodes >= NO_NODE)
            return CM_ETOOBIG;
    }
    for (int t = 0; t < nparts; t++)
        if (cm_grow_zeroed((void **)&parts[t].count, &parts[t].cap, &parts[t].nsteps, nsteps,
                           sizeof *parts[t].count) != CM_OK)
            return CM_ENOMEM;
    o->nsteps = nsteps + 1;
    o->start = malloc(o->nsteps * sizeof *o->start);
    if (!o->start ||
        cm_grow((void **)&rs->nodes, &rs->nodes_cap, nodes, sizeof *rs->nodes) != CM_OK)
        return CM_ENOMEM;
    uint32_t pos = 0;
    for (uint64_t s = 0; s < nsteps; s++) {
        o->start[s] = pos;
        for (int t = 0; t < nparts; t++) {
            const uint32_t count = parts[t].count[s];
            parts[t].count[s] = pos;
            pos += count;
        }
    }
    o->start[nsteps] = pos;
    if (rs->first_pass)
        rs->nnodes = nodes;
    o->cells = malloc(((uint64_t)pos + 1) * sizeof *o->cells);
    return o->cells ? CM_OK : CM_ENOMEM;
}

/* Puts the part's sink cells in step order and gives each one whose image
 * leaves the region its node id in group[]; pass 1 makes these nodes. Ids
 * follow cell order whatever the parts, so pass 2 finds the same ones. */
static void place_part(const resolver *rs, uint32_t k, uint64_t lo, uint64_t hi, part_count *pc)
{
    cm_region *r = &rs->c->regions[k].r;
    uint32_t *cells = rs->order.cells, hint = k;
    for (uint64_t i = lo; i < hi; i++) {
        const uint32_t s = r->step[i];
        if (!(s & PENDING))
            continue;
        cells[pc->count[s & ~PENDING]++] = (uint32_t)i;
        if (r->image[i] >= r->ncells) {
            const uint32_t id = pc->node_base++;
            r->group[i] = id;
            if (!rs->first_pass)
                continue;
            const int64_t e = cm_image_exit_index(r->image[i]);
            uint64_t local = 0;
            const int64_t t =
                e < 0 ? -1
                      : cm_cluster_locate(rs->c, cm_region_exit(r, (uint64_t)e), &hint, &local);
            rs->nodes[id] = (node){k,
                                   (uint32_t)i,
                                   t < 0 ? NO_REGION : (uint32_t)t,
                                   (uint32_t)local,
                                   NO_NODE,
                                   0,
                                   s & ~PENDING,
                                   0,
                                   0,
                                   NODE_NEW};
        }
    }
}

/* Region k's sink cells sorted by old step number (a counting sort over
 * parts of the region in parallel). */
static cm_status order_region(resolver *rs, uint32_t k, uint64_t *nsink)
{
    cm_region *r = &rs->c->regions[k].r;
    const int nparts = r->ncells >= PARALLEL_MIN_CELLS ? rs->threads : 1;
    part_count *parts = calloc((size_t)nparts, sizeof *parts);
    if (!parts)
        return CM_ENOMEM;
#define PART_LO(t) (r->ncells * (uint64_t)(t) / (uint64_t)nparts)
#pragma omp parallel for schedule(static, 1) num_threads(nparts)
    for (int t = 0; t < nparts; t++)
        count_part(r, PART_LO(t), PART_LO(t + 1), &parts[t]);
    cm_status st = plan_parts(rs, k, &rs->order, parts, nparts);
    if (st == CM_OK) {
#pragma omp parallel for schedule(static, 1) num_threads(nparts)
        for (int t = 0; t < nparts; t++)
            place_part(rs, k, PART_LO(t), PART_LO(t + 1), &parts[t]);
    }
#undef PART_LO
    *nsink = 0;
    for (int t = 0; t < nparts; t++) {
        *nsink += parts[t].sink;
        free(parts[t].count);
    }
    free(parts);
    return st;
}

/* The root pass reads the image of each cell of a step and then the
 * image's group: independent cache misses, fetched this many cells ahead
 * (the image entry twice as far ahead) so that they overlap. */
#define AHEAD 16

/* Pass 1: every sink cell takes the node at the root of its tree. */
static void propagate_roots(const resolver *rs, uint32_t k)
{
    cm_region *r = &rs->c->regions[k].r;
    const step_order *o = &rs->order;
    const uint32_t *image = r->image, *cells = o->cells;
    uint32_t *group = r->group;
    const uint32_t n = (uint32_t)r->ncells;
#pragma omp parallel num_threads(rs->threads) if (o->start[o->nsteps - 1] >= PARALLEL_MIN_CELLS)
    for (uint64_t s = 0; s + 1 < o->nsteps; s++) {
        const int64_t end = o->start[s + 1];
#pragma omp for schedule(static)
        for (int64_t p = o->start[s]; p < end; p++) {
            if (p + 2 * AHEAD < end)
                __builtin_prefetch(&image[cells[p + 2 * AHEAD]]);
            if (p + AHEAD < end && image[cells[p + AHEAD]] < n)
                __builtin_prefetch(&group[image[cells[p + AHEAD]]]);
            const uint32_t i = cells[p], j = image[i];
            if (j < n)
                group[i] = group[j];
        }
    }
}

/* Where node id's exit leads, given the group and step of the cell it
 * leads to: a final value, or the tree of another node. */
static cm_status link_node(const resolver *rs, uint32_t id, uint32_t group, uint32_t step)
{
    node *nd = &rs->nodes[id];
    if (!(step & PENDING)) { /* a classified cell, or a sink cell that stays */
        nd->state = NODE_DONE;
        nd->group = group;
        return add_steps(step, 1, &nd->step);
    }
    /* In a tree without cycle cells, the chain from the target to the root
     * is as long as the difference of their old step numbers. */
    nd->next = group;
    nd->dist = 1 + (step & ~PENDING) - rs->nodes[group].old_step;
    return CM_OK;
}

/* Whether region k still holds pass 1's marks. */
static int has_marks(const resolver *rs, uint32_t k)
{
    const cm_cluster_region *cr = &rs->c->regions[k];
    return cr->r.group && rs->marked_at[k] == cr->read_at + 1;
}

/* Links the nodes whose exits lead into region k: an affected region's
 * entries were noted in pass 1 (or still hold pass 1's values), any other
 * region is read. */
static cm_status link_into(const resolver *rs, uint32_t k, const uint32_t *ids, uint64_t n)
{
    const cm_cluster_region *cr = &rs->c->regions[k];
    /* A region that keeps pass 1's marks holds the noted values itself */
    const entry_value *noted = rs->affected[k] && !has_marks(rs, k) ? rs->entries[k] : NULL;
    cm_status st =
        noted || rs->affected[k] ? CM_OK : cm_cluster_acquire(rs->c, k, rs->msg, rs->msg_size);
    if (st != CM_OK)
        return st;
    int failed = 0; /* 1: a step number overflow */
#pragma omp parallel for schedule(static)                                                          \
    num_threads(rs->threads) if (n >= PARALLEL_MIN_CELLS / 4) reduction(|                          \
                                                                        : failed)
    for (int64_t p = 0; p < (int64_t)n; p++) {
        const uint32_t cell = rs->nodes[ids[p]].target_cell;
        if (noted) {
            const int64_t e = cm_cluster_entry(cr, cell);
            if (e < 0) { /* cannot happen: every exit's cell is an entry */
                failed |= 2;
                continue;
            }
            const entry_value v = noted[e];
            failed |= link_node(rs, ids[p], v.group, v.step) != CM_OK;
        } else {
            failed |= link_node(rs, ids[p], cr->r.group[cell], cr->r.step[cell]) != CM_OK;
        }
    }
    return failed & 2 ? CM_EINVAL : failed ? CM_ETOOBIG : CM_OK;
}

/* Links every node, grouped by the region its exit leads into, from the
 * last region to the first: pass 1 went the other way, so the regions it
 * read last are still resident. */
static cm_status link_nodes(resolver *rs)
{
    const uint32_t nregions = rs->c->nregions;
    uint64_t *start = calloc((size_t)nregions + 2, sizeof *start);
    uint32_t *ids = malloc((rs->nnodes + 1) * sizeof *ids);
    if (!start || !ids) {
        free(start);
        free(ids);
        return CM_ENOMEM;
    }
    for (uint64_t id = 0; id < rs->nnodes; id++) {
        node *nd = &rs->nodes[id];
        if (nd->target_region == NO_REGION) {
            nd->state = NODE_DONE; /* the sequence leaves the cluster (or the world) */
            nd->step = 1;
        } else {
            start[nd->target_region + 1]++;
        }
    }
    for (uint32_t k = 0; k < nregions; k++)
        start[k + 1] += start[k];
    for (uint64_t id = 0; id < rs->nnodes; id++)
        if (rs->nodes[id].target_region != NO_REGION)
            ids[start[rs->nodes[id].target_region]++] = (uint32_t)id;
    /* start[k] is now the end of region k's nodes */
    cm_status st = CM_OK;
    for (uint32_t k = nregions; st == CM_OK && k-- > 0;) {
        const uint64_t first = k ? start[k - 1] : 0;
        if (start[k] > first)
            st = link_into(rs, k, ids + first, start[k] - first);
    }
    free(start);
    free(ids);
    return st;
}

/* The cell after `at`, following exits into the cluster (at is on a cycle). */
static void next_cell(const cm_cluster *c, uint32_t *region, uint32_t *cell, uint32_t *hint)
{
    const cm_region *r = &c->regions[*region].r;
    const uint32_t v = r->image[*cell];
    if (v < r->ncells) {
        *cell = v;
        return;
    }
    uint64_t local;
    const int64_t e = cm_image_exit_index(v);
    *region = (uint32_t)cm_cluster_locate(c, cm_region_exit(r, (uint64_t)e), hint, &local);
    *cell = (uint32_t)local;
}

/* Notes the cells of the cycle through node `start` for group g; pass 2
 * gives them group g and step 0 (the regions stay as they are till then). */
static cm_status note_cycle(resolver *rs, uint32_t start, uint32_t g)
{
    const node *nd = &rs->nodes[start];
    uint32_t region = nd->region, cell = nd->cell, hint = region;
    do {
        cm_status st = cm_cluster_acquire(rs->c, region, rs->msg, rs->msg_size);
        if (st == CM_OK && cm_grow((void **)&rs->cycles, &rs->cycles_cap, rs->ncycles + 1,
                                   sizeof *rs->cycles) != CM_OK)
            st = CM_ENOMEM;
        if (st != CM_OK)
            return st;
        rs->cycles[rs->ncycles++] = (cycle_cell){region, cell, g};
        next_cell(rs->c, &region, &cell, &hint);
    } while (region != nd->region || cell != nd->cell);
    return CM_OK;
}

/* The walk on the stack ended at node x: a cycle (new group) if x is on it. */
static cm_status close_walk(resolver *rs, uint32_t x, cm_join_stats *stats)
{
    const uint32_t *walk = rs->walk.v;
    uint64_t len = rs->walk.len;
    if (rs->nodes[x].state == NODE_ON_WALK) {
        if (rs->c->ngroups == CM_MAX_GROUPS)
            return CM_ETOOBIG;
        const uint32_t g = ++rs->c->ngroups;
        stats->straddling_groups++;
        const uint64_t from = rs->nodes[x].step;
        for (uint64_t p = from; p < len; p++) {
            node *y = &rs->nodes[walk[p]];
            y->group = g;
            y->step = 0;
            y->state = NODE_CYCLE;
        }
        cm_status st = note_cycle(rs, x, g);
        if (st != CM_OK)
            return st;
        len = from;
    }
    for (uint64_t p = len; p-- > 0;) {
        node *y = &rs->nodes[walk[p]];
        const node *next = &rs->nodes[y->next];
        y->group = next->group;
        y->state = next->state == NODE_DONE ? NODE_DONE : NODE_CYCLE_BOUND;
        if (y->state == NODE_DONE && add_steps(next->step, y->dist, &y->step) != CM_OK)
            return CM_ETOOBIG;
    }
    return CM_OK;
}

/* Walks the graph of nodes in id order: each walk ends at a resolved node or
 * closes a cycle across region borders. */
static cm_status walk_nodes(resolver *rs, cm_join_stats *stats)
{
    for (uint64_t first = 0; first < rs->nnodes; first++) {
        rs->walk.len = 0;
        uint32_t x = (uint32_t)first;
        while (rs->nodes[x].state == NODE_NEW) {
            rs->nodes[x].state = NODE_ON_WALK;
            rs->nodes[x].step = (uint32_t)rs->walk.len;
            if (push(&rs->walk, x) != CM_OK)
                return CM_ENOMEM;
            x = rs->nodes[x].next;
        }
        if (rs->walk.len > 0) {
            cm_status st = close_walk(rs, x, stats);
            if (st != CM_OK)
                return st;
        }
    }
    return CM_OK;
}

/* Steps from `cell` of region k, in the tree of a cycle node, to the cycle;
 * the cells of the chain on the way are resolved too. */
static cm_status steps_to_cycle(resolver *rs, uint32_t k, uint32_t cell, uint32_t *steps)
{
    cm_region *r = &rs->c->regions[k].r; /* resident in pass 2 */
    rs->chain.len = 0;
    while (r->step[cell] & PENDING) {
        if (push(&rs->chain, cell) != CM_OK)
            return CM_ENOMEM;
        cell = r->image[cell]; /* stays in the region up to the cycle node */
    }
    const uint32_t g = r->group[cell];
    uint32_t s = r->step[cell];
    for (uint64_t p = rs->chain.len; p-- > 0;) {
        if (add_steps(s, 1, &s) != CM_OK)
            return CM_ETOOBIG;
        r->group[rs->chain.v[p]] = g;
        r->step[rs->chain.v[p]] = s;
    }
    *steps = s;
    return CM_OK;
}

static int cycle_cell_cmp(const void *a, const void *b)
{
    const cycle_cell *x = a, *y = b;
    if (x->region != y->region)
        return x->region < y->region ? -1 : 1;
    return (x->cell > y->cell) - (x->cell < y->cell);
}

static int on_cycle(const resolver *rs, uint32_t region, uint32_t cell)
{
    const cycle_cell key = {region, cell, 0};
    return bsearch(&key, rs->cycles, rs->ncycles, sizeof key, cycle_cell_cmp) != NULL;
}

/* Step number of node nd, whose exit leads into the tree of a cycle node:
 * there the chain can meet the cycle before the root, so it is walked
 * (reading only: pass 2 gives the chain's cells their steps). */
static cm_status cycle_entry_step(resolver *rs, const node *nd, uint32_t *step)
{
    uint32_t region = nd->region, cell = nd->cell, hint = region, steps = 1;
    cm_status st = acquire(rs, region);
    if (st != CM_OK)
        return st;
    next_cell(rs->c, &region, &cell, &hint);
    st = acquire(rs, region);
    const cm_region *r = &rs->c->regions[region].r;
    while (st == CM_OK && !on_cycle(rs, region, cell)) {
        if (r->image[cell] >= r->ncells) /* the tree's root is on the cycle */
            return CM_EINVAL;
        cell = r->image[cell];
        st = add_steps(steps, 1, &steps);
    }
    *step = steps;
    return st;
}

/* Counts the steps of the nodes that lead into cycles, chain by chain from
 * the node nearest the cycle. */
static cm_status count_cycle_bound(resolver *rs)
{
    for (uint64_t id = 0; id < rs->nnodes; id++) {
        rs->walk.len = 0;
        for (uint32_t x = (uint32_t)id; rs->nodes[x].state == NODE_CYCLE_BOUND;
             x = rs->nodes[x].next)
            if (push(&rs->walk, x) != CM_OK)
                return CM_ENOMEM;
        for (uint64_t p = rs->walk.len; p-- > 0;) {
            node *nd = &rs->nodes[rs->walk.v[p]];
            const node *next = &rs->nodes[nd->next];
            cm_status st = next->state == NODE_CYCLE ? cycle_entry_step(rs, nd, &nd->step)
                                                     : add_steps(next->step, nd->dist, &nd->step);
            if (st != CM_OK)
                return st;
            nd->state = NODE_DONE;
        }
    }
    return CM_OK;
}

/* Pass 2: every pending cell outside the trees of cycle nodes takes its
 * root node's group, and its step number moves as the root's did. Returns
 * the number of cells left pending. */
static uint64_t assign_region(const resolver *rs, uint32_t k, int *overflow)
{
    cm_region *r = &rs->c->regions[k].r;
    uint32_t *group = r->group, *step = r->step;
    const node *nodes = rs->nodes;
    uint64_t left = 0;
    int over = 0;
#pragma omp parallel for schedule(static) num_threads(rs->threads) \
    if (r->ncells >= PARALLEL_MIN_CELLS) reduction(+ : left) reduction(| : over)
    for (int64_t i = 0; i < (int64_t)r->ncells; i++) {
        if (!(step[i] & PENDING))
            continue;
        const node *nd = &nodes[group[i]];
        if (nd->state == NODE_CYCLE) {
            left++;
            continue;
        }
        const uint64_t s = (uint64_t)(step[i] & ~PENDING) - nd->old_step + nd->step;
        over |= s >= PENDING;
        group[i] = nd->group;
        step[i] = (uint32_t)s;
    }
    *overflow |= over;
    return left;
}

/* The cells left in the trees of cycle nodes: their chains can meet the
 * cycle before the root, so they are walked (these trees are small). */
static cm_status assign_cycle_trees(resolver *rs, uint32_t k)
{
    const cm_region *r = &rs->c->regions[k].r; /* resident: steps_to_cycle stays in k */
    uint32_t steps;
    for (uint64_t i = 0; i < r->ncells; i++)
        if (r->step[i] & PENDING) {
            cm_status st = steps_to_cycle(rs, k, (uint32_t)i, &steps);
            if (st != CM_OK)
                return st;
        }
    return CM_OK;
}

/* What the links into region k need after pass 1: group and step of its
 * entries, so that linking does not read k again. */
static cm_status note_entries(resolver *rs, uint32_t k)
{
    const cm_cluster_region *cr = &rs->c->regions[k];
    entry_value *v = malloc((cr->nentries + 1) * sizeof *v);
    if (!v)
        return CM_ENOMEM;
    for (uint64_t e = 0; e < cr->nentries; e++)
        v[e] = (entry_value){cr->r.group[cr->entries[e]], cr->r.step[cr->entries[e]]};
    rs->entries[k] = v;
    return CM_OK;
}

/* Undoes pass 1's marks on region k (root ids in group[], PENDING in
 * step[]). */
static void unmark(const resolver *rs, uint32_t k)
{
    cm_region *r = &rs->c->regions[k].r;
    uint32_t *group = r->group, *step = r->step;
#pragma omp parallel for schedule(static)                                                          \
    num_threads(rs->threads) if (r->ncells >= PARALLEL_MIN_CELLS)
    for (int64_t i = 0; i < (int64_t)r->ncells; i++)
        if (step[i] & PENDING) {
            group[i] = 0;
            step[i] &= ~PENDING;
        }
}

/* Each sink cell of region k learns its root node (both passes). */
static cm_status find_roots(resolver *rs, uint32_t k, uint64_t *nsink)
{
    cm_status st = order_region(rs, k, nsink);
    if (st == CM_OK)
        propagate_roots(rs, k);
    free(rs->order.cells);
    free(rs->order.start);
    memset(&rs->order, 0, sizeof rs->order);
    return st;
}

/* Pass 1 on region k: its nodes and where the links into it lead. */
static cm_status root_pass(resolver *rs, uint32_t k, cm_join_stats *stats)
{
    uint64_t nsink = 0;
    cm_status st = acquire(rs, k);
    if (st == CM_OK)
        st = find_roots(rs, k, &nsink);
    if (st == CM_OK)
        st = note_entries(rs, k);
    /* A clean region keeps the marks for pass 2 while it stays resident:
     * evicted, it is read back as saved. A dirty one is left as it was, so
     * that evicting it never saves the marks. */
    const cm_cluster_region *cr = &rs->c->regions[k];
    if (st == CM_OK && cr->dirty && rs->c->page_out && rs->c->mem_budget)
        unmark(rs, k);
    else if (st == CM_OK)
        rs->marked_at[k] = cr->read_at + 1;
    stats->resolved_cells += nsink;
    return st;
}

/* Gives region k's cells of cross-border cycles their group and step 0. */
static void mark_cycles(const resolver *rs, uint32_t k)
{
    cm_region *r = &rs->c->regions[k].r;
    const cycle_cell key = {k, 0, 0};
    uint64_t lo = 0, hi = rs->ncycles; /* the first of region k */
    while (lo < hi) {
        const uint64_t mid = lo + (hi - lo) / 2;
        if (cycle_cell_cmp(&rs->cycles[mid], &key) < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (uint64_t p = lo; p < rs->ncycles && rs->cycles[p].region == k; p++) {
        r->group[rs->cycles[p].cell] = rs->cycles[p].group;
        r->step[rs->cycles[p].cell] = 0;
    }
}

/* Sets region k's links for the next joins from its nodes (the sink cells
 * whose images leave it, in cell order): the regions their exits lead into,
 * for those still in the sink's domain. */
static cm_status relink(const resolver *rs, uint32_t k)
{
    cm_status st = CM_OK;
    rs->c->regions[k].ntargets = 0;
    for (uint64_t id = rs->node_base[k]; id < rs->nnodes && rs->nodes[id].region == k; id++) {
        const node *nd = &rs->nodes[id];
        if (st == CM_OK && nd->group == 0 && nd->target_region != NO_REGION)
            st = cm_cluster_add_target(rs->c, k, nd->target_region);
    }
    return st;
}

/* Pass 2 on region k: final groups and steps, and its links for the next
 * joins. */
static cm_status assign_pass(resolver *rs, uint32_t k)
{
    uint64_t nsink = 0;
    int overflow = 0;
    const int marked = has_marks(rs, k);
    cm_status st = acquire(rs, k);
    rs->c->regions[k].dirty = 1;
    if (st == CM_OK && !marked)
        st = find_roots(rs, k, &nsink);
    if (st == CM_OK) {
        mark_cycles(rs, k);
        if (assign_region(rs, k, &overflow) > 0)
            st = assign_cycle_trees(rs, k);
    }
    if (st == CM_OK && overflow)
        st = CM_ETOOBIG;
    return st == CM_OK ? relink(rs, k) : st;
}

/* The regions pass 2 must change: those with a node whose sequence no
 * longer leaves the cluster, or leaves it in another number of steps (the
 * other regions' sink cells stay as they are), and the new region, whose
 * links it sets. */
static void mark_changed(const resolver *rs, uint8_t *changed)
{
    for (uint64_t id = 0; id < rs->nnodes; id++) {
        const node *nd = &rs->nodes[id];
        changed[nd->region] |= nd->group != 0 || nd->step != nd->old_step;
    }
    const uint32_t added = rs->c->nregions - 1;
    changed[added] |= rs->affected[added];
}

static cm_status resolve(resolver *rs, cm_join_stats *stats)
{
    const uint32_t nregions = rs->c->nregions;
    cm_status st = CM_OK;
    rs->first_pass = 1;
    for (uint32_t k = 0; k < nregions && st == CM_OK; k++)
        if (rs->affected[k])
            st = root_pass(rs, k, stats);
    rs->first_pass = 0;
    stats->nodes = rs->nnodes;
    if (st == CM_OK)
        st = link_nodes(rs);
    if (st == CM_OK)
        st = walk_nodes(rs, stats);
    if (st == CM_OK && rs->ncycles)
        qsort(rs->cycles, rs->ncycles, sizeof *rs->cycles, cycle_cell_cmp);
    if (st == CM_OK)
        st = count_cycle_bound(rs);
    uint8_t *changed = st == CM_OK ? calloc(nregions, 1) : NULL;
    if (st == CM_OK && !changed)
        st = CM_ENOMEM;
    if (st == CM_OK)
        mark_changed(rs, changed);
    /* the regions read last in linking are resident: assign from there */
    for (uint32_t k = nregions; k-- > 0 && st == CM_OK;)
        if (changed[k])
            st = assign_pass(rs, k);
        else if (rs->affected[k] && has_marks(rs, k))
            unmark(rs, k);
    free(changed);
    return st;
}

cm_status cm_resolve_sink_cells(cm_cluster *c, const uint8_t *affected, cm_join_stats *stats,
                                char *msg, size_t msg_size)
{
    resolver rs = {.c = c, .affected = affected, .threads = cm_cluster_threads(c)};
    rs.msg = msg;
    rs.msg_size = msg_size;
    rs.entries = calloc(c->nregions, sizeof *rs.entries);
    rs.node_base = calloc(c->nregions, sizeof *rs.node_base);
    rs.marked_at = calloc(c->nregions, sizeof *rs.marked_at);
    const cm_status st =
        rs.entries && rs.node_base && rs.marked_at ? resolve(&rs, stats) : CM_ENOMEM;
    for (uint32_t k = 0; rs.entries && k < c->nregions; k++)
        free(rs.entries[k]);
    free(rs.entries);
    free(rs.node_base);
    free(rs.marked_at);
    free(rs.cycles);
    free(rs.order.cells);
    free(rs.order.start);
    free(rs.nodes);
    free(rs.walk.v);
    free(rs.chain.v);
    return st;
}
