/* bench_continue: the time of the thesis' Fig. 2.17 diagram by
 * continuation (Omega = 0.5, S0 = 0.4, S in 0.02..0.4): the 2s branch from
 * S = 0.38 and the 1a branch from S = 0.3, each both ways, with their
 * events. Continuation is sequential, so the thread count does not enter;
 * prints the median of REPS runs, points and events.
 * usage: bench_continue [REPS (default 7)] */
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "models/fo_continuation.h"

static int count_point(void *user, const cm_fo_solution *s)
{
    (void)s;
    ((int *)user)[0]++;
    return 0;
}

static int count_event(void *user, const cm_fo_branch_event *e)
{
    (void)e;
    ((int *)user)[1]++;
    return 0;
}

/* The four branches; counts[0] points, counts[1] events. */
static double diagram(int counts[2])
{
    const double t0 = now();
    const double starts[2] = {0.38, 0.3};
    counts[0] = counts[1] = 0;
    for (int b = 0; b < 2; b++)
        for (int dir = -1; dir <= 1; dir += 2) {
            cm_fo o;
            cm_fo_init(&o, starts[b], 0.4, 0.5, 0);
            double z[2] = {1 + 0.9 * 0.4, 0};
            const int k = cm_fo_find_periodic(&o, z, 500, 16);
            const cm_fo_continue_options opt = {CM_FO_P_S, 0.02, 0.4, dir, 0, 0, 0, 5000};
            int stop;
            if (k > 0)
                cm_fo_continue(&o, &opt, starts[b], z, k, count_point, count_event, counts, &stop);
        }
    return now() - t0;
}

int main(int argc, char **argv)
{
    const int reps = argc > 1 ? atoi(argv[1]) : 7;
    if (reps < 1 || reps > 100) {
        fprintf(stderr, "usage: bench_continue [REPS 1..100]\n");
        return 2;
    }
    double t[100];
    int counts[2];
    diagram(counts); /* untimed warm-up */
    for (int r = 0; r < reps; r++)
        t[r] = diagram(counts);
    printf("Fig. 2.17 by continuation (4 branches): %d points, %d events, median %.3f s of %d runs\n",
           counts[0], counts[1], median(t, reps), reps);
    return 0;
}
