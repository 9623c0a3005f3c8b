/* Orbits that leave the computed cells (cellmap/outside.h). */
#include "cellmap/outside.h"

#include "cellmap/exit_memo.h"
#include "cellmap/grow.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

void cm_exits_free(cm_exits *x)
{
    if (!x)
        return;
    free(x->cell);
    free(x->weight);
    free(x->node);
    free(x->node_exit);
    memset(x, 0, sizeof *x);
}

/* Radix sorting: digits of this many bits, as many passes as the keys'
 * spread needs (a cluster's cells span few bits; 2^40 at most). */
#define DIGIT_BITS 11
#define DIGITS (1u << DIGIT_BITS)

/* Reorders order[0..n) stably by key(order[i]) = keys[order[i] * stride],
 * tmp: n entries of scratch. */
static void radix_pass_all(uint32_t *order, uint32_t *tmp, uint64_t n, const int64_t *keys,
                           size_t stride)
{
    if (n < 2)
        return;
    int64_t lo = keys[(size_t)order[0] * stride], hi = lo;
    for (uint64_t i = 1; i < n; i++) {
        const int64_t k = keys[(size_t)order[i] * stride];
        lo = k < lo ? k : lo;
        hi = k > hi ? k : hi;
    }
    const uint64_t spread = (uint64_t)hi - (uint64_t)lo;
    for (int shift = 0; shift < 64 && (shift == 0 || (spread >> shift) != 0); shift += DIGIT_BITS) {
        uint64_t count[DIGITS + 1] = {0};
        for (uint64_t i = 0; i < n; i++)
            count[((((uint64_t)keys[(size_t)order[i] * stride] - (uint64_t)lo) >> shift) &
                   (DIGITS - 1)) + 1]++;
        for (uint32_t d = 1; d <= DIGITS; d++)
            count[d] += count[d - 1];
        for (uint64_t i = 0; i < n; i++) {
            const uint64_t d =
                (((uint64_t)keys[(size_t)order[i] * stride] - (uint64_t)lo) >> shift) & (DIGITS - 1);
            tmp[count[d]++] = order[i];
        }
        memcpy(order, tmp, (size_t)n * sizeof *order);
    }
}

/* The order of n cells (dim coordinates each) in box order: the first
 * coordinate sorted first, the last (the most significant) last. */
static cm_status box_order(const int64_t *cells, uint64_t n, int dim, uint32_t **out)
{
    uint32_t *order = malloc(((size_t)n + 1) * sizeof *order);
    uint32_t *tmp = malloc(((size_t)n + 1) * sizeof *tmp);
    if (!order || !tmp) {
        free(order);
        free(tmp);
        return CM_ENOMEM;
    }
    for (uint64_t i = 0; i < n; i++)
        order[i] = (uint32_t)i;
    for (int d = 0; n > 0 && d < dim; d++) /* no cell: cells may be NULL */
        radix_pass_all(order, tmp, n, cells + d, (size_t)dim);
    free(tmp);
    *out = order;
    return CM_OK;
}

/* The distinct cells of targets[0..n) (dim coordinates each) in box order
 * into x->cell, their weights summed into x->weight (weight NULL: 0 each,
 * for the caller to add); exit_of[i] (may be NULL) receives the exit of
 * target i. */
static cm_status exits_of_targets(const int64_t *targets, const uint64_t *weight, uint64_t n,
                                  int dim, cm_exits *x, uint32_t *exit_of)
{
    if (n >= UINT32_MAX)
        return CM_ETOOBIG;
    uint32_t *order = NULL;
    const size_t bytes = (size_t)dim * sizeof *targets;
    cm_status st = box_order(targets, n, dim, &order);
    uint64_t distinct = 0; /* counted first: the listing of a cluster's exits peaks here */
    for (uint64_t k = 0; st == CM_OK && k < n; k++)
        distinct += k == 0 || memcmp(targets + (size_t)order[k] * (size_t)dim,
                                     targets + (size_t)order[k - 1] * (size_t)dim, bytes) != 0;
    x->cell = st == CM_OK ? malloc(((size_t)distinct + 1) * bytes) : NULL;
    x->weight = st == CM_OK ? malloc(((size_t)distinct + 1) * sizeof *x->weight) : NULL;
    if (st != CM_OK || !x->cell || !x->weight) {
        free(order);
        return CM_ENOMEM;
    }
    x->n = 0;
    for (uint64_t k = 0; k < n; k++) {
        const int64_t *t = targets + (size_t)order[k] * (size_t)dim;
        if (!x->n || memcmp(t, x->cell + (x->n - 1) * (uint64_t)dim, (size_t)dim * sizeof *t)) {
            memcpy(x->cell + x->n * (uint64_t)dim, t, (size_t)dim * sizeof *t);
            x->weight[x->n++] = 0;
        }
        x->weight[x->n - 1] += weight ? weight[order[k]] : 0;
        if (exit_of)
            exit_of[order[k]] = (uint32_t)(x->n - 1);
    }
    free(order);
    return CM_OK;
}

/* Whether the image of a sink cell leaves the region's cells: an exit, or
 * a cell of the box that was not computed. */
static bool leaves(const cm_region *r, uint32_t image)
{
    return image >= CM_IMAGE_EXIT_BASE ? image != CM_IMAGE_SINK
                                       : image < r->ncells && r->group[image] == CM_GROUP_NONE;
}

/* The exit cell a leaving cell's image lands in: the recorded exit's
 * target, the uncomputed cell of the box it points to, or (an image
 * CM_IMAGE_EXIT, not recorded) found again by the image rule. Returns the
 * model's status; 1 when the model now gives no image. */
static int exit_of(const cm_region_cells *rc, uint64_t local, int64_t *exit)
{
    const cm_region *r = rc->r;
    const uint32_t image = r->image[local];
    const int64_t k = cm_image_exit_index(image);
    if (k >= 0 && r->exit_target) {
        memcpy(exit, cm_region_exit(r, (uint64_t)k), (size_t)r->box.dim * sizeof *exit);
        return 0;
    }
    if (image < r->ncells) {
        cm_box_cell(&r->box, image, exit);
        return 0;
    }
    int64_t from[CM_MAX_DIM];
    bool in_world;
    cm_box_cell(&r->box, local, from);
    const int st = cm_scm_image_cell(rc->m, rc->lat, from, rc->max_steps, exit, &in_world);
    return st < 0 ? st : in_world ? 0 : 1;
}

static int threads_of(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

cm_status cm_region_settle_exits(cm_region *r, int threads, cm_exits *out, char *msg,
                                 size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (!r->exits_recorded)
        return cm_fail(CM_EINVAL, msg, msg_size, "the region's exits were not recorded");
    const int dim = r->box.dim;
    uint64_t *weight = calloc((size_t)r->nexits + 1, sizeof *weight);
    if (!weight)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                       (unsigned long long)r->nexits);
    uint64_t world = 0;
#pragma omp parallel num_threads(threads_of(threads)) reduction(+ : world)
    {
        uint64_t *mine = calloc((size_t)r->nexits + 1, sizeof *mine); /* NULL: atomics */
#pragma omp for schedule(static)
        for (uint64_t i = 0; i < r->ncells; i++) {
            const uint32_t g = r->group[i];
            if (g == 0) {
                world++;
            } else if (cm_is_node_ref(g)) {
                r->group[i] = 0; /* the sink, as a resolved region has it */
                if (mine) {
                    mine[g & ~CM_NODE_REF]++;
                } else {
#pragma omp atomic
                    weight[g & ~CM_NODE_REF]++;
                }
            }
        }
        for (uint64_t k = 0; mine && k < r->nexits; k++) {
            if (mine[k]) {
#pragma omp atomic
                weight[k] += mine[k];
            }
        }
        free(mine);
    }
    out->world_cells = world;
    const cm_status st = exits_of_targets(r->exit_target, weight, r->nexits, dim, out, NULL);
    free(weight);
    if (st != CM_OK) {
        cm_exits_free(out);
        return cm_fail(st, msg, msg_size, "out of memory for %llu exits",
                       (unsigned long long)r->nexits);
    }
    return CM_OK;
}

typedef struct escape_list {
    int dim;
    int64_t *cell;
    uint32_t *node;
    uint64_t *weight;
    uint64_t n, cap, cap_node, cap_weight;
    int failed;
} escape_list;

static void add_escape(void *user, uint32_t node, const int64_t *cell, uint64_t weight)
{
    escape_list *l = user;
    if (l->failed ||
        cm_grow((void **)&l->cell, &l->cap, (l->n + 1) * (uint64_t)l->dim, sizeof *l->cell) != CM_OK ||
        cm_grow((void **)&l->node, &l->cap_node, l->n + 1, sizeof *l->node) != CM_OK ||
        cm_grow((void **)&l->weight, &l->cap_weight, l->n + 1, sizeof *l->weight) != CM_OK) {
        l->failed = 1;
        return;
    }
    memcpy(l->cell + l->n * (uint64_t)l->dim, cell, (size_t)l->dim * sizeof *cell);
    l->weight[l->n] = weight;
    l->node[l->n++] = node;
}

