/* Clustered SCM: the invariant. For tilings of a box into 2, 3, 4 and 9
 * regions of unequal sizes, and 64 and 256 equal ones, joined in several
 * orders, and for a sequence of 200 pans, the cluster equals
 * simple cell mapping on the whole box cell by cell: the same images, the
 * same partition into groups up to renumbering, the same periodic cells and
 * step numbers. Models: the PD micro-chaos map (sec. 4.6.3 and Fig. 4.21
 * parameters), the 2-D delayed map, a 3-D map, random functional maps, and a
 * rotation whose periodic groups exist only across the borders. Also: group
 * ids of existing groups survive a join, and the thread count changes
 * nothing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/cover.h"
#include "cellmap/join.h"
#include "cellmap/join_stage1.h"
#include "check.h"
#include "mix.h"
#include "models/registry.h"

/* ---- tilings ------------------------------------------------------------ */

/* Splits [0, n) at the given fractions (ascending, in (0, 1)). */
static int cuts(int64_t n, const double *fractions, int nf, int64_t *at)
{
    at[0] = 0;
    for (int k = 0; k < nf; k++)
        at[k + 1] = (int64_t)llround(fractions[k] * (double)n);
    at[nf + 1] = n;
    return nf + 1;
}

/* Tiles `whole` (dims 0 and 1 cut, others whole) into a grid of boxes. */
static uint32_t tile(const cm_box *whole, const double *fx, int nfx, const double *fy, int nfy,
                     cm_box *boxes)
{
    int64_t ax[8], ay[8];
    const int nx = cuts(whole->hi[0] - whole->lo[0], fx, nfx, ax);
    const int ny = whole->dim > 1 ? cuts(whole->hi[1] - whole->lo[1], fy, nfy, ay) : 1;
    uint32_t n = 0;
    for (int j = 0; j < ny; j++) {
        for (int i = 0; i < nx; i++) {
            cm_box b = *whole;
            b.lo[0] = whole->lo[0] + ax[i];
            b.hi[0] = whole->lo[0] + ax[i + 1];
            if (whole->dim > 1) {
                b.lo[1] = whole->lo[1] + ay[j];
                b.hi[1] = whole->lo[1] + ay[j + 1];
            }
            boxes[n++] = b;
        }
    }
    return n;
}

/* ---- comparison --------------------------------------------------------- */

/* Equal up to a bijection of group ids that keeps the sink; returns the
 * number of differing cells (reports the first few). */
static uint64_t compare_regions(const char *what, const cm_region *a, const cm_region *b)
{
    uint32_t *a_to_b = calloc(a->ngroups + 2, sizeof *a_to_b);
    uint32_t *b_to_a = calloc(b->ngroups + 2, sizeof *b_to_a);
    uint64_t bad = 0;
    for (uint64_t i = 0; i < a->ncells; i++) {
        const uint32_t ga = a->group[i], gb = b->group[i];
        bool same = a->image[i] == b->image[i] && a->step[i] == b->step[i] &&
                    (ga == 0) == (gb == 0) && ga <= a->ngroups && gb <= b->ngroups;
        if (same && a_to_b[ga] == 0 && b_to_a[gb] == 0) {
            a_to_b[ga] = gb + 1;
            b_to_a[gb] = ga + 1;
        } else if (same) {
            same = a_to_b[ga] == gb + 1 && b_to_a[gb] == ga + 1;
        }
        if (!same && bad++ < 5)
            fprintf(stderr, "%s: cell %llu: image %u/%u group %u/%u step %u/%u\n", what,
                    (unsigned long long)i, a->image[i], b->image[i], ga, gb, a->step[i],
                    b->step[i]);
    }
    if (a->ngroups != b->ngroups) {
        fprintf(stderr, "%s: %u groups vs %u\n", what, a->ngroups, b->ngroups);
        bad++;
    }
    free(a_to_b);
    free(b_to_a);
    return bad;
}

