/* cellmap/classify.c - classification of a region's functional graph
 * (image[]) into periodic groups, their domains and step numbers.
 *
 * Each cell has one image, so the graph is a set of trees hanging on cycles
 * (or on the sink). The classic algorithm walks from every unvisited cell
 * until it meets the sink, a classified cell or its own path, then labels the
 * path. That walk is a chain of dependent memory loads: one cache miss per
 * cell, about 20 ns on large regions. Here LANES walks run interleaved, one
 * step each in turn, and each prefetches the cell it enters next, so the
 * misses of different walks overlap. Most walks would end after their first
 * cell; the scan for unvisited cells labels those itself.
 *
 * Walks can meet. A walk that enters a cell on another walk's path waits
 * until that walk is done. If the walk it waits for (directly or through a
 * chain of waiting walks) comes back to the waiting walk, the paths close a
 * cycle together; the walk that discovers this takes over the other
 * walk's path from the meeting cell on and goes on until the cycle closes on
 * its own path. Because every walk only ever labels a path whose forward orbit is
 * fully known, the result equals the sequential algorithm's: group ids are
 * finally renumbered in order of the lowest local index in each domain,
 * which is exactly the order in which a sequential scan discovers them.
 *
 * With threads, the cells are cut into one block of indices per thread
 * (cm_classify_threads): each thread walks its block as above, and a path
 * that runs into another block stops at the block's edge, pending, its cells
 * keeping the last cell before the edge (the block's *exit*) and their
 * distance to it. One thread then follows the exits from block to block:
 * to a classified cell (each exit takes that cell's group and step), or
 * back to an exit of the same chain (a cycle through several blocks, whose
 * cells it marks periodic). Each thread finally settles its pending cells
 * from their exits; those whose exit lies on such a cycle are walked again,
 * since their step counts to where they meet the cycle. Groups are
 * renumbered as above, so the result is the sequential one, whatever the
 * number of threads.
 */
#include "cellmap/classify.h"

#include "cellmap/grow.h"

#include <stdbool.h>
#include <stdlib.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* step[] holds each cell's state (classify.h); while a cell is on a walk's
 * path, group[] holds LANE_MARK + the walk's lane, above every group id. */
#define LANE_MARK UINT32_C(0xFFFFFF00)
/* Enough walks in flight to overlap memory latency, few enough that their
 * path buffers stay in cache (16 against 8: 5-15 % faster on the lattices
 * of bench_scm). */
#define LANES 16
/* Paths up to this length are remembered; labelling a longer one follows
 * image[] from the last remembered cell. */
#define LANE_BUFFER 4096
#define NO_LANE (-1)
/* With blocks, a cell whose path left its block is pending: step[] holds
 * PENDING | its distance to the block's exit plus one, group[] the exit.
 * Blocks are used only below 2^30 cells, so final steps stay below it. */
#define PENDING UINT32_C(0x40000000)
#define BLOCKS_MAX_CELLS (UINT32_C(1) << 30)

typedef struct lane {
    bool busy;
    bool parked; /* waits for another walk; nothing it waits on changed since */
    uint32_t start; /* first cell of the path */
    uint32_t len;   /* cells on the path */
    uint32_t next;  /* cell the walk enters next: image of the last path cell */
    uint32_t last;  /* the last path cell */
    uint32_t *path; /* LANE_BUFFER entries */
} lane;

/* Each thread's classifier on its own cache lines: the lane state one
 * thread writes at every step shared a line with fields the other thread
 * reads at every step, which cost 10-30 % of the walks on two threads. */
typedef struct classifier {
    _Alignas(CM_CACHE_LINE) uint32_t n;
    uint32_t lo, hi; /* the block of cells walked; images outside it leave it */
    const uint32_t *image;
    uint32_t *group, *step;
    uint32_t cursor;  /* every cell of the block below it has been started or visited */
    uint32_t ngroups; /* provisional groups found so far */
    uint32_t max_groups; /* the largest provisional id the block may give */
    uint32_t *exits;     /* the block's exits, in the order found (with blocks) */
    uint64_t nexits, exits_cap;
    cm_status status; /* of the block's last walk */
    int node_refs;    /* paths into recorded exits take CM_NODE_REF | exit */
    lane lanes[LANES];
} classifier;