/* Each open node's exit (exit_of[i] for node l->node[i]), by node id. */
static cm_status index_nodes(const escape_list *l, const uint32_t *exit_of, cm_exits *x)
{
    uint32_t *order = malloc(((size_t)l->n + 1) * sizeof *order);
    uint32_t *tmp = malloc(((size_t)l->n + 1) * sizeof *tmp);
    x->node = malloc(((size_t)l->n + 1) * sizeof *x->node);
    x->node_exit = malloc(((size_t)l->n + 1) * sizeof *x->node_exit);
    cm_status st = order && tmp && x->node && x->node_exit ? CM_OK : CM_ENOMEM;
    /* node_exit holds the sort's keys (the node ids) until they are sorted:
     * a cluster's listing peaks here, a million open nodes and more */
    int64_t *ids = (int64_t *)x->node_exit;
    for (uint64_t i = 0; st == CM_OK && i < l->n; i++) {
        order[i] = (uint32_t)i;
        ids[i] = l->node[i];
    }
    if (st == CM_OK)
        radix_pass_all(order, tmp, l->n, ids, 1);
    for (uint64_t i = 0; st == CM_OK && i < l->n; i++) {
        x->node[i] = l->node[order[i]];
        x->node_exit[i] = exit_of[order[i]];
    }
    x->nnodes = st == CM_OK ? l->n : 0;
    free(order);
    free(tmp);
    return st;
}

uint64_t cm_cluster_exits_room(const cm_cluster *c)
{
    const uint64_t escapes = cm_cluster_escape_count(c);
    /* the cells, in the listing twice at its peak (targets and exits) */
    const uint64_t wider = 2 * sizeof(int64_t) * (uint64_t)(c->lat.dim > 2 ? c->lat.dim - 2 : 0);
    return escapes * (CM_EXITS_PASS_BYTES + wider);
}

cm_status cm_cluster_exits(cm_cluster *c, cm_exits *out, char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (c->open_released)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's open nodes were released: its exits are not known");
    if (c->resolved_cells) { /* where sink cells leave is not known: all outside */
        out->unknown_cells = cm_cluster_sink_cells(c);
        return CM_OK;
    }
    /* counted first, so that the lists take no more than they hold: the
     * listing of a long session's cluster (a million open nodes and more)
     * is what its close holds at its peak */
    const uint64_t escapes = cm_cluster_escape_count(c);
    escape_list l = {.dim = c->lat.dim,
                     .cap = escapes * (uint64_t)c->lat.dim,
                     .cap_node = escapes,
                     .cap_weight = escapes};
    l.cell = malloc(((size_t)l.cap + 1) * sizeof *l.cell);
    l.node = malloc(((size_t)l.cap_node + 1) * sizeof *l.node);
    l.weight = malloc(((size_t)l.cap_weight + 1) * sizeof *l.weight);
    l.failed = !l.cell || !l.node || !l.weight;
    cm_status st = cm_cluster_each_escape(c, add_escape, &l, msg, msg_size);
    if (st != CM_OK) {
        free(l.cell), free(l.node), free(l.weight);
        return st;
    }
    st = l.failed ? CM_ENOMEM : CM_OK;
    uint32_t *exit_of = st == CM_OK ? malloc(((size_t)l.n + 1) * sizeof *exit_of) : NULL;
    if (st == CM_OK && !exit_of)
        st = CM_ENOMEM;
    if (st == CM_OK)
        st = exits_of_targets(l.cell, l.weight, l.n, l.dim, out, exit_of);
    free(l.cell); /* in out now: its room is index_nodes' */
    uint64_t open = 0;
    for (uint64_t i = 0; st == CM_OK && i < l.n; i++)
        open += l.weight[i];
    free(l.weight);
    if (st == CM_OK)
        st = index_nodes(&l, exit_of, out);
    const uint64_t sink = cm_cluster_sink_cells(c);
    out->world_cells = sink > open ? sink - open : 0;
    free(l.node);
    free(exit_of);
    if (st != CM_OK) {
        cm_exits_free(out);
        return cm_fail(st, msg, msg_size, "out of memory for the cluster's exits");
    }
    return CM_OK;
}

/* The region adapter: a computed cell is a cell of the box with a group. */
static bool region_holds(const void *user, const int64_t *cell)
{
    const cm_region *r = ((const cm_region_cells *)user)->r;
    return cm_box_contains(&r->box, cell) && r->group[cm_box_index(&r->box, cell)] != CM_GROUP_NONE;
}

static cm_status region_end(void *user, const int64_t *cell, uint32_t *group, bool *out_leaves,
                            int64_t *exit, char *msg, size_t msg_size)
{
    const cm_region_cells *rc = user;
    const cm_region *r = rc->r;
    *out_leaves = false;
    *group = region_holds(rc, cell) ? r->group[cm_box_index(&r->box, cell)] : CM_GROUP_NONE;
    if (*group != 0)
        return CM_OK;
    uint64_t j = cm_box_index(&r->box, cell);
    while (r->image[j] != CM_IMAGE_SINK && !leaves(r, r->image[j]))
        j = r->image[j]; /* a sink chain: it ends */
    if (r->image[j] == CM_IMAGE_SINK)
        return CM_OK;
    const int st = exit_of(rc, j, exit);
    *out_leaves = st == 0;
    return st < 0 ? cm_fail(CM_EMODEL, msg, msg_size, "the model aborted finding an exit's cell")
                  : CM_OK;
}

cm_computed cm_region_computed(cm_region_cells *rc)
{
    return (cm_computed){region_holds, region_end, rc, rc->r->box, NULL, NULL};
}

static bool cluster_holds(const void *user, const int64_t *cell)
{
    uint64_t local;
    return cm_cluster_locate(((const cm_cluster_cells *)user)->c, cell, &local) >= 0;
}

/* The exit cell of open node id: from its region's open list (in node
 * order), else from its exit table (paged in). */
