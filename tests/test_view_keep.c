/* test_view_keep: a view's labels kept between views of a growing cluster
 * (cellmap/view_keep.h) are, cell by cell, the labels the view gets afresh
 * (cm_cluster_view_labels on cm_cluster_flatten_open), with the same
 * counts, whatever the views before it, the regions added between them
 * and the threads. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/join.h"
#include "cellmap/outside.h"
#include "cellmap/view_keep.h"
#include "check.h"
#include "shift_map.h"
#include "models/registry.h"

/* What one comparison saw, so that a test can check it was not vacuous. */
typedef struct seen {
    uint64_t views, basin_cells, returned, outside, diverged;
} seen;

/* The labels of view afresh and through each keep (one thread, two
 * threads): the same labels and counts; the figure's cells as promised. */
static void check_view(cm_cluster *c, const cm_model *m, const cm_group_info *g,
                       cm_view_keep *const keeps[2], const cm_box *view, seen *saw)
{
    char msg[512];
    const uint64_t n = cm_box_cells(view);
    cm_region part;
    uint32_t *open = malloc((n + 1) * sizeof *open);
    int32_t *want = malloc((n + 1) * sizeof *want), *got = NULL;
    CHECK(cm_cluster_flatten_open(c, view, &part, open, msg, sizeof msg) == CM_OK);
    cm_attractor_set fresh;
    CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL, &fresh,
                             msg, sizeof msg) == CM_OK);
    CHECK(cm_cluster_view_labels(m, c, &part, open, NULL, NULL, &fresh, want, msg, sizeof msg) ==
          CM_OK);
    for (int t = 0; t < 2; t++) {
        const cm_attractor_options opt = {.threads = t + 1};
        cm_attractor_options o;
        cm_attractor_defaults(m, &opt, &o);
        cm_attractor_set kept;
        cm_region shown;
        CHECK(cm_attractors_find(m, &c->lat, g, c->ngroups, cm_cluster_cells_group, c, NULL,
                                 &kept, msg, sizeof msg) == CM_OK);
        const cm_status st =
            cm_view_keep_labels(keeps[t], m, c, NULL, view, &o, &kept, &got, &shown, msg, sizeof msg);
        if (st != CM_OK)
            fprintf(stderr, "cm_view_keep_labels: %s\n", msg);
        CHECK(st == CM_OK);
        uint64_t differ = 0, figure = 0;
        for (uint64_t i = 0; i < n; i++) {
            differ += got[i] != want[i];
            figure += shown.group[i] != 0 || shown.step[i] != 1;
        }
        if (differ)
            fprintf(stderr, "view %lld:%lld x %lld:%lld, %d thread(s): %llu labels differ\n",
                    (long long)view->lo[0], (long long)view->hi[0], (long long)view->lo[1],
                    (long long)view->hi[1], t + 1, (unsigned long long)differ);
        CHECK_INT(differ, 0);
        CHECK_INT(figure, 0);
        CHECK_INT(shown.ncells, n);
        CHECK_INT(kept.returned_cells, fresh.returned_cells);
        CHECK_INT(kept.outside_cells, fresh.outside_cells);
        CHECK_INT(kept.sink_diverged_cells, fresh.sink_diverged_cells);
        CHECK_INT(kept.outside_steps_taken, fresh.outside_steps_taken);
        CHECK_INT(kept.n, fresh.n);
        for (uint32_t a = 0; a < kept.n && a < fresh.n; a++)
            CHECK_INT(kept.a[a].basin_cells, fresh.a[a].basin_cells);
        CHECK_INT(kept.nexits, 0);
        CHECK(cm_view_keep_bytes(keeps[t]) > n * sizeof(uint32_t));
        cm_attractors_free(&kept);
    }
    saw->views++;
    saw->returned += fresh.returned_cells;
    saw->outside += fresh.outside_cells;
    saw->diverged += fresh.sink_diverged_cells;
    for (uint64_t i = 0; i < n; i++)
        saw->basin_cells += want[i] > 0;
    cm_attractors_free(&fresh);
    cm_region_free(&part);
    free(open);
    free(want);
}

/* Solves box into c (its groups described into *g, the caller's). */
static void grow(cm_cluster *c, const cm_model *m, const cm_box *box, cm_group_info **g)
{
    char msg[512];
    const cm_scm_options opt = {.max_steps = 1, .threads = 2, .record_exits = 1};
    CHECK(cm_cluster_solve_boxes(c, m, box, 1, &opt, NULL, NULL, NULL, msg, sizeof msg) == CM_OK);
    free(*g);
    *g = calloc(c->ngroups + 1, sizeof **g);
    CHECK(cm_cluster_describe_new(c, m, *g, msg, sizeof msg) == CM_OK);
}

/* A cluster that grows, two keeps (one thread, two) that follow its
 * views, and what the comparisons saw. */
