#include "cellmap/join.h"

#include "cellmap/clock.h"
#include "cellmap/grow.h"

#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* A link to make: node `node`'s exit leads to cell `cell` of region `region`,
 * whose group and step are read before linking. */
typedef struct link_job {
    uint32_t node, region, cell, group, step;
} link_job;

/* Where an exit of a region that cm_cluster_solve_boxes solves leads among
 * its boxes: the box and the target's local index there, found by the
 * thread that solved the region (box PLAN_NONE: in none of them). */
typedef struct plan_target {
    uint32_t box, cell;
} plan_target;
#define PLAN_NONE UINT32_MAX

/* The open nodes whose exits lead into a box still to join, handed over by
 * the joins of the boxes before it (in order of node id). */
typedef struct handover {
    cm_escape *v;
    uint64_t n, cap;
} handover;

/* The boxes cm_cluster_solve_boxes joins, beyond what the cluster knows:
 * box b becomes region first + b. Exits between them never enter the
 * cluster's index of escapes, whose upkeep would fall on the joining thread. */
typedef struct plan {
    const cm_box *boxes;
    uint32_t nboxes, first;
    cm_bricks *index; /* box ids by brick; read-only while the threads solve */
    handover *in;     /* per box */
} plan;

typedef struct joiner {
    cm_cluster *c;
    cm_join_stats *stats;
    const plan *plan;            /* NULL: a join on its own */
    uint32_t box;                /* with plan: the box joining */
    const plan_target *targets;  /* with plan: where the region's exits lead */
    uint8_t *touched; /* per region: a node record of it changed */
    uint32_t *stack;  /* nodes of a chain */
    uint64_t stack_cap;
    char *msg;
    size_t msg_size;
} joiner;

/* Node id's record changed: its chunk is saved at the next commit. */
static void touch(joiner *j, uint32_t id)
{
    cm_cluster *c = j->c;
    const uint32_t k = cm_cluster_node_region(c, id);
    cm_cluster_region *cr = &c->regions[k];
    cr->nodes_dirty = 1;
    cr->dirty_chunks[(id - cr->node_base) / CM_NODE_CHUNK] = 1;
    j->stats->affected_regions += !j->touched[k];
    j->touched[k] = 1;
}

/* The sequences through node id (record nd, open until now, the cells of
 * weight `weight`) take group g; its cell's step is s. */
static cm_status finish(joiner *j, uint32_t id, cm_node *nd, uint32_t g, uint64_t s,
                        uint64_t weight)
{
    if (s >= CM_STEP_ON_PATH)
        return cm_fail(CM_ETOOBIG, j->msg, j->msg_size, "a step number overflows");
    if (nd->next == CM_NODE_OPEN) { /* the exit lands on a cell whose outcome is final */
        nd->next = CM_NODE_FINAL;
        nd->dist = (uint32_t)s;
    }
    nd->up = CM_NODE_FINAL;
    nd->up_dist = (uint32_t)s;
    nd->group = g;
    if (g != 0) {
        j->c->basin[g] += weight;
        j->c->basin_dirty[g] = 1;
        j->stats->resolved_cells += weight;
    }
    touch(j, id);
    return CM_OK;
}

static cm_status push(joiner *j, uint64_t *len, uint32_t id)
{
    if (cm_grow((void **)&j->stack, &j->stack_cap, *len + 1, sizeof *j->stack) != CM_OK)
        return CM_ENOMEM;
    j->stack[(*len)++] = id;
    return CM_OK;
}

/* Notes the periodic cells of cycle node x, from where the cycle enters its
 * tree down to the node's cell. */
static cm_status trace_cycle_cells(joiner *j, uint32_t x, uint32_t entry, uint32_t g)
{
    const uint32_t k = cm_cluster_node_region(j->c, x);
    cm_status st = cm_cluster_acquire(j->c, k, j->msg, j->msg_size);
    const cm_region *r = &j->c->regions[k].r;
    for (uint32_t a = entry; st == CM_OK; a = r->image[a]) {
        if (cm_cluster_note_periodic(j->c, g, k, a) != CM_OK)
            return CM_ENOMEM;
        if (r->image[a] >= r->ncells)
            break; /* the node's own cell */
    }
    return st;
}

/* The nodes linked into the tree of new cycle node q (its region's cells
 * resident) become final: their steps count through that tree to the cycle.
 * Every sequence that reaches the cycle through q passes one of them, so
 * the others settle from these (cm_cluster_resolve) without reading cells. */