cm_status cm_cluster_open_exit(cm_cluster *c, uint32_t id, int64_t *cell, char *msg,
                               size_t msg_size)
{
    const uint32_t k = cm_cluster_node_region(c, id);
    const cm_cluster_region *cr = &c->regions[k];
    const uint32_t e = id - cr->node_base;
    const size_t bytes = (size_t)c->lat.dim * sizeof *cell;
    bool listed;
    cm_status st = cm_cluster_open_target(c, id, cell, &listed, msg, msg_size);
    if (st != CM_OK || listed)
        return st;
    st = cm_cluster_acquire(c, k, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (!cr->r.exit_target)
        return cm_fail(CM_EINVAL, msg, msg_size, "region %u kept no exit table", k);
    memcpy(cell, cm_region_exit(&cr->r, e), bytes);
    return CM_OK;
}

/* The exit open node id leads to (cm_cluster_exits' node index). */
static const int64_t *node_exit(const cm_exits *x, int dim, uint32_t id)
{
    const uint64_t lo = cm_first_not_below(x->node, x->nnodes, id);
    return lo < x->nnodes && x->node[lo] == id && x->node_exit[lo] < x->n
               ? x->cell + x->node_exit[lo] * (uint64_t)dim
               : NULL;
}

static cm_status cluster_end(void *user, const int64_t *cell, uint32_t *group, bool *out_leaves,
                             int64_t *exit, char *msg, size_t msg_size)
{
    const cm_cluster_cells *cc = user;
    const int dim = cc->c->lat.dim;
    uint32_t open;
    *out_leaves = false;
    const cm_status st = cm_cluster_cell_end(cc->c, cell, group, &open, msg, msg_size);
    if (st != CM_OK || *group != 0)
        return st;
    if (cc->c->resolved_cells) { /* the exit is not known, and no exit is that cell */
        *out_leaves = true;
        memcpy(exit, cell, (size_t)dim * sizeof *exit);
        return CM_OK;
    }
    if (open == CM_NODE_OPEN) /* the world's sink */
        return CM_OK;
    *out_leaves = true;
    if (!cc->exits) /* no listing: the open node's list says */
        return cm_cluster_open_exit(cc->c, open, exit, msg, msg_size);
    const int64_t *e = node_exit(cc->exits, dim, open);
    if (!e)
        return cm_fail(CM_EINVAL, msg, msg_size, "open node %u is not among the cluster's exits",
                       open);
    memcpy(exit, e, (size_t)dim * sizeof *exit);
    return CM_OK;
}

static void cluster_between(void *user) { cm_cluster_trim(((cm_cluster_cells *)user)->c); }

static cm_status cluster_order(void *user, const int64_t *cells, uint64_t n, uint64_t **order)
{
    return cm_cluster_region_order(((cm_cluster_cells *)user)->c, cells, n, order);
}

cm_computed cm_cluster_computed(cm_cluster_cells *cc)
{
    cm_computed out = {cluster_holds, cluster_end, cc, {0}, cluster_between, cluster_order};
    cm_cluster_bounds(cc->c, &out.bounds);
    return out;
}

/* Exits followed together, through the model's step_n where it has one. */
#define FOLLOW_BATCH 256

/* One batch's points: states, images, their cells (as doubles), and per
 * point whether the image is in the world and within the computed
 * cells' bounds. */
typedef struct follow_buf {
    double x[CM_MAX_DIM][FOLLOW_BATCH], y[CM_MAX_DIM][FOLLOW_BATCH];
    double at[CM_MAX_DIM][FOLLOW_BATCH];
    double world[FOLLOW_BATCH], near[FOLLOW_BATCH];
    int rc[FOLLOW_BATCH], who[FOLLOW_BATCH];
} follow_buf;

/* The batch's images one step on (n points). */
static void step_points(const cm_model *m, int dim, int n, follow_buf *b)
{
    if (m->step_n) {
        const double *xs[CM_MAX_DIM];
        double *ys[CM_MAX_DIM];
        for (int d = 0; d < dim; d++) {
            xs[d] = b->x[d];
            ys[d] = b->y[d];
        }
        m->step_n(m, (size_t)n, xs, ys, b->rc);
        return;
    }
    for (int i = 0; i < n; i++) {
        double p[CM_MAX_DIM], q[CM_MAX_DIM];
        for (int d = 0; d < dim; d++)
            p[d] = b->x[d][i];
        b->rc[i] = m->step(m, p, q);
        for (int d = 0; d < dim; d++)
            b->y[d][i] = q[d];
    }
}

/* The cells of the images (as cm_lattice_cell finds them), whether they
 * are in the world, and whether within bounds: loops the compiler
 * vectorises. */
CM_VECTOR_LOOP
static void place_points(const cm_lattice *lat, const cm_box *bounds, int n, follow_buf *b)
{
    const double limit = (double)CM_WORLD_LIMIT;
    for (int i = 0; i < n; i++) {
        b->world[i] = b->rc[i] == CM_STEP_OK ? 1.0 : 0.0;
        b->near[i] = 1.0;
    }
    for (int d = 0; d < lat->dim; d++) {
        const double origin = lat->origin[d], width = lat->width[d];
        const double lo = (double)bounds->lo[d], hi = (double)bounds->hi[d];
        for (int i = 0; i < n; i++) {
            const double u = (b->y[d][i] - origin) / width;
            const double inside = ((u >= -limit) & (u < limit)) ? 1.0 : 0.0; /* 0 for NaN */
            const double at = cm_floor_exact(inside != 0.0 ? u : 0.0);
            b->at[d][i] = at;
            b->world[i] *= inside;
            b->near[i] *= ((at >= lo) & (at < hi)) ? 1.0 : 0.0;
        }
    }
}

/* Point i's box (box + 2 dim i: lo, hi inclusive) grown by its cell. */
static void grow_path_box(int64_t *box, int dim, int i, const int64_t *cell)
{
    int64_t *lo = box + (uint64_t)i * 2 * (uint64_t)dim, *hi = lo + dim;
    for (int d = 0; d < dim; d++) {
        lo[d] = cell[d] < lo[d] ? cell[d] : lo[d];
        hi[d] = cell[d] > hi[d] ? cell[d] : hi[d];
    }
}

/* The true orbits from the centres of exits first..first+n-1 (n at most
 * FOLLOW_BATCH), at most `steps` steps each, until each lands in a
 * computed cell, diverges or runs out of steps (outside). Returns the
 * steps taken. box (NULL: not wanted) gets each orbit's box of the cells
 * it visited, exit and landing cell included (2 dim words per exit, as
 * out). */
static uint64_t follow_batch(const cm_model *m, const cm_lattice *lat, const cm_computed *cells,
                             const int64_t *exit_cell, uint64_t first, int n, uint32_t steps,
                             follow_buf *b, cm_followed *out, int64_t *box)
{
    const int dim = lat->dim;
    for (int i = 0; i < n; i++) {
        double c[CM_MAX_DIM];
        const int64_t *cell = exit_cell + (first + (uint64_t)i) * (uint64_t)dim;
        cm_lattice_centre(lat, cell, c);
        for (int d = 0; d < dim; d++)
            b->x[d][i] = c[d];
        b->who[i] = i;
        out[i].how = CM_FOLLOW_OUTSIDE;
        out[i].taken = steps;
        if (box) {
            memcpy(box + (uint64_t)i * 2 * (uint64_t)dim, cell, (size_t)dim * sizeof *cell);
            memcpy(box + ((uint64_t)i * 2 + 1) * (uint64_t)dim, cell, (size_t)dim * sizeof *cell);
        }
    }
    uint64_t taken = 0;
    for (uint32_t k = 1; k <= steps && n > 0; k++) {
        step_points(m, dim, n, b);
        place_points(lat, &cells->bounds, n, b);
        taken += (uint64_t)n;
        int kept = 0;
        for (int i = 0; i < n; i++) {
            cm_followed *f = &out[b->who[i]];
            if (b->world[i] == 0.0) {
                f->how = b->rc[i] < 0 ? CM_FOLLOW_ABORTED : CM_FOLLOW_DIVERGED;
                f->taken = k;
                continue;
            }
            for (int d = 0; d < dim; d++)
                f->cell[d] = (int64_t)b->at[d][i];
            if (box)
                grow_path_box(box, dim, b->who[i], f->cell);
            if (b->near[i] != 0.0 && cells->holds(cells->user, f->cell)) {
                f->how = CM_FOLLOW_RETURNED;
                f->taken = k;
                continue;
            }
            for (int d = 0; d < dim; d++) /* still outside: on to the next step */
                b->x[d][kept] = b->y[d][i];
            b->who[kept++] = b->who[i];
        }
        n = kept;
    }
    return taken;
}

/* Chains of exits: an exit whose orbit returns into the sink's domain goes
 * where the exit of that cell's sequence goes. */
#define NEXT_LABEL UINT64_MAX       /* label[e] is final */
#define LABEL_PENDING INT32_MIN     /* not known yet */
#define LABEL_WALKING (INT32_MIN + 1) /* on the walk under way */

/* Settles label[] along next[]: a chain that ends at a final label takes
 * it; a chain that comes back on itself is outside. */
static void settle_chains(uint64_t n, const uint64_t *next, int32_t *label)
{
    for (uint64_t e = 0; e < n; e++) {
        if (label[e] != LABEL_PENDING)
            continue;
        uint64_t j = e;
        while (label[j] == LABEL_PENDING) {
            label[j] = LABEL_WALKING;
            j = next[j];
        }
        const int32_t v = label[j] == LABEL_WALKING ? CM_LABEL_OUTSIDE : label[j];
        for (uint64_t i = e; label[i] == LABEL_WALKING; i = next[i])
            label[i] = v;
    }
}

/* The fate of the cell an orbit returned to. */
static cm_status returned_to(const cm_computed *cells, const cm_exits *x, int dim,
                             const cm_attractor_set *s, const int64_t *cell, int32_t *label,
                             uint64_t *next, char *msg, size_t msg_size)
{
    uint32_t g;
    bool out;
    int64_t exit[CM_MAX_DIM];
    const cm_status st = cells->end(cells->user, cell, &g, &out, exit, msg, msg_size);
    *next = NEXT_LABEL;
    if (st != CM_OK)
        return st;
    if (g != 0) {
        *label = cm_attractor_label(s, g);
        return CM_OK;
    }
    if (!out) {
        *label = CM_LABEL_DIVERGED;
        return CM_OK;
    }
    *next = cm_cell_search(x->cell, x->n, dim, exit);
    *label = *next == UINT64_MAX ? CM_LABEL_OUTSIDE : LABEL_PENDING;
    if (*next == UINT64_MAX)
        *next = NEXT_LABEL;
    return CM_OK;
}

/* The counts of s from its exits' fates and weights. */
static void count_fates(const cm_exits *x, cm_attractor_set *s)
{
    s->sink_diverged_cells = x->world_cells;
    s->outside_cells = x->unknown_cells;
    s->returned_cells = 0;
    for (uint64_t e = 0; e < x->n; e++) {
        const int32_t v = s->exit_label[e];
        if (v > 0 && (uint32_t)v <= s->n) {
            s->a[v - 1].basin_cells += x->weight[e];
            s->returned_cells += x->weight[e];
        } else if (v == CM_LABEL_DIVERGED)
            s->sink_diverged_cells += x->weight[e];
        else
            s->outside_cells += x->weight[e];
    }
}

/* The true orbits from the centres of n exit cells (dim coordinates each),
 * in batches on `threads` threads, into f[0..n) (and their boxes into box,
 * unless NULL: follow_batch); the steps taken added to *taken. CM_EMODEL
 * when the model aborts. */
cm_status cm_exits_follow(const cm_model *m, const cm_lattice *lat, const cm_computed *cells,
                          const int64_t *exit_cell, uint64_t n, uint32_t steps, int threads,
                          cm_followed *f, int64_t *box, uint64_t *taken, char *msg,
                          size_t msg_size)
{
    const int64_t batches = (int64_t)((n + FOLLOW_BATCH - 1) / FOLLOW_BATCH);
    uint64_t sum = 0;
    int no_memory = 0;
#pragma omp parallel num_threads(threads_of(threads)) reduction(+ : sum) reduction(| : no_memory)
    {
        follow_buf *buf = malloc(sizeof *buf);
        no_memory |= !buf;
#pragma omp for schedule(dynamic, 1)
        for (int64_t b = 0; b < batches; b++) {
            const uint64_t first = (uint64_t)b * FOLLOW_BATCH;
            const int k = (int)(n - first < FOLLOW_BATCH ? n - first : FOLLOW_BATCH);
            if (buf)
                sum += follow_batch(m, lat, cells, exit_cell, first, k, steps, buf, f + first,
                                    box ? box + first * 2 * (uint64_t)lat->dim : NULL);
        }
        free(buf);
    }
    *taken += sum;
    if (no_memory)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory following the exits");
    for (uint64_t e = 0; e < n; e++)
        if (f[e].how == CM_FOLLOW_ABORTED)
            return cm_fail(CM_EMODEL, msg, msg_size, "the model aborted following an exit's orbit");
    return CM_OK;
}

/* Exits followed at a time by cm_attractors_outside, so that what it keeps
 * of an orbit stays small (a cluster can have millions of exits). */
#define FOLLOW_CHUNK ((uint64_t)1 << 14)

/* The exits whose orbits returned to a computed cell, and those cells:
 * their ends are asked once every exit is followed, in the order the cells'
 * owner reads best. Asked chunk by chunk, a paged cluster read a region
 * back for nearly every one: a 400-pan explore session's close read its
 * first region about 260 times. */
typedef struct returned_list {
    uint64_t n, cap, cell_cap;
    uint64_t *exit;
    int64_t *cell;
} returned_list;

static cm_status returned_add(returned_list *l, int dim, uint64_t e, const int64_t *cell)
{
    if (cm_grow((void **)&l->exit, &l->cap, l->n + 1, sizeof *l->exit) != CM_OK ||
        cm_grow((void **)&l->cell, &l->cell_cap, (l->n + 1) * (uint64_t)dim, sizeof *l->cell) !=
            CM_OK)
        return CM_ENOMEM;
    l->exit[l->n] = e;
    memcpy(l->cell + l->n++ * (uint64_t)dim, cell, (size_t)dim * sizeof *cell);
    return CM_OK;
}

/* The returned exits' labels and links (returned_to), in cells->order. */
static cm_status returned_all(const cm_computed *cells, const cm_exits *x, int dim,
                              const cm_attractor_set *s, const returned_list *l, int32_t *label,
                              uint64_t *next, char *msg, size_t msg_size)
{
    uint64_t *order = NULL;
    if (cells->order && cells->order(cells->user, l->cell, l->n, &order) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory ordering %llu returned orbits",
                       (unsigned long long)l->n);
    cm_status st = CM_OK;
    for (uint64_t k = 0; k < l->n && st == CM_OK; k++) {
        const uint64_t i = order ? order[k] : k;
        if (cells->between && k % 1024 == 1023) /* as cm_cluster_cells_group_shedding */
            cells->between(cells->user);        /* nothing an end read is held here */
        st = returned_to(cells, x, dim, s, l->cell + i * (uint64_t)dim, &label[l->exit[i]],
                         &next[l->exit[i]], msg, msg_size);
    }
    free(order);
    return st;
}

/* The set's exit cells, once following is done: x's own when it is spent
 * (the rest of it freed), else a copy. */
static cm_status set_exit_cells(const cm_exits *x, cm_exits *spent, int dim, cm_attractor_set *s)
{
    if (spent == x) {
        s->exit_cell = spent->cell;
        spent->cell = NULL;
        cm_exits_free(spent);
        return CM_OK;
    }
    s->exit_cell = malloc(((size_t)x->n + 1) * (size_t)dim * sizeof *s->exit_cell);
    if (!s->exit_cell)
        return CM_ENOMEM;
    if (x->n)
        memcpy(s->exit_cell, x->cell, (size_t)x->n * (size_t)dim * sizeof *x->cell);
    return CM_OK;
}

/* cm_attractors_outside, x spent (set_exit_cells) when spent is x. */
static cm_status outside_fates(const cm_model *m, const cm_lattice *lat, const cm_exits *x,
                               cm_exits *spent, const cm_computed *cells, uint32_t steps,
                               int threads, cm_attractor_set *s, char *msg, size_t msg_size)
{
    const int dim = lat->dim;
    free(s->exit_cell);
    free(s->exit_label);
    s->nexits = x->n;
    s->outside_steps = steps;
    s->outside_steps_taken = 0;
    s->exit_cell = NULL; /* copied last, once what following holds is freed */
    s->exit_label = malloc(((size_t)x->n + 1) * sizeof *s->exit_label);
    const uint64_t chunk = x->n < FOLLOW_CHUNK ? x->n : FOLLOW_CHUNK;
    cm_followed *f = malloc(((size_t)chunk + 1) * sizeof *f);
    uint64_t *next = malloc(((size_t)x->n + 1) * sizeof *next);
    cm_status st = s->exit_label && f && next
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                                 (unsigned long long)x->n);
    uint64_t taken = 0;
    returned_list back;
    memset(&back, 0, sizeof back);
    if (cells->between) /* what the caller's lookups read: following reads no end */
        cells->between(cells->user);
    for (uint64_t first = 0; st == CM_OK && first < x->n; first += chunk) {
        const uint64_t n = x->n - first < chunk ? x->n - first : chunk;
        st = cm_exits_follow(m, lat, cells, x->cell + first * (uint64_t)dim, n, steps, threads,
                             f, NULL, &taken, msg, msg_size);
        for (uint64_t i = 0; st == CM_OK && i < n; i++) {
            const uint64_t e = first + i;
            next[e] = NEXT_LABEL;
            s->exit_label[e] =
                f[i].how == CM_FOLLOW_DIVERGED ? CM_LABEL_DIVERGED : CM_LABEL_OUTSIDE;
            if (f[i].how == CM_FOLLOW_RETURNED && returned_add(&back, dim, e, f[i].cell) != CM_OK)
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the returned orbits");
        }
    }
    if (st == CM_OK)
        st = returned_all(cells, x, dim, s, &back, s->exit_label, next, msg, msg_size);
    free(back.exit);
    free(back.cell);
    if (st == CM_OK) {
        settle_chains(x->n, next, s->exit_label);
        s->outside_steps_taken = taken;
        count_fates(x, s);
    }
    free(f);
    free(next);
    if (cells->between) /* what the ends read, before the copy below */
        cells->between(cells->user);
    if (st == CM_OK && set_exit_cells(x, spent, dim, s) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                     (unsigned long long)x->n);
    if (st != CM_OK)
        s->nexits = 0;
    return st;
}

