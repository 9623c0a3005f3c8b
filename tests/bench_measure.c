/* Benchmark of the basin measures (cellmap/basin_measure): ns per cell of
 * basin entropy (boxes of 5), the eps-uncertain fractions (eps 1..16, the
 * five together) and the Wada test (r up to 5) on Newton's z^3 - 1 basins
 * over -2:2^2 at N^2 cells (default 2000), each cell labelled by its
 * centre's true orbit (tests/newton_map.h): the median of 5 runs, and the
 * range. usage: bench_measure [N] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "cellmap/basin_measure.h"
#include "newton_map.h"

/* The root the orbit from (x, y) reaches: 1, 2, 3 by the argument of the
 * root (0, 2 pi / 3, -2 pi / 3), 0 when it does not within 200 steps. */
static int32_t root_of(double x, double y)
{
    double z[2] = {x, y};
    for (int k = 0; k < 200; k++) {
        double next[2];
        if (newton_step(NULL, z, next) != CM_STEP_OK)
            return 0;
        z[0] = next[0], z[1] = next[1];
        if (fabs(z[0] - 1) < 1e-9 && fabs(z[1]) < 1e-9)
            return 1;
        if (fabs(z[0] + 0.5) < 1e-9 && fabs(fabs(z[1]) - 0.8660254037844386) < 1e-9)
            return z[1] > 0 ? 2 : 3;
    }
    return 0;
}

static int by_time(const void *a, const void *b) { return compare_doubles(a, b); }

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 2000;
    if (n < 50 || n > 20000)
        return fprintf(stderr, "usage: bench_measure [N: 50..20000]\n"), 2;
    int32_t *label = malloc((size_t)n * (size_t)n * sizeof *label);
    if (!label)
        return fprintf(stderr, "out of memory\n"), 1;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            label[(size_t)i * (size_t)n + (size_t)j] =
                root_of(-2 + 4 * (i + 0.5) / n, -2 + 4 * (j + 0.5) / n);
    const cm_label_grid g = {.dim = 2, .n = {n, n}, .label = label, .lo = -2, .hi = 3};
    const double cells = (double)n * n;
    const char *names[3] = {"basin entropy (boxes of 5)", "uncertain fractions (eps 1..16)",
                            "Wada test (r 1..5)"};
    double t[3][5];
    char msg[256];
    cm_entropy e;
    cm_wada w;
    double f = 0;
    uint64_t counted;
    for (int run = 0; run < 5; run++) {
        double t0 = now();
        if (cm_basin_entropy(&g, 5, &e, NULL, msg, sizeof msg) != CM_OK)
            return fprintf(stderr, "%s\n", msg), 1;
        t[0][run] = now() - t0, t0 = now();
        for (int eps = 1; eps <= 16; eps *= 2)
            if (cm_uncertain_fraction(&g, eps, &f, &counted, NULL, msg, sizeof msg) != CM_OK)
                return fprintf(stderr, "%s\n", msg), 1;
        t[1][run] = now() - t0, t0 = now();
        if (cm_wada_test(&g, 5, &w, msg, sizeof msg) != CM_OK)
            return fprintf(stderr, "%s\n", msg), 1;
        t[2][run] = now() - t0;
    }
    printf("Newton z^3 - 1 on -2:2^2, %d^2 cells: Sb %.4f Sbb %.4f, f(16) %.4f, Wada %.4f of "
           "%llu boundary cells at r = 5\n",
           n, e.sb, e.sbb, f, w.fraction[4], (unsigned long long)w.boundary);
    for (int k = 0; k < 3; k++) {
        qsort(t[k], 5, sizeof t[k][0], by_time);
        printf("%-34s %8.2f ns/cell (median of 5; range %.2f .. %.2f)\n", names[k],
               1e9 * t[k][2] / cells, 1e9 * t[k][0] / cells, 1e9 * t[k][4] / cells);
    }
    free(label);
    return 0;
}
