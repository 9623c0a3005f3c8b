#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/classify.h"
#include "cellmap/scm.h"
#include "check.h"
#include "mix.h"
#include "models/registry.h"

/* ---- hand-made maps ---------------------------------------------------- */

static int contraction(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = 0.1 * (x[0] - 0.34) + 0.34;
    y[1] = 0.1 * (x[1] - 0.76) + 0.76;
    return 0;
}

static int quarter_turn(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = -x[1];
    y[1] = x[0];
    return 0;
}

static int half_turn(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = -x[0];
    y[1] = -x[1];
    return 0;
}

static int shift_right(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = x[0] + 0.35;
    return 0;
}

static int creep(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = x[0] + 0.01;
    return 0;
}

static int no_image(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = x[0] > 0.5 ? NAN : x[0];
    return x[0] < 0.25 ? CM_STEP_NO_IMAGE : 0;
}

/* A random functional graph: each cell maps to a pseudo-random cell of a
 * box a little larger than the region (so some images leave). */
typedef struct random_map {
    int64_t lo, hi; /* target range per dimension */
    uint64_t seed;
} random_map;

static int random_step(const cm_model *m, const double *x, double *y)
{
    const random_map *r = m->ctx;
    uint64_t h = r->seed;
    for (int d = 0; d < m->dim; d++)
        h = mix(h ^ (uint64_t)(int64_t)floor(x[d]));
    const uint64_t span = (uint64_t)(r->hi - r->lo);
    for (int d = 0; d < m->dim; d++) {
        h = mix(h + (uint64_t)d);
        /* Bias towards few targets so that long trees and shared cycles form. */
        y[d] = (double)(r->lo + (int64_t)(h % span) / (1 + (int64_t)(h >> 60) % 3)) + 0.5;
    }
    return 0;
}

static cm_model hand_model(int dim, int (*step)(const cm_model *, const double *, double *))
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "test";
    m.dim = dim;
    m.step = step;
    return m;
}

static cm_status solve(const cm_model *m, const cm_lattice *lat, const cm_box *box, int threads,
                       int max_steps, cm_region *r)
{
    char msg[256];
    cm_status st = cm_region_alloc(r, box, msg, sizeof msg);
    const cm_scm_options opt = {.max_steps = max_steps, .threads = threads};
    if (st == CM_OK)
        st = cm_scm_solve(m, lat, &opt, r, msg, sizeof msg);
    if (st != CM_OK)
        fprintf(stderr, "solve: %s\n", msg);
    return st;
}

/* ---- brute force ------------------------------------------------------- */

/* Classifies every cell by walking its own sequence; compares with r:
 * the same partition (bijection of group ids, sink <-> sink), the same
 * periodic cells and the same step numbers. Returns mismatches. */
static int compare_with_brute_force(const cm_region *r)
{
    const uint64_t n = r->ncells;
    int64_t *seen = malloc(n * sizeof *seen);
    uint32_t *cycle_id = malloc(n * sizeof *cycle_id); /* brute: min cell of the cycle + 1 */
    uint32_t *brute_to_engine = calloc(n + 1, sizeof *brute_to_engine);
    uint32_t *engine_to_brute = calloc(r->ngroups + 1, sizeof *engine_to_brute);
    int bad = 0;
    for (uint64_t i = 0; i < n; i++)
        seen[i] = -1;
    for (uint64_t start = 0; start < n && bad < 10; start++) {
        uint64_t cell = start, len = 0;
        uint32_t id = 0, steps = 0;
        bool periodic = false;
        while (cell < n && seen[cell] < 0) {
            seen[cell] = (int64_t)len++;
            cell = r->image[cell];
        }
        if (cell >= n) {
            steps = (uint32_t)len;
        } else {
            steps = (uint32_t)seen[cell];
            uint64_t c = cell, min = cell;
            do {
                min = c < min ? c : min;
                c = r->image[c];
            } while (c != cell);
            id = (uint32_t)min + 1;
            periodic = steps == 0;
        }
        /* reset the marks of this walk */
        for (uint64_t c = start, k = 0; k < len; k++, c = r->image[c])
            seen[c] = -1;
        cycle_id[start] = id;
        const uint32_t g = r->group[start];
        if (g > r->ngroups) {
            bad++;
            continue;
        }
        if ((id == 0) != (g == 0) || r->step[start] != steps || (periodic != (r->step[start] == 0 && g != 0))) {
            fprintf(stderr, "cell %llu: engine group %u step %u, brute id %u step %u\n",
                    (unsigned long long)start, g, r->step[start], id, steps);
            bad++;
        }
        if (brute_to_engine[id] == 0 && engine_to_brute[g] == 0) {
            brute_to_engine[id] = g + 1;
            engine_to_brute[g] = id + 1;
        } else if (brute_to_engine[id] != g + 1 || engine_to_brute[g] != id + 1) {
            fprintf(stderr, "cell %llu: partition differs (engine %u, brute %u)\n",
                    (unsigned long long)start, g, id);
            bad++;
        }
    }
    free(seen);
    free(cycle_id);
    free(brute_to_engine);
    free(engine_to_brute);
    return bad;
}

