/* bench_continue: the time of the thesis' Fig. 2.17 diagram by
 * continuation (Omega = 0.5, S0 = 0.4, S in 0.02..0.4) as the example
 * figure draws it: the 1a, 2s and 1a,9seg branches from S = 0.3, 0.38 and
 * 0.04 and the period-doubled branches from their PD events, each both
 * ways, with their events. Continuation is sequential, so the thread count does not enter;
 * prints the median of REPS runs, points and events.
 * usage: bench_continue [REPS (default 7)] */
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "models/fo_continuation.h"

typedef struct tally {
    int points, events, n_pd;
    cm_fo_branch_event pd[8]; /* the period doublings, to switch at */
} tally;

static int count_point(void *user, const cm_fo_solution *s)
{
    (void)s;
    ((tally *)user)->points++;
    return 0;
}

static int count_event(void *user, const cm_fo_branch_event *e)
{
    tally *t = user;
    t->events++;
    if (e->type == CM_FO_EVENT_PD && t->n_pd < 8)
        t->pd[t->n_pd++] = *e;
    return 0;
}

/* The branch through the period-k solution z of o at p0, both ways. */
static void both_ways(const cm_fo *o, double p0, const double z[2], int k, tally *t)
{
    for (int dir = -1; dir <= 1; dir += 2) {
        const cm_fo_continue_options opt = {CM_FO_P_S, 0.02, 0.4, dir, 0, 0, 0, 5000};
        int stop;
        cm_fo_continue(o, &opt, p0, z, k, count_point, count_event, t, &stop);
    }
}

/* The diagram of assets/examples/make-figures.sh: 1a (S = 0.3), 2s (0.38)
 * and 1a,9seg (0.04), both ways, then the period-doubled branches. */
static double diagram(tally *t)
{
    const double t0 = now();
    const double starts[3] = {0.3, 0.38, 0.04};
    *t = (tally){0};
    for (int b = 0; b < 3; b++) {
        cm_fo o;
        cm_fo_init(&o, starts[b], 0.4, 0.5, 0);
        double z[2] = {1 + 0.9 * 0.4, 0};
        const int k = cm_fo_find_periodic(&o, z, 500, 16);
        if (k > 0)
            both_ways(&o, starts[b], z, k, t);
    }
    const int n_pd = t->n_pd;
    for (int i = 0; i < n_pd; i++) {
        cm_fo base, from;
        cm_fo_init(&base, 0.3, 0.4, 0.5, 0);
        double z[2], q;
        if (!cm_fo_period_doubled(&base, CM_FO_P_S, &t->pd[i], z, &q))
            continue;
        cm_fo_init(&from, q, 0.4, 0.5, t->pd[i].at.phi);
        both_ways(&from, q, z, 2 * t->pd[i].at.period, t);
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
    tally counts;
    diagram(&counts); /* untimed warm-up */
    for (int r = 0; r < reps; r++)
        t[r] = diagram(&counts);
    printf("Fig. 2.17 by continuation (1a, 2s, 1a,9seg and the doubled 2a, each both ways): "
           "%d points, %d events, median %.3f s of %d runs\n",
           counts.points, counts.events, median(t, reps), reps);
    return 0;
}
