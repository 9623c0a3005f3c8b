#include "cellmap/cluster.h"

#include "cellmap/classify.h"
#include "cellmap/grow.h"
#include "cellmap/resolve.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

void cm_cluster_init(cm_cluster *c, const cm_lattice *lat)
{
    memset(c, 0, sizeof *c);
    c->lat = *lat;
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
        free(c->regions[k].escapes);
        free(c->regions[k].targets);
        free(c->regions[k].entries);
    }
    free(c->regions);
    memset(c, 0, sizeof *c);
}

int64_t cm_cluster_locate(const cm_cluster *c, const int64_t *cell, uint32_t *hint, uint64_t *local)
{
    for (uint32_t n = 0; n < c->nregions; n++) {
        /* try the region of the last hit first: exits mostly land next door */
        const uint32_t k = (*hint + n) % c->nregions;
        const cm_box *box = &c->regions[k].r.box;
        if (cm_box_contains(box, cell)) {
            *hint = k;
            *local = cm_box_index(box, cell);
            return k;
        }
    }
    return -1;
}

void cm_cluster_bounds(const cm_cluster *c, cm_box *box)
{
    *box = c->regions[0].r.box;
    for (uint32_t k = 1; k < c->nregions; k++) {
        const cm_box *b = &c->regions[k].r.box;
        for (int d = 0; d < box->dim; d++) {
            box->lo[d] = b->lo[d] < box->lo[d] ? b->lo[d] : box->lo[d];
            box->hi[d] = b->hi[d] > box->hi[d] ? b->hi[d] : box->hi[d];
        }
    }
}

static int is_resident(const cm_cluster_region *cr) { return cr->r.group != NULL; }

uint64_t cm_cluster_resident_bytes(const cm_cluster *c)
{
    uint64_t bytes = 0;
    for (uint32_t k = 0; k < c->nregions; k++)
        if (is_resident(&c->regions[k]))
            bytes += cm_region_bytes(&c->regions[k].r);
    return bytes;
}

uint64_t cm_cluster_bytes(const cm_cluster *c)
{
    uint64_t bytes = cm_cluster_resident_bytes(c);
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        bytes += cr->nescapes * (uint64_t)c->lat.dim * sizeof *cr->escapes +
                 cr->targets_cap * sizeof *cr->targets + cr->entries_cap * sizeof *cr->entries;
    }
    return bytes;
}

static void evict(cm_cluster_region *cr)
{
    free(cr->r.image);
    free(cr->r.group);
    free(cr->r.step);
    free(cr->r.exit_target);
    cr->r.image = cr->r.group = cr->r.step = NULL;
    cr->r.exit_target = NULL;
}

/* The resident region to evict next, other than `keep`, or -1: clean ones
 * before dirty ones (which only with_dirty allows), then those no sequence
 * leaves (all neighbours known), then the least recently used. */
static int64_t eviction_victim(const cm_cluster *c, int64_t keep, int with_dirty)
{
    int64_t best = -1;
    for (uint32_t k = 0; k < c->nregions; k++) {
        const cm_cluster_region *cr = &c->regions[k];
        if (!is_resident(cr) || (int64_t)k == keep || (cr->dirty && !with_dirty))
            continue;
        if (best < 0) {
            best = k;
            continue;
        }
        const cm_cluster_region *b = &c->regions[best];
        const int rank = 2 * !cr->dirty + (cr->nescapes == 0),
                  best_rank = 2 * !b->dirty + (b->nescapes == 0);
        if (rank > best_rank || (rank == best_rank && cr->last_used < b->last_used))
            best = k;
    }
    return best;
}

/* Evicts regions other than `keep` until `extra` more bytes fit the budget. */
static cm_status make_room(cm_cluster *c, int64_t keep, uint64_t extra, char *msg, size_t msg_size)
{
    if (!c->page_in || c->mem_budget == 0)
        return CM_OK;
    uint64_t bytes = cm_cluster_resident_bytes(c) + extra;
    while (bytes > c->mem_budget) {
        const int64_t k = eviction_victim(c, keep, c->page_out != NULL);
        if (k < 0)
            return CM_OK;
        cm_cluster_region *cr = &c->regions[k];
        if (cr->dirty) {
            cm_status st = c->page_out(c->pager, c, (uint32_t)k, msg, msg_size);
            if (st != CM_OK)
                return st;
            cr->dirty = 0;
        }
        bytes -= cm_region_bytes(&cr->r);
        evict(cr);
    }
    return CM_OK;
}