/* ---- tests -------------------------------------------------------------- */

static void test_contraction(void)
{
    const cm_model m = hand_model(2, contraction);
    const cm_lattice lat = {2, {0, 0}, {0.1, 0.1}};
    const cm_box box = {2, {0, 0}, {10, 10}};
    cm_region r;
    CHECK(solve(&m, &lat, &box, 2, 1, &r) == CM_OK);
    CHECK_INT(r.ngroups, 1);
    const int64_t fixed[2] = {3, 7};
    const uint64_t k = cm_box_index(&box, fixed);
    CHECK_INT(r.image[k], k);
    CHECK_INT(r.step[k], 0);
    for (uint64_t i = 0; i < r.ncells; i++)
        CHECK_INT(r.group[i], 1);
    const int64_t corner[2] = {0, 0}; /* y: 0.05 -> 0.689 (cell 6) -> 0.749 (cell 7) */
    CHECK_INT(r.step[cm_box_index(&box, corner)], 2);
    CHECK_INT(compare_with_brute_force(&r), 0);
    cm_group_info g;
    uint64_t sink = 99;
    cm_scm_groups(&r, &lat, &g, &sink);
    CHECK_INT(sink, 0);
    CHECK_INT(g.period, 1);
    CHECK_INT(g.basin_cells, 100);
    CHECK_NEAR(g.centre[0], 0.35, 1e-12);
    CHECK_NEAR(g.centre[1], 0.75, 1e-12);
    cm_region_free(&r);
}

static void test_rotation(int quarter)
{
    const cm_model m = hand_model(2, quarter ? quarter_turn : half_turn);
    const cm_lattice lat = {2, {-1, -1}, {0.2, 0.2}};
    const cm_box box = {2, {0, 0}, {10, 10}};
    const uint32_t k = quarter ? 4 : 2;
    cm_region r;
    CHECK(solve(&m, &lat, &box, 2, 1, &r) == CM_OK);
    CHECK_INT(r.ngroups, 100 / k);
    cm_group_info *g = calloc(r.ngroups, sizeof *g);
    cm_scm_groups(&r, &lat, g, NULL);
    for (uint32_t i = 0; i < r.ngroups; i++) {
        CHECK_INT(g[i].period, k);
        CHECK_INT(g[i].basin_cells, k);
        CHECK_NEAR(g[i].centre[0], 0.0, 1e-12); /* symmetric about the origin */
    }
    for (uint64_t i = 0; i < r.ncells; i++)
        CHECK_INT(r.step[i], 0);
    CHECK_INT(compare_with_brute_force(&r), 0);
    free(g);
    cm_region_free(&r);
}