typedef enum { WALK_ON, WALK_WAIT, WALK_TOOK_OVER, WALK_DONE } walk_result;

static bool in_block(const classifier *c, uint32_t cell) { return cell - c->lo < c->hi - c->lo; }

static void prefetch_cell(const classifier *c, uint32_t cell)
{
    if (in_block(c, cell)) {
        __builtin_prefetch(&c->step[cell], 1);
        __builtin_prefetch(&c->group[cell], 1);
        __builtin_prefetch(&c->image[cell], 0);
    }
}

/* The lane whose path holds `cell`, or NO_LANE if the cell is unvisited,
 * classified or outside the region. */
static int lane_of(const classifier *c, uint32_t cell)
{
    if (!in_block(c, cell))
        return NO_LANE;
    const uint32_t s = c->step[cell];
    if (s == CM_STEP_UNVISITED || !(s & CM_STEP_ON_PATH))
        return NO_LANE;
    return (int)(c->group[cell] - LANE_MARK);
}

/* Does the chain of walks waiting on each other, starting at lane `from`,
 * lead back to lane `self`? */
static bool waits_on(const classifier *c, int from, int self)
{
    int k = from;
    for (int hops = 0; hops <= LANES; hops++) {
        if (k == self)
            return true;
        k = lane_of(c, c->lanes[k].next);
        if (k == NO_LANE)
            return false;
    }
    return false;
}

static inline void append(classifier *c, int k, uint32_t cell)
{
    lane *l = &c->lanes[k];
    if (l->len < LANE_BUFFER)
        l->path[l->len] = cell;
    c->step[cell] = CM_STEP_ON_PATH | l->len++;
    c->group[cell] = LANE_MARK + (uint32_t)k;
    l->last = cell;
    l->next = c->image[cell];
    prefetch_cell(c, l->next);
}

/* Labels the lane's path: the cells from position cycle_at on are periodic
 * (cycle_at == UINT32_MAX: none), the others count their steps to the cycle
 * or to the cell the path ran into, whose step is tail_step; `pending`
 * (0 or PENDING) marks steps counted to the block's exit. */
static void label(classifier *c, const lane *l, uint32_t group, uint32_t cycle_at,
                  uint32_t tail_step, uint32_t pending)
{
    uint32_t cell = l->start;
    for (uint32_t pos = 0; pos < l->len; pos++) {
        cell = pos < LANE_BUFFER ? l->path[pos] : c->image[cell];
        c->group[cell] = group;
        if (cycle_at == UINT32_MAX)
            c->step[cell] = pending | (tail_step + (l->len - pos));
        else
            c->step[cell] = pos >= cycle_at ? 0 : cycle_at - pos;
    }
}

/* How a path whose last cell is `last` ends when it runs into `cell`
 * (last's image): in the sink's domain, through the node on its end; pending
 * at this block's exit `last` if the cell is another block's; or where the
 * cell, classified or pending, is. Sets the group, the step of the cell run
 * into (tail; 0 for the sink and exits) and PENDING or 0. False if the cell
 * is unvisited or on a path, so the walk goes on or waits. */
static inline bool end_of_path(classifier *c, uint32_t last, uint32_t cell, uint32_t *group,
                               uint32_t *tail, uint32_t *pending, cm_status *st)
{
    *tail = 0;
    *pending = 0;
    if (cell >= c->n) {
        const int64_t exit = c->node_refs ? cm_image_exit_index(cell) : -1;
        *group = exit >= 0 ? CM_NODE_REF | (uint32_t)exit : 0;
        return true;
    }
    if (!in_block(c, cell)) {
        if (cm_grow((void **)&c->exits, &c->exits_cap, c->nexits + 1, sizeof *c->exits) != CM_OK)
            *st = CM_ENOMEM;
        else
            c->exits[c->nexits++] = last;
        *group = last;
        *pending = PENDING;
        return true;
    }
    const uint32_t s = c->step[cell];
    if (s == CM_STEP_UNVISITED || (s & CM_STEP_ON_PATH))
        return false;
    *group = c->group[cell];
    *tail = s & ~PENDING;
    *pending = s & PENDING;
    return true;
}