cm_status cm_attractors_outside(const cm_model *m, const cm_lattice *lat, const cm_exits *x,
                                const cm_computed *cells, uint32_t steps, int threads,
                                cm_attractor_set *s, char *msg, size_t msg_size)
{
    return outside_fates(m, lat, x, NULL, cells, steps, threads, s, msg, msg_size);
}

/* The label of a sink cell whose sequence leaves the flat region at cell j
 * (local index): into an uncomputed cell of the box, or out of the box,
 * where `cells` knows where it goes. */
typedef struct leaving_cells {
    const cm_attractor_set *s;
    const cm_computed *cells;
} leaving_cells;

static cm_status leaving_label(void *user, const cm_region *flat, uint64_t j, int32_t *v,
                               char *msg, size_t msg_size)
{
    const leaving_cells *lc = user;
    const cm_attractor_set *s = lc->s;
    const int dim = flat->box.dim;
    int64_t at[CM_MAX_DIM], exit[CM_MAX_DIM];
    const uint32_t image = flat->image[j];
    if (image < flat->ncells) { /* an uncomputed cell of the box: an exit itself */
        cm_box_cell(&flat->box, image, exit);
        *v = cm_attractor_exit_label(s, dim, exit);
        return CM_OK;
    }
    uint32_t g;
    bool out;
    if (!lc->cells) { /* orbits not cm_followed */
        *v = CM_LABEL_OUTSIDE;
        return CM_OK;
    }
    cm_box_cell(&flat->box, j, at);
    const cm_status st = lc->cells->end(lc->cells->user, at, &g, &out, exit, msg, msg_size);
    *v = g != 0 ? cm_attractor_label(s, g)
         : out  ? cm_attractor_exit_label(s, dim, exit)
                : CM_LABEL_DIVERGED;
    return st;
}

