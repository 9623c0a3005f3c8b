/* Benchmark of simple cell mapping of one region (images, then
 * classification) on the micro-chaos PD map: the thesis' Table 4.1
 * configuration (alpha = 0.078, beta = 0, P = 0.007, D = 0.02 on 0:500 x
 * -40:40, a square grid), and the four configurations of the speed issue
 * on 4000 x 2000 cells: the same map and box, alpha = 0.07 on
 * 85.4:485.4 x -12.5:12.5 with at most 20 steps, a wide box, and Fig.
 * 4.21's. Each runs once untimed (pages faulted in, threads woken), then
 * `repeats` times with 1 and 2 threads in turns; the program prints the
 * medians: image time, classification time, total, images and total in ns
 * per cell, and bytes per cell (the region's per-cell arrays).
 *
 * usage: bench_scm [repeats (default 5)] [million cells (default 8)] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "bench_util.h"
#include "models/registry.h"

typedef struct config {
    const char *name, *params;
    double lo[2], hi[2];
    int max_steps;
    int square; /* a square grid; else twice as wide as high */
} config;

static const config configs[] = {
    {"table4.1", "alpha=0.078,beta=0,P=0.007,D=0.02", {0, -40}, {500, 40}, 1, 1},
    {"4.6.3", "alpha=0.078,beta=0,P=0.007,D=0.02", {0, -40}, {500, 40}, 1, 0},
    {"a.07", "alpha=0.07,beta=0,P=0.007,D=0.02", {85.4, -12.5}, {485.4, 12.5}, 20, 0},
    {"wide", "alpha=0.078,beta=0,P=0.007,D=0.02", {-50, -12.5}, {1050, 12.5}, 1, 0},
    {"4.21", "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3", {-125000, -600}, {125000, 600},
     100000, 0},
};

static void die(const char *msg)
{
    fprintf(stderr, "bench_scm: %s\n", msg);
    exit(1);
}

static void run_config(const config *c, double million, int repeats)
{
    cm_model m;
    char msg[256];
    const char *texts[1] = {c->params};
    if (cm_model_create("microchaos-pd", texts, 1, &m, msg, sizeof msg) != CM_OK)
        die(msg);
    const int64_t ny = c->square ? (int64_t)llround(sqrt(million * 1e6))
                                 : (int64_t)llround(sqrt(million * 1e6 / 2));
    const int64_t nx = c->square ? ny : 2 * ny;
    const cm_lattice lat = {2,
                            {c->lo[0], c->lo[1]},
                            {(c->hi[0] - c->lo[0]) / (double)nx, (c->hi[1] - c->lo[1]) / (double)ny}};
    const cm_box box = {2, {0, 0}, {nx, ny}};
    cm_region r;
    if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK)
        die(msg);
    double t_img[2][100], t_cls[2][100], t_tot[2][100];
    for (int k = -1; k < repeats; k++)
        for (int threads = 1; threads <= 2; threads++) {
            const cm_scm_options opt = {c->max_steps, threads, NULL, NULL, 0};
            const double t0 = now();
            if (cm_scm_images(&m, &lat, &opt, &r, msg, sizeof msg) != CM_OK)
                die(msg);
            const double t1 = now();
            if (cm_scm_classify(&r, threads, msg, sizeof msg) != CM_OK)
                die(msg);
            const double t2 = now();
            if (k < 0)
                continue;
            t_img[threads - 1][k] = t1 - t0;
            t_cls[threads - 1][k] = t2 - t1;
            t_tot[threads - 1][k] = t2 - t0;
        }
    const double n = (double)r.ncells;
    for (int t = 0; t < 2; t++) {
        const double img = median(t_img[t], repeats), cls = median(t_cls[t], repeats),
                     tot = median(t_tot[t], repeats);
        printf("%-9s %10.0f %7d %10.1f %11.1f %9.1f %9.2f %9.2f %10.1f %7u\n", c->name, n, t + 1,
               1e3 * img, 1e3 * cls, 1e3 * tot, 1e9 * img / n, 1e9 * tot / n,
               (double)cm_region_bytes(&r) / n, r.ngroups);
    }
    fflush(stdout);
    cm_region_free(&r);
    cm_model_release(&m);
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    const double million = argc > 2 ? atof(argv[2]) : 8;
    if (repeats < 1 || repeats > 100 || !(million > 0 && million <= 200)) {
        fprintf(stderr, "usage: bench_scm [repeats 1..100] [million cells, at most 200]\n");
        return 2;
    }
    printf("%-9s %10s %7s %10s %11s %9s %9s %9s %10s %7s\n", "config", "cells", "threads",
           "images_ms", "classify_ms", "total_ms", "img_ns/c", "tot_ns/c", "bytes/cell",
           "groups");
    for (size_t c = 0; c < sizeof configs / sizeof configs[0]; c++)
        run_config(&configs[c], million, repeats);
    return 0;
}