/* Most walks would end after their first cell: its image is classified
 * already (68-99 % of the walks on bench_scm's lattices, 15-41 % of the
 * cells). The cursor labels those cells itself, with their images' lines
 * fetched AHEAD cells before it gets there, and starts a walk only where
 * the path goes on. */
#define AHEAD 32

static void prefetch_ahead(const classifier *c, uint32_t cell)
{
    if (cell < c->hi && c->step[cell] == CM_STEP_UNVISITED) {
        const uint32_t t = c->image[cell];
        if (in_block(c, t)) {
            __builtin_prefetch(&c->step[t], 0);
            __builtin_prefetch(&c->group[t], 0);
        }
    }
}

/* Labels the unvisited cells from the cursor on whose image ends the path
 * at once, and starts the lane on the first other one; false when the
 * block has no unvisited cell left. */
static bool start_walk(classifier *c, int k, cm_status *st)
{
    for (;; c->cursor++) {
        while (c->cursor < c->hi && c->step[c->cursor] != CM_STEP_UNVISITED)
            prefetch_ahead(c, ++c->cursor + AHEAD);
        uint32_t group, tail, pending;
        const uint32_t i = c->cursor;
        if (i == c->hi || !end_of_path(c, i, c->image[i], &group, &tail, &pending, st))
            break;
        c->group[i] = group;
        c->step[i] = pending | (tail + 1);
        if (*st != CM_OK)
            break;
        prefetch_ahead(c, i + 1 + AHEAD);
    }
    lane *l = &c->lanes[k];
    l->busy = c->cursor < c->hi && *st == CM_OK;
    if (!l->busy)
        return false;
    l->start = c->cursor;
    l->len = 0;
    append(c, k, c->cursor);
    return true;
}

/* One step of lane k: enters its next cell, or finishes, or waits. */
static walk_result advance(classifier *c, int k, cm_status *st)
{
    lane *l = &c->lanes[k];
    const uint32_t cell = l->next;
    if (in_block(c, cell) && c->step[cell] == CM_STEP_UNVISITED) {
        append(c, k, cell);
        return WALK_ON;
    }
    uint32_t group, tail, pending;
    if (end_of_path(c, l->last, cell, &group, &tail, &pending, st)) {
        label(c, l, group, UINT32_MAX, tail, pending);
        return WALK_DONE;
    }
    const uint32_t s = c->step[cell]; /* on a path */
    const int owner = (int)(c->group[cell] - LANE_MARK);
    if (owner == k) { /* the path closes a new cycle */
        if (c->ngroups == c->max_groups) {
            *st = CM_ETOOBIG;
            return WALK_DONE;
        }
        label(c, l, ++c->ngroups, s & ~CM_STEP_ON_PATH, 0, 0);
        return WALK_DONE;
    }
    if (!waits_on(c, owner, k))
        return WALK_WAIT;
    /* The owner waits (maybe through others) on this walk, so the paths
     * close a cycle together: take the owner's path over from this cell to
     * its end. The owner then waits on this walk and is off the cycle, so
     * every takeover shortens the chain of walks around it. */
    lane *o = &c->lanes[owner];
    const uint32_t from = s & ~CM_STEP_ON_PATH, count = o->len - from;
    o->len = from;
    o->next = cell;
    for (uint32_t q = 0; q < count; q++)
        append(c, k, q == 0 ? cell : c->lanes[k].next);
    return WALK_TOOK_OVER;
}

/* Walks every unvisited cell of the classifier's block. A walk that has to
 * wait is parked until some walk finishes or takes a path over: until
 * then its wait cannot end, and where neighbouring cells' paths merge (as
 * on Fig. 4.21's lattice) the others would otherwise check it at every
 * step of the one walk that goes on. */