static void test_leaving(void)
{
    const cm_model m = hand_model(1, shift_right);
    const cm_lattice lat = {1, {0}, {0.1}};
    const cm_box box = {1, {0}, {10}};
    cm_region r;
    CHECK(solve(&m, &lat, &box, 1, 1, &r) == CM_OK);
    CHECK_INT(r.ngroups, 0);
    /* cell 9 (0.95) leaves at once; cell 0 (0.05 -> .4 -> .75 -> 1.1) after 3 steps */
    CHECK_INT(r.image[9], CM_IMAGE_EXIT);
    CHECK_INT(r.step[9], 1);
    CHECK_INT(r.step[0], 3);
    for (uint64_t i = 0; i < r.ncells; i++)
        CHECK_INT(r.group[i], 0);
    CHECK_INT(compare_with_brute_force(&r), 0);
    cm_region_free(&r);
}

static void test_no_image(void)
{
    const cm_model m = hand_model(1, no_image);
    const cm_lattice lat = {1, {0}, {0.1}};
    const cm_box box = {1, {0}, {10}};
    cm_region r;
    CHECK(solve(&m, &lat, &box, 2, 1, &r) == CM_OK);
    CHECK_INT(r.image[0], CM_IMAGE_SINK); /* step said "no image" */
    CHECK_INT(r.image[7], CM_IMAGE_SINK); /* NaN image: outside the world */
    CHECK_INT(r.image[3], 3);             /* identity in the middle */
    CHECK_INT(r.group[7], 0);
    CHECK_INT(r.group[0], 0);
    CHECK_INT(r.group[2], 1); /* cells 0, 1 go to the sink: cell 2 is the first group */
    CHECK_INT(r.group[3], 2);
    CHECK_INT(r.ngroups, 3);  /* cells 2..4 are fixed; 5..9 have NaN images */
    cm_region_free(&r);
}

static void test_max_steps(void)
{
    const cm_model m = hand_model(1, creep);
    const cm_lattice lat = {1, {0}, {0.1}};
    const cm_box box = {1, {0}, {10}};
    cm_region r;
    CHECK(solve(&m, &lat, &box, 1, 1, &r) == CM_OK);
    CHECK_INT(r.image[2], 2); /* 0.25 + 0.01 stays in cell 2: a spurious fixed cell */
    CHECK_INT(r.ngroups, 10);
    cm_region_free(&r);
    CHECK(solve(&m, &lat, &box, 1, 20, &r) == CM_OK);
    CHECK_INT(r.image[2], 3); /* re-stepped until it left its cell */
    CHECK_INT(r.ngroups, 0);
    cm_region_free(&r);
    CHECK(solve(&m, &lat, &box, 1, 3, &r) == CM_OK);
    CHECK_INT(r.image[2], 2); /* three steps are not enough */
    cm_region_free(&r);
    /* the exact step: the n steps that take cell 2's centre out of it are
     * allowed by max_steps = n, not by n - 1 */
    double x = 0.25, y;
    int64_t cell = 2;
    int n = 0;
    while (cell == 2 && n < 100) {
        m.step(&m, &x, &y);
        x = y;
        n++;
        CHECK(cm_lattice_cell(&lat, &x, &cell));
    }
    CHECK(n > 3 && cell == 3);
    CHECK(solve(&m, &lat, &box, 1, n, &r) == CM_OK);
    CHECK_INT(r.image[2], 3);
    cm_region_free(&r);
    CHECK(solve(&m, &lat, &box, 1, n - 1, &r) == CM_OK);
    CHECK_INT(r.image[2], 2);
    cm_region_free(&r);
}

static void test_random_maps(void)
{
    uint64_t groups = 0, sink_cells = 0;
    for (uint64_t seed = 1; seed <= 12; seed++) {
        const int dim = 1 + (int)(seed % 3);
        random_map rm = {-1, 13, seed};
        cm_model m = hand_model(dim, random_step);
        m.ctx = &rm;
        const cm_lattice lat = {dim, {0, 0, 0}, {1, 1, 1}};
        const cm_box box = {dim, {0, 0, 0}, {12, 12, 12}};
        cm_region r;
        CHECK(solve(&m, &lat, &box, 2, 1, &r) == CM_OK);
        groups += r.ngroups;
        for (uint64_t i = 0; i < r.ncells; i++)
            sink_cells += r.group[i] == 0;
        CHECK_INT(compare_with_brute_force(&r), 0);
        cm_region_free(&r);
    }
    /* the maps must exercise both outcomes */
    fprintf(stderr, "random maps: %llu groups, %llu sink cells\n", (unsigned long long)groups,
            (unsigned long long)sink_cells);
    CHECK(groups > 12);
    CHECK(sink_cells > 100);
}