static void solve_whole(const cm_model *m, const cm_lattice *lat, const cm_box *box, int max_steps,
                        cm_region *r)
{
    char msg[256];
    const cm_scm_options opt = {.max_steps = max_steps};
    CHECK(cm_region_alloc(r, box, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(m, lat, &opt, r, msg, sizeof msg) == CM_OK);
}

/* A flatten through the cache kept since the last join equals a fresh
 * flatten of the same cluster, cell by cell, open nodes included. */
static void check_cached_flatten(cm_cluster *c, const cm_box *view, cm_resolve_cache *cache)
{
    char msg[256];
    cm_region a, b;
    const uint64_t n = cm_box_cells(view);
    uint32_t *open_a = malloc(n * sizeof *open_a), *open_b = malloc(n * sizeof *open_b);
    CHECK(cm_cluster_flatten_cached(c, view, cache, &a, open_a, msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_flatten_open(c, view, &b, open_b, msg, sizeof msg) == CM_OK);
    uint64_t bad = 0;
    for (uint64_t i = 0; i < n; i++)
        bad += a.group[i] != b.group[i] || a.step[i] != b.step[i] || a.image[i] != b.image[i] ||
               open_a[i] != open_b[i];
    CHECK_INT(bad, 0);
    CHECK_INT(a.ngroups, b.ngroups);
    cm_region_free(&a);
    cm_region_free(&b);
    free(open_a);
    free(open_b);
}

/* Solves the boxes one by one, joins them in `order`, flattens over whole.
 * After each join a view (whole, or the box just joined) is flattened
 * through a cache kept since the first join (check_cached_flatten). */
static void solve_clustered(const cm_model *m, const cm_lattice *lat, const cm_box *whole,
                            const cm_box *boxes, const uint32_t *order, uint32_t n, int max_steps,
                            cm_region *flat, uint32_t *straddling)
{
    char msg[256];
    cm_cluster c;
    cm_cluster_init(&c, lat);
    const cm_scm_options opt = {.max_steps = max_steps, .record_exits = 1};
    cm_resolve_cache *cache = cm_resolve_cache_new();
    CHECK(cache != NULL);
    *straddling = 0;
    for (uint32_t k = 0; k < n; k++) {
        cm_region r;
        cm_join_stats stats;
        CHECK(cm_region_alloc(&r, &boxes[order[k]], msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(m, lat, &opt, &r, msg, sizeof msg) == CM_OK);
        CHECK(cm_cluster_join(&c, &r, &stats, msg, sizeof msg) == CM_OK);
        *straddling += stats.straddling_groups;
        check_cached_flatten(&c, k % 2 ? &boxes[order[k]] : whole, cache);
    }
    CHECK(cm_cluster_flatten(&c, whole, flat, msg, sizeof msg) == CM_OK);
    cm_resolve_cache_free(cache);
    cm_cluster_free(&c);
}

/* Every tiling, in natural, reversed and interleaved order, against the
 * whole box. Returns the straddling groups found by the 2x2 tiling. */
static uint32_t check_invariant(const char *name, const cm_model *m, const cm_lattice *lat,
                                const cm_box *whole, int max_steps)
{
    static const double f2[] = {0.37}, f3[] = {0.21, 0.58}, f3b[] = {0.4, 0.77};
    const struct {
        const double *fx, *fy;
        int nfx, nfy;
    } tilings[] = {{f2, NULL, 1, 0}, {f3, NULL, 2, 0}, {f2, f2, 1, 1}, {f3, f3b, 2, 2}};
    cm_region whole_r;
    solve_whole(m, lat, whole, max_steps, &whole_r);
    uint32_t straddling_2x2 = 0;
    for (size_t t = 0; t < sizeof tilings / sizeof tilings[0]; t++) {
        if (whole->dim == 1 && tilings[t].nfy > 0)
            continue;
        cm_box boxes[9];
        const uint32_t n =
            tile(whole, tilings[t].fx, tilings[t].nfx, tilings[t].fy, tilings[t].nfy, boxes);
        uint32_t orders[3][9];
        for (uint32_t k = 0; k < n; k++) {
            orders[0][k] = k;
            orders[1][k] = n - 1 - k;
            orders[2][k] = (k * 5 + 2) % n; /* n <= 9 and coprime with 5 except n = 5 */
        }
        for (int o = 0; o < 3; o++) {
            cm_region flat;
            uint32_t straddling;
            char what[128];
            snprintf(what, sizeof what, "%s, %u regions, order %d", name, n, o);
            solve_clustered(m, lat, whole, boxes, orders[o], n, max_steps, &flat, &straddling);
            CHECK_INT(compare_regions(what, &whole_r, &flat), 0);
            if (t == 2)
                straddling_2x2 = straddling;
            cm_region_free(&flat);
        }
    }
    fprintf(stderr, "%s: %u groups; 2x2 tiling found %u groups across borders\n", name,
            whole_r.ngroups, straddling_2x2);
    cm_region_free(&whole_r);
    return straddling_2x2;
}

/* ---- models --------------------------------------------------------------- */

static cm_model registry_model(const char *name, const char *params)
{
    cm_model m;
    char msg[256];
    const char *texts[1] = {params};
    if (cm_model_create(name, params ? texts : NULL, params ? 1 : 0, &m, msg, sizeof msg) !=
        CM_OK) {
        fprintf(stderr, "%s\n", msg);
        exit(1);
    }
    return m;
}

static void test_pd_maps(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {500.0 / 300, 80.0 / 240}};
    const cm_box whole = {2, {0, 0}, {300, 240}};
    check_invariant("PD sec. 4.6.3", &m, &lat, &whole, 1);
    cm_model_release(&m);

    m = registry_model("microchaos-pd", "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3");
    const cm_lattice lat21 = {2, {-125000, -600}, {250000.0 / 200, 1200.0 / 80}};
    const cm_box whole21 = {2, {0, 0}, {200, 80}};
    check_invariant("PD Fig. 4.21", &m, &lat21, &whole21, 1000);
    cm_model_release(&m);
}

/* n x n equal regions over whole (the last row and column take the rest). */
static uint32_t grid(const cm_box *whole, int64_t n, cm_box *boxes)
{
    const int64_t wx = (whole->hi[0] - whole->lo[0]) / n, wy = (whole->hi[1] - whole->lo[1]) / n;
    uint32_t k = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) {
            cm_box b = *whole;
            b.lo[0] = whole->lo[0] + i * wx;
            b.hi[0] = i == n - 1 ? whole->hi[0] : b.lo[0] + wx;
            b.lo[1] = whole->lo[1] + j * wy;
            b.hi[1] = j == n - 1 ? whole->hi[1] : b.lo[1] + wy;
            boxes[k++] = b;
        }
    return k;
}

/* Tilings of 64 and 256 regions (most cells of a small region are nodes
 * there), in order and scattered. */
static void test_many_regions(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {500.0 / 300, 80.0 / 240}};
    const cm_box whole = {2, {0, 0}, {300, 240}};
    cm_region whole_r;
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    static cm_box boxes[256];
    static uint32_t order[256];
    for (int64_t n = 8; n <= 16; n += 8) {
        const uint32_t count = grid(&whole, n, boxes);
        for (int o = 0; o < 2; o++) {
            for (uint32_t k = 0; k < count; k++)
                order[k] = o == 0 ? k : (k * 37 + 11) % count; /* 37 is coprime with 64, 256 */
            cm_region flat;
            uint32_t straddling;
            char what[128];
            snprintf(what, sizeof what, "PD sec. 4.6.3, %u regions, order %d", count, o);
            solve_clustered(&m, &lat, &whole, boxes, order, count, 1, &flat, &straddling);
            CHECK_INT(compare_regions(what, &whole_r, &flat), 0);
            fprintf(stderr, "%s: %u groups across borders\n", what, straddling);
            cm_region_free(&flat);
        }
    }
    cm_region_free(&whole_r);
    cm_model_release(&m);
}