static cm_status walk_block(classifier *c, uint32_t *buffers)
{
    c->cursor = c->lo;
    int busy = 0;
    for (int k = 0; k < LANES; k++) {
        c->lanes[k].path = buffers + (size_t)k * LANE_BUFFER;
        c->lanes[k].parked = false;
    }
    cm_status st = CM_OK;
    for (int k = 0; k < LANES; k++)
        busy += start_walk(c, k, &st);
    int parked = 0;
    while (busy > 0 && st == CM_OK) {
        for (int k = 0; k < LANES; k++) {
            if (!c->lanes[k].busy || c->lanes[k].parked)
                continue;
            const walk_result w = advance(c, k, &st);
            if (w == WALK_ON)
                continue;
            if (w == WALK_WAIT) {
                c->lanes[k].parked = true;
                parked++;
                continue;
            }
            for (int m = 0; parked > 0 && m < LANES; m++)
                c->lanes[m].parked = false;
            parked = 0;
            if (w == WALK_DONE) {
                c->lanes[k].busy = false;
                busy--;
                busy += st == CM_OK && start_walk(c, k, &st);
            }
        }
    }
    return st;
}

/* Writes one element of group[lo, hi) per page. Every cell's group is
 * labelled (by a walk, or by the scan), so the array needs no other start;
 * but a fresh array's pages are then mapped in one sequential pass (with
 * step[]'s), not one fault at a time in the middle of the walks' cache
 * misses. */
static void map_pages(uint32_t *group, uint32_t lo, uint32_t hi)
{
    const uint32_t per_page = 4096 / sizeof *group;
    for (uint32_t i = lo; i < hi; i += per_page)
        group[i] = 0;
    if (hi > lo)
        group[hi - 1] = 0;
}

/* Renumbers groups 1..found in order of the lowest local index of their
 * domain. */
static cm_status renumber(uint32_t n, uint32_t *group, uint32_t found, uint32_t *ngroups,
                          char *msg, size_t msg_size)
{
    uint32_t *final_id = malloc(((size_t)found + 1) * sizeof *final_id);
    if (!final_id)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory renumbering groups");
    final_id[0] = 0;
    for (uint32_t g = 1; g <= found; g++)
        final_id[g] = UINT32_MAX;
    uint32_t next_id = 1;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t *g = &group[i];
        if (*g & CM_NODE_REF)
            continue;
        if (final_id[*g] == UINT32_MAX)
            final_id[*g] = next_id++;
        *g = final_id[*g];
    }
    free(final_id);
    *ngroups = next_id - 1;
    return CM_OK;
}

/* ---- several blocks ------------------------------------------------------------ */

/* Where block b of `threads` starts (b = threads: n). */
static uint32_t block_end(uint32_t n, int b, int threads)
{
    return (uint32_t)((uint64_t)n * (uint64_t)b / (uint64_t)threads);
}

/* Provisional group ids: block b numbers its groups b * 2^shift + 1 .. and
 * the cycles through several blocks take the next range; compact[] says
 * where each range starts in one dense numbering. */
typedef struct id_ranges {
    int shift;
    uint32_t compact[65]; /* per range: dense index of its id 0 */
    uint32_t count;       /* dense indices in use, the sink's 0 included */
} id_ranges;

static uint32_t dense_id(const id_ranges *r, uint32_t g)
{
    return r->compact[g >> r->shift] + (g & ((UINT32_C(1) << r->shift) - 1));
}

static bool is_final(uint32_t s) { return !(s & (PENDING | CM_STEP_ON_PATH)); }

/* An exit on the chain the resolver follows, and the distance plus one from
 * its image to the image's own exit (when that image is pending). */
typedef struct chain_link {
    uint32_t exit, target_local;
} chain_link;

typedef struct resolver {
    const uint32_t *image;
    uint32_t *group, *step;
    chain_link *chain; /* the exits followed so far; step[] of each: ON_PATH | position */
    size_t len;
    uint64_t cap;
    uint32_t *path; /* cells of a tree walked to a cycle */
    uint64_t path_cap;
    uint32_t next_group, max_group; /* ids of cycles through several blocks */
} resolver;

/* The step of pending cell t whose exit lies on a cycle: the walk from t to
 * the first classified cell (a cell of the cycle, or of a tree labelled
 * before), whose cells it labels. */