cm_status cm_cluster_acquire(cm_cluster *c, uint32_t k, char *msg, size_t msg_size)
{
    cm_cluster_region *cr = &c->regions[k];
    cr->last_used = ++c->clock;
    if (is_resident(cr))
        return CM_OK;
    if (!c->page_in)
        return cm_fail(CM_EINVAL, msg, msg_size, "region %u is paged out and there is no pager", k);
    cm_status st = make_room(c, k, cm_region_bytes(&cr->r), msg, msg_size);
    if (st == CM_OK)
        st = c->page_in(c->pager, k, &cr->r, msg, msg_size);
    cr->read_at = c->clock;
    if (st == CM_OK && !is_resident(cr))
        st = cm_fail(CM_EIO, msg, msg_size, "region %u was not read back", k);
    return st;
}

cm_status cm_cluster_acquire_all(cm_cluster *c, char *msg, size_t msg_size)
{
    const uint64_t budget = c->mem_budget;
    cm_status st = CM_OK;
    c->mem_budget = 0;
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++)
        st = cm_cluster_acquire(c, k, msg, msg_size);
    c->mem_budget = budget;
    return st;
}

void cm_cluster_trim(cm_cluster *c)
{
    if (!c->page_in || c->mem_budget == 0)
        return;
    uint64_t bytes = cm_cluster_resident_bytes(c);
    while (bytes > c->mem_budget) {
        const int64_t k = eviction_victim(c, -1, 0);
        if (k < 0)
            return;
        bytes -= cm_region_bytes(&c->regions[k].r);
        evict(&c->regions[k]);
    }
}

static cm_status check_region(const cm_cluster *c, const cm_region *r, char *msg, size_t msg_size)
{
    if (r->box.dim != c->lat.dim)
        return cm_fail(CM_EINVAL, msg, msg_size, "region of %d dimensions, lattice of %d",
                       r->box.dim, c->lat.dim);
    if (c->nregions == UINT32_MAX)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many regions in one cluster");
    if (c->ngroups > CM_MAX_GROUPS - r->ngroups)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many periodic groups in one cluster");
    cm_box both;
    for (uint32_t k = 0; k < c->nregions; k++)
        if (cm_box_intersect(&c->regions[k].r.box, &r->box, &both))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the new region overlaps region %u of the cluster; regions of a "
                           "cluster must not share cells",
                           k);
    if (!r->exits_recorded)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the region was solved without record_exits; its exits cannot be "
                       "followed into the cluster");
    return CM_OK;
}

static cm_status add_target(cm_cluster_region *cr, uint32_t region)
{
    for (uint32_t t = 0; t < cr->ntargets; t++)
        if (cr->targets[t] == region)
            return CM_OK;
    if (cm_grow((void **)&cr->targets, &cr->targets_cap, cr->ntargets + 1, sizeof *cr->targets) !=
        CM_OK)
        return CM_ENOMEM;
    cr->targets[cr->ntargets++] = region;
    return CM_OK;
}

static cm_status add_entry(cm_cluster_region *cr, uint64_t cell)
{
    if (cm_grow((void **)&cr->entries, &cr->entries_cap, cr->nentries + 1, sizeof *cr->entries) !=
        CM_OK)
        return CM_ENOMEM;
    cr->entries[cr->nentries++] = (uint32_t)cell;
    return CM_OK;
}

