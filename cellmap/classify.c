/* cellmap/classify.c - classification of a region's functional graph
 * (image[]) into periodic groups, their domains and step numbers.
 *
 * Each cell has one image, so the graph is a set of trees hanging on cycles
 * (or on the sink). The classic algorithm walks from every unvisited cell
 * until it meets the sink, a classified cell or its own path, then labels the
 * path. That walk is a chain of dependent memory loads: one cache miss per
 * cell, about 20 ns on large regions. Here LANES walks run interleaved, one
 * step each in turn, and each prefetches the cell it enters next, so the
 * misses of different walks overlap.
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
 * Everything runs on one thread, so it is deterministic.
 */
#include "cellmap/classify.h"

#include "cellmap/scm.h"

#include <stdbool.h>
#include <stdlib.h>

/* step[] holds each cell's state (classify.h); while a cell is on a walk's
 * path, group[] holds LANE_MARK + the walk's lane, above every group id. */
#define LANE_MARK UINT32_C(0xFFFFFF00)
/* Enough walks in flight to overlap memory latency, few enough that their
 * path buffers stay in cache. */
#define LANES 8
/* Paths up to this length are remembered; labelling a longer one follows
 * image[] from the last remembered cell. */
#define LANE_BUFFER 4096
#define NO_LANE (-1)

typedef struct lane {
    bool busy;
    uint32_t start; /* first cell of the path */
    uint32_t len;   /* cells on the path */
    uint32_t next;  /* cell the walk enters next: image of the last path cell */
    uint32_t *path; /* LANE_BUFFER entries */
} lane;

typedef struct classifier {
    uint32_t n;
    const uint32_t *image;
    uint32_t *group, *step;
    uint32_t cursor;  /* every cell below it has been started or visited */
    uint32_t ngroups; /* provisional groups found so far */
    int node_refs;    /* paths into recorded exits take CM_NODE_REF | exit */
    lane lanes[LANES];
} classifier;

typedef enum { WALK_ON, WALK_WAIT, WALK_DONE } walk_result;

static void prefetch_cell(const classifier *c, uint32_t cell)
{
    if (cell < c->n) {
        __builtin_prefetch(&c->step[cell], 1);
        __builtin_prefetch(&c->group[cell], 1);
        __builtin_prefetch(&c->image[cell], 0);
    }
}

/* The lane whose path holds `cell`, or NO_LANE if the cell is unvisited,
 * classified or outside the region. */
static int lane_of(const classifier *c, uint32_t cell)
{
    if (cell >= c->n)
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

static void append(classifier *c, int k, uint32_t cell)
{
    lane *l = &c->lanes[k];
    if (l->len < LANE_BUFFER)
        l->path[l->len] = cell;
    c->step[cell] = CM_STEP_ON_PATH | l->len++;
    c->group[cell] = LANE_MARK + (uint32_t)k;
    l->next = c->image[cell];
    prefetch_cell(c, l->next);
}

/* Labels the lane's path: the cells from position cycle_at on are periodic
 * (cycle_at == UINT32_MAX: none), the others count their steps to the cycle
 * or to the cell the path ran into, whose step is tail_step. */
static void label(classifier *c, const lane *l, uint32_t group, uint32_t cycle_at,
                  uint32_t tail_step)
{
    uint32_t cell = l->start;
    for (uint32_t pos = 0; pos < l->len; pos++) {
        cell = pos < LANE_BUFFER ? l->path[pos] : c->image[cell];
        c->group[cell] = group;
        if (cycle_at == UINT32_MAX)
            c->step[cell] = tail_step + (l->len - pos);
        else
            c->step[cell] = pos >= cycle_at ? 0 : cycle_at - pos;
    }
}

/* Starts the lane on the next unvisited cell; false when none is left. */
static bool start_walk(classifier *c, int k)
{
    while (c->cursor < c->n && c->step[c->cursor] != CM_STEP_UNVISITED)
        c->cursor++;
    lane *l = &c->lanes[k];
    l->busy = c->cursor < c->n;
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
    if (cell >= c->n) { /* the sink's domain, through the node on the path's end */
        const int64_t exit = c->node_refs ? cm_image_exit_index(cell) : -1;
        label(c, l, exit >= 0 ? CM_NODE_REF | (uint32_t)exit : 0, UINT32_MAX, 0);
        return WALK_DONE;
    }
    const uint32_t s = c->step[cell];
    if (s == CM_STEP_UNVISITED) {
        append(c, k, cell);
        return WALK_ON;
    }
    if (!(s & CM_STEP_ON_PATH)) { /* a classified cell */
        label(c, l, c->group[cell], UINT32_MAX, s);
        return WALK_DONE;
    }
    const int owner = (int)(c->group[cell] - LANE_MARK);
    if (owner == k) { /* the path closes a new cycle */
        if (c->ngroups == CM_MAX_GROUPS) {
            *st = CM_ETOOBIG;
            return WALK_DONE;
        }
        label(c, l, ++c->ngroups, s & ~CM_STEP_ON_PATH, 0);
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
    return WALK_ON;
}

/* Renumbers groups in order of the lowest local index of their domain. */
static cm_status renumber(classifier *c, char *msg, size_t msg_size)
{
    uint32_t *final_id = malloc(((size_t)c->ngroups + 1) * sizeof *final_id);
    if (!final_id)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory renumbering groups");
    final_id[0] = 0;
    for (uint32_t g = 1; g <= c->ngroups; g++)
        final_id[g] = UINT32_MAX;
    uint32_t next_id = 1;
    for (uint32_t i = 0; i < c->n; i++) {
        uint32_t *g = &c->group[i];
        if (*g & CM_NODE_REF)
            continue;
        if (final_id[*g] == UINT32_MAX)
            final_id[*g] = next_id++;
        *g = final_id[*g];
    }
    free(final_id);
    return CM_OK;
}

cm_status cm_classify(uint32_t n, const uint32_t *image, uint32_t *group, uint32_t *step,
                      uint32_t *ngroups, int node_refs, char *msg, size_t msg_size)
{
    classifier c = {n, image, group, step, 0, 0, node_refs, {{0}}};
    uint32_t *buffers = malloc((size_t)LANES * LANE_BUFFER * sizeof *buffers);
    if (!buffers)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the path buffers");
    for (uint32_t i = 0; i < n; i++)
        step[i] = CM_STEP_UNVISITED;
    int busy = 0;
    for (int k = 0; k < LANES; k++) {
        c.lanes[k].path = buffers + (size_t)k * LANE_BUFFER;
        busy += start_walk(&c, k);
    }
    cm_status st = CM_OK;
    while (busy > 0 && st == CM_OK) {
        for (int k = 0; k < LANES; k++) {
            if (!c.lanes[k].busy || advance(&c, k, &st) != WALK_DONE)
                continue;
            c.lanes[k].busy = false;
            busy--;
            busy += st == CM_OK && start_walk(&c, k);
        }
    }
    free(buffers);
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "more than %lu periodic groups in one region",
                       (unsigned long)CM_MAX_GROUPS);
    *ngroups = c.ngroups;
    return renumber(&c, msg, msg_size);
}
