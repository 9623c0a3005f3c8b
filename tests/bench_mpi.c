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
 * Then the scaling model of docs/engine.md ("How a solve on ranks
 * scales") against the solve's time on R = 1, 2, 3 ranks of t = 1, 2
 * threads, for duffing and the Table 4.1 4x4 split: its inputs measured on
 * 1 rank of 1 thread (S, J) and 2 ranks of 1 thread (X), its predictions
 * and their errors for the other runs.
 * usage: bench_mpi PATH/TO/cellmap [REPS] [CORES]   (REPS default 5; CORES
 * default the online processors; mpirun on PATH) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CM_BENCH_COMMAND_JSON
#include "bench_util.h"

enum { MAX_REPS = 50 };

typedef struct run_out {
    double wall, solve, joins, bytes_per_cell;
} run_out;

/* One solve: in one process (ranks 0 or 1), or under mpirun on `ranks`. */
static int run(const char *cm, int ranks, int threads, const char *args, run_out *o)
{
    char cmd[2048], out[1 << 16], launch[256] = "";
    if (ranks > 1)
        snprintf(launch, sizeof launch,
                 "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun "
                 "--oversubscribe -n %d ",
                 ranks);
    snprintf(cmd, sizeof cmd, "%s'%s' solve %s --threads %d --json", launch, cm, args, threads);
    if (command_json(cmd, out, sizeof out, &o->wall) != 0)
        return -1;
    o->solve = json_number(out, "regions and joins") + json_number(out, "summary");
    o->joins = json_number(out, "joins");
    o->bytes_per_cell = ranks > 1 ? json_number(out, "bytes_per_cell") : 0;
    return o->solve > 0 ? 0 : -1;
}

/* The scaling model (docs/engine.md): the solve's time on R ranks of t
 * threads and P cores, from S (the regions' SCM on one thread), J (the
 * joins, serial on rank 0) and X (what taking every region from other
 * ranks would cost rank 0: receiving it, its node table, its exits
 * located). Boxes go to whichever thread is free (lib/ranks.h), so the
 * workers take the share of their threads, (R - 1) / R, and rank 0 that
 * share of X. The longer of two: rank 0's joining thread (the joins and
 * what it receives), and all the work over the threads, or the cores. */
static double model(double S, double J, double X, int R, int t, int P)
{
    const double XR = X * (R - 1) / R;
    const double joining = J + XR;
    const double spread = (S + J + XR) / (R * t < P ? R * t : P);
    return fmax(joining, spread);
}

/* Medians of the solve and its joins on R ranks of t threads. */
static int measure(const char *cm, int reps, int R, int t, const char *args, double *solve,
                   double *joins)
{
    double v[MAX_REPS], w[MAX_REPS];
    for (int r = 0; r < reps; r++) {
        run_out o;
        if (run(cm, R, t, args, &o) != 0)
            return -1;
        v[r] = o.solve;
        w[r] = o.joins;
    }
    *solve = median(v, reps);
    *joins = median(w, reps);
    return 0;
}

static int model_table(const char *cm, int reps, int cores, const char *duffing,
                       const char *table41_4x4)
{
    const char *names[2] = {"duffing 400^2", "table4.1 4x4"}, *args[2] = {duffing, table41_4x4};
    printf("\nscaling model on %d cores (S, J from 1 rank x 1 thread, X from 2 x 1):\n", cores);
    printf("%-14s %6s %6s %6s %2s %2s %10s %10s %7s\n", "case", "S_ms", "J_ms", "X_ms", "R", "t",
           "measured", "model", "error");
    for (int c = 0; c < 2; c++) {
        double T11, J, T21, J21, S, X;
        if (measure(cm, reps, 1, 1, args[c], &T11, &J) != 0 ||
            measure(cm, reps, 2, 1, args[c], &T21, &J21) != 0) {
            fprintf(stderr, "bench_mpi: %s failed\n", names[c]);
            return 1;
        }
        S = T11 - J;
        /* the model's 2 x 1 time inverted: each of its two terms grows with X */
        X = fmax(0, fmin(2 * (T21 - J), 2 * ((cores < 2 ? cores : 2) * T21 - S - J)));
        for (int R = 1; R <= 3; R++)
            for (int t = 1; t <= 2; t++) {
                double T = T11, unused;
                if (R == 2 && t == 1)
                    T = T21;
                else if ((R > 1 || t > 1) && measure(cm, reps, R, t, args[c], &T, &unused) != 0)
                    return 1;
                const double p = model(S, J, X, R, t, cores);
                printf("%-14s %6.1f %6.1f %6.1f %2d %2d %10.1f %10.1f %6.0f%%%s\n", names[c], 1e3 * S,
                       1e3 * J, 1e3 * X, R, t, 1e3 * T, 1e3 * p, 100 * (p - T) / T,
                       (R == 1 && t == 1) || (R == 2 && t == 1) ? " (input)" : "");
                fflush(stdout);
            }
    }
    return 0;
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
                run(argv[1], 2, 1, cases[c].args, &m) != 0) {
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
    const int cores = argc > 3 ? atoi(argv[3]) : (int)sysconf(_SC_NPROCESSORS_ONLN);
    return model_table(argv[1], reps, cores, cases[2].args, split4);
}