/* cm_scm_slow_share against its definition, by cm_box_cell, on random
 * images (some to the sink, some fixed) in boxes of unequal sides off the
 * origin, on 1 to 3 threads (the last box is big enough to be shared out,
 * with shares that start mid-row). */
static void test_slow_share(void)
{
    const cm_box boxes[] = {{1, {-3}, {17}},
                            {2, {-2, 5}, {5, 9}},
                            {3, {-2, 5, 1}, {5, 9, 4}},
                            {3, {-7, 2, -1}, {60, 53, 40}}};
    uint64_t x = 12345;
    for (size_t b = 0; b < sizeof boxes / sizeof *boxes; b++) {
        const cm_box *box = &boxes[b];
        cm_region r;
        char msg[256];
        CHECK(cm_region_alloc(&r, box, msg, sizeof msg) == CM_OK);
        for (uint32_t i = 0; i < r.ncells; i++) {
            x = x * 6364136223846793005u + 1442695040888963407u;
            const uint32_t pick = (uint32_t)(x >> 33);
            r.image[i] = pick % 7 == 0 ? CM_IMAGE_SINK : pick % 7 == 1 ? i : pick % (uint32_t)r.ncells;
        }
        uint64_t moved = 0, same[CM_MAX_DIM] = {0};
        for (uint32_t i = 0; i < r.ncells; i++) {
            if (r.image[i] >= r.ncells || r.image[i] == i)
                continue;
            int64_t from[CM_MAX_DIM], to[CM_MAX_DIM];
            cm_box_cell(box, i, from);
            cm_box_cell(box, r.image[i], to);
            moved++;
            for (int d = 0; d < box->dim; d++)
                same[d] += from[d] == to[d];
        }
        for (int threads = 1; threads <= 3; threads++) {
            double share[CM_MAX_DIM];
            cm_scm_slow_share(&r, threads, share);
            for (int d = 0; d < box->dim; d++)
                CHECK_NEAR(share[d], (double)same[d] / (double)moved, 0);
        }
        for (int d = 0; d < box->dim && box->dim > 1; d++) /* both outcomes, in 2-D and 3-D */
            CHECK(same[d] > 0 && same[d] < moved);
        cm_region_free(&r);
    }
}

static void test_threads_identical(void)
{
    cm_model m;
    char msg[256];
    CHECK(cm_model_create("microchaos-pd", NULL, 0, &m, msg, sizeof msg) == CM_OK);
    const cm_lattice lat = {2, {0, -40}, {0.5, 0.1}};
    const cm_box box = {2, {0, 0}, {1000, 800}};
    cm_region a, b;
    CHECK(solve(&m, &lat, &box, 1, 1, &a) == CM_OK);
    CHECK(solve(&m, &lat, &box, 2, 1, &b) == CM_OK);
    CHECK_INT(a.ngroups, b.ngroups);
    CHECK(memcmp(a.image, b.image, a.ncells * 4) == 0);
    CHECK(memcmp(a.group, b.group, a.ncells * 4) == 0);
    CHECK(memcmp(a.step, b.step, a.ncells * 4) == 0);
    CHECK_INT(compare_with_brute_force(&a), 0);
    cm_region_free(&a);
    cm_region_free(&b);
    cm_model_release(&m);
}

/* x -> x + (the model's ctx, a double) */
static int shift(const cm_model *m, const double *x, double *y)
{
    y[0] = x[0] + *(const double *)m->ctx;
    return 0;
}

/* 1000 cells of a 1-D lattice of unit cells, moved by `by`, solved with
 * their exits recorded. */
static void solve_recorded(double by, cm_region *r)
{
    cm_model m = hand_model(1, shift);
    m.ctx = &by;
    const cm_lattice lat = {1, {0}, {1}};
    const cm_box box = {1, {0}, {1000}};
    const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
    char msg[256];
    CHECK(cm_region_alloc(r, &box, msg, sizeof msg) == CM_OK);
    CHECK(cm_scm_solve(&m, &lat, &opt, r, msg, sizeof msg) == CM_OK);
}