static cm_status settle_linked_in(joiner *j, uint32_t q, uint32_t g)
{
    cm_node *nq;
    cm_status st = cm_cluster_node(j->c, q, &nq, j->msg, j->msg_size);
    uint32_t p = st == CM_OK ? nq->first_in : CM_NODE_OPEN;
    if (st == CM_OK)
        nq->first_in = CM_NODE_OPEN;
    while (st == CM_OK && p != CM_NODE_OPEN) {
        cm_node *np;
        if ((st = cm_cluster_node(j->c, p, &np, j->msg, j->msg_size)) != CM_OK)
            break;
        const uint32_t sibling = np->sibling;
        uint64_t s;
        if (np->next == q) { /* not itself on the cycle */
            if ((st = cm_cluster_into_cycle(j->c, q, np->target, &s, j->msg, j->msg_size)) !=
                CM_OK)
                break;
            if (s >= CM_STEP_ON_PATH)
                return cm_fail(CM_ETOOBIG, j->msg, j->msg_size, "a step number overflows");
            np->next = np->up = CM_NODE_FINAL;
            np->dist = np->up_dist = (uint32_t)s;
            np->group = g;
            touch(j, p);
        }
        np->sibling = CM_NODE_OPEN;
        p = sibling;
    }
    return st;
}

/* Linking node n (open until now, its component of weight `weight`) closed
 * a chain of links on itself: a new group whose cycle crosses region
 * borders. Its nodes become cycle nodes; the sequences through n's
 * component all end on it. */
static cm_status close_cycle(joiner *j, uint32_t n, uint64_t weight)
{
    uint32_t g;
    cm_status st = cm_cluster_new_group(j->c, &g);
    if (st != CM_OK)
        return cm_fail(st, j->msg, j->msg_size, "too many groups");
    j->stats->straddling_groups++;
    uint64_t len = 0;
    uint32_t x = n;
    do {
        cm_node *nd;
        if ((st = cm_cluster_node(j->c, x, &nd, j->msg, j->msg_size)) != CM_OK)
            return st;
        if (push(j, &len, x) != CM_OK)
            return CM_ENOMEM;
        x = nd->next;
    } while (x != n);
    /* where the cycle enters each node's tree: its predecessor's target */
    uint32_t prev_target;
    cm_node *last;
    if ((st = cm_cluster_node(j->c, j->stack[len - 1], &last, j->msg, j->msg_size)) != CM_OK)
        return st;
    prev_target = last->target;
    for (uint64_t i = 0; i < len && st == CM_OK; i++) {
        cm_node *nd;
        st = cm_cluster_node(j->c, j->stack[i], &nd, j->msg, j->msg_size);
        if (st != CM_OK)
            break;
        const uint32_t entry = prev_target;
        prev_target = nd->target;
        nd->next = CM_NODE_CYCLE;
        nd->dist = entry;
        nd->group = g;
        nd->up = CM_NODE_CYCLE;
        nd->up_dist = 0;
        touch(j, j->stack[i]);
    }
    /* once all of them are cycle nodes: their cells, and who linked in */
    for (uint64_t i = 0; i < len && st == CM_OK; i++) {
        cm_node *nd;
        st = cm_cluster_node(j->c, j->stack[i], &nd, j->msg, j->msg_size);
        if (st == CM_OK)
            st = trace_cycle_cells(j, j->stack[i], nd->dist, g);
        if (st == CM_OK)
            st = settle_linked_in(j, j->stack[i], g);
    }
    j->c->basin[g] += weight;
    j->stats->resolved_cells += weight;
    return st;
}

/* Links open node job->node to the cell its exit leads to. */
static cm_status link_node(joiner *j, const link_job *job)
{
    cm_cluster *c = j->c;
    cm_node *nd, *nm, *end;
    uint64_t weight; /* first: the open record holds it */
    cm_status st = cm_cluster_node(c, job->node, &nd, j->msg, j->msg_size);
    if (st == CM_OK)
        st = cm_cluster_take_open(c, job->node, nd, &weight);
    if (st != CM_OK)
        return st;
    nd->target = job->cell;
    if (!cm_is_node_ref(job->group)) /* a cell whose group is final */
        return finish(j, job->node, nd, job->group, (uint64_t)job->step + 1, weight);
    const uint32_t m = c->regions[job->region].node_base + (job->group & ~CM_NODE_REF);
    if ((st = cm_cluster_node(c, m, &nm, j->msg, j->msg_size)) != CM_OK)
        return st;
    if (nm->next == CM_NODE_CYCLE) { /* its tree holds a cycle that can enter above m */
        uint64_t s;
        const uint32_t g = nm->group;
        st = cm_cluster_into_cycle(c, m, job->cell, &s, j->msg, j->msg_size);
        return st == CM_OK ? finish(j, job->node, nd, g, s, weight) : st;
    }
    uint32_t g, s, open;
    if ((st = cm_cluster_resolve(c, m, &g, &s, &open, j->msg, j->msg_size)) != CM_OK)
        return st;
    nd->next = m;
    nd->dist = job->step; /* 1 to the target, then its depth in m's tree */
    if (open == CM_NODE_OPEN)
        return finish(j, job->node, nd, g, (uint64_t)job->step + s, weight);
    if (open == job->node)
        return close_cycle(j, job->node, weight);
    if ((uint64_t)job->step + s - 1 >= CM_STEP_ON_PATH)
        return cm_fail(CM_ETOOBIG, j->msg, j->msg_size, "a step number overflows");
    if ((st = cm_cluster_node(c, open, &end, j->msg, j->msg_size)) != CM_OK)
        return st;
    cm_cluster_add_open_weight(c, open, end, weight); /* its cells leave through it */
    nd->up = open;
    nd->up_dist = job->step + s - 1; /* s counts the open node's own step */
    /* m's sequences still leave the cluster: if m turns out to be on a
     * straddling cycle, this node is settled through m's tree */
    nd->sibling = nm->first_in;
    nm->first_in = job->node;
    touch(j, m);
    touch(j, job->node);
    return CM_OK;
}

