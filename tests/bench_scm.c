/* Benchmark of simple cell mapping of one region (images, then
 * classification) on the micro-chaos PD map: the thesis' Table 4.1
 * configuration (alpha = 0.078, beta = 0, P = 0.007, D = 0.02 on 0:500 x
 * -40:40, a square grid), and the four configurations of the speed issue
 * on 4000 x 2000 cells: the same map and box, alpha = 0.07 on
 * 85.4:485.4 x -12.5:12.5 with at most 20 steps, a wide box, and Fig.
 * 4.21's. Each runs once untimed (pages faulted in, threads woken), then
 * `repeats` times with 1 and 2 threads in turns; the program prints the
 * medians: image time, classification time, total, images and total in ns
 * per cell, and bytes per cell (the region's per-cell arrays). A last line
 * gives the machine's own limits to read them by (machine_reference).
 *
 * usage: bench_scm [repeats (default 5)] [million cells (default 8)] */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, madvise */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include <omp.h>

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
            const cm_scm_options opt = {.max_steps = c->max_steps, .threads = threads};
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

/* Seconds to touch `bytes` of fresh memory, a byte per 4 KiB page from
 * `threads` threads; in transparent huge pages if `huge` (as the engine
 * asks for its region's arrays). */
static double first_touch(size_t bytes, bool huge, int threads)
{
    char *fresh = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (fresh == MAP_FAILED)
        die("out of memory for the machine reference");
    if (huge)
        madvise(fresh, bytes, MADV_HUGEPAGE);
    const double t0 = now();
#pragma omp parallel for num_threads(threads) schedule(static)
    for (size_t page = 0; page < bytes / 4096; page++)
        fresh[page * 4096] = 1;
    const double seconds = now() - t0;
    munmap(fresh, bytes);
    return seconds;
}

/* The machine's limits for arrays the size of the region's (12 bytes per
 * cell), medians of 3: a random read, as the classification's walks make
 * them (32 independent chains per thread through one cycle over every
 * entry, 2 threads; ns per read of both threads together), and the first
 * touch of fresh memory in 4 KiB and in huge pages (the page faults a
 * command pays on its region and this benchmark, which reuses its region,
 * does not; ns per cell). */
static void machine_reference(double million)
{
    enum { CHAINS = 32, THREADS = 2, RUNS = 3 };
    const size_t n = (size_t)(3 * million * 1e6), cells = (size_t)(million * 1e6);
    uint32_t *next = malloc(n * sizeof *next);
    if (!next)
        die("out of memory for the machine reference");
    for (size_t i = 0; i < n; i++)
        next[i] = (uint32_t)i;
    uint64_t x = UINT64_C(88172645463325252);
    for (size_t i = n - 1; i > 0; i--) { /* Sattolo's shuffle: a single cycle */
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        const size_t j = (size_t)(x % i);
        const uint32_t t = next[i];
        next[i] = next[j];
        next[j] = t;
    }
    const size_t steps = (size_t)1 << 18; /* per chain */
    double t_read[RUNS], t_touch[RUNS], t_huge[RUNS];
    uint64_t sink = 0;
    for (int r = 0; r < RUNS; r++) {
        const double t0 = now();
#pragma omp parallel num_threads(THREADS) reduction(+ : sink)
        {
            const size_t spacing = n / (THREADS * CHAINS);
            uint32_t at[CHAINS];
            for (int c = 0; c < CHAINS; c++)
                at[c] = (uint32_t)((size_t)(omp_get_thread_num() * CHAINS + c) * spacing);
            for (size_t s = 0; s < steps; s++)
                for (int c = 0; c < CHAINS; c++)
                    at[c] = next[at[c]];
            for (int c = 0; c < CHAINS; c++)
                sink += at[c];
        }
        t_read[r] = (now() - t0) / ((double)steps * CHAINS * THREADS);
        t_touch[r] = first_touch(n * sizeof *next, false, THREADS) / (double)cells;
        t_huge[r] = first_touch(n * sizeof *next, true, THREADS) / (double)cells;
    }
    free(next);
    const volatile uint64_t keep = sink; /* the chains' ends: the reads are not optimised away */
    (void)keep;
    printf("machine: a random read in %.0f MiB %.2f ns (%d threads x %d chains); first touch of "
           "fresh memory %.2f ns/cell, in huge pages %.2f ns/cell\n",
           (double)(n * sizeof *next) / 1048576.0, 1e9 * median(t_read, RUNS), THREADS, CHAINS,
           1e9 * median(t_touch, RUNS), 1e9 * median(t_huge, RUNS));
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
    machine_reference(million);
    return 0;
}