/* The join order of large splits: a square grid keeps its row order; a
 * grid wider than high is scanned along its columns, a 3-D grid with its
 * dimension of most places slowest and of fewest fastest; every box once;
 * and a 16 x 8 grid joined in that order still equals the whole box. */
static void test_scan_order(void)
{
    const cm_box whole = {2, {0, 0}, {320, 240}};
    static cm_box boxes[256];
    uint32_t n = grid(&whole, 4, boxes);
    CHECK(cm_boxes_scan_order(boxes, n) == CM_OK);
    for (uint32_t k = 0; k < n; k++) {
        CHECK_INT(boxes[k].lo[0], (int64_t)(k % 4) * 80);
        CHECK_INT(boxes[k].lo[1], (int64_t)(k / 4) * 60);
    }
    n = 0;
    for (int j = 0; j < 8; j++) /* row order, as project_split makes it */
        for (int i = 0; i < 16; i++)
            boxes[n++] = (cm_box){2, {i * 20, j * 30}, {i * 20 + 20, j * 30 + 30}};
    CHECK(cm_boxes_scan_order(boxes, n) == CM_OK);
    for (uint32_t k = 0; k < n; k++) { /* columns of 8, left to right */
        CHECK_INT(boxes[k].lo[0], (int64_t)(k / 8) * 20);
        CHECK_INT(boxes[k].lo[1], (int64_t)(k % 8) * 30);
    }
    cm_box cube[24];
    uint32_t m3 = 0;
    for (int z = 0; z < 3; z++)
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 2; x++)
                cube[m3++] = (cm_box){3, {x, y, z}, {x + 1, y + 1, z + 1}};
    CHECK(cm_boxes_scan_order(cube, m3) == CM_OK);
    uint32_t seen = 0;
    for (uint32_t k = 0; k < m3; k++) { /* y slowest (4 places), then z (3), x fastest (2) */
        CHECK_INT(cube[k].lo[0], (int64_t)(k % 2));
        CHECK_INT(cube[k].lo[2], (int64_t)(k / 2 % 3));
        CHECK_INT(cube[k].lo[1], (int64_t)(k / 6));
        seen |= 1u << (cube[k].lo[2] * 8 + cube[k].lo[1] * 2 + cube[k].lo[0]);
    }
    CHECK_INT(seen, 0xFFFFFF);

    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {500.0 / 320, 80.0 / 240}};
    cm_region whole_r, flat;
    char msg[256];
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(&c, &m, boxes, n, &opt, NULL, NULL, NULL, msg, sizeof msg) ==
          CM_OK);
    CHECK(cm_cluster_flatten(&c, &whole, &flat, msg, sizeof msg) == CM_OK);
    CHECK_INT(compare_regions("16 x 8 regions in scan order", &whole_r, &flat), 0);
    cm_cluster_free(&c);
    cm_region_free(&flat);
    cm_region_free(&whole_r);
    cm_model_release(&m);
}

