/* Adaptive extension (cellmap/extend.h): the choice of the next tile is
 * checked against brute force (every sink cell's sequence followed cell by
 * cell to where it leaves the cluster), and on the thesis' example (Fig.
 * 4.25 with the Figs. 4.26-4.28 parameters): from the left region the right
 * neighbour is chosen, and joining it finds the attractors there. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    const cm_scm_options opt = {1, 0, NULL, NULL, 1};
    char msg[256];
    CHECK(cm_cluster_solve_boxes(c, m, boxes, n, &opt, NULL, NULL, NULL, msg, sizeof msg) == CM_OK);
}

static int64_t floor_div(int64_t a, int64_t b)
{
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}

/* Escaping sequences per tile, following each sink cell's sequence. */
static uint64_t brute_force(const cm_cluster *c, const cm_box *tile, uint64_t *per_tile)
{
    uint64_t all = 0;
    uint32_t hint = 0;
    memset(per_tile, 0, sizeof(uint64_t) * 4 * SPAN * SPAN);
    for (uint32_t k0 = 0; k0 < c->nregions; k0++)
        for (uint64_t i0 = 0; i0 < c->regions[k0].r.ncells; i0++) {
            if (c->regions[k0].r.group[i0] != 0)
                continue;
            uint32_t k = k0;
            uint64_t i = i0;
            for (;;) {
                const cm_region *r = &c->regions[k].r;
                const uint32_t v = r->image[i];
                if (v < r->ncells) {
                    i = v;
                    continue;
                }
                const int64_t e = cm_image_exit_index(v);
                if (e < 0)
                    break;
                const int64_t *cell = cm_region_exit(r, (uint64_t)e);
                const int64_t next = cm_cluster_locate(c, cell, &hint, &i);
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

/* A cluster of three tiles (an L shape): the chosen tile's count and the
 * total equal brute force, and no face neighbour receives more. */
static void test_brute_force(void)
{
    cm_model m = fig_model();
    const cm_lattice lat = {2, {85.4, -12.5}, {0.8, 0.1}};
    const cm_box tile = {2, {0, 0}, {250, 250}};
    const cm_box boxes[3] = {tile, {2, {250, 0}, {500, 250}}, {2, {250, -250}, {500, 0}}};
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    add_boxes(&c, &m, boxes, 3);
    cm_extend_choice choice;
    char msg[256];
    CHECK(cm_extend_choose(&c, &tile, NULL, &choice, msg, sizeof msg) == CM_OK);
    static uint64_t per_tile[4 * SPAN * SPAN];
    const uint64_t all = brute_force(&c, &tile, per_tile);
    CHECK_INT(choice.all_escaping, all);
    CHECK_INT(choice.cluster_cells, 3 * 250 * 250);
    CHECK_INT(choice.escaping, tile_count(per_tile, &tile, &choice.box));
    CHECK(choice.escaping > 0);
    /* face neighbours of the L: none receives more than the chosen one */
    static const int64_t neighbours[][2] = {{-1, 0}, {0, 1}, {0, -1}, {1, 1}, {2, 0}, {2, -1},
                                            {1, -2}, {0, -1}};
    for (size_t n = 0; n < sizeof neighbours / sizeof neighbours[0]; n++) {
        const cm_box b = {2,
                          {neighbours[n][0] * 250, neighbours[n][1] * 250},
                          {neighbours[n][0] * 250 + 250, neighbours[n][1] * 250 + 250}};
        CHECK(tile_count(per_tile, &tile, &b) <= choice.escaping);
    }
    cm_cluster_free(&c);
    cm_model_release(&m);
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
    const cm_scm_options opt = {1, 0, NULL, NULL, 1};
    CHECK(cm_cluster_solve_boxes(&c, &m, &choice.box, 1, &opt, NULL, NULL, &stats, msg, sizeof msg) ==
          CM_OK);
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

int main(void)
{
    test_brute_force();
    test_fig_4_25();
    CHECK_DONE();
}
