/* Adaptive extension (cellmap/extend.h): the choice of the next tile is
 * checked against brute force (every sink cell's sequence followed cell by
 * cell to where it leaves the cluster), and on the thesis' example (Fig.
 * 4.25 with the Figs. 4.26-4.28 parameters): from the left region the right
 * neighbour is chosen, and joining it finds the attractors there. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/cover.h"
#include "cellmap/extend.h"
#include "check.h"
#include "models/registry.h"

enum { SPAN = 8 }; /* brute force counts tiles with indices in [-SPAN, SPAN) */

static cm_model fig_model(void)
{
    cm_model m;
    char msg[256];
    const char *params[1] = {"alpha=0.07,beta=0,P=0.007,D=0.02"};
    if (cm_model_create("microchaos-pd", params, 1, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        exit(1);
    }
    return m;
}

static void add_boxes(cm_cluster *c, const cm_model *m, const cm_box *boxes, uint32_t n)
{
    const cm_scm_options opt = {.max_steps = 1, .record_exits = 1};
    char msg[256];
    CHECK(cm_cluster_solve_boxes(c, m, boxes, n, &opt, NULL, NULL, NULL, msg, sizeof msg) == CM_OK);
}

static int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/* Escaping sequences per tile, following each sink cell's sequence. */
static uint64_t brute_force(const cm_cluster *c, const cm_box *tile, uint64_t *per_tile)
{
    uint64_t all = 0, cells = 0;
    for (uint32_t k = 0; k < c->nregions; k++)
        cells += c->regions[k].r.ncells;
    memset(per_tile, 0, sizeof(uint64_t) * 4 * SPAN * SPAN);
    for (uint32_t k0 = 0; k0 < c->nregions; k0++)
        for (uint64_t i0 = 0; i0 < c->regions[k0].r.ncells; i0++) {
            uint32_t k = k0;
            uint64_t i = i0;
            for (uint64_t steps = 0; steps <= cells; steps++) {
                const cm_region *r = &c->regions[k].r;
                const uint32_t g = r->group[i], v = r->image[i];
                if (g != 0 && !cm_is_node_ref(g))
                    break; /* a group of the region: the sequence stays */
                if (v < r->ncells) {
                    i = v;
                    continue;
                }
                const int64_t e = cm_image_exit_index(v);
                if (e < 0)
                    break;
                const int64_t *cell = cm_region_exit(r, (uint64_t)e);
                const int64_t next = cm_cluster_locate(c, cell, &i);
                if (next >= 0) {
                    k = (uint32_t)next;
                    continue;
                }
                all++;
                const int64_t tx = floor_div(cell[0] - tile->lo[0], tile->hi[0] - tile->lo[0]);
                const int64_t ty = floor_div(cell[1] - tile->lo[1], tile->hi[1] - tile->lo[1]);
                if (tx >= -SPAN && tx < SPAN && ty >= -SPAN && ty < SPAN)
                    per_tile[(ty + SPAN) * 2 * SPAN + tx + SPAN]++;
                break;
            }
        }
    return all;
}

static uint64_t tile_count(const uint64_t *per_tile, const cm_box *tile, const cm_box *box)
{
    const int64_t tx = floor_div(box->lo[0] - tile->lo[0], tile->hi[0] - tile->lo[0]);
    const int64_t ty = floor_div(box->lo[1] - tile->lo[1], tile->hi[1] - tile->lo[1]);
    return per_tile[(ty + SPAN) * 2 * SPAN + tx + SPAN];
}

/* The cluster of the boxes on the lattice, and the extension it chooses
 * for `tile`. */
static void choose_on(const cm_lattice *lat, cm_cluster *c, const cm_model *m,
                      const cm_box *boxes, uint32_t n, const cm_box *tile,
                      cm_extend_choice *choice)
{
    char msg[256];
    cm_cluster_init(c, lat);
    add_boxes(c, m, boxes, n);
    CHECK(cm_extend_choose(c, tile, NULL, choice, msg, sizeof msg) == CM_OK);
}

/* The same on the Fig. 4.16 lattice. */
static void choose_for(cm_cluster *c, const cm_model *m, const cm_box *boxes, uint32_t n,
                       const cm_box *tile, cm_extend_choice *choice)
{
    const cm_lattice lat = {2, {85.4, -12.5}, {0.8, 0.1}};
    choose_on(&lat, c, m, boxes, n, tile, choice);
}

/* A cluster of three tiles (an L shape): the chosen tile's count and the
 * total equal brute force, and no face neighbour receives more. */
static void test_brute_force(void)
{
    cm_model m = fig_model();
    const cm_box tile = {2, {0, 0}, {250, 250}};
    const cm_box boxes[3] = {tile, {2, {250, 0}, {500, 250}}, {2, {250, -250}, {500, 0}}};
    cm_cluster c;
    cm_extend_choice choice;
    choose_for(&c, &m, boxes, 3, &tile, &choice);
    static uint64_t per_tile[4 * SPAN * SPAN];
    const uint64_t all = brute_force(&c, &tile, per_tile);
    CHECK_INT(choice.all_escaping, all);
    CHECK_INT(choice.cluster_cells, 3 * 250 * 250);
    CHECK_INT(choice.escaping, tile_count(per_tile, &tile, &choice.box));
    CHECK(choice.escaping > 0);
    /* face neighbours of the L: none receives more than the chosen one */
    static const int64_t neighbours[][2] = {{-1, 0}, {0, 1},  {0, -1}, {1, 1},
                                            {2, 0},  {2, -1}, {1, -2}, {0, -1}};
    for (size_t n = 0; n < sizeof neighbours / sizeof neighbours[0]; n++) {
        const cm_box b = {2,
                          {neighbours[n][0] * 250, neighbours[n][1] * 250},
                          {neighbours[n][0] * 250 + 250, neighbours[n][1] * 250 + 250}};
        CHECK(tile_count(per_tile, &tile, &b) <= choice.escaping);
    }
    cm_cluster_free(&c);
    cm_model_release(&m);
}

/* Regions not aligned to the grid (what panning leaves): the chosen tile's
 * count equals brute force, and the part of it the cluster lacks is what a
 * session computes. */
static void test_unaligned(void)
{
    cm_model m = fig_model();
    const cm_box tile = {2, {0, 0}, {200, 200}};
    /* a view, then a pan right by 70 cells and up by 30 */
    const cm_box boxes[3] = {tile, {2, {200, 0}, {270, 200}}, {2, {70, 200}, {270, 230}}};
    cm_cluster c;
    cm_extend_choice choice;
    choose_for(&c, &m, boxes, 3, &tile, &choice);
    static uint64_t per_tile[4 * SPAN * SPAN];
    CHECK_INT(choice.all_escaping, brute_force(&c, &tile, per_tile));
    CHECK_INT(choice.escaping, tile_count(per_tile, &tile, &choice.box));
    CHECK_INT(cm_box_cells(&choice.box), 200 * 200); /* a whole tile of the grid */
    CHECK_INT(choice.box.lo[0] % 200, 0);
    CHECK_INT(choice.box.lo[1] % 200, 0);
    cm_box *rest = NULL;
    uint32_t n = 0;
    char msg[256];
    CHECK(cm_cluster_uncovered(&c, &choice.box, &rest, &n, msg, sizeof msg) == CM_OK);
    uint64_t covered = 0;
    for (uint32_t k = 0; k < c.nregions; k++) {
        cm_box both;
        if (cm_box_intersect(&c.regions[k].r.box, &choice.box, &both))
            covered += cm_box_cells(&both);
    }
    CHECK_INT(cm_boxes_cells(rest, n) + covered, 200 * 200);
    free(rest);
    cm_cluster_free(&c);
    cm_model_release(&m);
}

/* cm_cluster_uncovered on random disjoint regions: the pieces are disjoint,
 * miss every region and, with the regions, cover the box exactly (checked
 * cell by cell); a pan right leaves one strip of the view's height. */
static void test_uncovered(void)
{
    enum { W = 40 };
    cm_cluster c;
    cm_cluster_init(&c, &(cm_lattice){2, {0, 0}, {1, 1}});
    c.regions = calloc(64, sizeof *c.regions);
    static uint8_t owner[W][W];
    memset(owner, 0, sizeof owner);
    srand(7);
    for (int tries = 0; tries < 400 && c.nregions < 64; tries++) {
        const int64_t x = rand() % W, y = rand() % W, w = 1 + rand() % 12, h = 1 + rand() % 12;
        if (x + w > W || y + h > W)
            continue;
        int free_cells = 1;
        for (int64_t i = x; i < x + w; i++)
            for (int64_t j = y; j < y + h; j++)
                free_cells &= owner[i][j] == 0;
        if (!free_cells)
            continue;
        for (int64_t i = x; i < x + w; i++)
            for (int64_t j = y; j < y + h; j++)
                owner[i][j] = 1;
        c.regions[c.nregions++].r.box = (cm_box){2, {x, y}, {x + w, y + h}};
    }
    const cm_box view = {2, {3, 5}, {37, 33}};
    cm_box *pieces = NULL;
    uint32_t n = 0;
    char msg[256];
    CHECK(cm_cluster_uncovered(&c, &view, &pieces, &n, msg, sizeof msg) == CM_OK);
    for (uint32_t k = 0; k < n; k++)
        for (int64_t i = pieces[k].lo[0]; i < pieces[k].hi[0]; i++)
            for (int64_t j = pieces[k].lo[1]; j < pieces[k].hi[1]; j++)
                owner[i][j] += 2; /* a region's cell becomes 3, a twice-covered one 4 */
    int wrong = 0;
    for (int64_t i = 0; i < W; i++)
        for (int64_t j = 0; j < W; j++) {
            const int inside =
                i >= view.lo[0] && i < view.hi[0] && j >= view.lo[1] && j < view.hi[1];
            wrong += inside ? owner[i][j] != 1 && owner[i][j] != 2 : owner[i][j] > 1;
        }
    CHECK_INT(wrong, 0);
    free(pieces);
    /* a pan right of a view the cluster holds: one strip */
    cm_cluster strip;
    cm_cluster_init(&strip, &c.lat);
    strip.regions = calloc(1, sizeof *strip.regions);
    strip.regions[0].r.box = (cm_box){2, {0, 0}, {100, 80}};
    strip.nregions = 1;
    const cm_box panned = {2, {10, 0}, {110, 80}};
    CHECK(cm_cluster_uncovered(&strip, &panned, &pieces, &n, msg, sizeof msg) == CM_OK);
    CHECK_INT(n, 1);
    CHECK(n == 1 && pieces[0].lo[0] == 100 && pieces[0].hi[0] == 110 && pieces[0].lo[1] == 0 &&
          pieces[0].hi[1] == 80);
    free(pieces);
    /* nothing uncovered: no pieces */
    const cm_box inside = {2, {5, 5}, {50, 50}};
    CHECK(cm_cluster_uncovered(&strip, &inside, &pieces, &n, msg, sizeof msg) == CM_OK);
    CHECK(n == 0 && pieces == NULL);
    free(strip.regions);
    free(c.regions);
}

/* Fig. 4.25: from the left region x in [85.4, 285.4], x' in [-12.5, 12.5]
 * (1000 x 1000 cells) the right-hand neighbour is chosen; joining it finds
 * the chaotic attractors at SW_2 (x = 2/P, across the border) and near SW_3
 * (x = 3/P). */
static void test_fig_4_25(void)
{
    cm_model m = fig_model();
    const cm_lattice lat = {2, {85.4, -12.5}, {0.2, 0.025}};
    const cm_box tile = {2, {0, 0}, {1000, 1000}}, right = {2, {1000, 0}, {2000, 1000}};
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    add_boxes(&c, &m, &tile, 1);
    cm_extend_choice choice;
    char msg[256];
    CHECK(cm_extend_choose(&c, &tile, NULL, &choice, msg, sizeof msg) == CM_OK);
    CHECK(memcmp(&choice.box, &right, sizeof right) == 0);
    fprintf(stderr, "Fig. 4.25: %llu of %llu escaping sequences lead into x in [%g, %g]\n",
            (unsigned long long)choice.escaping, (unsigned long long)choice.all_escaping,
            85.4 + 0.2 * (double)choice.box.lo[0], 85.4 + 0.2 * (double)choice.box.hi[0]);
    CHECK(2 * choice.escaping > choice.all_escaping); /* most of them */
    cm_join_stats stats;
    const cm_scm_options opt = {.max_steps = 1, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(&c, &m, &choice.box, 1, &opt, NULL, NULL, &stats, msg,
                                 sizeof msg) == CM_OK);
    CHECK(stats.straddling_groups > 0);
    cm_region flat;
    const cm_box whole = {2, {0, 0}, {2000, 1000}};
    CHECK(cm_cluster_flatten(&c, &whole, &flat, msg, sizeof msg) == CM_OK);
    cm_group_info *g = calloc(flat.ngroups + 1, sizeof *g);
    cm_scm_groups(&flat, &lat, g, NULL);
    int at_sw2 = 0, at_sw3 = 0;
    for (uint32_t k = 0; k < flat.ngroups; k++) {
        at_sw2 += fabs(g[k].centre[0] - 2 / 0.007) < 1 && g[k].lo[0] < 285.4 && g[k].hi[0] > 285.4;
        at_sw3 += fabs(g[k].centre[0] - 3 / 0.007) < 3 && g[k].period > 1;
    }
    CHECK(at_sw2 > 0);
    CHECK(at_sw3 > 0);
    free(g);
    cm_region_free(&flat);
    /* bounds that exclude the right-hand side: another tile; bounds that
     * leave no neighbour: nothing to choose */
    const cm_box no_right = {2, {-3000, -3000}, {2000, 3000}};
    cm_extend_choice other;
    CHECK(cm_extend_choose(&c, &tile, &no_right, &other, msg, sizeof msg) == CM_OK);
    CHECK(other.box.hi[0] <= 2000);
    const cm_box tight = {2, {0, 0}, {2000, 1000}};
    CHECK(cm_extend_choose(&c, &tile, &tight, &other, msg, sizeof msg) == CM_ENOTFOUND);
    cm_cluster_free(&c);
    cm_model_release(&m);
}

/* Tie-breaks (extend.h): a map that moves the left half of a 10 x 10 tile
 * one tile along first_dim (first_dir: +1 or -1) and the right half one tile
 * along second_dim (second_dir) gives two neighbours equal counts. */
typedef struct tie_map {
    int first_dim, first_dir, second_dim, second_dir;
} tie_map;

static int tie_step(const cm_model *m, const double *x, double *y)
{
    const tie_map *t = m->ctx;
    y[0] = x[0];
    y[1] = x[1];
    if (x[0] < 5) /* the left half of the tile [0, 10) x [0, 10) */
        y[t->first_dim] += 10 * t->first_dir;
    else
        y[t->second_dim] += 10 * t->second_dir;
    return 0;
}

static cm_box tie_choice(tie_map t)
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "tie";
    m.dim = 2;
    m.step = tie_step;
    m.ctx = &t;
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    const cm_box tile = {2, {0, 0}, {10, 10}};
    cm_cluster c;
    cm_extend_choice choice;
    choose_on(&lat, &c, &m, &tile, 1, &tile, &choice);
    CHECK(choice.escaping == 50 && choice.all_escaping == 100);
    cm_cluster_free(&c);
    return choice.box;
}

/* Equal counts go to the neighbour first in the promised order: by
 * dimension, the lower side first. */
static void test_ties(void)
{
    const cm_box left = {2, {-10, 0}, {0, 10}}, right = {2, {10, 0}, {20, 10}};
    const cm_box below = {2, {0, -10}, {10, 0}};
    cm_box b = tie_choice((tie_map){0, 1, 0, -1}); /* right and left */
    CHECK(memcmp(&b, &left, sizeof b) == 0);
    b = tie_choice((tie_map){0, -1, 0, 1}); /* the same, the other way round */
    CHECK(memcmp(&b, &left, sizeof b) == 0);
    b = tie_choice((tie_map){1, 1, 1, -1}); /* up and down */
    CHECK(memcmp(&b, &below, sizeof b) == 0);
    b = tie_choice((tie_map){1, -1, 0, 1}); /* down and right: dimension 0 first */
    CHECK(memcmp(&b, &right, sizeof b) == 0);
}

int main(void)
{
    test_ties();
    test_brute_force();
    test_unaligned();
    test_uncovered();
    test_fig_4_25();
    CHECK_DONE();
}