typedef struct growing {
    cm_cluster c;
    cm_view_keep *keeps[2];
    cm_group_info *g;
    seen saw;
} growing;

static void start(growing *w, const cm_lattice *lat)
{
    memset(w, 0, sizeof *w);
    cm_cluster_init(&w->c, lat);
    w->keeps[0] = cm_view_keep_new();
    w->keeps[1] = cm_view_keep_new();
    CHECK(w->keeps[0] && w->keeps[1]);
}

static void finish(growing *w)
{
    cm_view_keep_free(w->keeps[0]);
    cm_view_keep_free(w->keeps[1]);
    free(w->g);
    cm_cluster_free(&w->c);
}

static cm_box box2(int64_t x0, int64_t x1, int64_t y0, int64_t y1)
{
    return (cm_box){2, {x0, y0}, {x1, y1}};
}

/* Section 4.6.3's example panned as `cellmap explore` pans it, on cells
 * ten times as wide: a view of 100 x 100 cells (0:500 x -40:40) moved
 * right by 10 cells at a time, each pan solving the strip it uncovers;
 * then up, back left, out, a region added inside the view, and in. */
static void test_panning(void)
{
    char msg[512];
    cm_model m;
    const char *const params[] = {"alpha=0.078,beta=0,P=0.007,D=0.02"};
    CHECK(cm_model_create("microchaos-pd", params, 1, &m, msg, sizeof msg) == CM_OK);
    const cm_lattice lat = {2, {0, -40}, {5, 0.8}};
    growing w;
    start(&w, &lat);
    cm_box view = box2(0, 100, 0, 100);
    grow(&w.c, &m, &view, &w.g);
    check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw);
    for (int p = 0; p < 12; p++) { /* right */
        const cm_box strip = box2(view.hi[0], view.hi[0] + 10, view.lo[1], view.hi[1]);
        grow(&w.c, &m, &strip, &w.g);
        view.lo[0] += 10;
        view.hi[0] += 10;
        check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw);
    }
    for (int p = 0; p < 3; p++) { /* up */
        const cm_box strip = box2(view.lo[0], view.hi[0], view.hi[1], view.hi[1] + 10);
        grow(&w.c, &m, &strip, &w.g);
        view.lo[1] += 10;
        view.hi[1] += 10;
        check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw);
    }
    for (int p = 0; p < 4; p++) { /* back left, over cells solved before and some not */
        view.lo[0] -= 30;
        view.hi[0] -= 30;
        check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw);
    }
    const cm_box out = box2(view.lo[0] - 40, view.hi[0] + 40, view.lo[1] - 30, view.hi[1] + 30);
    check_view(&w.c, &m, w.g, w.keeps, &out, &w.saw); /* zoomed out: uncomputed cells around */
    const cm_box hole = box2(view.lo[0] - 40, view.lo[0], view.hi[1] + 1, view.hi[1] + 20);
    grow(&w.c, &m, &hole, &w.g); /* a region inside the last view, not at its edge */
    check_view(&w.c, &m, w.g, w.keeps, &out, &w.saw);
    check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw); /* zoomed in again */
    const seen *saw = &w.saw;
    fprintf(stderr, "panning: %llu views, %llu cells in basins, %llu returned, %llu outside, "
                    "%llu diverged\n",
            (unsigned long long)saw->views, (unsigned long long)saw->basin_cells,
            (unsigned long long)saw->returned, (unsigned long long)saw->outside,
            (unsigned long long)saw->diverged);
    CHECK(saw->basin_cells > 0 && saw->returned > 0); /* exits whose orbits come back */
    finish(&w);
    cm_model_release(&m);
}

/* Chains of exits: A = 0..10's exits land in B = 20..30's sink cells,
 * whose exits land on C = 40..50's fixed points. Solved C, A, then the gap
 * between A and B, then B: a kept exit of A is computed by the gap (its
 * cells then end where the gap's sequences end), and B's arrival changes
 * where the orbits of the gap's exits land. */
static void test_chains(void)
{
    const cm_model m = {.name = "shift", .dim = 2, .step = shift_step};
    const cm_lattice lat = {2, {0, 0}, {1, 1}};
    const cm_box order[4] = {box2(40, 50, 0, 4), box2(0, 10, 0, 4), box2(10, 14, 0, 4),
                             box2(20, 30, 0, 4)};
    growing w;
    start(&w, &lat);
    const cm_box view = box2(0, 12, 0, 4);
    for (int k = 0; k < 4; k++) {
        grow(&w.c, &m, &order[k], &w.g);
        check_view(&w.c, &m, w.g, w.keeps, &view, &w.saw);
    }
    CHECK(w.saw.returned > 0); /* once B is there, A's cells return (and so the gap's) */
    finish(&w);
}

int main(void)
{
    test_chains();
    test_panning();
    CHECK_DONE();
}
