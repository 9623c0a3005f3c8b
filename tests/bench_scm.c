/* Benchmark of simple cell mapping on the thesis' Table 4.1 configuration:
 * the micro-chaos PD map at alpha = 0.078, beta = 0, P = 0.007, D = 0.02 on
 * the left region of the C-SCM example (0:500 x -40:40), square grids of
 * 0.5 to 8 million cells, with 1 and 2 threads. Prints the median of
 * `repeats` runs: image time, classification time, total ns/cell and
 * bytes/cell (the region's per-cell arrays over its cell count).
 *
 * usage: bench_scm [repeats (default 5)] [max million cells (default 8)] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "bench_util.h"
#include "models/registry.h"

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    const double max_million = argc > 2 ? atof(argv[2]) : 8;
    if (repeats < 1 || repeats > 100) {
        fprintf(stderr, "usage: bench_scm [repeats 1..100] [max million cells]\n");
        return 2;
    }
    cm_model m;
    char msg[256];
    if (cm_model_create("microchaos-pd", NULL, 0, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    const double millions[] = {0.5, 1, 2, 4, 8};
    printf("%10s %7s %11s %11s %13s %14s %11s %7s\n", "cells", "threads", "images_ms",
           "classify_ms", "total_ms", "total_ns/cell", "bytes/cell", "groups");
    for (int s = 0; s < 5 && millions[s] <= max_million; s++) {
        const int64_t side = (int64_t)llround(sqrt(millions[s] * 1e6));
        const cm_lattice lat = {2, {0, -40}, {500.0 / (double)side, 80.0 / (double)side}};
        const cm_box box = {2, {0, 0}, {side, side}};
        cm_region r;
        if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK) {
            fprintf(stderr, "%s\n", msg);
            return 1;
        }
        /* One untimed run faults the pages in and wakes the threads; then the
         * thread counts alternate, so that the machine's noise hits both. */
        double t_img[2][100], t_cls[2][100], t_tot[2][100];
        for (int k = -1; k < repeats; k++) {
            for (int threads = 1; threads <= 2; threads++) {
                const cm_scm_options opt = {1, threads, NULL, NULL, 0};
                const double t0 = now();
                cm_scm_images(&m, &lat, &opt, &r, msg, sizeof msg);
                const double t1 = now();
                cm_scm_classify(&r, msg, sizeof msg);
                const double t2 = now();
                if (k < 0)
                    continue;
                t_img[threads - 1][k] = t1 - t0;
                t_cls[threads - 1][k] = t2 - t1;
                t_tot[threads - 1][k] = t2 - t0;
            }
        }
        const double n = (double)r.ncells;
        for (int threads = 1; threads <= 2; threads++) {
            const int t = threads - 1;
            printf("%10.0f %7d %11.1f %11.1f %13.1f %14.1f %11.1f %7u\n", n, threads,
                   1e3 * median(t_img[t], repeats), 1e3 * median(t_cls[t], repeats),
                   1e3 * median(t_tot[t], repeats), 1e9 * median(t_tot[t], repeats) / n,
                   (double)cm_region_bytes(&r) / n, r.ngroups);
        }
        fflush(stdout);
        cm_region_free(&r);
    }
    cm_model_release(&m);
    return 0;
}
