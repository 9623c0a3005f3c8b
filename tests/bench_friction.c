/* Benchmark of the hybrid micro-chaos map with dry friction (issue 8):
 * images per second with the Fig. 4.30 parameters (alpha = 6.53e-3,
 * beta = 0, P = 5.5e-5, D = 2.5e-3) at mu = 0 and mu = 0.095, on 1 and 2
 * threads. The images are those of cell mapping: the centres of a
 * 2000x2000-cell lattice over the Fig. 4.30 window (|x| <= 1e5,
 * |x'| <= 30) and over the band |x'| <= 1 where blocks stop, one step each
 * (cm_scm_images with max-steps 1). Also counts which events the steps met. Prints medians of
 * `repeats` runs.
 *
 * usage: bench_friction [repeats (default 5)] */
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "cellmap/scm.h"
#include "models/microchaos_pd_friction.h"
#include "models/registry.h"

enum { SIDE = 2000 };

/* The Fig. 4.30 window, and the thin band along the x-axis where blocks
 * stop within a sampling interval, the worst case for the event path. */
static const cm_lattice windows[2] = {{2, {-1e5, -30}, {2e5 / SIDE, 60.0 / SIDE}},
                                      {2, {-1e5, -1}, {2e5 / SIDE, 2.0 / SIDE}}};
static const char *const window_names[2] = {"[-1e5, 1e5] x [-30, 30]", "[-1e5, 1e5] x [-1, 1]"};

/* How often each event kind occurs over the lattice's centres. */
static void count_events(const cm_lattice *window, double mu)
{
    cm_pdf_coef c;
    cm_pdf_coefficients(6.53e-3, 0, 5.5e-5, 2.5e-3, mu, mu, &c);
    long kinds[4] = {0};
    for (int64_t i = 0; i < SIDE; i++)
        for (int64_t j = 0; j < SIDE; j++) {
            const int64_t cell[2] = {i, j};
            double x[2];
            cm_pdf_result r;
            cm_lattice_centre(window, cell, x);
            if (cm_pdf_step(&c, x[0], x[1], &r))
                kinds[r.event]++;
        }
    const double n = (double)SIDE * SIDE / 100;
    printf("  events: slide %.1f %%, stay stuck %.1f %%, stick %.1f %%, reverse %.1f %%\n",
           (double)kinds[CM_PDF_NONE] / n, (double)kinds[CM_PDF_STUCK_WHOLE] / n,
           (double)kinds[CM_PDF_STICK] / n, (double)kinds[CM_PDF_REVERSE] / n);
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    if (repeats < 1 || repeats > 100) {
        fprintf(stderr, "usage: bench_friction [repeats 1..100]\n");
        return 2;
    }
    const char *texts[] = {"mu=0", "mu=0.095"};
    const cm_box box = {2, {0, 0}, {SIDE, SIDE}};
    char msg[256];
    cm_region r;
    if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    printf("microchaos-pd-friction, Fig. 4.30 (alpha=6.53e-3, beta=0, P=5.5e-5, D=2.5e-3), "
           "%dx%d cell centres\n",
           SIDE, SIDE);
    for (int t = 0; t < 4; t++) {
        const cm_lattice *window = &windows[t / 2];
        cm_model m;
        if (cm_model_create("microchaos-pd-friction", &texts[t % 2], 1, &m, msg, sizeof msg) !=
            CM_OK) {
            fprintf(stderr, "%s\n", msg);
            return 1;
        }
        printf("%s on %s\n", texts[t % 2], window_names[t / 2]);
        count_events(window, t % 2 ? 0.095 : 0);
        for (int threads = 1; threads <= 2; threads++) {
            double rate[100];
            const cm_scm_options opt = {.max_steps = 1, .threads = threads};
            cm_scm_images(&m, window, &opt, &r, msg, sizeof msg); /* warm-up */
            for (int k = 0; k < repeats; k++) {
                const double t0 = now();
                if (cm_scm_images(&m, window, &opt, &r, msg, sizeof msg) != CM_OK) {
                    fprintf(stderr, "%s\n", msg);
                    return 1;
                }
                rate[k] = (double)r.ncells / (now() - t0);
            }
            const double med = median(rate, repeats);
            printf("  %d thread%s: %.2f M images/s (median of %d), %.1f ns/image\n", threads,
                   threads > 1 ? "s" : "", med / 1e6, repeats, 1e9 / med * threads);
        }
        cm_model_release(&m);
    }
    cm_region_free(&r);
    return 0;
}