/* A joined callback that fails after `left` joins. */
static cm_status stop_after(void *user, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                            char *msg, size_t msg_size)
{
    int *left = user;
    (void)c, (void)box, (void)stats;
    return --*left > 0 ? CM_OK : cm_fail(CM_EINVAL, msg, msg_size, "stopped on purpose");
}

/* cm_cluster_solve_boxes hands exits between its boxes over without the
 * index of escapes: the cluster it makes (keeping exit tables or not)
 * equals joins one by one in the same order, byte for byte, on a cluster that already has a region (whose
 * open nodes lead into the boxes), for grids of 64 and 256 regions in
 * order and scattered; and a solve stopped half-way leaves the exits handed
 * to the boxes it did not join where later joins find them. */
static void test_solve_boxes_equals_joins(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {500.0 / 300, 80.0 / 240}};
    const cm_box whole = {2, {0, 0}, {300, 240}};
    const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
    cm_region whole_r;
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    static cm_box boxes[256], ordered[256];
    char msg[256];
    for (int64_t n = 8; n <= 16; n += 8) {
        const uint32_t count = grid(&whole, n, boxes);
        for (int o = 0; o < 2; o++) {
            for (uint32_t k = 0; k < count; k++)
                ordered[k] = boxes[o == 0 ? k : (k * 37 + 11) % count];
            cm_region flat[3];
            for (int way = 0; way < 3; way++) {
                cm_cluster c;
                cm_cluster_init(&c, &lat);
                c.threads = 2;
                c.keep_exits = way != 0; /* no one saves the first or reads its images */
                for (uint32_t k = 0; k < count; k++) {
                    /* the first region joins alone; the rest as the way says:
                     * one solve_boxes, joins one by one, or a solve_boxes that
                     * stops half-way followed by joins */
                    if (k > 0 && way != 1) {
                        int left = way == 0 ? INT32_MAX : (int)count / 2;
                        const cm_status st = cm_cluster_solve_boxes(
                            &c, &m, ordered + 1, count - 1, &opt, stop_after, &left, NULL, msg,
                            sizeof msg);
                        CHECK(way == 0 ? st == CM_OK : st == CM_EINVAL);
                        k = c.nregions;
                        if (k >= count)
                            break;
                    }
                    cm_region r;
                    CHECK(cm_region_alloc(&r, &ordered[k], msg, sizeof msg) == CM_OK);
                    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
                    CHECK(cm_cluster_join(&c, &r, NULL, msg, sizeof msg) == CM_OK);
                }
                CHECK_INT(c.nregions, count);
                CHECK(cm_cluster_flatten(&c, &whole, &flat[way], msg, sizeof msg) == CM_OK);
                cm_cluster_free(&c);
            }
            char what[128];
            snprintf(what, sizeof what, "solve_boxes, %u regions, order %d", count, o);
            CHECK_INT(compare_regions(what, &whole_r, &flat[1]), 0);
            for (int way = 1; way < 3; way++) {
                CHECK_INT(flat[way].ngroups, flat[0].ngroups);
                CHECK(memcmp(flat[0].group, flat[way].group, flat[0].ncells * 4) == 0);
                CHECK(memcmp(flat[0].step, flat[way].step, flat[0].ncells * 4) == 0);
            }
            CHECK(memcmp(flat[1].image, flat[2].image, flat[0].ncells * 4) == 0);
            /* the first kept no exit table: its exits' images are unknown, the
             * others are the same */
            uint64_t unknown = 0, other = 0;
            for (uint64_t i = 0; i < flat[0].ncells; i++) {
                unknown += flat[0].image[i] == CM_IMAGE_EXIT && flat[1].image[i] < flat[1].ncells;
                other += flat[0].image[i] != flat[1].image[i] && flat[0].image[i] != CM_IMAGE_EXIT;
            }
            CHECK(unknown > 0);
            CHECK_INT(other, 0);
            for (int way = 0; way < 3; way++)
                cm_region_free(&flat[way]);
        }
    }
    cm_region_free(&whole_r);
    cm_model_release(&m);
}

