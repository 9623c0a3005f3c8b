#define _DEFAULT_SOURCE
/* bench_mpi: `cellmap solve` on MPI ranks (lib/ranks.h), from the command
 * line, against the same solve in one process (issue: clustered SCM over
 * MPI). In turns, REPS times each, medians printed:
 *   - the thesis' Table 4.1 configuration (alpha = 0.07, x in [85.4, 485.4],
 *     x' in [-12.5, 12.5], two regions of 4 M cells: --split 2x1), and the
 *     same as --split 4x4: 2 ranks of 1 thread against 1 process of 2
 *     threads; the bytes between the ranks per cell; the joins' share;
 *   - the ODE model duffing at 400 x 400 cells (--split 4x4): 2 ranks of 1
 *     thread against 1 process of 1 thread, the speed-up.
 * Each figure twice: the solve (rank 0's "regions and joins" and summary
 * from --json) and the whole command (mpirun's start and MPI's included).
 * usage: bench_mpi PATH/TO/cellmap [REPS]   (REPS default 5; mpirun on PATH) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

enum { MAX_REPS = 50 };

/* The number after "key": in text, or -1. */
static double json_number(const char *text, const char *key)
{
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\":", key);
    const char *at = strstr(text, quoted);
    return at ? strtod(at + strlen(quoted), NULL) : -1;
}

typedef struct run_out {
    double wall, solve, joins, bytes_per_cell;
} run_out;

/* One solve: in one process (ranks 0), or on 2 ranks under mpirun. */
static int run(const char *cm, int ranks, int threads, const char *args, run_out *o)
{
    char cmd[2048], out[1 << 16];
    snprintf(cmd, sizeof cmd, "%s'%s' solve %s --threads %d --json",
             ranks ? "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun "
                     "--oversubscribe -n 2 "
                   : "",
             cm, args, threads);
    const double t0 = now();
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    const size_t n = fread(out, 1, sizeof out - 1, p);
    out[n] = '\0';
    if (pclose(p) != 0)
        return -1;
    o->wall = now() - t0;
    char *w = out; /* the keys as cmd_solve writes them, without spaces after the colon */
    for (const char *r = out; *r; r++)
        if (!(*r == ' ' && r > out && r[-1] == ':'))
            *w++ = *r;
    *w = '\0';
    o->solve = json_number(out, "regions and joins") + json_number(out, "summary");
    o->joins = json_number(out, "joins");
    o->bytes_per_cell = ranks ? json_number(out, "bytes_per_cell") : 0;
    return o->solve > 0 ? 0 : -1;
}

static const char *const table41 =
    "--param alpha=0.07,beta=0,P=0.007,D=0.02 --region 85.4:485.4,-12.5:12.5 --max-steps 20 "
    "--cells 4000x2000";

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_mpi PATH/TO/cellmap [REPS]\n");
        return 2;
    }
    const int reps = argc > 2 ? atoi(argv[2]) : 5;
    if (reps < 1 || reps > MAX_REPS) {
        fprintf(stderr, "bench_mpi: REPS must be 1..%d\n", MAX_REPS);
        return 2;
    }
    char split2[512], split4[512];
    snprintf(split2, sizeof split2, "%s --split 2x1", table41);
    snprintf(split4, sizeof split4, "%s --split 4x4", table41);
    const struct {
        const char *name, *args;
        int threads_alone; /* the one process's threads */
    } cases[] = {{"table4.1 2x1", split2, 2},
                 {"table4.1 4x4", split4, 2},
                 {"duffing 400^2", "--model duffing --cells 400x400 --split 4x4", 1}};
    printf("%-14s %10s %10s %8s %10s %10s %8s %8s %8s\n", "case", "alone_ms", "2ranks_ms", "ratio",
           "alone_cmd", "2ranks_cmd", "ratio", "joins", "B/cell");
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double ratio[MAX_REPS], cmd_ratio[MAX_REPS], alone[MAX_REPS], ranked[MAX_REPS],
            alone_cmd[MAX_REPS], ranked_cmd[MAX_REPS], share[MAX_REPS], bytes[MAX_REPS];
        for (int r = 0; r < reps; r++) {
            run_out a, m;
            if (run(argv[1], 0, cases[c].threads_alone, cases[c].args, &a) != 0 ||
                run(argv[1], 1, 1, cases[c].args, &m) != 0) {
                fprintf(stderr, "bench_mpi: %s failed\n", cases[c].name);
                return 1;
            }
            alone[r] = a.solve;
            ranked[r] = m.solve;
            alone_cmd[r] = a.wall;
            ranked_cmd[r] = m.wall;
            ratio[r] = m.solve / a.solve;
            cmd_ratio[r] = m.wall / a.wall;
            share[r] = m.joins / m.solve;
            bytes[r] = m.bytes_per_cell;
        }
        printf("%-14s %10.1f %10.1f %8.2f %10.1f %10.1f %8.2f %8.2f %8.2f\n", cases[c].name,
               1e3 * median(alone, reps), 1e3 * median(ranked, reps), median(ratio, reps),
               1e3 * median(alone_cmd, reps), 1e3 * median(ranked_cmd, reps),
               median(cmd_ratio, reps), median(share, reps), median(bytes, reps));
        fflush(stdout);
    }
    return 0;
}