/* The label of a sink cell of flat whose sequence leaves it at cell j. */
typedef cm_status (*leaving_fn)(void *user, const cm_region *flat, uint64_t j, int32_t *v,
                                char *msg, size_t msg_size);

/* Threads share the labels while they walk: a label is read and written
 * whole (relaxed atomics), and every value a thread may see for a cell is
 * unknown or that cell's final label. */
static int32_t label_get(const int32_t *labels, uint64_t i)
{
    return __atomic_load_n(&labels[i], __ATOMIC_RELAXED);
}

static void label_set(int32_t *labels, uint64_t i, int32_t v)
{
    __atomic_store_n(&labels[i], v, __ATOMIC_RELAXED);
}

/* Labels of flat's cells [from, to) that need no walk: a group's cell its
 * attractor's label, a sink cell whose image is the world's sink diverged,
 * the others LABEL_PENDING; the sink cells whose image leaves flat's cells
 * appended to *ends. False: out of memory. */
static bool first_labels(const cm_attractor_set *s, const cm_region *flat, uint64_t from,
                         uint64_t to, int32_t *labels, uint64_t **ends, uint64_t *n,
                         uint64_t *cap)
{
    for (uint64_t i = from; i < to; i++) {
        const uint32_t g = flat->group[i], image = flat->image[i];
        labels[i] = g != 0                    ? cm_attractor_label(s, g)
                    : image == CM_IMAGE_SINK ? CM_LABEL_DIVERGED
                                             : LABEL_PENDING;
        if (labels[i] != LABEL_PENDING || !leaves(flat, image))
            continue;
        if (cm_grow((void **)ends, cap, *n + 1, sizeof **ends) != CM_OK)
            return false;
        (*ends)[(*n)++] = i;
    }
    return true;
}

/* Every LABEL_PENDING cell of flat takes the label of the first labelled
 * cell its sequence reaches, as do the cells on the way. */
static void walk_to_labels(const cm_region *flat, int threads, int32_t *labels)
{
    const int64_t n = (int64_t)flat->ncells;
#pragma omp parallel for schedule(dynamic, 4096) num_threads(threads)
    for (int64_t i = 0; i < n; i++) {
        if (label_get(labels, (uint64_t)i) != LABEL_PENDING)
            continue;
        uint64_t j = (uint64_t)i;
        int32_t v;
        while ((v = label_get(labels, j)) == LABEL_PENDING)
            j = flat->image[j];
        for (uint64_t k = (uint64_t)i; k != j; k = flat->image[k])
            label_set(labels, k, v);
    }
}

/* Labels flat's cells: a group's cell its attractor's label, a sink cell
 * the label its sequence ends on (diverged in the world's sink, else what
 * `leave` gives at the cell where it leaves flat's cells).
 * The cells where sequences leave are labelled first, in cell order on the
 * calling thread (`leave` may read the cluster and number exits); then the
 * other sink cells walk to them on every thread. Every walk ends on a
 * labelled cell, and the label it copies is its sequence's, so the result
 * does not depend on the threads. */
static cm_status label_cells(const cm_attractor_set *s, const cm_region *flat, leaving_fn leave,
                             void *user, int threads, int32_t *labels, char *msg,
                             size_t msg_size)
{
    const int nt = threads_of(threads);
    uint64_t **ends = calloc((size_t)nt, sizeof *ends);
    uint64_t *nends = calloc((size_t)nt, sizeof *nends);
    bool ok = ends && nends;
    const uint64_t ncells = flat->ncells;
#pragma omp parallel num_threads(nt) if (ok) reduction(&& : ok)
    {
        const int t = omp_get_thread_num();
        uint64_t cap = 0;
        ok = first_labels(s, flat, ncells * (uint64_t)t / (uint64_t)nt,
                          ncells * (uint64_t)(t + 1) / (uint64_t)nt, labels, &ends[t], &nends[t],
                          &cap);
    }
    cm_status st = ok ? CM_OK : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
    for (int t = 0; st == CM_OK && t < nt; t++)
        for (uint64_t k = 0; st == CM_OK && k < nends[t]; k++)
            st = leave(user, flat, ends[t][k], &labels[ends[t][k]], msg, msg_size);
    if (st == CM_OK)
        walk_to_labels(flat, nt, labels);
    for (int t = 0; ends && t < nt; t++)
        free(ends[t]);
    free(ends);
    free(nends);
    return st;
}

cm_status cm_attractor_cell_labels(const cm_attractor_set *s, const cm_region *flat,
                                   const cm_computed *cells, int32_t *labels, char *msg,
                                   size_t msg_size)
{
    leaving_cells lc = {s, cells};
    return label_cells(s, flat, leaving_label, &lc, 0, labels, msg, msg_size);
}

/* The budget opt asks (0 when not followed). */
uint32_t cm_outside_budget(const cm_model *m, const cm_attractor_options *opt)
{
    cm_attractor_options o;
    cm_attractor_defaults(m, opt, &o);
    return o.outside == CM_OUTSIDE_OFF ? 0 : o.outside;
}

/* ---- a view's labels: only the exits its cells reach ------------------- */

/* While a view is labelled, a cell whose sequence leaves the cluster
 * through an exit holds VIEW_EXIT - k, k the exit's slot (the exit cells in
 * the order they were found), and one whose sequence leaves the view where
 * only the cluster knows its end holds VIEW_END - p, p the place of that
 * cell in the list of such ends: they are looked up region by region, so
 * that a paged cluster reads each region once. */
#define VIEW_EXIT (-16)
#define VIEW_MOST ((uint64_t)1 << 30) /* slots, and ends */
#define VIEW_END (VIEW_EXIT - (int32_t)VIEW_MOST)

static bool is_slot(int32_t label) { return label <= VIEW_EXIT && label > VIEW_END; }
static bool is_end(int32_t label) { return label <= VIEW_END && label > LABEL_WALKING; }

/* Open node ids remembered with their slots (a direct-mapped cache: the
 * cells of one tree, which share an open node, lie together). */
#define OPEN_CACHE 4096

typedef struct view_exits {
    cm_cluster *c;
    const cm_attractor_set *s;
    int dim;
    const cm_region *flat;
    const uint32_t *open; /* flat's cells' open nodes (NULL: ask the cluster) */
    uint32_t *cached_open, *cached_slot; /* OPEN_CACHE each, with open */
    const int32_t *labels; /* flat's labels, once its ends are settled (else NULL) */
    int64_t *cell;  /* each slot's exit cell, dim coordinates */
    uint64_t n, cap;
    int64_t *end;   /* the cells whose ends the cluster knows, dim coordinates */
    uint64_t nend, end_cap;
    uint32_t *hash; /* open addressing by cell: slot + 1, 0 empty; hash_size a power of 2 */
    uint64_t hash_size;
} view_exits;

/* Where cell's slot is, or the empty place it would take. */
static uint64_t hash_place(const view_exits *v, const int64_t *cell)
{
    return cm_cell_table_place(v->hash, v->hash_size, v->cell, v->dim, cell);
}

/* Room for `need` slots: the cells, and the hash at most half full. */
static cm_status view_room(view_exits *v, uint64_t need)
{
    if (need >= VIEW_MOST - 64)
        return CM_ETOOBIG;
    if (need > v->cap) {
        const uint64_t cap = need > 2 * v->cap ? need : v->cap ? 2 * v->cap : 1024;
        int64_t *cell = realloc(v->cell, (size_t)cap * (size_t)v->dim * sizeof *cell);
        if (!cell)
            return CM_ENOMEM;
        v->cell = cell;
        v->cap = cap;
    }
    if (2 * need <= v->hash_size)
        return CM_OK;
    uint64_t size = v->hash_size ? 2 * v->hash_size : 2048;
    while (size < 2 * need)
        size *= 2;
    return cm_cell_table_rebuild(&v->hash, &v->hash_size, size, v->cell, v->n, v->dim);
}

/* The slot of exit cell `cell`, added when new. */
static cm_status view_slot(view_exits *v, const int64_t *cell, uint64_t *slot, char *msg,
                           size_t msg_size)
{
    if (v->hash_size) {
        const uint64_t i = hash_place(v, cell);
        if (v->hash[i]) {
            *slot = v->hash[i] - 1;
            return CM_OK;
        }
    }
    const cm_status st = view_room(v, v->n + 1);
    if (st == CM_ETOOBIG)
        return cm_fail(st, msg, msg_size, "the view reaches more than %llu exits",
                       (unsigned long long)(VIEW_MOST - 64));
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "out of memory for the view's exits");
    memcpy(v->cell + v->n * (uint64_t)v->dim, cell, (size_t)v->dim * sizeof *cell);
    v->hash[hash_place(v, cell)] = (uint32_t)(v->n + 1);
    *slot = v->n++;
    return CM_OK;
}