/* 200 pans of an explore session: a view 40 cells wide pans right 100
 * times, then back and 100 times left of where it began, each pan joining
 * the strip of 2 columns it uncovers; the cluster then equals the whole
 * box it covers. */
static void test_pan_sequence(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {-200, -40}, {500.0 / 300, 80.0 / 60}};
    const cm_box whole = {2, {-200, 0}, {240, 60}};
    static cm_box boxes[201];
    static uint32_t order[201];
    uint32_t n = 0;
    boxes[n++] = (cm_box){2, {0, 0}, {40, 60}};
    for (int k = 0; k < 100; k++)
        boxes[n++] = (cm_box){2, {40 + 2 * k, 0}, {42 + 2 * k, 60}};
    for (int k = 0; k < 100; k++)
        boxes[n++] = (cm_box){2, {-2 - 2 * k, 0}, {-2 * k, 60}};
    for (uint32_t k = 0; k < n; k++)
        order[k] = k;
    cm_region whole_r, flat;
    uint32_t straddling;
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    solve_clustered(&m, &lat, &whole, boxes, order, n, 1, &flat, &straddling);
    CHECK_INT(compare_regions("PD sec. 4.6.3, 200 pans", &whole_r, &flat), 0);
    fprintf(stderr, "PD sec. 4.6.3, 200 pans: %u groups, %u across borders\n", whole_r.ngroups,
            straddling);
    cm_region_free(&whole_r);
    cm_region_free(&flat);
    cm_model_release(&m);
}

static void test_delay_and_3d(void)
{
    cm_model m = registry_model("microchaos-delay", NULL);
    const cm_lattice lat = {2, {-12, -12}, {0.1, 0.1}};
    const cm_box whole = {2, {0, 0}, {240, 240}};
    check_invariant("delayed map", &m, &lat, &whole, 1);
    cm_model_release(&m);

    m = registry_model("microchaos-general", "n=1,d=2,A=1.5,B=-1,K=0.6:0.2:0.1");
    const cm_lattice lat3 = {3, {-6, -6, -6}, {0.5, 0.5, 0.5}};
    const cm_box whole3 = {3, {0, 0, 0}, {24, 24, 24}};
    check_invariant("3-D map", &m, &lat3, &whole3, 1);
    cm_model_release(&m);
}

/* ---- hand-made maps --------------------------------------------------------- */

static cm_model hand_model(int dim, int (*step)(const cm_model *, const double *, double *),
                           void *ctx)
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "test";
    m.dim = dim;
    m.step = step;
    m.ctx = ctx;
    return m;
}

/* Each cell moves by a pseudo-random offset of -2..2 cells per dimension
 * (many small cycles, some across borders, long trees), or one time in eight
 * jumps to a pseudo-random cell of a box a little larger than the region. */
