#define _DEFAULT_SOURCE
/* bench_split: what splitting a solve into regions costs, from the command
 * line (issue: joins in O(boundary)). For each configuration, `cellmap
 * solve --cells 4000x2000` (8 M cells, 2 threads) runs whole and with
 * --split 2x1, 4x4 and 16x16, in turns; the program prints the median wall
 * time of REPS runs, the median of its ratios to the whole solve of the
 * same turn, the largest peak RSS and its ratio to the whole solve's.
 * usage: bench_split PATH/TO/cellmap [REPS]   (REPS default 3) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#define CM_BENCH_RUN_COMMAND
#include "bench_util.h"

static const char *const configs[][3] = {
    {"4.6.3", "alpha=0.078,beta=0,P=0.007,D=0.02", "0:500,-40:40"},
    {"a.07", "alpha=0.07,beta=0,P=0.007,D=0.02", "85.4:485.4,-12.5:12.5"},
    {"wide", "alpha=0.078,beta=0,P=0.007,D=0.02", "-50:1050,-12.5:12.5"},
    {"4.21", "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3", "-125000:125000,-600:600"},
};
static const char *const max_steps[] = {NULL, "20", NULL, "100000"};
static const char *const splits[] = {NULL, "2x1", "4x4", "16x16"};

/* One run: wall seconds and peak RSS in MiB of the child. */
static int run(const char *cm, int c, int s, double *wall, double *rss_mib)
{
    const char *argv[16];
    int n = 0;
    argv[n++] = cm;
    argv[n++] = "solve";
    argv[n++] = "--param";
    argv[n++] = configs[c][1];
    argv[n++] = "--region";
    argv[n++] = configs[c][2];
    argv[n++] = "--cells";
    argv[n++] = "4000x2000";
    argv[n++] = "--threads";
    argv[n++] = "2";
    if (max_steps[c]) {
        argv[n++] = "--max-steps";
        argv[n++] = max_steps[c];
    }
    if (splits[s]) {
        argv[n++] = "--split";
        argv[n++] = splits[s];
    }
    argv[n] = NULL;
    return run_command(argv, wall, rss_mib);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_split PATH/TO/cellmap [REPS]\n");
        return 2;
    }
    const int reps = argc > 2 ? atoi(argv[2]) : 3;
    if (reps < 1 || reps > 50) {
        fprintf(stderr, "bench_split: REPS must be 1..50\n");
        return 2;
    }
    printf("%-6s %-6s %10s %8s %10s %8s\n", "config", "split", "wall_s", "x_whole", "rss_MiB",
           "x_whole");
    for (int c = 0; c < 4; c++) {
        /* the splits take turns within each repetition, and a split's time
         * ratio is the median of its ratios to the whole solve of the same
         * repetition: load that drifts on a shared machine cancels out */
        double walls[4][50], ratios[4][50], rss[4] = {0};
        for (int r = 0; r < reps; r++)
            for (int s = 0; s < 4; s++) {
                double one_rss;
                if (run(argv[1], c, s, &walls[s][r], &one_rss) != 0) {
                    fprintf(stderr, "bench_split: %s %s failed\n", configs[c][0],
                            splits[s] ? splits[s] : "whole");
                    return 1;
                }
                rss[s] = one_rss > rss[s] ? one_rss : rss[s];
                ratios[s][r] = walls[s][r] / walls[0][r];
            }
        for (int s = 0; s < 4; s++) {
            printf("%-6s %-6s %10.3f %8.2f %10.1f %8.2f\n", configs[c][0],
                   splits[s] ? splits[s] : "whole", median(walls[s], reps),
                   median(ratios[s], reps), rss[s], rss[s] / rss[0]);
            fflush(stdout);
        }
    }
    return 0;
}
