/* Benchmark of the dry friction oscillator's Poincare map (issue 7):
 * images per second on 1 and 2 threads at three parameter points,
 *   non-sticking  S = S0 = 0.05, Omega = 0.8 (the symmetric solution (2.25)),
 *   sticking      S = 0.32, S0 = 0.4, Omega = 0.5 (the 1a pair, Sec. 2.5.2),
 *   chaotic       S = 0.05, S0 = 0.4, Omega = 0.5 (Sec. 2.6.1),
 * two ways: along the attractor (2048 trajectories started on it, 100
 * periods each, trajectories split over the threads), and as cell mapping
 * computes them (the centres of a 1000x1000 lattice over [-3, 3]^2, one
 * image each, cm_scm_images). Prints medians of `repeats` runs, and the
 * events per image along the attractor.
 *
 * usage: bench_oscillator [repeats (default 5)] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "cellmap/scm.h"
#include "models/friction_oscillator.h"
#include "models/registry.h"

enum { ORBITS = 2048, PERIODS = 100, SIDE = 1000 };

static const struct {
    const char *name, *params;
    double S, S0, Omega;
} points[] = {
    {"non-sticking", "S=0.05,S0=0.05,Omega=0.8", 0.05, 0.05, 0.8},
    {"sticking", "S=0.32,S0=0.4,Omega=0.5", 0.32, 0.4, 0.5},
    {"chaotic", "S=0.05,S0=0.4,Omega=0.5", 0.05, 0.4, 0.5},
};

/* Starts on the attractor: ORBITS states after 300 periods from spread
 * initial conditions. */
static void settle_starts(const cm_fo *o, double (*z)[2])
{
    for (int i = 0; i < ORBITS; i++) {
        z[i][0] = -1.5 + 3.0 * i / ORBITS;
        z[i][1] = 0.5;
        for (int k = 0; k < 300; k++)
            cm_fo_poincare(o, z[i], z[i], NULL, NULL, NULL);
    }
}

/* Seconds for PERIODS images of every orbit; events counted into *events. */
static double run_orbits(const cm_fo *o, double (*start)[2], int threads, long *events)
{
    long ev = 0;
    const double t0 = now();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) reduction(+ : ev)
    for (int i = 0; i < ORBITS; i++) {
        double z[2] = {start[i][0], start[i][1]};
        for (int k = 0; k < PERIODS; k++) {
            cm_fo_tally t;
            cm_fo_poincare(o, z, z, &t, NULL, NULL);
            ev += t.n_stick + t.n_turn + t.n_break;
        }
    }
    *events = ev;
    return now() - t0;
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 5;
    if (repeats < 1 || repeats > 100) {
        fprintf(stderr, "usage: bench_oscillator [repeats 1..100]\n");
        return 2;
    }
    static double starts[ORBITS][2];
    const cm_box box = {2, {0, 0}, {SIDE, SIDE}};
    const cm_lattice lat = {2, {-3, -3}, {6.0 / SIDE, 6.0 / SIDE}};
    char msg[256];
    cm_region r;
    if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "%s\n", msg);
        return 1;
    }
    printf("friction-oscillator Poincare map, %d cores available\n", omp_get_num_procs());
    for (size_t p = 0; p < sizeof points / sizeof points[0]; p++) {
        cm_fo o;
        cm_fo_init(&o, points[p].S, points[p].S0, points[p].Omega, 0);
        settle_starts(&o, starts);
        cm_model m;
        if (cm_model_create("friction-oscillator", &points[p].params, 1, &m, msg, sizeof msg) !=
            CM_OK) {
            fprintf(stderr, "%s\n", msg);
            return 1;
        }
        printf("%s (%s)\n", points[p].name, points[p].params);
        for (int threads = 1; threads <= 2; threads++) {
            double orbit_rate[100], cell_rate[100];
            long events = 0;
            const cm_scm_options opt = {.max_steps = 1, .threads = threads};
            for (int k = 0; k < repeats; k++) {
                orbit_rate[k] = (double)ORBITS * PERIODS / run_orbits(&o, starts, threads, &events);
                const double t0 = now();
                if (cm_scm_images(&m, &lat, &opt, &r, msg, sizeof msg) != CM_OK) {
                    fprintf(stderr, "%s\n", msg);
                    return 1;
                }
                cell_rate[k] = (double)SIDE * SIDE / (now() - t0);
            }
            const double orbit = median(orbit_rate, repeats), cells = median(cell_rate, repeats);
            printf("  %d thread(s): on the attractor %8.0f k images/s (%.0f ns/image, %.2f "
                   "events/image); lattice centres %8.0f k images/s (%.0f ns/image)\n",
                   threads, orbit / 1e3, 1e9 / orbit, (double)events / (ORBITS * PERIODS),
                   cells / 1e3, 1e9 / cells);
        }
        cm_model_release(&m);
    }
    cm_region_free(&r);
    return 0;
}