/* The label a computed cell's sequence ends on: its group's attractor,
 * diverged in the world's sink, or VIEW_EXIT - slot of the exit it leaves
 * the cluster by. */
static cm_status view_end(view_exits *v, const int64_t *cell, int32_t *label, char *msg,
                          size_t msg_size)
{
    uint32_t g, open;
    int64_t exit[CM_MAX_DIM];
    uint64_t slot = 0;
    cm_status st = cm_cluster_cell_end(v->c, cell, &g, &open, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (g != 0) {
        *label = cm_attractor_label(v->s, g);
        return CM_OK;
    }
    if (open == CM_NODE_OPEN) {
        *label = CM_LABEL_DIVERGED;
        return CM_OK;
    }
    st = cm_cluster_open_exit(v->c, open, exit, msg, msg_size);
    if (st == CM_OK)
        st = view_slot(v, exit, &slot, msg, msg_size);
    *label = VIEW_EXIT - (int32_t)slot;
    return st;
}

/* The label of a sink cell that leaves the cluster by open node id
 * (CM_NODE_OPEN: it ends in the world's sink). */
static cm_status open_label(view_exits *v, uint32_t id, int32_t *label, char *msg,
                            size_t msg_size)
{
    if (id == CM_NODE_OPEN) {
        *label = CM_LABEL_DIVERGED;
        return CM_OK;
    }
    const uint32_t at = (id * UINT32_C(2654435761)) >> 20; /* 12 bits: OPEN_CACHE */
    if (v->cached_open[at] == id) {
        *label = VIEW_EXIT - (int32_t)v->cached_slot[at];
        return CM_OK;
    }
    int64_t exit[CM_MAX_DIM];
    uint64_t slot = 0;
    cm_status st = cm_cluster_open_exit(v->c, id, exit, msg, msg_size);
    if (st == CM_OK)
        st = view_slot(v, exit, &slot, msg, msg_size);
    if (st == CM_OK) {
        v->cached_open[at] = id;
        v->cached_slot[at] = (uint32_t)slot;
    }
    *label = VIEW_EXIT - (int32_t)slot;
    return st;
}

/* A sink cell's sequence leaves the view at cell j: into an uncomputed
 * cell of the view (the exit itself), else beyond it (the cluster knows
 * where it ends, and so does v->open when given). */
static cm_status view_leaving(void *user, const cm_region *flat, uint64_t j, int32_t *v,
                              char *msg, size_t msg_size)
{
    int64_t at[CM_MAX_DIM];
    const uint32_t image = flat->image[j];
    if (image < flat->ncells) {
        uint64_t slot = 0;
        cm_box_cell(&flat->box, image, at);
        const cm_status st = view_slot(user, at, &slot, msg, msg_size);
        *v = VIEW_EXIT - (int32_t)slot;
        return st;
    }
    view_exits *x = user;
    if (x->open)
        return open_label(x, x->open[j], v, msg, msg_size);
    if (x->nend >= VIEW_MOST - 64)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "the view leaves itself at more than %llu cells",
                       (unsigned long long)(VIEW_MOST - 64));
    if (cm_grow((void **)&x->end, &x->end_cap, (x->nend + 1) * (uint64_t)x->dim,
                sizeof *x->end) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's ends");
    cm_box_cell(&flat->box, j, x->end + x->nend * (uint64_t)x->dim);
    *v = VIEW_END - (int32_t)x->nend++;
    return CM_OK;
}

/* The ends (view_end) of n cells (dim coordinates each) into label[0..n),
 * looked up region by region. */
static cm_status ends_by_region(view_exits *v, const int64_t *cell, uint64_t n, int32_t *label,
                                char *msg, size_t msg_size)
{
    uint64_t *order = NULL;
    cm_status st = cm_cluster_region_order(v->c, cell, n, &order) == CM_OK
                       ? CM_OK
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's ends");
    for (uint64_t i = 0; st == CM_OK && i < n; i++)
        st = view_end(v, cell + order[i] * (uint64_t)v->dim, &label[order[i]], msg, msg_size);
    free(order);
    return st;
}

/* The view's labels that wait for the cluster's ends get them. */
static cm_status settle_ends(view_exits *v, int32_t *labels, uint64_t ncells, int threads,
                             char *msg, size_t msg_size)
{
    int32_t *end = malloc(((size_t)v->nend + 1) * sizeof *end);
    cm_status st = end ? ends_by_region(v, v->end, v->nend, end, msg, msg_size)
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's ends");
    if (st == CM_OK) {
        const int64_t n = (int64_t)ncells;
#pragma omp parallel for schedule(static) num_threads(threads_of(threads))
        for (int64_t i = 0; i < n; i++)
            if (is_end(labels[i]))
                labels[i] = end[VIEW_END - labels[i]];
    }
    free(end);
    return st;
}

/* The settled label of a computed cell of the view (false: not one, or the
 * view's labels are not settled yet). */
static bool view_label(const view_exits *v, const int64_t *cell, int32_t *label)
{
    if (!v->labels || !cm_box_contains(&v->flat->box, cell))
        return false;
    const uint64_t i = cm_box_index(&v->flat->box, cell);
    if (v->flat->group[i] == CM_GROUP_NONE)
        return false;
    *label = v->labels[i];
    return true;
}

/* The labels of n followed exits: diverged, outside, or the end of the
 * cell their orbit returned to (the view's label, else found region by
 * region). */
static cm_status returned_ends(view_exits *v, const cm_followed *f, uint64_t n, int32_t *label,
                               char *msg, size_t msg_size)
{
    const int dim = v->dim;
    int64_t *cell = malloc(((size_t)n + 1) * (size_t)dim * sizeof *cell);
    uint64_t *asked = malloc(((size_t)n + 1) * sizeof *asked), nasked = 0;
    int32_t *end = malloc(((size_t)n + 1) * sizeof *end);
    cm_status st = cell && asked && end ? CM_OK
                                        : cm_fail(CM_ENOMEM, msg, msg_size,
                                                  "out of memory for the view's exits");
    for (uint64_t e = 0; st == CM_OK && e < n; e++) {
        label[e] = f[e].how == CM_FOLLOW_DIVERGED ? CM_LABEL_DIVERGED : CM_LABEL_OUTSIDE;
        if (f[e].how != CM_FOLLOW_RETURNED || view_label(v, f[e].cell, &label[e]))
            continue;
        memcpy(cell + nasked * (uint64_t)dim, f[e].cell, (size_t)dim * sizeof *cell);
        asked[nasked++] = e;
    }
    if (st == CM_OK)
        st = ends_by_region(v, cell, nasked, end, msg, msg_size);
    for (uint64_t i = 0; st == CM_OK && i < nasked; i++)
        label[asked[i]] = end[i];
    free(cell);
    free(asked);
    free(end);
    return st;
}

/* What the orbits of n exit cells (dim coordinates each) do, into f[0..n):
 * from the memo where it knows them, the others followed (cm_exits_follow) and
 * added to it. Steps taken, as if every exit were followed, to *taken. */
static cm_status follow_memo(const cm_model *m, const cm_computed *cells, const cm_lattice *lat,
                             const int64_t *exit_cell, uint64_t n, uint32_t steps, int threads,
                             cm_exit_memo *memo, cm_followed *f, uint64_t *taken, char *msg,
                             size_t msg_size)
{
    const int dim = lat->dim;
    const size_t bytes = (size_t)dim * sizeof *exit_cell;
    uint64_t *miss = malloc(((size_t)n + 1) * sizeof *miss), nmiss = 0;
    int64_t *miss_cell = malloc(((size_t)n + 1) * bytes);
    cm_exit_fate known;
    for (uint64_t e = 0; miss && miss_cell && e < n; e++) {
        const int64_t *cell = exit_cell + e * (uint64_t)dim;
        if (cm_exit_memo_find(memo, cell, &known)) {
            f[e].how = known.how;
            f[e].taken = known.taken;
            memcpy(f[e].cell, known.cell, bytes);
            *taken += known.taken;
        } else {
            memcpy(miss_cell + nmiss * (uint64_t)dim, cell, bytes);
            miss[nmiss++] = e;
        }
    }
    cm_followed *fm = malloc(((size_t)nmiss + 1) * sizeof *fm);
    int64_t *box = malloc(((size_t)nmiss + 1) * 2 * bytes);
    cm_status st = miss && miss_cell && fm && box
                       ? cm_exits_follow(m, lat, cells, miss_cell, nmiss, steps, threads, fm,
                                         box, taken, msg, msg_size)
                       : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    for (uint64_t i = 0; st == CM_OK && i < nmiss; i++) {
        f[miss[i]] = fm[i];
        known.how = fm[i].how;
        known.taken = fm[i].taken;
        memcpy(known.cell, fm[i].cell, bytes);
        memcpy(known.lo, box + i * 2 * (uint64_t)dim, bytes);
        memcpy(known.hi, box + (i * 2 + 1) * (uint64_t)dim, bytes);
        /* a memo that cannot grow only forgets: it saves work, nothing more */
        (void)cm_exit_memo_put(memo, miss_cell + i * (uint64_t)dim, &known);
    }
    free(miss);
    free(miss_cell);
    free(fm);
    free(box);
    return st;
}

/* The fates of the view's exits into label[0..v->n): followed in rounds
 * (through the memo unless NULL), as orbits that return into the sink's
 * domain reach exits not found yet, then their chains settled. */
static cm_status view_fates(const cm_model *m, view_exits *v, uint32_t steps, int threads,
                            cm_exit_memo *memo, int32_t **label, uint64_t *taken, char *msg,
                            size_t msg_size)
{
    cm_cluster *c = v->c;
    cm_cluster_cells cc = {c, NULL, NULL};
    const cm_computed cells = cm_cluster_computed(&cc); /* holds only: ends come from view_end */
    cm_followed *f = NULL;
    uint64_t *next = NULL, done = 0;
    *label = calloc(1, sizeof **label); /* no exit: no fate, but an array */
    cm_status st = *label ? CM_OK
                          : cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    while (st == CM_OK && done < v->n) {
        const uint64_t to = v->n;
        cm_followed *f2 = realloc(f, (size_t)to * sizeof *f);
        f = f2 ? f2 : f;
        uint64_t *next2 = f2 ? realloc(next, (size_t)to * sizeof *next) : NULL;
        next = next2 ? next2 : next;
        int32_t *label2 = next2 ? realloc(*label, (size_t)to * sizeof **label) : NULL;
        *label = label2 ? label2 : *label;
        if (!label2) {
            st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
            break;
        }
        const int64_t *first = v->cell + done * (uint64_t)c->lat.dim;
        st = memo ? follow_memo(m, &cells, &c->lat, first, to - done, steps, threads, memo,
                                f + done, taken, msg, msg_size)
                  : cm_exits_follow(m, &c->lat, &cells, first, to - done, steps, threads,
                                    f + done, NULL, taken, msg, msg_size);
        if (st == CM_OK)
            st = returned_ends(v, f + done, to - done, *label + done, msg, msg_size);
        for (uint64_t e = done; st == CM_OK && e < to; e++) {
            int32_t *l = &(*label)[e];
            next[e] = NEXT_LABEL;
            if (is_slot(*l)) {
                next[e] = (uint64_t)(VIEW_EXIT - *l);
                *l = LABEL_PENDING;
            }
        }
        done = to;
    }
    if (st == CM_OK)
        settle_chains(v->n, next, *label);
    free(f);
    free(next);
    return st;
}

/* s's exits: the view's exit cells in box order, with their fates and
 * weights (the view's cells that leave by them); the counts from them. */
static cm_status view_exit_set(const view_exits *v, const int32_t *label, const uint64_t *weight,
                               cm_attractor_set *s)
{
    cm_exits x;
    memset(&x, 0, sizeof x);
    uint32_t *exit_of = malloc(((size_t)v->n + 1) * sizeof *exit_of);
    cm_status st = exit_of ? exits_of_targets(v->cell, weight, v->n, v->dim, &x, exit_of)
                           : CM_ENOMEM;
    free(s->exit_cell);
    free(s->exit_label);
    s->exit_cell = x.cell;
    s->exit_label = st == CM_OK ? malloc(((size_t)x.n + 1) * sizeof *s->exit_label) : NULL;
    s->nexits = st == CM_OK && s->exit_label ? x.n : 0;
    if (st == CM_OK && !s->exit_label)
        st = CM_ENOMEM;
    for (uint64_t e = 0; st == CM_OK && e < v->n; e++)
        s->exit_label[exit_of[e]] = label[e];
    if (st == CM_OK)
        count_fates(&x, s);
    x.cell = NULL; /* s's now */
    cm_exits_free(&x);
    free(exit_of);
    return st;
}

/* Each view cell that leaves by an exit takes the exit's fate, and the
 * exit's weight (weight[0..v->n), zeroed) counts it: one pass on every
 * thread, each counting into its own array (summed after, so the counts do
 * not depend on the threads). */
static cm_status fates_of_cells(const view_exits *v, const int32_t *fate, int32_t *labels,
                                int threads, uint64_t *weight)
{
    const int nt = threads_of(threads);
    const uint64_t n = v->n;
    uint64_t *mine = calloc((size_t)nt * (size_t)n + 1, sizeof *mine);
    if (!mine)
        return CM_ENOMEM;
    const int64_t cells = (int64_t)v->flat->ncells;
#pragma omp parallel num_threads(nt)
    {
        uint64_t *count = mine + (uint64_t)omp_get_thread_num() * n;
#pragma omp for schedule(static)
        for (int64_t i = 0; i < cells; i++)
            if (is_slot(labels[i])) {
                const int32_t slot = VIEW_EXIT - labels[i];
                count[slot]++;
                labels[i] = fate[slot];
            }
    }
    for (int t = 0; t < nt; t++)
        for (uint64_t e = 0; e < n; e++)
            weight[e] += mine[(uint64_t)t * n + e];
    free(mine);
    return CM_OK;
}

cm_status cm_cluster_view_labels(const cm_model *m, cm_cluster *c, const cm_region *flat,
                                 const uint32_t *open, const cm_attractor_options *opt,
                                 cm_exit_memo *memo, cm_attractor_set *s, int32_t *labels,
                                 char *msg, size_t msg_size)
{
    if (c->resolved_cells || c->open_released || !c->keep_exits)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster does not know its exits (an old file, or released)");
    view_exits v;
    memset(&v, 0, sizeof v);
    v.c = c;
    v.s = s;
    v.dim = c->lat.dim;
    v.flat = flat;
    v.open = open;
    if (open) {
        v.cached_open = malloc(OPEN_CACHE * sizeof *v.cached_open);
        v.cached_slot = malloc(OPEN_CACHE * sizeof *v.cached_slot);
        if (!v.cached_open || !v.cached_slot) {
            free(v.cached_open);
            free(v.cached_slot);
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
        }
        memset(v.cached_open, 0xFF, OPEN_CACHE * sizeof *v.cached_open); /* CM_NODE_OPEN */
    }
    const uint32_t steps = cm_outside_budget(m, opt);
    const int threads = opt ? opt->threads : 0;
    int32_t *fate = NULL;
    uint64_t *weight = NULL, taken = 0;
    if (memo) /* a view like the last: room for its exits at once, no rehashing */
        (void)view_room(&v, cm_exit_memo_count(memo));
    if (memo)
        cm_exit_memo_sync(memo, c, steps);
    cm_status st = label_cells(s, flat, view_leaving, &v, threads, labels, msg, msg_size);
    if (st == CM_OK && v.nend) /* none when the cells' open nodes are given */
        st = settle_ends(&v, labels, flat->ncells, threads, msg, msg_size);
    v.labels = labels;
    if (st == CM_OK)
        st = view_fates(m, &v, steps, threads, memo, &fate, &taken, msg, msg_size);
    if (memo)
        cm_exit_memo_keep_used(memo);
    weight = st == CM_OK ? calloc((size_t)v.n + 1, sizeof *weight) : NULL;
    if (st == CM_OK && (!weight || fates_of_cells(&v, fate, labels, threads, weight) != CM_OK))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    if (st == CM_OK && view_exit_set(&v, fate, weight, s) != CM_OK)
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the view's exits");
    if (st == CM_OK) {
        s->outside_steps = steps;
        s->outside_steps_taken = taken;
    }
    free(fate);
    free(weight);
    free(v.cell);
    free(v.hash);
    free(v.end);
    free(v.cached_open);
    free(v.cached_slot);
    return st;
}

cm_status cm_region_attractors(const cm_model *m, const cm_lattice *lat, const cm_region *r,
                               int max_steps, const cm_exits *x, const cm_group_info *groups,
                               const cm_attractor_options *opt, cm_attractor_set *out, char *msg,
                               size_t msg_size)
{
    cm_status st = cm_attractors_find(m, lat, groups, r->ngroups, cm_region_cells_group,
                                      (void *)r, opt, out, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_region_cells rc = {r, m, lat, max_steps};
    const cm_computed cells = cm_region_computed(&rc);
    return cm_attractors_outside(m, lat, x, &cells, cm_outside_budget(m, opt), opt ? opt->threads : 0,
                                 out, msg, msg_size);
}

cm_status cm_cluster_attractors(const cm_model *m, cm_cluster_cells *cc,
                                const cm_group_info *groups, const cm_attractor_options *opt,
                                cm_attractor_set *out, char *msg, size_t msg_size)
{
    cm_cluster *c = cc->c;
    cm_status st = cm_attractors_find(m, &c->lat, groups, c->ngroups,
                                      cm_cluster_cells_group_shedding, c, opt, out, msg, msg_size);
    if (st != CM_OK)
        return st;
    const cm_computed cells = cm_cluster_computed(cc);
    return outside_fates(m, &c->lat, cc->exits, cc->spent, &cells, cm_outside_budget(m, opt),
                         opt ? opt->threads : 0, out, msg, msg_size);
}

/* ---- a cluster's labels, region by region ------------------------------ */

/* While node labels are made, a label below NODE_LINK is a link: the node
 * takes the label of node NODE_LINK - label (its exit lands in that node's
 * tree); an open node without an escape record is NODE_UNLABELLED. Final
 * labels are -2 .. the attractors' count. */
#define NODE_LINK (-3)
#define NODE_UNLABELLED INT32_MIN
#define NODE_MOST ((uint64_t)INT32_MAX - 4) /* node ids a link can name */

static bool is_link(int32_t label) { return label <= NODE_LINK && label != NODE_UNLABELLED; }

typedef struct exit_fates {
    const cm_attractor_set *s;
    int dim;
    int32_t *label;
} exit_fates;

static void label_escape(void *user, uint32_t node, const int64_t *cell, uint64_t weight)
{
    (void)weight;
    const exit_fates *f = user;
    f->label[node] = cm_attractor_exit_label(f->s, f->dim, cell);
}

cm_status cm_node_labels_open(cm_cluster *c, const cm_attractor_set *s, int32_t **out,
                              char *msg, size_t msg_size)
{
    *out = NULL;
    if (c->resolved_cells)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's sink cells are resolved (a file before version 4): "
                       "label its flattened cells instead");
    if (c->open_released)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the cluster's open nodes were released: their exits are not known");
    if (c->nnodes > NODE_MOST)
        return cm_fail(CM_ETOOBIG, msg, msg_size,
                       "%llu nodes: labels are made for at most %llu",
                       (unsigned long long)c->nnodes, (unsigned long long)NODE_MOST);
    int32_t *label = malloc(((size_t)c->nnodes + 1) * sizeof *label);
    if (!label)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels of %llu nodes",
                       (unsigned long long)c->nnodes);
    for (uint64_t id = 0; id < c->nnodes; id++)
        label[id] = NODE_UNLABELLED;
    exit_fates f = {s, c->lat.dim, label};
    const cm_status st = cm_cluster_each_escape(c, label_escape, &f, msg, msg_size);
    if (st != CM_OK) {
        free(label);
        return st;
    }
    *out = label;
    return CM_OK;
}

