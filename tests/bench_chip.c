/* bench_chip: the section map of Palmai's chip formation flow (model
 * chip-4d, the plane T0 = 0.1 crossed downwards, zeta = 21) by each of
 * GSL's integrators at the default tolerances 1e-9: microseconds per
 * image of the engine's images over N^3 cells of the model's region on 2
 * threads (medians of REPS alternating runs), and the images' error
 * against rk8pd at tolerances 1e-12 from 500 cell centres (largest and
 * median over the centres of the largest coordinate error, in cell
 * widths of a 100^3 lattice of the region). This is how the default
 * integrator was chosen (docs/models.md 12.1).
 * usage: bench_chip [N (default 24)] [REPS (default 3)] [XI (default 4.8)] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "cellmap/scm.h"
#include "models/ode_flow.h"
#include "models/registry.h"

static const char *const methods[] = {"rk8pd", "rkf45", "rkck", "msbdf", "rk4imp", "bsimp"};
enum { METHODS = sizeof methods / sizeof methods[0], SAMPLES = 500 };
static const double lo[3] = {0.9, 0.15, 0.2}, hi[3] = {1.25, 0.25, 0.35}; /* its region */

static cm_model chip(const char *method, const char *tol, double xi)
{
    char text[3][64];
    snprintf(text[0], sizeof text[0], "method=%s", method);
    snprintf(text[1], sizeof text[1], "abs_tol=%s,rel_tol=%s", tol, tol);
    snprintf(text[2], sizeof text[2], "xi=%.17g", xi);
    const char *texts[3] = {text[0], text[1], text[2]};
    cm_model m;
    char msg[256];
    if (cm_model_create("chip-4d", texts, 3, &m, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_chip: %s\n", msg);
        exit(1);
    }
    return m;
}

static double images_seconds(const cm_model *m, int n, uint64_t *with_image)
{
    cm_lattice lat = {3, {0}, {0}};
    const cm_box box = {3, {0, 0, 0}, {n, n, n}};
    for (int d = 0; d < 3; d++) {
        lat.origin[d] = lo[d];
        lat.width[d] = (hi[d] - lo[d]) / n;
    }
    const cm_scm_options opt = {.threads = 2};
    cm_region r;
    char msg[256];
    const double t0 = now();
    if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK ||
        cm_scm_images(m, &lat, &opt, &r, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_chip: %s\n", msg);
        exit(1);
    }
    const double t = now() - t0;
    *with_image = 0;
    for (uint64_t i = 0; i < r.ncells; i++)
        *with_image += r.image[i] != CM_IMAGE_SINK;
    cm_region_free(&r);
    return t;
}

/* A pseudo-random centre of the 100^3 lattice (the same for every method). */
static void sample(int k, double *x)
{
    uint64_t s = 0x9E3779B97F4A7C15u * (uint64_t)(k + 1);
    for (int d = 0; d < 3; d++) {
        s ^= s >> 29, s *= 0xBF58476D1CE4E5B9u, s ^= s >> 32;
        x[d] = lo[d] + ((double)(s % 100) + 0.5) * (hi[d] - lo[d]) / 100;
    }
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 24, reps = argc > 2 ? atoi(argv[2]) : 3;
    const double xi = argc > 3 ? atof(argv[3]) : 4.8;
    if (n < 4 || n > 400 || reps < 1 || reps > 50 || !(xi > -100 && xi < 100)) {
        fprintf(stderr, "usage: bench_chip [N 4..400] [REPS 1..50] [XI]\n");
        return 2;
    }
    cm_model ref = chip("rk8pd", "1e-12", xi), m[METHODS];
    double ref_y[SAMPLES][3];
    int ref_rc[SAMPLES];
    for (int k = 0; k < SAMPLES; k++) {
        double x[3];
        sample(k, x);
        ref_rc[k] = cm_flow_map(&ref, x, ref_y[k], NULL, NULL);
    }
    for (int j = 0; j < METHODS; j++)
        m[j] = chip(methods[j], "1e-9", xi);
    double t[METHODS][50];
    uint64_t with_image[METHODS];
    for (int k = 0; k < reps; k++) /* alternating, so that drift hits every method */
        for (int j = 0; j < METHODS; j++)
            t[j][k] = images_seconds(&m[j], n, &with_image[j]);
    printf("chip-4d section map T0 = 0.1 (down), xi = %g, zeta = 21; %d^3 cells of "
           "0.9:1.25,0.15:0.25,0.2:0.35, 2 threads, medians of %d\n",
           xi, n, reps);
    printf("%-8s %10s %12s %14s %14s %10s\n", "method", "us/image", "with image",
           "max error", "median error", "steps");
    for (int j = 0; j < METHODS; j++) {
        double err[SAMPLES], worst = 0;
        long steps = 0;
        int compared = 0;
        for (int k = 0; k < SAMPLES; k++) {
            double x[3], y[3];
            long s;
            sample(k, x);
            const int rc = cm_flow_map(&m[j], x, y, NULL, &s);
            steps += s;
            if (rc != CM_STEP_OK || ref_rc[k] != CM_STEP_OK)
                continue;
            double e = 0;
            for (int d = 0; d < 3; d++)
                e = fmax(e, fabs(y[d] - ref_y[k][d]) / ((hi[d] - lo[d]) / 100));
            err[compared++] = e;
            worst = fmax(worst, e);
        }
        const double cells = (double)n * n * n;
        printf("%-8s %10.1f %12llu %14.2e %14.2e %10.1f\n", methods[j],
               1e6 * median(t[j], reps) / cells, (unsigned long long)with_image[j], worst,
               compared ? median(err, compared) : NAN, (double)steps / SAMPLES);
    }
    printf("(errors in cell widths of 100^3 cells, against rk8pd at 1e-12; steps: mean "
           "integration steps per image)\n");
    for (int j = 0; j < METHODS; j++)
        cm_model_release(&m[j]);
    cm_model_release(&ref);
    return 0;
}