/* cm_region_check: a region as solved passes; each kind of damage a file
 * can hold is found, with the cell it is in. */
static void test_region_check(void)
{
    char msg[256];
    cm_region r;
    solve_recorded(5000, &r); /* every cell its own exit: exits 0..999 in cell order */
    CHECK_INT(r.nexits, 1000);
    CHECK(cm_region_check(&r, 0, true, 2, msg, sizeof msg) == CM_OK);
    /* exit 3 twice (cells 2 and 3), each cell still its own node: the numbering is wrong */
    r.image[2] = CM_IMAGE_EXIT_BASE + 3;
    r.group[2] = CM_NODE_REF | 3;
    CHECK(cm_region_check(&r, 0, true, 2, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "cell 2:") != NULL); /* it holds exit 3 where exit 2 is due */
    r.image[2] = CM_IMAGE_EXIT_BASE + 2;
    r.group[2] = CM_NODE_REF | 2;
    r.exit_target[7] = 500; /* an exit whose target is inside the region */
    CHECK(cm_region_check(&r, 0, true, 2, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "exit 7:") != NULL);
    cm_region_free(&r);

    solve_recorded(1, &r); /* one exit (cell 999); every cell in its tree */
    CHECK_INT(r.nexits, 1);
    CHECK(cm_region_check(&r, 0, true, 1, msg, sizeof msg) == CM_OK);
    r.step[500]++;
    CHECK(cm_region_check(&r, 0, true, 1, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "cell 499:") != NULL); /* 499's image, 500, now disagrees with it */
    r.step[500]--;
    r.group[10] = 5; /* a group the file does not have */
    CHECK(cm_region_check(&r, 4, true, 1, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "cell 9:") != NULL || strstr(msg, "cell 10:") != NULL);
    CHECK(cm_region_check(&r, 5, false, 1, msg, sizeof msg) == CM_EFORMAT); /* no node refs */
    r.group[10] = CM_NODE_REF;
    r.image[20] = CM_IMAGE_SINK; /* the sink, with a node's group and step */
    CHECK(cm_region_check(&r, 0, true, 1, msg, sizeof msg) == CM_EFORMAT);
    CHECK(strstr(msg, "cell 19:") != NULL || strstr(msg, "cell 20:") != NULL);
    cm_region_free(&r);
}

/* ---- today's results, as digests ------------------------------------------ */

static uint64_t digest_u32(uint64_t h, const uint32_t *v, uint64_t n)
{
    for (uint64_t i = 0; i < n; i++)
        h = mix(h ^ v[i]);
    return h;
}

/* The images, groups, steps and exit targets of the configurations of the
 * speed issue's table (on 1000 x 500 cells), with 1 and 2 threads, equal
 * the digests of the results the engine gave before its image loop was
 * made faster: a faster loop must give the same cells, bit for bit. */