static int random_step(const cm_model *m, const double *x, double *y)
{
    const uint64_t *seed = m->ctx;
    uint64_t h = *seed;
    for (int d = 0; d < m->dim; d++)
        h = mix(h ^ (uint64_t)(int64_t)floor(x[d]));
    const bool jump = (h & 7) == 0;
    for (int d = 0; d < m->dim; d++) {
        h = mix(h + (uint64_t)d);
        y[d] = jump ? (double)((int64_t)(h % 34) - 2) + 0.5 : x[d] + (double)((int64_t)(h % 5) - 2);
    }
    return 0;
}

static void test_random_maps(void)
{
    for (uint64_t seed = 1; seed <= 6; seed++) {
        const int dim = 1 + (int)(seed % 3);
        cm_model m = hand_model(dim, random_step, &seed);
        const cm_lattice lat = {dim, {0, 0, 0}, {1, 1, 1}};
        const cm_box whole = {dim, {0, 0, 0}, {30, 30, 30}};
        char name[64];
        snprintf(name, sizeof name, "random map %llu (%d-D)", (unsigned long long)seed, dim);
        check_invariant(name, &m, &lat, &whole, 1);
    }
}

/* Rotation by a quarter turn about the centre of a 20x20 box: every orbit
 * visits all four quadrants, so with a 2x2 tiling each group exists only
 * across the borders. */
static int quarter_turn(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = 20 - x[1];
    y[1] = x[0];
    return 0;
}

static void test_straddling_groups(void)
{
    cm_model m = hand_model(2, quarter_turn, NULL);
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    const cm_box whole = {2, {0, 0}, {20, 20}};
    static const double half[] = {0.5};
    cm_box boxes[4];
    tile(&whole, half, 1, half, 1, boxes);
    const uint32_t order[4] = {0, 1, 2, 3};
    cm_region whole_r, flat;
    uint32_t straddling;
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    solve_clustered(&m, &lat, &whole, boxes, order, 4, 1, &flat, &straddling);
    CHECK_INT(whole_r.ngroups, 100); /* 400 cells in orbits of 4 */
    CHECK_INT(straddling, 100);
    CHECK_INT(compare_regions("quarter turn 2x2", &whole_r, &flat), 0);
    cm_region_free(&whole_r);
    cm_region_free(&flat);
}