/* How far ahead of the one being read or linked the records of later jobs
 * are fetched: jobs touch random cells and nodes of the cluster, each a
 * likely cache miss, so the misses of several jobs overlap. The loops are
 * short next to a miss, hence the distances; the chain's node is read from
 * the target's node, which must have arrived by then. */
#define TARGETS_AHEAD 32
#define NODES_AHEAD 16
#define CHAINS_AHEAD 8

static void prefetch_target(const cm_cluster *c, const link_job *job)
{
    const cm_region *r = &c->regions[job->region].r;
    __builtin_prefetch(&r->group[job->cell]);
    __builtin_prefetch(&r->step[job->cell]);
}

/* The record of node id in region k's table, or NULL if it is paged out. */
static const cm_node *resident_node(const cm_cluster *c, uint32_t k, uint32_t id)
{
    const cm_cluster_region *cr = &c->regions[k];
    return cr->nodes ? &cr->nodes[id - cr->node_base] : NULL;
}

/* The node whose tree the job's exit lands in, or NULL (a final cell, or
 * a paged-out table). */
static const cm_node *target_node(const cm_cluster *c, const link_job *job)
{
    if (!cm_is_node_ref(job->group))
        return NULL;
    return resident_node(c, job->region,
                         c->regions[job->region].node_base + (job->group & ~CM_NODE_REF));
}

/* The records link_node reads first: the node's, and the target's node. */
static void prefetch_nodes(const cm_cluster *c, const link_job *job)
{
    const cm_node *nd = resident_node(c, cm_cluster_node_region(c, job->node), job->node);
    const cm_node *nm = target_node(c, job);
    if (nd)
        __builtin_prefetch(nd, 1);
    if (nm)
        __builtin_prefetch(nm, 1);
}

/* Then the node the target's node's chain goes on to. */
static void prefetch_chain(const cm_cluster *c, const link_job *job)
{
    const cm_node *nm = target_node(c, job);
    const cm_node *up = nm && nm->up < CM_NODE_MAX
                            ? resident_node(c, cm_cluster_node_region(c, nm->up), nm->up)
                            : NULL;
    if (up)
        __builtin_prefetch(up, 1);
}

/* The group and step of every job's target cell. Jobs stay in node order;
 * when some target regions are paged out, they are visited region by
 * region (a counting sort of the jobs' positions) so that each is read once. */
static cm_status read_targets(joiner *j, link_job *jobs, uint64_t n)
{
    cm_cluster *c = j->c;
    bool resident = true;
    for (uint64_t i = 0; i < n && resident; i++)
        resident = c->regions[jobs[i].region].r.group != NULL;
    uint64_t *start = resident ? NULL : calloc((size_t)c->nregions + 1, sizeof *start);
    uint64_t *order = resident ? NULL : malloc((n + 1) * sizeof *order);
    if (!resident && (!start || !order)) {
        free(start);
        free(order);
        return CM_ENOMEM;
    }
    if (!resident) {
        for (uint64_t i = 0; i < n; i++)
            start[jobs[i].region + 1]++;
        for (uint32_t k = 0; k < c->nregions; k++)
            start[k + 1] += start[k];
        for (uint64_t i = 0; i < n; i++)
            order[start[jobs[i].region]++] = i;
    }
    cm_status st = CM_OK;
    uint32_t held = UINT32_MAX;
    for (uint64_t p = 0; p < n && st == CM_OK; p++) {
        link_job *job = &jobs[order ? order[p] : p];
        if (job->region != held) {
            st = cm_cluster_acquire(c, job->region, j->msg, j->msg_size);
            held = job->region;
        }
        if (resident && p + TARGETS_AHEAD < n)
            prefetch_target(c, &jobs[p + TARGETS_AHEAD]);
        const cm_region *r = &c->regions[job->region].r;
        job->group = st == CM_OK ? r->group[job->cell] : 0;
        job->step = st == CM_OK ? r->step[job->cell] : 0;
    }
    free(start);
    free(order);
    return st;
}