static int u32_cmp(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void sort_entries(cm_cluster_region *cr)
{
    if (cr->nentries == 0)
        return;
    qsort(cr->entries, cr->nentries, sizeof *cr->entries, u32_cmp);
    uint64_t kept = 1;
    for (uint64_t e = 1; e < cr->nentries; e++)
        if (cr->entries[e] != cr->entries[kept - 1])
            cr->entries[kept++] = cr->entries[e];
    cr->nentries = kept;
}

int64_t cm_cluster_entry(const cm_cluster_region *cr, uint32_t cell)
{
    const uint32_t *e = bsearch(&cell, cr->entries, cr->nentries, sizeof cell, u32_cmp);
    return e ? e - cr->entries : -1;
}

/* Escapes of the older regions that land in the new region `added` become
 * region links and entries of `added`; the new region's exits become links
 * and entries of older regions, or escapes. Escapes keep their target
 * cells, so this works on paged-out regions too. */
static cm_status update_links(cm_cluster *c, uint32_t added)
{
    cm_cluster_region *nr = &c->regions[added];
    const cm_box *new_box = &nr->r.box;
    const size_t dim = (size_t)c->lat.dim;
    for (uint32_t k = 0; k < added; k++) {
        cm_cluster_region *cr = &c->regions[k];
        uint64_t kept = 0;
        for (uint64_t e = 0; e < cr->nescapes; e++) {
            const int64_t *cell = cr->escapes + e * dim;
            if (!cm_box_contains(new_box, cell))
                memmove(cr->escapes + kept++ * dim, cell, dim * sizeof *cell);
            else if (add_target(cr, added) != CM_OK ||
                     add_entry(nr, cm_box_index(new_box, cell)) != CM_OK)
                return CM_ENOMEM;
        }
        cr->nescapes = kept;
    }
    nr->escapes = malloc((nr->r.nexits + 1) * dim * sizeof *nr->escapes);
    if (!nr->escapes)
        return CM_ENOMEM;
    uint32_t hint = 0;
    for (uint64_t e = 0; e < nr->r.nexits; e++) {
        uint64_t local;
        const int64_t *cell = cm_region_exit(&nr->r, e);
        const int64_t k = cm_cluster_locate(c, cell, &hint, &local);
        if (k < 0)
            memcpy(nr->escapes + nr->nescapes++ * dim, cell, dim * sizeof *cell);
        else if (add_target(nr, (uint32_t)k) != CM_OK || add_entry(&c->regions[k], local) != CM_OK)
            return CM_ENOMEM;
    }
    sort_entries(nr);
    for (uint32_t t = 0; t < nr->ntargets; t++)
        sort_entries(&c->regions[nr->targets[t]]);
    return CM_OK;
}

/* Marks the regions whose sink cells can change: those from which the
 * region `added` can be reached through exits, and `added` itself if its
 * exits lead into the cluster (if not, its sink cells keep leaving it). */
static uint32_t mark_affected(const cm_cluster *c, uint32_t added, uint8_t *affected)
{
    uint8_t *reaches = affected; /* reaches[k]: region k leads into `added` */
    memset(reaches, 0, c->nregions);
    reaches[added] = 1;
    for (bool grew = true; grew;) {
        grew = false;
        for (uint32_t k = 0; k < c->nregions; k++) {
            const cm_cluster_region *cr = &c->regions[k];
            for (uint32_t t = 0; t < cr->ntargets && !reaches[k]; t++)
                if (reaches[cr->targets[t]])
                    reaches[k] = grew = true;
        }
    }
    affected[added] = c->regions[added].ntargets > 0;
    uint32_t count = 0;
    for (uint32_t k = 0; k < c->nregions; k++)
        count += affected[k];
    return count;
}

cm_status cm_cluster_add_target(cm_cluster *c, uint32_t k, uint32_t target)
{
    return add_target(&c->regions[k], target);
}

cm_status cm_cluster_join(cm_cluster *c, cm_region *r, cm_join_stats *stats, char *msg,
                          size_t msg_size)
{
    cm_join_stats local_stats;
    if (!stats)
        stats = &local_stats;
    memset(stats, 0, sizeof *stats);
    cm_status st = check_region(c, r, msg, msg_size);
    if (st != CM_OK)
        return st;
    if (cm_grow((void **)&c->regions, &c->cap, c->nregions + 1, sizeof *c->regions) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the region list");
    /* the region's own groups take the next cluster-wide ids */
    const uint32_t base = c->ngroups;
    uint32_t *group = r->group;
#pragma omp parallel for schedule(static) num_threads(cm_cluster_threads(c)) if (r->ncells >= 65536)
    for (int64_t i = 0; i < (int64_t)r->ncells; i++)
        if (group[i] != 0)
            group[i] += base;
    const uint32_t added = c->nregions++;
    memset(&c->regions[added], 0, sizeof c->regions[added]);
    c->regions[added].r = *r;
    memset(r, 0, sizeof *r);
    c->ngroups += c->regions[added].r.ngroups;
    stats->new_groups = c->regions[added].r.ngroups;
    c->regions[added].dirty = 1;
    c->regions[added].last_used = ++c->clock;
    uint8_t *affected = malloc(c->nregions);
    char detail[256] = "";
    st = affected ? update_links(c, added) : CM_ENOMEM;
    if (st == CM_OK) {
        stats->affected_regions = mark_affected(c, added, affected);
        st = cm_resolve_sink_cells(c, affected, stats, detail, sizeof detail);
    }
    free(affected);
    stats->new_groups += stats->straddling_groups;
    if (st != CM_OK)
        return cm_fail(st, msg, msg_size, "joining region %u: %s", added,
                       detail[0] ? detail : cm_strerror(st));
    return CM_OK;
}

cm_status cm_cluster_restore(cm_cluster *c, const cm_region *record, const int64_t *exit_target,
                             const uint32_t *targets, uint32_t ntargets, char *msg, size_t msg_size)
{
    if (record->box.dim != c->lat.dim)
        return cm_fail(CM_EFORMAT, msg, msg_size, "region of %d dimensions, lattice of %d",
                       record->box.dim, c->lat.dim);
    if (cm_grow((void **)&c->regions, &c->cap, c->nregions + 1, sizeof *c->regions) != CM_OK)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the region list");
    const uint32_t added = c->nregions++;
    cm_cluster_region *cr = &c->regions[added];
    memset(cr, 0, sizeof *cr);
    cr->r.box = record->box;
    cr->r.ncells = record->ncells;
    cr->r.nexits = record->nexits;
    cr->r.ngroups = record->ngroups;
    cr->r.exits_recorded = 1;
    cr->r.exit_target = (int64_t *)exit_target; /* borrowed for update_links only */
    cm_status st = update_links(c, added);
    cr->r.exit_target = NULL;
    cr->ntargets = 0; /* the saved links: those of sink cells only */
    for (uint32_t t = 0; t < ntargets && st == CM_OK; t++)
        st = add_target(cr, targets[t]);
    return st == CM_OK
               ? CM_OK
               : cm_fail(st, msg, msg_size, "restoring region %u: %s", added, cm_strerror(st));
}

static void add_join_stats(cm_join_stats *sum, const cm_join_stats *one)
{
    sum->affected_regions += one->affected_regions;
    sum->resolved_cells += one->resolved_cells;
    sum->nodes += one->nodes;
    sum->new_groups += one->new_groups;
    sum->straddling_groups += one->straddling_groups;
}

/* Solves boxes[0..n) concurrently, one region per thread. */
static void solve_batch(const cm_cluster *c, const cm_model *model, const cm_box *boxes, uint32_t n,
                        const cm_scm_options *one, int threads, cm_region *solved,
                        cm_status *status, char (*msgs)[256])
{
    if (n == 1) { /* a lone box (a strip uncovered by panning) takes every thread for its images */
        cm_scm_options all = *one;
        all.threads = threads;
        status[0] = cm_region_alloc(&solved[0], &boxes[0], msgs[0], sizeof msgs[0]);
        if (status[0] == CM_OK)
            status[0] = cm_scm_solve(model, &c->lat, &all, &solved[0], msgs[0], sizeof msgs[0]);
        return;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int64_t k = 0; k < (int64_t)n; k++) {
        status[k] = cm_region_alloc(&solved[k], &boxes[k], msgs[k], sizeof msgs[k]);
        if (status[k] == CM_OK)
            status[k] = cm_scm_solve(model, &c->lat, one, &solved[k], msgs[k], sizeof msgs[k]);
    }
    (void)threads;
}

cm_status cm_cluster_solve_boxes(cm_cluster *c, const cm_model *model, const cm_box *boxes,
                                 uint32_t nboxes, const cm_scm_options *opt, cm_joined_fn joined,
                                 void *user, cm_join_stats *stats, char *msg, size_t msg_size)
{
    int threads = 1;
#ifdef _OPENMP
    threads = opt && opt->threads > 0 ? opt->threads : omp_get_max_threads();
#endif
    cm_region *solved = calloc((size_t)threads, sizeof *solved);
    cm_status *status = calloc((size_t)threads, sizeof *status);
    char(*msgs)[256] = calloc((size_t)threads, sizeof *msgs);
    if (!solved || !status || !msgs) {
        free(solved);
        free(status);
        free(msgs);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d regions", threads);
    }
    cm_scm_options one = opt ? *opt : (cm_scm_options){0};
    one.record_exits = 1;
    one.threads = 1;
    if (stats)
        memset(stats, 0, sizeof *stats);
    /* One region per thread: classification is sequential, so this is how
     * a big box uses every core. Each region's result depends on its box
     * alone, and the joins run in a fixed order. */
    cm_status st = CM_OK;
    for (uint32_t first = 0; first < nboxes && st == CM_OK; first += (uint32_t)threads) {
        const uint32_t n = nboxes - first < (uint32_t)threads ? nboxes - first : (uint32_t)threads;
        solve_batch(c, model, boxes + first, n, &one, threads, solved, status, msgs);
        for (uint32_t k = 0; k < n; k++) {
            cm_join_stats one_join;
            if (st == CM_OK && status[k] != CM_OK)
                st = cm_fail(status[k], msg, msg_size, "region %u: %s", first + k, msgs[k]);
            if (st == CM_OK)
                st = cm_cluster_join(c, &solved[k], &one_join, msg, msg_size);
            if (st == CM_OK && stats)
                add_join_stats(stats, &one_join);
            if (st == CM_OK && joined)
                st = joined(user, c, first + k, &one_join, msg, msg_size);
            cm_region_free(&solved[k]);
        }
    }
    free(solved);
    free(status);
    free(msgs);
    return st;
}

/* Image of a cluster cell as an index of `box`, or CM_IMAGE_EXIT beyond it. */
static uint32_t flat_image(const cm_region *r, uint64_t i, const cm_box *box)
{
    int64_t cell[CM_MAX_DIM];
    const uint32_t v = r->image[i];
    const int64_t e = cm_image_exit_index(v);
    if (v < r->ncells)
        cm_box_cell(&r->box, v, cell);
    else if (e >= 0)
        memcpy(cell, cm_region_exit(r, (uint64_t)e), (size_t)box->dim * sizeof *cell);
    else
        return CM_IMAGE_SINK;
    return cm_box_contains(box, cell) ? (uint32_t)cm_box_index(box, cell) : CM_IMAGE_EXIT;
}

/* Copies the cells of region r inside `both` (their intersection) into
 * out, one row along dimension 0 at a time: rows are contiguous in both. */
static void flatten_part(const cm_region *r, const cm_box *both, cm_region *out)
{
    const int64_t width = both->hi[0] - both->lo[0];
    const int64_t rows = (int64_t)(cm_box_cells(both) / (uint64_t)width);
#pragma omp parallel for schedule(static)
    for (int64_t q = 0; q < rows; q++) {
        int64_t cell[CM_MAX_DIM];
        cm_box row = *both;
        row.hi[0] = row.lo[0] + 1;
        cm_box_cell(&row, (uint64_t)q, cell);
        const uint64_t from = cm_box_index(&r->box, cell), to = cm_box_index(&out->box, cell);
        memcpy(out->group + to, r->group + from, (size_t)width * sizeof *out->group);
        memcpy(out->step + to, r->step + from, (size_t)width * sizeof *out->step);
        for (int64_t i = 0; i < width; i++)
            out->image[to + (uint64_t)i] = flat_image(r, from + (uint64_t)i, &out->box);
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
    if (cm_box_intersect(&r->box, &out->box, &both))
        flatten_part(r, &both, out);
}

cm_status cm_cluster_flatten(cm_cluster *c, const cm_box *box, cm_region *out, char *msg,
                             size_t msg_size)
{
    cm_status st = cm_flat_alloc(box, c->ngroups, out, msg, msg_size);
    for (uint32_t k = 0; k < c->nregions && st == CM_OK; k++) {
        cm_box both;
        if (!cm_box_intersect(&c->regions[k].r.box, box, &both))
            continue;
        st = cm_cluster_acquire(c, k, msg, msg_size);
        if (st == CM_OK)
            flatten_part(&c->regions[k].r, &both, out);
        cm_cluster_trim(c);
    }
    if (st != CM_OK)
        cm_region_free(out);
    return st;
}