/* Node id's label from its saved fields: its group's for a node whose
 * group is known, the link to node nd->next for one whose exit lands in
 * that node's tree; an open node keeps the label its exit gave it. */
static cm_status own_node_label(const cm_attractor_set *s, uint64_t n, uint32_t id,
                                const cm_node *nd, int32_t *label, char *msg, size_t msg_size)
{
    if (nd->next == CM_NODE_OPEN && *label == NODE_UNLABELLED)
        return cm_fail(CM_EFORMAT, msg, msg_size,
                       "open node %u is not among the cluster's exits", id);
    if (nd->next == CM_NODE_FINAL || nd->next == CM_NODE_CYCLE)
        *label = nd->group ? cm_attractor_label(s, nd->group) : CM_LABEL_DIVERGED;
    else if (nd->next < n)
        *label = NODE_LINK - (int32_t)nd->next;
    else if (nd->next != CM_NODE_OPEN)
        return cm_fail(CM_EFORMAT, msg, msg_size, "node %u has no valid link", id);
    return CM_OK;
}

/* Every linked node takes the label its chain of links ends on: each
 * chain is walked once, its nodes then hold the end's label. */
static cm_status settle_links(uint64_t n, int32_t *label, char *msg, size_t msg_size)
{
    for (uint64_t id = 0; id < n; id++) {
        uint64_t end = id;
        for (uint64_t hops = 0; is_link(label[end]); hops++) {
            if (hops > n)
                return cm_fail(CM_EFORMAT, msg, msg_size,
                               "the links from node %llu form a loop", (unsigned long long)id);
            end = (uint64_t)(NODE_LINK - label[end]);
        }
        const int32_t v = label[end];
        for (uint64_t x = id; is_link(label[x]);) {
            const uint64_t next = (uint64_t)(NODE_LINK - label[x]);
            label[x] = v;
            x = next;
        }
    }
    return CM_OK;
}

