#define _DEFAULT_SOURCE
/* bench_join: what the joins of a split solve cost, from the command line
 * (issue: clustered SCM over MPI, "the parallel join on one machine"). For
 * each of the configurations (8 M cells, 2 threads), `cellmap
 * solve --json` runs whole and with --split 4x4 and 16x16, in turns; the
 * program prints the medians over REPS turns of the solve's time (whole:
 * images and classification; split: regions and joins), of the joins'
 * time on the joining thread and its share of the solve, and the median
 * of each turn's ratio to the whole solve of the same turn (load that
 * drifts on a shared machine cancels out).
 * usage: bench_join PATH/TO/cellmap [REPS]   (REPS default 5) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CM_BENCH_COMMAND_JSON
#include "bench_util.h"

enum { MAX_REPS = 50 };

static const char *const configs[][4] = {
    {"4.6.3", "alpha=0.078,beta=0,P=0.007,D=0.02", "0:500,-40:40", "1"},
    {"a.07", "alpha=0.07,beta=0,P=0.007,D=0.02", "85.4:485.4,-12.5:12.5", "20"},
};
static const char *const splits[] = {NULL, "4x4", "16x16"};

/* One solve: its time and its joins' (0 whole), in seconds; 0 on success. */
static int run(const char *cm, int c, int s, double *solve, double *joins)
{
    char cmd[1024], out[1 << 16];
    snprintf(cmd, sizeof cmd,
             "'%s' solve --param %s --region %s --max-steps %s --cells 4000x2000 --threads 2 "
             "%s%s --json",
             cm, configs[c][1], configs[c][2], configs[c][3], splits[s] ? "--split " : "",
             splits[s] ? splits[s] : "");
    if (command_json(cmd, out, sizeof out, NULL) != 0)
        return -1;
    /* a cellmap older than time_s.joins: NaN (the other figures stand) */
    const double joined = json_number(out, "joins");
    *joins = !s ? 0 : joined >= 0 ? joined : NAN;
    *solve = s ? json_number(out, "regions and joins")
               : json_number(out, "images") + json_number(out, "classification");
    return *solve > 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_join PATH/TO/cellmap [REPS]\n");
        return 2;
    }
    const int reps = argc > 2 ? atoi(argv[2]) : 5;
    if (reps < 1 || reps > MAX_REPS) {
        fprintf(stderr, "bench_join: REPS must be 1..%d\n", MAX_REPS);
        return 2;
    }
    printf("%-6s %-6s %9s %9s %7s %8s\n", "config", "split", "solve_ms", "joins_ms", "share",
           "x_whole");
    for (int c = 0; c < 2; c++) {
        double solve[3][MAX_REPS], joins[3][MAX_REPS], share[3][MAX_REPS], ratio[3][MAX_REPS];
        for (int r = 0; r < reps; r++)
            for (int s = 0; s < 3; s++) {
                if (run(argv[1], c, s, &solve[s][r], &joins[s][r]) != 0) {
                    fprintf(stderr, "bench_join: %s %s failed\n", configs[c][0],
                            splits[s] ? splits[s] : "whole");
                    return 1;
                }
                share[s][r] = joins[s][r] / solve[s][r];
                ratio[s][r] = solve[s][r] / solve[0][r];
            }
        for (int s = 0; s < 3; s++) {
            printf("%-6s %-6s %9.1f %9.1f %7.2f %8.2f\n", configs[c][0],
                   splits[s] ? splits[s] : "whole", 1e3 * median(solve[s], reps),
                   1e3 * median(joins[s], reps), median(share[s], reps), median(ratio[s], reps));
            fflush(stdout);
        }
    }
    return 0;
}