static void test_digests(void)
{
    static const struct {
        const char *params, *region;
        int max_steps;
        uint64_t digest;
    } configs[] = {
        {"alpha=0.078,beta=0,P=0.007,D=0.02", "0:500,-40:40", 1, UINT64_C(0xe077f93dba3929d1)},
        {"alpha=0.07,beta=0,P=0.007,D=0.02", "85.4:485.4,-12.5:12.5", 20, UINT64_C(0x3e2895765ceb84db)},
        {"alpha=0.078,beta=0,P=0.007,D=0.02", "-50:1050,-12.5:12.5", 1, UINT64_C(0xe5fed8ab2821e227)},
        {"alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3", "-125000:125000,-600:600", 100000, UINT64_C(0x5645f63dd76dff71)},
    };
    for (size_t k = 0; k < sizeof configs / sizeof configs[0]; k++) {
        double lo[2], hi[2];
        CHECK(sscanf(configs[k].region, "%lf:%lf,%lf:%lf", &lo[0], &hi[0], &lo[1], &hi[1]) == 4);
        cm_model m;
        char msg[256];
        const char *texts[1] = {configs[k].params};
        CHECK(cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) == CM_OK);
        const cm_lattice lat = {2, {lo[0], lo[1]}, {(hi[0] - lo[0]) / 1000, (hi[1] - lo[1]) / 500}};
        const cm_box box = {2, {0, 0}, {1000, 500}};
        for (int threads = 1; threads <= 2; threads++) {
            cm_region r;
            const cm_scm_options opt = {configs[k].max_steps, threads, NULL, NULL, 1};
            CHECK(cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK);
            CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
            uint64_t h = digest_u32(1, r.image, r.ncells);
            h = digest_u32(h, r.group, r.ncells);
            h = digest_u32(h, r.step, r.ncells);
            for (uint64_t e = 0; e < 2 * r.nexits; e++)
                h = mix(h ^ (uint64_t)r.exit_target[e]);
            if (h != configs[k].digest)
                fprintf(stderr, "digest of %s on %s: 0x%016llx\n", configs[k].params,
                        configs[k].region, (unsigned long long)h);
            CHECK(h == configs[k].digest);
            cm_region_free(&r);
        }
        cm_model_release(&m);
    }
}

/* Every model with step_n gives through it exactly what step gives: images
 * of regions on several lattices (cells whose centres are 0 or beyond the
 * range of Int, where steps have no image), with and without step_n. */
static void test_step_n_equals_step(void)
{
    for (size_t k = 0; k < cm_model_count(); k++) {
        const cm_model_entry *e = cm_model_at(k);
        cm_model m;
        char msg[256];
        CHECK(cm_model_create(e->name, NULL, 0, &m, msg, sizeof msg) == CM_OK);
        if (!m.step_n) {
            cm_model_release(&m);
            continue;
        }
        cm_model scalar = m;
        scalar.step_n = NULL;
        /* widths from coarse to ones where Int overflows; an origin that puts
         * a centre on 0 */
        const double widths[] = {0.37, 1.0, 3.1e14, 7.7e17};
        for (size_t w = 0; w < sizeof widths / sizeof widths[0]; w++) {
            cm_lattice lat = {m.dim, {0}, {0}};
            cm_box box = {m.dim, {0}, {0}};
            for (int d = 0; d < m.dim; d++) {
                lat.origin[d] = -60.5 * widths[w];
                lat.width[d] = widths[w] * (d ? 0.61 : 1.0);
                box.lo[d] = d ? -3 : -7;
                /* rows of more than one batch; beyond two dimensions a
                 * layer or two, and a flow's rows a few (a section map
                 * costs up to milliseconds a cell: 90 rows of Duffing's
                 * took half a minute) */
                box.hi[d] = d == 0 ? 300 : d == 1 ? (m.flow.field ? 0 : 90)
                                     : d == 2 ? -1 : -2;
            }
            cm_region a, b;
            const cm_scm_options opt = {.max_steps = 5, .threads = 2, .record_exits = 1};
            CHECK(cm_region_alloc(&a, &box, msg, sizeof msg) == CM_OK);
            CHECK(cm_region_alloc(&b, &box, msg, sizeof msg) == CM_OK);
            CHECK(cm_scm_images(&m, &lat, &opt, &a, msg, sizeof msg) == CM_OK);
            CHECK(cm_scm_images(&scalar, &lat, &opt, &b, msg, sizeof msg) == CM_OK);
            CHECK(memcmp(a.image, b.image, a.ncells * sizeof *a.image) == 0);
            CHECK_INT(a.nexits, b.nexits);
            CHECK(memcmp(a.exit_target, b.exit_target,
                         a.nexits * (size_t)m.dim * sizeof *a.exit_target) == 0);
            cm_region_free(&a);
            cm_region_free(&b);
        }
        cm_model_release(&m);
    }
}

int main(void)
{
    test_digests();
    test_step_n_equals_step();
    test_region_check();
    test_contraction();
    test_rotation(1);
    test_rotation(0);
    test_leaving();
    test_no_image();
    test_max_steps();
    test_random_maps();
    test_slow_share();
    test_threads_identical();
    CHECK_DONE();
}