/* Exit `id` (to `cell`) leads into a box of the plan still to join: its
 * join takes it. */
static cm_status hand_over(joiner *j, const plan_target *t, uint32_t id, const int64_t *cell,
                           uint64_t weight)
{
    handover *h = &j->plan->in[t->box];
    if (cm_grow((void **)&h->v, &h->cap, h->n + 1, sizeof *h->v) != CM_OK)
        return CM_ENOMEM;
    h->v[h->n++] = (cm_escape){id, t->cell};
    return cm_cluster_add_open(j->c, id, cell, weight);
}

/* Where exit e of the new region (node id) leads: a link to make, an open
 * node handed to a later box of the plan, or an escape from the cluster. */
static cm_status place_exit(joiner *j, const cm_cluster_region *cr, uint64_t e, link_job *jobs,
                            uint64_t *n)
{
    cm_cluster *c = j->c;
    const uint32_t id = cr->node_base + (uint32_t)e;
    const plan_target *t = j->targets ? &j->targets[e] : NULL;
    if (t && t->box != PLAN_NONE && t->box < j->box) {
        jobs[(*n)++] = (link_job){id, j->plan->first + t->box, t->cell, 0, 0};
        return CM_OK;
    }
    const int64_t *cell = cm_region_exit(&cr->r, e);
    if (t && t->box != PLAN_NONE)
        return hand_over(j, t, id, cell, cr->nodes[e].tree);
    uint64_t local;
    const int64_t k = cm_cluster_locate(c, cell, &local);
    if (k < 0)
        return cm_cluster_add_escape(c, id, cell, cr->nodes[e].tree);
    jobs[(*n)++] = (link_job){id, (uint32_t)k, (uint32_t)local, 0, 0};
    return CM_OK;
}

/* The links to make, in order of node id: the open nodes whose exits lead
 * into the new region (from the index of escapes, then those the plan
 * handed over, all of them newer), and the new region's exits into the
 * cluster (the others stay open). */
static cm_status collect_jobs(joiner *j, uint32_t added, link_job **jobs, uint64_t *n)
{
    cm_cluster *c = j->c;
    const cm_cluster_region *cr = &c->regions[added];
    handover *h = j->plan ? &j->plan->in[j->box] : NULL;
    const uint64_t nh = h ? h->n : 0;
    cm_escape *in = NULL;
    uint64_t nin = 0, cap = 0;
    cm_status st = cm_cluster_take_escapes(c, &cr->r.box, &in, &nin, j->msg, j->msg_size);
    if (st == CM_OK &&
        cm_grow((void **)jobs, &cap, nin + nh + cr->r.nexits + 1, sizeof **jobs) != CM_OK)
        st = CM_ENOMEM;
    /* a take from the open lists finds the nodes handed over too: once each */
    for (uint64_t i = 0, hi = 0; i < nin && st == CM_OK; i++) {
        while (hi < nh && h->v[hi].node < in[i].node)
            hi++;
        if (hi == nh || h->v[hi].node != in[i].node)
            (*jobs)[(*n)++] = (link_job){in[i].node, added, in[i].cell, 0, 0};
    }
    free(in);
    for (uint64_t i = 0; i < nh && st == CM_OK; i++)
        (*jobs)[(*n)++] = (link_job){h->v[i].node, added, h->v[i].cell, 0, 0};
    if (h && st == CM_OK) {
        free(h->v);
        *h = (handover){NULL, 0, 0};
    }
    for (uint64_t e = 0; e < cr->r.nexits && st == CM_OK; e++)
        st = place_exit(j, cr, e, *jobs, n);
    return st;
}

static cm_status link_all(joiner *j)
{
    const uint32_t added = j->c->nregions - 1;
    link_job *jobs = NULL;
    uint64_t n = 0;
    cm_status st = collect_jobs(j, added, &jobs, &n);
    /* the regions the links read stay; room is made among the others */
    for (uint64_t i = 0; i < n; i++)
        j->c->regions[jobs[i].region].pinned = 1;
    if (st == CM_OK)
        cm_cluster_trim_joining(j->c, added);
    if (st == CM_OK)
        st = read_targets(j, jobs, n);
    for (uint64_t i = 0; i < n && st == CM_OK; i++) {
        if (i + NODES_AHEAD < n)
            prefetch_nodes(j->c, &jobs[i + NODES_AHEAD]);
        if (i + CHAINS_AHEAD < n)
            prefetch_chain(j->c, &jobs[i + CHAINS_AHEAD]);
        st = link_node(j, &jobs[i]);
    }
    for (uint64_t i = 0; i < n; i++)
        j->c->regions[jobs[i].region].pinned = 0;
    j->stats->nodes = n;
    free(jobs);
    return st;
}