static cm_status walk_to_cycle(resolver *r, uint32_t t, uint32_t *step_of_t)
{
    size_t len = 0;
    uint32_t cell = t;
    for (; !is_final(r->step[cell]); cell = r->image[cell]) {
        if (cm_grow((void **)&r->path, &r->path_cap, len + 1, sizeof *r->path) != CM_OK)
            return CM_ENOMEM;
        r->path[len++] = cell;
    }
    const uint32_t g = r->group[cell];
    uint32_t s = r->step[cell];
    while (len > 0) {
        const uint32_t c = r->path[--len];
        r->group[c] = g;
        r->step[c] = ++s;
    }
    *step_of_t = r->step[t];
    return CM_OK;
}

/* Settles the exits chain[0..top]: the top one's image has group g and
 * step t; each lower exit's image is pending at the exit above it. */
static void settle_chain(resolver *r, size_t top, uint32_t g, uint32_t t)
{
    for (size_t j = top;; j--) {
        const uint32_t e = r->chain[j].exit;
        r->group[e] = g;
        r->step[e] = 1 + t;
        if (j == 0)
            return;
        t = r->chain[j - 1].target_local - 1 + r->step[e];
    }
}

/* The exits chain[a..top] close a cycle: every cell from each exit's image
 * to the next exit (chain[a] after the top) is periodic. */
static void mark_cycle(resolver *r, size_t a, uint32_t g)
{
    const size_t top = r->len - 1;
    for (size_t j = a; j <= top; j++) {
        const uint32_t end = r->chain[j == top ? a : j + 1].exit;
        for (uint32_t cell = r->image[r->chain[j].exit];; cell = r->image[cell]) {
            r->group[cell] = g;
            r->step[cell] = 0;
            if (cell == end)
                break;
        }
    }
}

/* Follows pending exit e from block to block until a classified cell or a
 * cycle, and settles every exit on the way. */
static cm_status resolve_exit(resolver *r, uint32_t e)
{
    r->len = 0;
    for (uint32_t cur = e;;) {
        if (cm_grow((void **)&r->chain, &r->cap, r->len + 1, sizeof *r->chain) != CM_OK)
            return CM_ENOMEM;
        r->chain[r->len] = (chain_link){cur, 0};
        r->step[cur] = CM_STEP_ON_PATH | (uint32_t)r->len++;
        const uint32_t t = r->image[cur], s = r->step[t];
        if (is_final(s)) { /* a classified cell: the chain ends */
            settle_chain(r, r->len - 1, r->group[t], s);
            return CM_OK;
        }
        const bool t_on_chain = s & CM_STEP_ON_PATH;
        const uint32_t next = t_on_chain ? t : r->group[t], s2 = r->step[next];
        r->chain[r->len - 1].target_local = t_on_chain ? 1 : s & ~PENDING;
        if (s2 & CM_STEP_ON_PATH) { /* back on this chain: a cycle */
            if (r->next_group == r->max_group)
                return CM_ETOOBIG;
            const uint32_t g = ++r->next_group;
            const size_t a = s2 & ~CM_STEP_ON_PATH;
            mark_cycle(r, a, g);
            if (a == 0)
                return CM_OK;
            const uint32_t below = r->image[r->chain[a - 1].exit];
            uint32_t t_below = r->step[below];
            if (!is_final(t_below)) {
                const cm_status st = walk_to_cycle(r, below, &t_below);
                if (st != CM_OK)
                    return st;
            }
            settle_chain(r, a - 1, g, t_below);
            return CM_OK;
        }
        if (is_final(s2)) { /* an exit settled before */
            uint32_t t_step = s2 == 0 ? 0 : r->chain[r->len - 1].target_local - 1 + s2;
            if (s2 == 0) { /* on a cycle: t hangs on a tree into it */
                const cm_status st = walk_to_cycle(r, t, &t_step);
                if (st != CM_OK)
                    return st;
            }
            settle_chain(r, r->len - 1, r->group[next], t_step);
            return CM_OK;
        }
        cur = next;
    }
}

/* A block's groups in the order they first appear in it (dense ids). */
typedef struct first_seen {
    uint8_t *seen; /* per dense id */
    uint32_t *order;
    uint32_t listed;
} first_seen;

