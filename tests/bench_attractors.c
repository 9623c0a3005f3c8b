/* Benchmark of the attractor layer (cellmap/attractors.h) and of following
 * the orbits that leave the cells (cellmap/outside.h) against the solve
 * they follow: for the quick start (§4.6.3 on 1000 x 1000 cells), Fig.
 * 4.21's configuration on 4000 x 2000 cells (8 M, --max-steps 100000),
 * Duffing on 401 x 401 cells (--max-steps 50) and Newton's method for
 * z^3 - 1 on 1000 x 1000 cells of -2:2^2, each `repeats` times after an
 * untimed run, on 2 threads: the solve (images, classification with the
 * exits recorded and settled, the groups' summaries, as `cellmap solve`
 * does them), then the attractors, then the exits followed, paired in
 * each turn. Prints the median seconds of the three, the median and range
 * of each layer's ratio to the solve (the targets: the attractors
 * 10 % for the first two and 25 % for Duffing; following 15 % for
 * Newton), the steps of the map each took and the attractors found.
 *
 * usage: bench_attractors [repeats (default 9)] [configuration name] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include <math.h>

#include "cellmap/attractors.h"
#include "cellmap/outside.h"
#include "cellmap/scm.h"
#include "models/registry.h"
#include "newton_map.h"


typedef struct config {
    const char *name, *model, *params; /* model NULL: Newton's method */
    double lo[2], hi[2];
    int64_t cells[2];
    int max_steps;
} config;

static const config configs[] = {
    {"quick-start", "microchaos-pd", "alpha=0.078,beta=0,P=0.007,D=0.02", {0, -40}, {500, 40},
     {1000, 1000}, 1},
    {"fig-4.21-8M", "microchaos-pd", "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3",
     {-125000, -600}, {125000, 600}, {4000, 2000}, 100000},
    {"duffing-401", "duffing", "", {-2.5, -2.5}, {2.5, 2.5}, {401, 401}, 50},
    {"newton-1000", NULL, "", {-2, -2}, {2, 2}, {1000, 1000}, 1},
};

static void die(const char *msg)
{
    fprintf(stderr, "bench_attractors: %s\n", msg);
    exit(1);
}

/* The lowest and highest of v[0..n). */
static void range(const double *v, int n, double *lo, double *hi)
{
    *lo = *hi = v[0];
    for (int k = 1; k < n; k++) {
        *lo = v[k] < *lo ? v[k] : *lo;
        *hi = v[k] > *hi ? v[k] : *hi;
    }
}

static void run_config(const config *c, int repeats)
{
    cm_model m = {.name = "newton", .dim = 2, .step = newton_step};
    char msg[256];
    const char *texts[1] = {c->params};
    if (c->model &&
        cm_model_create(c->model, texts, c->params[0] ? 1 : 0, &m, msg, sizeof msg) != CM_OK)
        die(msg);
    const cm_lattice lat = {2,
                            {c->lo[0], c->lo[1]},
                            {(c->hi[0] - c->lo[0]) / (double)c->cells[0],
                             (c->hi[1] - c->lo[1]) / (double)c->cells[1]}};
    const cm_box box = {2, {0, 0}, {c->cells[0], c->cells[1]}};
    double t_solve[64], t_att[64], t_out[64], r_att[64], r_out[64];
    uint64_t steps = 0, out_steps = 0, exits = 0;
    uint32_t found = 0, groups = 0;
    for (int k = -1; k < repeats; k++) {
        cm_region r;
        cm_group_info *g = NULL;
        cm_exits x;
        uint64_t sink;
        const cm_scm_options opt = {.max_steps = c->max_steps, .threads = 2, .record_exits = 1};
        const double t0 = now();
        if (cm_region_alloc(&r, &box, msg, sizeof msg) != CM_OK ||
            cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) != CM_OK ||
            cm_region_settle_exits(&r, 2, &x, msg, sizeof msg) != CM_OK ||
            cm_scm_describe(&m, &lat, &r, &g, &sink, msg, sizeof msg) != CM_OK)
            die(msg);
        const double t1 = now();
        cm_attractor_set s;
        const cm_attractor_options ao = {.threads = 2};
        if (cm_attractors_find(&m, &lat, g, r.ngroups, cm_region_cells_group, &r, &ao, &s, msg,
                               sizeof msg) != CM_OK)
            die(msg);
        const double t2 = now();
        cm_region_cells rc = {&r, &m, &lat, c->max_steps};
        const cm_computed cells = cm_region_computed(&rc);
        if (cm_attractors_outside(&m, &lat, &x, &cells, CM_OUTSIDE_STEPS, 2, &s, msg,
                                  sizeof msg) != CM_OK)
            die(msg);
        const double t3 = now();
        if (k >= 0) {
            t_solve[k] = t1 - t0;
            t_att[k] = t2 - t1;
            t_out[k] = t3 - t2;
            r_att[k] = t_att[k] / t_solve[k];
            r_out[k] = t_out[k] / t_solve[k];
        }
        steps = s.steps;
        out_steps = s.outside_steps_taken;
        exits = x.n;
        found = s.n;
        groups = r.ngroups;
        cm_attractors_free(&s);
        cm_exits_free(&x);
        free(g);
        cm_region_free(&r);
    }
    double alo, ahi, olo, ohi;
    range(r_att, repeats, &alo, &ahi);
    range(r_out, repeats, &olo, &ohi);
    printf("%-12s solve %8.4f s  attractors %8.4f s  ratio %.3f (%.3f-%.3f)  %9llu steps  "
           "%u groups -> %u attractors\n",
           c->name, median(t_solve, repeats), median(t_att, repeats), median(r_att, repeats), alo,
           ahi, (unsigned long long)steps, groups, found);
    printf("%-12s outside %8.4f s  ratio %.3f (%.3f-%.3f)  %9llu steps from %llu exits\n",
           c->name, median(t_out, repeats), median(r_out, repeats), olo, ohi,
           (unsigned long long)out_steps, (unsigned long long)exits);
    fflush(stdout);
    if (c->model)
        cm_model_release(&m);
}

int main(int argc, char **argv)
{
    const int repeats = argc > 1 ? atoi(argv[1]) : 9;
    if (repeats < 1 || repeats > 64)
        die("repeats must be 1..64");
    printf("2 threads, medians of %d paired runs\n", repeats);
    for (size_t k = 0; k < sizeof configs / sizeof *configs; k++)
        if (argc < 3 || strcmp(argv[2], configs[k].name) == 0)
            run_config(&configs[k], repeats);
    return 0;
}