/* Joins region r (its node table `nodes`, or NULL: made here), box `box`
 * of the plan p (NULL: a join on its own, box and targets unused). */
static cm_status join_region(cm_cluster *c, cm_region *r, cm_node *nodes, const plan *p,
                             uint32_t box, const plan_target *targets, cm_join_stats *stats,
                             char *msg, size_t msg_size)
{
    cm_join_stats local_stats;
    if (!stats)
        stats = &local_stats;
    memset(stats, 0, sizeof *stats);
    const double started = cm_seconds();
    cm_status st = cm_cluster_add_region(c, r, nodes, msg, msg_size);
    if (st != CM_OK)
        return st;
    const uint32_t added = c->nregions - 1;
    stats->new_groups = c->regions[added].r.ngroups;
    char detail[256] = "";
    joiner j = {c,    stats, p, box, targets, calloc(c->nregions, 1), NULL, 0, detail,
                sizeof detail};
    st = j.touched ? CM_OK : CM_ENOMEM;
    if (st == CM_OK) {
        j.touched[added] = 1;
        stats->affected_regions = 1;
        st = link_all(&j);
    }
    free(j.touched);
    free(j.stack);
    if (st == CM_OK && !c->keep_exits) { /* linked or indexed: the targets are not read again */
        free(c->regions[added].r.exit_target);
        c->regions[added].r.exit_target = NULL;
    }
    stats->new_groups += stats->straddling_groups;
    stats->seconds = cm_seconds() - started;
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "joining region %u: %s", added,
                       detail[0] ? detail : cm_strerror(st));
    return CM_OK;
}

cm_status cm_cluster_join(cm_cluster *c, cm_region *r, cm_join_stats *stats, char *msg,
                          size_t msg_size)
{
    return join_region(c, r, NULL, NULL, 0, NULL, stats, msg, msg_size);
}

static void add_join_stats(cm_join_stats *sum, const cm_join_stats *one)
{
    sum->affected_regions += one->affected_regions;
    sum->resolved_cells += one->resolved_cells;
    sum->nodes += one->nodes;
    sum->new_groups += one->new_groups;
    sum->straddling_groups += one->straddling_groups;
    sum->seconds += one->seconds;
}

/* Region `next`'s exits that land in the cluster: their regions stay through
 * the trim before the join under way (box b of the plan pl, which may be
 * NULL) reads; next joins after it. Where the exits land among the boxes
 * of the plan was found when next was solved (targets); the others are
 * looked up. */
static void pin_expected(cm_cluster *c, const cm_region *next, const plan *pl,
                         const plan_target *targets, uint32_t b, int pin)
{
    if (!c->page_in || c->mem_budget == 0)
        return; /* nothing is evicted */
    for (uint64_t e = 0; next && e < next->nexits; e++) {
        const plan_target *t = pl && targets ? &targets[e] : NULL;
        if (t && t->box != PLAN_NONE) { /* box b and later ones are not regions yet */
            if (t->box < b)
                c->regions[pl->first + t->box].pinned = pin;
            continue;
        }
        uint64_t local;
        const int64_t k = cm_cluster_locate(c, cm_region_exit(next, e), &local);
        if (k >= 0)
            c->regions[k].pinned = pin;
    }
}

/* Where a slot's region is: here (solved, or fetched from the source), at
 * the source (taken by it, not fetched yet), or being fetched by a thread. */
enum { AWAY_NONE, AWAY_WAITING, AWAY_FETCHING };

/* The pipeline of cm_cluster_solve_boxes. Box b is solved into slot
 * b % window by whichever thread claims it: claims go in box order, at most
 * `window` boxes ahead of the joins. Thread 0 joins the boxes in order, and
 * solves boxes itself while the next one is not ready, so joins and commits
 * run while the other threads solve. A region's result depends on its box
 * alone and the joins run in box order: the cluster is the same whatever
 * the thread count or timing. */
typedef struct pipeline {
    cm_cluster *c;
    const cm_model *model;
    const cm_box *boxes;
    uint32_t nboxes, window;
    cm_scm_options one;
    cm_region *slot;
    cm_status *status;
    char (*msgs)[256];
    atomic_uint next;   /* the next box to claim */
    atomic_uint joined; /* boxes joined (and their slots free) */
    atomic_uint *ready; /* per slot: the box solved there, plus one; 0: none */
    atomic_int stop;    /* a join failed: no more claims */
    plan pl;            /* pl.index NULL: the joins go without it */
    plan_target **targets; /* per slot: where its region's exits lead */
    cm_node **nodes;       /* per slot: its region's node table */
    atomic_uchar *away;    /* per slot: AWAY_* */
} pipeline;

/* Where region r's exits lead among the boxes of the plan (on the thread
 * that solved it: the plan's index is only read). */
