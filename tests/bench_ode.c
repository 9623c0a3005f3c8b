/* bench_ode: what cellmap adds to the integration of an ODE map. The
 * forced Duffing oscillator's stroboscopic map (model duffing at its
 * defaults, GSL rk8pd, tolerances 1e-9) over N x N cells of -2.5:2.5
 * squared on 2 threads: cellmap's SCM (images and classification) against
 * a plain OpenMP loop that calls gsl_odeiv2_driver_apply over one period
 * from each cell's centre, the same integrator, tolerances and first step.
 * Prints the medians of REPS alternating runs, cells/s and the overhead.
 * usage: bench_ode [N (default 400)] [REPS (default 5)] */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "cellmap/scm.h"
#include "models/registry.h"

#define TWO_PI 6.283185307179586476925286766559
static const double delta = 0.15, gamma_ = 0.1, omega = 1.0;

static int field(double t, const double y[], double f[], void *params)
{
    (void)params;
    f[0] = y[1];
    f[1] = -delta * y[1] + y[0] - y[0] * y[0] * y[0] + gamma_ * cos(omega * t);
    return GSL_SUCCESS;
}

/* The plain loop: every centre over one period; a checksum of the images
 * so that nothing is optimised away. */
static double plain_loop(int n, double *checksum)
{
    const double t0 = now(), T = TWO_PI / omega, h = 5.0 / n;
    double sum = 0;
#pragma omp parallel num_threads(2) reduction(+ : sum)
    {
        gsl_odeiv2_system sys = {field, NULL, 2, NULL};
        gsl_odeiv2_driver *d =
            gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, T / 64, 1e-9, 1e-9);
#pragma omp for schedule(static)
        for (long i = 0; i < (long)n * n; i++) {
            double y[2] = {-2.5 + (i % n + 0.5) * h, -2.5 + (i / n + 0.5) * h}, t = 0;
            gsl_odeiv2_driver_reset(d);
            if (gsl_odeiv2_driver_apply(d, &t, T, y) == GSL_SUCCESS)
                sum += y[0] + y[1];
        }
        gsl_odeiv2_driver_free(d);
    }
    *checksum = sum;
    return now() - t0;
}

static double cellmap_scm(const cm_model *m, int n)
{
    const cm_lattice lat = {2, {-2.5, -2.5}, {5.0 / n, 5.0 / n}};
    const cm_box box = {2, {0, 0}, {n, n}};
    const cm_scm_options opt = {.threads = 2};
    cm_region r;
    char msg[256];
    const double t0 = now();
    if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK ||
        cm_scm_solve(m, &lat, &opt, &r, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_ode: %s\n", msg);
        exit(1);
    }
    const double t = now() - t0;
    cm_region_free(&r);
    return t;
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 400, reps = argc > 2 ? atoi(argv[2]) : 5;
    if (n < 10 || n > 4000 || reps < 1 || reps > 50) {
        fprintf(stderr, "usage: bench_ode [N 10..4000] [REPS 1..50]\n");
        return 2;
    }
    gsl_set_error_handler_off();
    cm_model m;
    char msg[256];
    if (cm_model_create("duffing", NULL, 0, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_ode: %s\n", msg);
        return 1;
    }
    double checksum, tp[50], tc[50], ratio[50];
    plain_loop(n / 4, &checksum); /* untimed warm-up */
    cellmap_scm(&m, n / 4);
    for (int k = 0; k < reps; k++) { /* alternating, so that drift hits both */
        tp[k] = plain_loop(n, &checksum);
        tc[k] = cellmap_scm(&m, n);
        ratio[k] = tc[k] / tp[k];
    }
    const double cells = (double)n * n, p = median(tp, reps), c = median(tc, reps),
                 r = median(ratio, reps);
    printf("duffing stroboscopic map, %d x %d cells, 2 threads, medians of %d\n", n, n, reps);
    printf("%-28s %10s %12s %10s\n", "", "seconds", "cells/s", "us/cell");
    printf("%-28s %10.3f %12.0f %10.2f\n", "plain GSL loop", p, cells / p, 1e6 * p / cells);
    printf("%-28s %10.3f %12.0f %10.2f\n", "cellmap SCM", c, cells / c, 1e6 * c / cells);
    printf("overhead (median of the per-run ratios): %+.1f %% (checksum %.6g)\n", 100 * (r - 1),
           checksum);
    cm_model_release(&m);
    return 0;
}