static void note_group(first_seen *f, const id_ranges *ids, uint32_t g)
{
    if (g & CM_NODE_REF)
        return;
    const uint32_t d = dense_id(ids, g);
    if (!f->seen[d]) {
        f->seen[d] = 1;
        f->order[f->listed++] = d;
    }
}

/* Settles the pending cells of [lo, hi) from their exits; those whose exit
 * lies on a cycle become unvisited, to be walked again (into the exit's
 * group). Lists the block's groups as they first appear. */
static void settle_block(uint32_t lo, uint32_t hi, uint32_t *group, uint32_t *step,
                         const id_ranges *ids, first_seen *f)
{
    for (uint32_t i = lo; i < hi; i++) {
        const uint32_t s = step[i];
        if (s & PENDING) {
            const uint32_t e = group[i], se = step[e];
            group[i] = group[e];
            step[i] = se == 0 ? CM_STEP_UNVISITED : (s & ~PENDING) - 1 + se;
        }
        note_group(f, ids, group[i]);
    }
}

/* Renumbers groups as renumber() does, from the blocks' lists: merged in
 * block order, then each block relabels its cells. */
static cm_status renumber_blocks(uint32_t n, uint32_t *group, const id_ranges *ids, int threads,
                                 const first_seen *f, uint32_t *ngroups)
{
    uint32_t *final_id = malloc((size_t)ids->count * sizeof *final_id);
    if (!final_id)
        return CM_ENOMEM;
    final_id[0] = 0;
    for (uint32_t d = 1; d < ids->count; d++)
        final_id[d] = UINT32_MAX;
    uint32_t next_id = 1;
    for (int b = 0; b < threads; b++)
        for (uint32_t k = 0; k < f[b].listed; k++)
            if (final_id[f[b].order[k]] == UINT32_MAX)
                final_id[f[b].order[k]] = next_id++;
#pragma omp parallel for num_threads(threads) schedule(static, 1)
    for (int b = 0; b < threads; b++) {
        const uint32_t hi = block_end(n, b + 1, threads);
        for (uint32_t i = block_end(n, b, threads); i < hi; i++)
            if (!(group[i] & CM_NODE_REF))
                group[i] = final_id[dense_id(ids, group[i])];
    }
    free(final_id);
    *ngroups = next_id - 1;
    return CM_OK;
}