cm_status cm_node_labels_settle(cm_cluster *c, const cm_attractor_set *s, int32_t *label,
                                char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        cm_node *table = NULL;
        if (cr->r.nexits)
            st = cm_cluster_node_load(c, cr->node_base, &table, msg, msg_size);
        for (uint64_t e = 0; e < cr->r.nexits && st == CM_OK; e++) {
            const uint32_t id = cr->node_base + (uint32_t)e;
            st = own_node_label(s, c->nnodes, id, &table[e], &label[id], msg, msg_size);
        }
        cm_cluster_trim(c); /* one table at a time is enough */
    }
    return st == CM_OK ? settle_links(c->nnodes, label, msg, msg_size) : st;
}

cm_status cm_cluster_node_labels(cm_cluster *c, const cm_attractor_set *s, int32_t **out,
                                 char *msg, size_t msg_size)
{
    cm_status st = cm_node_labels_open(c, s, out, msg, msg_size);
    if (st == CM_OK && (st = cm_node_labels_settle(c, s, *out, msg, msg_size)) != CM_OK) {
        free(*out);
        *out = NULL;
    }
    return st;
}

/* Cell i of a region with groups `group`: a node reference takes its
 * node's label; a sink cell's sequence ends in the world's sink inside the
 * region. group NULL: no cell computed. */
static int32_t region_cell_label(const uint32_t *group, uint64_t i, const int32_t *node_label,
                                 const cm_attractor_set *s)
{
    if (!group)
        return CM_LABEL_UNCOMPUTED;
    const uint32_t g = group[i];
    return cm_is_node_ref(g) ? node_label[g & ~CM_NODE_REF]
           : g == 0          ? CM_LABEL_DIVERGED
                             : cm_attractor_label(s, g);
}

/* Labels the cells of `part` (inside the region's box `rbox` and `box`;
 * group NULL: none computed) into labels with the strides of box, a row
 * along dimension 0 at a time (contiguous in the region). */
static void label_part(const cm_box *rbox, const uint32_t *group, const int32_t *node_label,
                       const cm_attractor_set *s, const cm_box *box, const cm_box *part,
                       const int64_t *stride, int32_t *labels, int threads)
{
    const int64_t width = part->hi[0] - part->lo[0];
    const int64_t rows = (int64_t)(cm_box_cells(part) / (uint64_t)width);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t q = 0; q < rows; q++) {
        int64_t cell[CM_MAX_DIM];
        cm_box row = *part;
        row.hi[0] = row.lo[0] + 1;
        cm_box_cell(&row, (uint64_t)q, cell);
        const uint64_t from = group ? cm_box_index(rbox, cell) : 0;
        int64_t to = 0;
        for (int d = 0; d < box->dim; d++)
            to += (cell[d] - box->lo[d]) * stride[d];
        for (int64_t i = 0; i < width; i++)
            labels[to + i * stride[0]] =
                region_cell_label(group, from + (uint64_t)i, node_label, s);
    }
}

cm_status cm_cluster_cell_labels(cm_cluster *c, const cm_attractor_set *s,
                                 const int32_t *node_label, const cm_box *box,
                                 const int64_t *stride, int32_t *labels, char *msg,
                                 size_t msg_size)
{
    int64_t own[CM_MAX_DIM];
    if (!stride) { /* cm_box_index's order */
        own[0] = 1;
        for (int d = 1; d < box->dim; d++)
            own[d] = own[d - 1] * (box->hi[d - 1] - box->lo[d - 1]);
        stride = own;
    }
    const int threads = cm_cluster_threads(c);
    label_part(NULL, NULL, NULL, s, box, box, stride, labels, threads);
    uint32_t *read = NULL; /* a paged-out region's groups, read alone */
    uint64_t cap = 0;
    cm_status st = CM_OK;
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++) {
        const cm_region *r = &c->regions[k].r;
        cm_box part;
        if (!cm_box_intersect(&r->box, box, &part))
            continue;
        const uint32_t *group = r->group;
        if (!group && c->groups_in && r->ncells > cap) {
            free(read);
            cap = r->ncells;
            if (!(read = malloc(cap * sizeof *read)))
                st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a region's groups");
        }
        if (st == CM_OK && !group && c->groups_in &&
            (st = c->groups_in(c->pager, k, read, msg, msg_size)) == CM_OK)
            group = read;
        if (st == CM_OK && !group && (st = cm_cluster_acquire(c, k, msg, msg_size)) == CM_OK)
            group = r->group;
        if (st == CM_OK) /* a region's node references count from its node_base */
            label_part(&r->box, group, node_label + c->regions[k].node_base, s, box, &part,
                       stride, labels, threads);
        cm_cluster_trim(c);
    }
    free(read);
    return st;
}