static cm_status locate_exits(const plan *pl, const cm_region *r, plan_target **out)
{
    plan_target *t = malloc((r->nexits + 1) * sizeof *t);
    if (!t)
        return CM_ENOMEM;
    for (uint64_t e = 0; e < r->nexits; e++) {
        const int64_t *cell = cm_region_exit(r, e);
        int64_t key[CM_MAX_DIM];
        uint64_t n;
        cm_bricks_of(pl->index, cell, key);
        const uint32_t *in_brick = cm_bricks_find(pl->index, key, &n);
        t[e] = (plan_target){PLAN_NONE, 0};
        for (uint64_t i = 0; i < n; i++)
            if (cm_box_contains(&pl->boxes[in_brick[i]], cell)) {
                t[e] = (plan_target){in_brick[i],
                                     (uint32_t)cm_box_index(&pl->boxes[in_brick[i]], cell)};
                break;
            }
    }
    *out = t;
    return CM_OK;
}

/* What the join of the region in slot s needs of it alone: its node
 * table (from its trees' sizes if another process sent them, else from
 * its cells), and where its exits lead among the plan's boxes. */
static void prepare_region(pipeline *p, uint32_t s, const uint32_t *tree)
{
    const cm_region *r = &p->slot[s];
    if (p->status[s] == CM_OK &&
        ((tree ? cm_region_nodes_of_trees(r, tree, &p->nodes[s])
               : cm_region_nodes(r, &p->nodes[s])) != CM_OK ||
         (p->pl.index && locate_exits(&p->pl, r, &p->targets[s]) != CM_OK)))
        p->status[s] = cm_fail(CM_ENOMEM, p->msgs[s], sizeof p->msgs[s],
                               "out of memory for its nodes");
}

static void pause_briefly(void)
{
    const struct timespec t = {0, 20000};
    nanosleep(&t, NULL);
}

/* Claims the next box into *b if the window allows; false if it does not. */
static bool claim(pipeline *p, unsigned *b)
{
    *b = atomic_load(&p->next);
    do {
        if (*b >= p->nboxes || *b >= atomic_load(&p->joined) + p->window ||
            atomic_load(&p->stop))
            return false;
    } while (!atomic_compare_exchange_weak(&p->next, b, *b + 1));
    return true;
}

/* Box b, just claimed into slot s, goes to the source: a thread fetches
 * it once it has come, its join at the latest. */
static void send_away(pipeline *p, unsigned b)
{
    const uint32_t s = b % p->window;
    p->status[s] = CM_OK;
    atomic_store(&p->away[s], (unsigned char)AWAY_WAITING);
    atomic_store(&p->ready[s], b + 1);
}

/* Fetches box b's region (slot s) if it has come and no other thread is
 * fetching it, and prepares it for its join; whether this thread did. */
static bool try_fetch(pipeline *p, uint32_t b, uint32_t s)
{
    unsigned char waiting = AWAY_WAITING;
    if (!atomic_compare_exchange_strong(&p->away[s], &waiting, (unsigned char)AWAY_FETCHING))
        return false;
    if (atomic_load(&p->ready[s]) != b + 1) { /* b was joined, and the slot is another box's */
        atomic_store(&p->away[s], (unsigned char)AWAY_WAITING);
        return false;
    }
    const cm_region_source *src = p->c->source;
    bool got = false;
    uint32_t *tree = NULL;
    p->status[s] = src->fetch(src->user, b, &p->slot[s], &tree, &got, p->msgs[s], sizeof p->msgs[s]);
    if (got)
        prepare_region(p, s, tree);
    free(tree);
    const bool done = got || p->status[s] != CM_OK; /* a failure goes to the join */
    atomic_store(&p->away[s], (unsigned char)(done ? AWAY_NONE : AWAY_WAITING));
    return done;
}

/* A thread that does not join takes the regions that have come for the
 * boxes claimed (off the joining thread, which otherwise receives and
 * prepares each at its join); whether it took one. */
static bool fetch_arrived(pipeline *p)
{
    if (!p->c->source)
        return false;
    const uint32_t claimed = atomic_load(&p->next);
    for (uint32_t b = atomic_load(&p->joined); b < claimed && b < p->nboxes; b++) {
        const uint32_t s = b % p->window;
        if (atomic_load(&p->ready[s]) == b + 1 && atomic_load(&p->away[s]) == AWAY_WAITING &&
            try_fetch(p, b, s))
            return true;
    }
    return false;
}

/* Claims the next box if the window allows, and solves it unless the
 * source takes it; false if the window does not allow. */