static cm_status classify_blocks(uint32_t n, const uint32_t *image, uint32_t *group,
                                 uint32_t *step, uint32_t *ngroups, int node_refs, int threads,
                                 char *msg, size_t msg_size)
{
    int shift = 31; /* threads + 1 ranges of ids, 2^shift each */
    while ((UINT32_C(1) << (31 - shift)) < (uint32_t)threads + 1)
        shift--;
    const uint32_t range = UINT32_C(1) << shift;
    uint32_t *buffers = malloc((size_t)threads * LANES * LANE_BUFFER * sizeof *buffers);
    classifier *blocks = cm_thread_records((size_t)threads, sizeof *blocks);
    resolver r = {image, group, step, NULL, 0, 0, NULL, 0, (uint32_t)threads * range,
                  (uint32_t)threads * range + range - 1};
    cm_status st = buffers && blocks ? CM_OK : CM_ENOMEM;
    for (int b = 0; st == CM_OK && b < threads; b++)
        blocks[b] = (classifier){.n = n,
                                 .lo = block_end(n, b, threads),
                                 .hi = block_end(n, b + 1, threads),
                                 .image = image,
                                 .group = group,
                                 .step = step,
                                 .ngroups = (uint32_t)b * range,
                                 .max_groups = (uint32_t)b * range + range - 1,
                                 .node_refs = node_refs};
    /* 1. each block alone; paths into other blocks stop pending at its exits */
#pragma omp parallel for num_threads(threads) schedule(static, 1) if (st == CM_OK)
    for (int b = 0; b < threads; b++) {
        classifier *c = &blocks[b];
        if (st != CM_OK)
            continue;
        for (uint32_t i = c->lo; i < c->hi; i++)
            step[i] = CM_STEP_UNVISITED;
        map_pages(group, c->lo, c->hi);
        c->status = walk_block(c, buffers + (size_t)b * LANES * LANE_BUFFER);
    }
    /* 2. the exits, followed from block to block */
    for (int b = 0; st == CM_OK && b < threads; b++)
        st = blocks[b].status;
    for (int b = 0; b < threads && st == CM_OK; b++)
        for (uint64_t k = 0; k < blocks[b].nexits && st == CM_OK; k++)
            if (step[blocks[b].exits[k]] & PENDING)
                st = resolve_exit(&r, blocks[b].exits[k]);
    id_ranges ids = {shift, {0}, 1};
    for (int b = 0; st == CM_OK && b <= threads; b++) {
        ids.compact[b] = ids.count - 1;
        ids.count += b < threads ? blocks[b].ngroups - (uint32_t)b * range
                                 : r.next_group - (uint32_t)threads * range;
    }
    first_seen *firsts = calloc((size_t)threads, sizeof *firsts);
    if (st == CM_OK && !firsts)
        st = CM_ENOMEM;
    for (int b = 0; st == CM_OK && b < threads; b++) {
        firsts[b].seen = calloc(ids.count, 1);
        firsts[b].order = malloc((size_t)ids.count * sizeof *firsts[b].order);
        if (!firsts[b].seen || !firsts[b].order)
            st = CM_ENOMEM;
    }
    /* 3. the pending cells, from their exits; each block lists its groups */
#pragma omp parallel for num_threads(threads) schedule(static, 1) if (st == CM_OK)
    for (int b = 0; b < threads; b++) {
        classifier *c = &blocks[b];
        if (st != CM_OK)
            continue;
        settle_block(c->lo, c->hi, group, step, &ids, &firsts[b]);
        const uint32_t found = c->ngroups;
        const uint64_t exits = c->nexits;
        c->status = walk_block(c, buffers + (size_t)b * LANES * LANE_BUFFER);
        /* every cycle and exit is known by now */
        if (c->status == CM_OK && (c->ngroups != found || c->nexits != exits))
            c->status = CM_EINVAL;
    }
    for (int b = 0; st == CM_OK && b < threads; b++)
        st = blocks[b].status;
    if (st == CM_OK) /* 4. groups numbered as one thread would */
        st = renumber_blocks(n, group, &ids, threads, firsts, ngroups);
    for (int b = 0; firsts && b < threads; b++) {
        free(firsts[b].seen);
        free(firsts[b].order);
    }
    free(firsts);
    for (int b = 0; blocks && b < threads; b++)
        free(blocks[b].exits);
    free(blocks);
    free(buffers);
    free(r.chain);
    free(r.path);
    if (st == CM_ETOOBIG) /* a block, or the cycles through blocks, ran out of ids */
        return cm_classify_threads(n, image, group, step, ngroups, node_refs, 1, msg, msg_size);
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, st == CM_ENOMEM ? "out of memory classifying cells"
                                                          : "classification in blocks failed");
    return CM_OK;
}

cm_status cm_classify_threads(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                              uint32_t *ngroups, int node_refs, int threads, char *msg,
                              size_t msg_size)
{
    if (threads > 64)
        threads = 64;
    if (threads > 1 && n < BLOCKS_MAX_CELLS && n >= (uint32_t)threads)
        return classify_blocks(n, image, group, step, ngroups, node_refs, threads, msg, msg_size);
    classifier c = {.n = n,
                    .hi = n,
                    .image = image,
                    .group = group,
                    .step = step,
                    .max_groups = CM_MAX_GROUPS,
                    .node_refs = node_refs};
    uint32_t *buffers = malloc((size_t)LANES * LANE_BUFFER * sizeof *buffers);
    if (!buffers)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the path buffers");
    for (uint32_t i = 0; i < n; i++)
        step[i] = CM_STEP_UNVISITED;
    map_pages(group, 0, n);
    const cm_status st = walk_block(&c, buffers);
    free(buffers);
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "more than %lu periodic groups in one region",
                       (unsigned long)CM_MAX_GROUPS);
    return renumber(n, group, c.ngroups, ngroups, msg, msg_size);
}

cm_status cm_classify(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                      uint32_t *ngroups, int node_refs, char *msg, size_t msg_size)
{
    return cm_classify_threads(n, image, group, step, ngroups, node_refs, 1, msg, msg_size);
}