/* Groups that existed before a join keep their ids and cells. */
static void test_ids_stable(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {1, 0.25}};
    const cm_box left = {2, {0, 0}, {250, 320}}, right = {2, {250, 0}, {500, 320}};
    const cm_scm_options opt = {.max_steps = 1, .record_exits = 1};
    char msg[256];
    cm_cluster c;
    cm_region r;
    cm_cluster_init(&c, &lat);
    CHECK(cm_region_alloc(&r, &left, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_join(&c, &r, NULL, msg, sizeof msg) == CM_OK);
    const uint64_t n = c.regions[0].r.ncells;
    uint32_t *before = malloc(n * sizeof *before);
    memcpy(before, c.regions[0].r.group, n * sizeof *before);
    CHECK(c.ngroups > 0);
    CHECK(cm_region_alloc(&r, &right, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
    cm_join_stats stats;
    CHECK(cm_cluster_join(&c, &r, &stats, msg, sizeof msg) == CM_OK);
    uint64_t kept = 0, had = 0;
    for (uint64_t i = 0; i < n; i++) {
        had += before[i] != 0;
        kept += before[i] != 0 && c.regions[0].r.group[i] == before[i];
    }
    CHECK(had > 0);
    CHECK_INT(kept, had);
    /* overlapping boxes are refused */
    const cm_box overlap = {2, {240, 0}, {260, 10}};
    CHECK(cm_region_alloc(&r, &overlap, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_join(&c, &r, NULL, msg, sizeof msg) == CM_EINVAL);
    cm_region_free(&r);
    free(before);
    cm_cluster_free(&c);
    cm_model_release(&m);
}

/* cm_cluster_solve_boxes gives the same bytes with 1 and 2 threads, for the
 * regions and for the joins (regions big enough for the joins' parallel
 * passes). */
static void test_threads_identical(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {0, -40}, {0.5, 0.125}};
    const cm_box whole = {2, {0, 0}, {1000, 640}};
    static const double f[] = {0.3, 0.55};
    cm_box boxes[9];
    const uint32_t n = tile(&whole, f, 2, f, 2, boxes);
    cm_region flat[2];
    char msg[256];
    for (int t = 0; t < 2; t++) {
        cm_cluster c;
        cm_cluster_init(&c, &lat);
        c.threads = t + 1;
        const cm_scm_options opt = {.max_steps = 1, .threads = t + 1, .record_exits = 1};
        CHECK(cm_cluster_solve_boxes(&c, &m, boxes, n, &opt, NULL, NULL, NULL, msg, sizeof msg) ==
              CM_OK);
        CHECK(cm_cluster_flatten(&c, &whole, &flat[t], msg, sizeof msg) == CM_OK);
        cm_cluster_free(&c);
    }
    CHECK(memcmp(flat[0].image, flat[1].image, flat[0].ncells * 4) == 0);
    CHECK(memcmp(flat[0].group, flat[1].group, flat[0].ncells * 4) == 0);
    CHECK(memcmp(flat[0].step, flat[1].step, flat[0].ncells * 4) == 0);
    cm_region whole_r;
    solve_whole(&m, &lat, &whole, 1, &whole_r);
    CHECK_INT(compare_regions("solve_boxes 3x3", &whole_r, &flat[0]), 0);
    cm_region_free(&whole_r);
    cm_region_free(&flat[0]);
    cm_region_free(&flat[1]);
    cm_model_release(&m);
}

/* Figs. 4.26-4.28 (alpha = 0.07, beta = 0, P = 0.007, D = 0.02): regions
 * x in [85.4, 285.4] and [285.4, 485.4], x' in [-12.5, 12.5], 1000x1000
 * cells each. The attractors at SW_2 (x = 2/P = 285.71) straddle the shared
 * border: neither region finds them alone, the join does, and the joined
 * cluster equals the 2000x1000 union solve. */
static void test_figs_4_26_to_4_28(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.07,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {85.4, -12.5}, {0.2, 0.025}};
    const cm_box left = {2, {0, 0}, {1000, 1000}}, right = {2, {1000, 0}, {2000, 1000}};
    const cm_box whole = {2, {0, 0}, {2000, 1000}};
    const cm_scm_options opt = {.max_steps = 1, .record_exits = 1};
    const double sw2 = 2 / 0.007;
    char msg[256];
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    int near_sw2_alone = 0;
    for (int k = 0; k < 2; k++) {
        cm_region r;
        CHECK(cm_region_alloc(&r, k ? &right : &left, msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
        cm_group_info *g = calloc(r.ngroups + 1, sizeof *g);
        cm_scm_groups(&r, &lat, g, NULL);
        for (uint32_t i = 0; i < r.ngroups; i++)
            near_sw2_alone += fabs(g[i].centre[0] - sw2) < 1.0;
        free(g);
        cm_join_stats stats;
        CHECK(cm_cluster_join(&c, &r, &stats, msg, sizeof msg) == CM_OK);
        if (k == 1)
            CHECK(stats.straddling_groups > 0);
    }
    cm_region flat, union_r;
    CHECK(cm_cluster_flatten(&c, &whole, &flat, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(flat.ngroups + 1, sizeof *g);
    cm_scm_groups(&flat, &lat, g, NULL);
    int near_sw2_joined = 0;
    for (uint32_t i = 0; i < flat.ngroups; i++)
        near_sw2_joined +=
            fabs(g[i].centre[0] - sw2) < 1.0 && g[i].lo[0] < 285.4 && g[i].hi[0] > 285.4;
    fprintf(stderr,
            "Figs 4.26-4.28: %d groups near SW_2 in the regions alone, %d straddling "
            "ones after the join\n",
            near_sw2_alone, near_sw2_joined);
    CHECK_INT(near_sw2_alone, 0);
    CHECK(near_sw2_joined > 0);
    solve_whole(&m, &lat, &whole, 1, &union_r);
    CHECK_INT(compare_regions("Figs 4.26-4.28", &union_r, &flat), 0);
    free(g);
    cm_region_free(&flat);
    cm_region_free(&union_r);
    cm_cluster_free(&c);
    cm_model_release(&m);
}

/* Fig. 4.27: Stage 1 alone on the regions of Figs. 4.26-4.28. Whatever
 * Stage 1 decides is final: a cell it sends to a group is in that group
 * (same anchor) after the whole join, and a cell it leaves in the sink
 * without a pending chain is in the sink; only the pending cells (Case 2,
 * the red bands of Fig. 4.27) are left to Stage 2. */
static void test_join_stage1(void)
{
    cm_model m = registry_model("microchaos-pd", "alpha=0.07,beta=0,P=0.007,D=0.02");
    const cm_lattice lat = {2, {85.4, -12.5}, {0.2, 0.025}};
    const cm_box boxes[2] = {{2, {0, 0}, {1000, 1000}}, {2, {1000, 0}, {2000, 1000}}};
    const cm_box whole = {2, {0, 0}, {2000, 1000}};
    const cm_scm_options opt = {.max_steps = 1, .record_exits = 1};
    char msg[256];
    cm_region parts[2], flat;
    uint8_t *pending[2];
    cm_group_info *alone[2];
    uint32_t uids = 0;
    for (int k = 0; k < 2; k++) {
        CHECK(cm_region_alloc(&parts[k], &boxes[k], msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(&m, &lat, &opt, &parts[k], msg, sizeof msg) == CM_OK);
        alone[k] = calloc(parts[k].ngroups + 1, sizeof *alone[k]);
        cm_scm_groups(&parts[k], &lat, alone[k], NULL);
        pending[k] = malloc(parts[k].ncells);
        uids += parts[k].ngroups;
    }
    const uint32_t n_left = parts[0].ngroups;
    cm_stage1_stats stats;
    CHECK(cm_join_stage1(parts, 2, pending, &stats, msg, sizeof msg) == CM_OK);
    CHECK_INT(parts[0].ngroups, uids);
    CHECK_INT(stats.to_group + stats.to_sink + stats.pending, stats.sink_cells);
    CHECK(stats.to_group > 0 && stats.pending > 0);

    cm_cluster c;
    cm_cluster_init(&c, &lat);
    for (int k = 0; k < 2; k++) {
        cm_region r;
        cm_join_stats js;
        CHECK(cm_region_alloc(&r, &boxes[k], msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
        CHECK(cm_cluster_join(&c, &r, &js, msg, sizeof msg) == CM_OK);
    }
    CHECK(cm_cluster_flatten(&c, &whole, &flat, msg, sizeof msg) == CM_OK);
    cm_group_info *joined = calloc(flat.ngroups + 1, sizeof *joined);
    cm_scm_groups(&flat, &lat, joined, NULL);
    uint64_t wrong = 0, pending_cells = 0, pending_to_groups = 0;
    for (int k = 0; k < 2; k++)
        for (uint64_t i = 0; i < parts[k].ncells; i++) {
            int64_t cell[CM_MAX_DIM];
            cm_box_cell(&boxes[k], i, cell);
            const uint32_t g = parts[k].group[i], fin = flat.group[cm_box_index(&whole, cell)];
            if (pending[k][i]) {
                pending_cells++;
                pending_to_groups += fin != 0;
                continue;
            }
            if (g == 0) {
                wrong += fin != 0;
                continue;
            }
            const cm_group_info *gi = g <= n_left ? &alone[0][g - 1] : &alone[1][g - n_left - 1];
            wrong += fin == 0 || memcmp(gi->anchor, joined[fin - 1].anchor, 2 * sizeof(int64_t));
        }
    fprintf(stderr,
            "Fig. 4.27: Stage 1 sends %llu sink cells to groups, %llu to the sink, leaves "
            "%llu pending (%llu of them reach groups in Stage 2); %llu cells disagree\n",
            (unsigned long long)stats.to_group, (unsigned long long)stats.to_sink,
            (unsigned long long)stats.pending, (unsigned long long)pending_to_groups,
            (unsigned long long)wrong);
    CHECK_INT(wrong, 0);
    CHECK_INT(pending_cells, stats.pending);
    CHECK(pending_to_groups > 0);
    free(joined);
    cm_region_free(&flat);
    cm_cluster_free(&c);
    for (int k = 0; k < 2; k++) {
        free(alone[k]);
        free(pending[k]);
        cm_region_free(&parts[k]);
    }
    cm_model_release(&m);
}

int main(void)
{
    test_straddling_groups();
    test_random_maps();
    test_pd_maps();
    test_delay_and_3d();
    test_many_regions();
    test_solve_boxes_equals_joins();
    test_scan_order();
    test_pan_sequence();
    test_ids_stable();
    test_threads_identical();
    test_figs_4_26_to_4_28();
    test_join_stage1();
    CHECK_DONE();
}