static bool solve_next(pipeline *p)
{
    unsigned b;
    if (!claim(p, &b))
        return false;
    const cm_region_source *src = p->c->source;
    if (src && src->take(src->user, b)) {
        send_away(p, b);
        return true;
    }
    const uint32_t s = b % p->window;
    p->status[s] = cm_region_alloc(&p->slot[s], &p->boxes[b], p->msgs[s], sizeof p->msgs[s]);
    if (p->status[s] == CM_OK)
        p->status[s] = cm_scm_solve(p->model, &p->c->lat, &p->one, &p->slot[s], p->msgs[s],
                                    sizeof p->msgs[s]);
    prepare_region(p, s, NULL); /* what the join needs of the region alone, off the joining thread */
    atomic_store(&p->ready[s], b + 1);
    return true;
}

/* The joining thread keeps the source supplied: boxes are claimed for it
 * while it has room (a box claimed when it has none meanwhile is solved
 * here, as solve_next would). */
static void supply_source(pipeline *p)
{
    const cm_region_source *src = p->c->source;
    while (src && src->room(src->user) && solve_next(p))
        ;
}

/* Box b, in slot s, taken by the source when it was claimed: fetched now
 * if no other thread did, the boxes after it solved meanwhile. */
static void fetch_deferred(pipeline *p, uint32_t b, uint32_t s)
{
    while (atomic_load(&p->away[s]) != AWAY_NONE)
        if (!try_fetch(p, b, s) && !solve_next(p))
            pause_briefly();
}

/* Bytes of the regions after box b solved ahead of their joins (complete
 * once their ready flag says so), with their node tables and exit
 * targets: the cluster's budget makes room for them. */
static uint64_t solved_ahead(pipeline *p, uint32_t b)
{
    uint64_t bytes = 0;
    const uint32_t claimed = atomic_load(&p->next);
    for (uint32_t k = b + 1; k < claimed && k < p->nboxes; k++) {
        const uint32_t s = k % p->window;
        if (atomic_load(&p->ready[s]) == k + 1 && p->status[s] == CM_OK)
            bytes += cm_region_bytes(&p->slot[s]) +
                     p->slot[s].nexits * (sizeof(cm_node) + sizeof(plan_target));
    }
    return bytes;
}

/* The joins, in box order (thread 0). */
static cm_status join_in_order(pipeline *p, cm_joined_fn joined, void *user,
                               cm_join_stats *stats, char *msg, size_t msg_size)
{
    cm_cluster *c = p->c;
    const uint64_t held = c->mem_reserved; /* the owner's own */
    cm_status st = CM_OK;
    for (uint32_t b = 0; b < p->nboxes && st == CM_OK; b++) {
        const uint32_t s = b % p->window;
        supply_source(p);
        while (atomic_load(&p->ready[s]) != b + 1)
            if (!solve_next(p))
                pause_briefly();
        fetch_deferred(p, b, s);
        if (p->status[s] != CM_OK)
            st = cm_fail(p->status[s], msg, msg_size, "region %u: %s", b, p->msgs[s]);
        const uint32_t ns = (b + 1) % p->window;
        const cm_region *next =
            b + 1 < p->nboxes && atomic_load(&p->ready[ns]) == b + 2 && p->status[ns] == CM_OK
                ? &p->slot[ns]
                : NULL;
        /* its own box while it joins, the boxes after it from then on */
        c->upcoming = p->boxes + b;
        c->nupcoming = p->nboxes - b;
        c->mem_reserved = held + solved_ahead(p, b);
        const plan *pl = p->pl.index ? &p->pl : NULL;
        pin_expected(c, next, pl, next ? p->targets[ns] : NULL, b, 1);
        cm_join_stats one_join;
        if (st == CM_OK) {
            st = join_region(c, &p->slot[s], p->nodes[s], pl, b, p->targets[s], &one_join, msg,
                             msg_size);
            p->nodes[s] = NULL; /* the cluster took it */
        }
        pin_expected(c, next, pl, next ? p->targets[ns] : NULL, b, 0);
        c->upcoming++;
        c->nupcoming--;
        if (st == CM_OK && stats)
            add_join_stats(stats, &one_join);
        if (st == CM_OK && joined)
            st = joined(user, c, b, &one_join, msg, msg_size);
        cm_region_free(&p->slot[s]);
        free(p->targets[s]);
        p->targets[s] = NULL;
        atomic_store(&p->ready[s], 0u);
        atomic_store(&p->joined, b + 1);
    }
    c->mem_reserved = held;
    if (st != CM_OK)
        atomic_store(&p->stop, 1);
    return st;
}

/* The plan of boxes[0..n) joining a cluster of `first` regions: pl->index
 * stays NULL (joins without it) for a lone box or boxes too big to index. */
