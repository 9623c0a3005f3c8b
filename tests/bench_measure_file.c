/* Benchmark of `cellmap measure` on a file (lib/measure): ns per cell of
 * reading the labels (both passes when the window is read in slabs),
 * basin entropy (boxes 3, 5, 7, 9), the eps-uncertain fractions (eps
 * 1..16), the Wada test (r 1..5) and the whole call (opening the file and
 * labelling the nodes included), under a memory budget; the median of the
 * runs and the range, the slabs and the peak resident memory.
 * usage: bench_measure_file FILE.cmdb [BUDGET_MIB (256)] [RUNS (3)] */
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "bench_util.h"
#include "cellmap/clock.h"
#include "lib/measure.h"

static int by_time(const void *a, const void *b) { return compare_doubles(a, b); }

int main(int argc, char **argv)
{
    if (argc < 2)
        return fprintf(stderr, "usage: bench_measure_file FILE.cmdb [BUDGET_MIB] [RUNS]\n"), 2;
    measure_args a = measure_defaults();
    a.file = argv[1];
    a.mem = (uint64_t)(argc > 2 ? atoi(argv[2]) : 256) << 20;
    const int runs = argc > 3 ? atoi(argv[3]) : 3;
    if (runs < 1 || runs > 20 || a.mem == 0)
        return fprintf(stderr, "usage: bench_measure_file FILE.cmdb [BUDGET_MIB] [RUNS 1..20]\n"), 2;
    double t[5][20];
    measure_result r;
    char msg[1024];
    for (int run = 0; run < runs; run++) {
        const double t0 = cm_seconds();
        if (measure_compute(&a, NULL, &r, msg, sizeof msg) != CM_OK)
            return fprintf(stderr, "%s\n", msg), 1;
        t[4][run] = cm_seconds() - t0;
        t[0][run] = r.seconds_read, t[1][run] = r.seconds_entropy;
        t[2][run] = r.seconds_uncertain, t[3][run] = r.seconds_wada;
        if (run + 1 < runs)
            measure_result_free(&r);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("%s: %llu cells in %lld slab(s) under %llu MiB; Sb %.4f Sbb %.4f, alpha %.4f, Wada %.4f "
           "at r = 5; peak resident %.0f MiB\n",
           r.model, (unsigned long long)r.cells, (long long)r.slabs,
           (unsigned long long)(a.mem >> 20), r.sb_mean, r.sbb_mean, r.alpha,
           r.has_wada ? r.wada.fraction[4] : -1.0, ru.ru_maxrss / 1024.0);
    const char *names[5] = {"reading the labels", "basin entropy (boxes 3,5,7,9)",
                            "uncertain fractions (eps 1..16)", "Wada test (r 1..5)",
                            "the whole measure (with opening)"};
    for (int k = 0; k < 5; k++) {
        qsort(t[k], (size_t)runs, sizeof t[k][0], by_time);
        printf("%-32s %8.2f ns/cell (median of %d; range %.2f .. %.2f)\n", names[k],
               1e9 * t[k][runs / 2] / (double)r.cells, runs, 1e9 * t[k][0] / (double)r.cells,
               1e9 * t[k][runs - 1] / (double)r.cells);
    }
    measure_result_free(&r);
    return 0;
}