static cm_status plan_boxes(plan *pl, const cm_cluster *c, const cm_box *boxes, uint32_t n)
{
    *pl = (plan){boxes, n, c->nregions, NULL, NULL};
    if (n < 2)
        return CM_OK;
    int shift[CM_MAX_DIM];
    cm_bricks_shift_for(&boxes[0], shift);
    pl->in = calloc(n, sizeof *pl->in);
    if (!pl->in || cm_bricks_alloc(c->lat.dim, shift, sizeof(uint32_t), &pl->index) != CM_OK)
        return CM_ENOMEM;
    for (uint32_t b = 0; b < n; b++) {
        const cm_status st = cm_bricks_add_box(pl->index, &boxes[b], &b);
        if (st != CM_OK) { /* CM_ETOOBIG: without the plan */
            cm_bricks_free(pl->index);
            pl->index = NULL;
            return st == CM_ETOOBIG ? CM_OK : st;
        }
    }
    return CM_OK;
}

/* Open nodes handed over to boxes that a failed solve did not join go to
 * the cluster's index of escapes, where any later join finds them. */
static cm_status free_plan(plan *pl, cm_cluster *c)
{
    cm_status st = CM_OK;
    for (uint32_t b = 0; pl->in && b < pl->nboxes; b++) {
        for (uint64_t i = 0; i < pl->in[b].n && st == CM_OK; i++) {
            int64_t cell[CM_MAX_DIM];
            cm_box_cell(&pl->boxes[b], pl->in[b].v[i].cell, cell);
            st = cm_cluster_index_escape(c, pl->in[b].v[i].node, cell);
        }
        free(pl->in[b].v);
    }
    free(pl->in);
    cm_bricks_free(pl->index);
    return st;
}

static void free_pipeline(pipeline *p)
{
    for (uint32_t k = 0; p->slot && k < p->window; k++)
        cm_region_free(&p->slot[k]);
    for (uint32_t k = 0; p->targets && k < p->window; k++)
        free(p->targets[k]);
    for (uint32_t k = 0; p->nodes && k < p->window; k++)
        free(p->nodes[k]);
    free(p->nodes);
    free(p->away);
    free(p->slot);
    free(p->status);
    free(p->msgs);
    free(p->ready);
    free(p->targets);
}

cm_status cm_cluster_solve_boxes(cm_cluster *c, const cm_model *model, const cm_box *boxes,
                                 uint32_t nboxes, const cm_scm_options *opt, cm_joined_fn joined,
                                 void *user, cm_join_stats *stats, char *msg, size_t msg_size)
{
    int threads = 1;
#ifdef _OPENMP
    threads = opt && opt->threads > 0 ? opt->threads : omp_get_max_threads();
#endif
    /* regions solved elsewhere come while this process solves its own */
    const uint32_t processes = c->source && c->source->processes > 1 ? c->source->processes : 1;
    pipeline p = {c,    model, boxes, nboxes, 2 * (uint32_t)threads * processes,
                  opt ? *opt : (cm_scm_options){0},
                  NULL, NULL, NULL, 0, 0, NULL, 0, {0}, NULL, NULL, NULL};
    p.one.record_exits = 1;
    /* one region per thread: classification is sequential, so this is how
     * a big box uses every core; a lone box (a strip uncovered by panning)
     * takes every thread for its images instead */
    p.one.threads = nboxes == 1 ? threads : 1;
    p.slot = calloc(p.window, sizeof *p.slot);
    p.status = calloc(p.window, sizeof *p.status);
    p.msgs = calloc(p.window, sizeof *p.msgs);
    p.ready = calloc(p.window, sizeof *p.ready);
    p.targets = calloc(p.window, sizeof *p.targets);
    p.nodes = calloc(p.window, sizeof *p.nodes);
    p.away = calloc(p.window, sizeof *p.away);
    if (!p.slot || !p.status || !p.msgs || !p.ready || !p.targets || !p.nodes || !p.away ||
        plan_boxes(&p.pl, c, boxes, nboxes) != CM_OK) {
        free_pipeline(&p);
        free_plan(&p.pl, c);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u regions", nboxes);
    }
    if (stats)
        memset(stats, 0, sizeof *stats);
    const cm_region_source *src = c->source;
    cm_status st = src ? src->ask(src->user, boxes, nboxes, msg, msg_size) : CM_OK;
    if (st != CM_OK) {
        free_pipeline(&p);
        free_plan(&p.pl, c);
        return st;
    }
    const int team = nboxes > 1 ? threads : 1;
#pragma omp parallel num_threads(team)
    {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        if (t == 0) {
            st = join_in_order(&p, joined, user, stats, msg, msg_size);
        } else { /* until the boxes are claimed and the source's regions taken */
            while (atomic_load(&p.joined) < p.nboxes && !atomic_load(&p.stop) &&
                   (atomic_load(&p.next) < p.nboxes || c->source))
                if (!fetch_arrived(&p) && !solve_next(&p))
                    pause_briefly();
        }
    }
    (void)team;
    free_pipeline(&p);
    if (free_plan(&p.pl, c) != CM_OK && st == CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the open nodes");
    c->upcoming = NULL;
    c->nupcoming = 0;
    cm_cluster_trim(c);
    return st;
}
