/* bench_explore: issue 5's panning benchmark. A session views a 1000x1000
 * cell window, then pans it right by 10 % PANS times (20 unless given),
 * rendering the view (1000x1000 PNG) after each pan; a full recompute
 * solves the final view from scratch in a fresh database and renders it
 * the same way.
 *
 *   bench_explore [463|421|osc] [DIR] [PANS]
 *
 * 463: the thesis' C-SCM example (4.6.3, panning right from the left
 * region); 421: the Fig. 4.21 parameters (max-steps 100000); osc: the dry
 * friction oscillator's Poincare map (Ch. 2, the 1a pair at S = 0.32), a
 * model whose images cost about a thousand times more. Prints each
 * pan's time (compute + join + commit, render), the medians, the ratio of
 * the last ten pans to pans 11-20 (with 20 pans or more) and the ratio of
 * a pan to the full recompute. Its threads wait as cellmap explore's do
 * and use the heap cellmap explore does (src/run_env.h). */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "bench_util.h"
#include "src/explore.h"
#include "src/run_env.h"

enum { MAX_PANS = 1000 };

typedef struct preset {
    const char *name, *model, *params, *view;
    double cell[2], origin[2];
    int max_steps;
} preset;

static const preset presets[] = {
    {"463",
     "microchaos-pd",
     "alpha=0.078,beta=0,P=0.007,D=0.02",
     "view 0:500 -40:40",
     {0.5, 0.08},
     {0, -40},
     1},
    {"421",
     "microchaos-pd",
     "alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3",
     "view -125000:125000 -600:600",
     {250, 1.2},
     {-125000, -600},
     100000},
    {"osc",
     "friction-oscillator",
     "S=0.32,S0=0.4,Omega=0.5,phi=0",
     "view -3:3 -3:3",
     {0.006, 0.006},
     {-3, -3},
     200},
};

/* Opens s in place: the session's store keeps a pointer to its model. */
static void open_session(explore *s, const preset *p, const char *path)
{
    session_options o;
    memset(&o, 0, sizeof o);
    unlink(path);
    o.path = path;
    o.mo.name = p->model;
    o.mo.texts[0] = p->params;
    o.mo.n_texts = 1;
    memcpy(o.cell_size, p->cell, sizeof p->cell);
    memcpy(o.origin, p->origin, sizeof p->origin);
    o.n_cell_size = o.n_origin = 2;
    o.max_steps = p->max_steps;
    o.command = "bench_explore";
    if (explore_open(s, &o, NULL) != 0)
        exit(1);
}

/* Runs a line and returns its time. */
static double timed(explore *s, const char *line)
{
    char msg[1024];
    const double t0 = now();
    if (explore_exec(s, line, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_explore: %s: %s\n", line, msg);
        exit(1);
    }
    return now() - t0;
}

static void close_session(explore *s)
{
    char msg[512];
    if (explore_close(s, msg, sizeof msg) != CM_OK) {
        fprintf(stderr, "bench_explore: %s\n", msg);
        exit(1);
    }
}

int main(int argc, char **argv)
{
    run_env_apply(argv, RUN_ENV_PASSIVE_WAIT | RUN_ENV_HUGE_PAGES); /* as cellmap explore runs */
    session_keep_freed();
    const preset *p = &presets[0];
    const char *dir = argc > 2 ? argv[2] : "/tmp";
    for (size_t k = 0; argc > 1 && k < sizeof presets / sizeof presets[0]; k++)
        if (strcmp(argv[1], presets[k].name) == 0)
            p = &presets[k];
    char db[4096], png[4200], render[4300];
    snprintf(db, sizeof db, "%s/bench_explore.cmdb", dir);
    snprintf(png, sizeof png, "%s/bench_explore.png", dir);
    snprintf(render, sizeof render, "render %s 1000x1000", png);

    explore s;
    open_session(&s, p, db);
    const double first = timed(&s, p->view), first_render = timed(&s, render);
    const int pans = argc > 3 ? atoi(argv[3]) : 20;
    if (pans < 1 || pans > MAX_PANS) {
        fprintf(stderr, "bench_explore: PANS must be 1..%d\n", MAX_PANS);
        return 2;
    }
    double pan[MAX_PANS], draw[MAX_PANS], total[MAX_PANS];
    printf("preset %s (%s %s, max-steps %d): first view %.1f ms + render %.1f ms\n", p->name,
           p->model, p->params, p->max_steps, 1e3 * first, 1e3 * first_render);
    printf("%4s %12s %12s %12s\n", "pan", "compute ms", "render ms", "total ms");
    for (int k = 0; k < pans; k++) {
        pan[k] = timed(&s, "pan right 10%");
        draw[k] = timed(&s, render);
        total[k] = pan[k] + draw[k];
        printf("%4d %12.1f %12.1f %12.1f\n", k + 1, 1e3 * pan[k], 1e3 * draw[k], 1e3 * total[k]);
    }
    char final_view[256];
    snprintf(final_view, sizeof final_view, "view %.17g:%.17g %.17g:%.17g", s.s.lo[0], s.s.hi[0],
             s.s.lo[1], s.s.hi[1]);
    close_session(&s);

    /* the same view from scratch, three times */
    double full[3], full_compute[3];
    for (int k = 0; k < 3; k++) {
        explore f;
        open_session(&f, p, db);
        full_compute[k] = timed(&f, final_view);
        full[k] = full_compute[k] + timed(&f, render);
        close_session(&f);
    }
    if (pans >= 20) { /* does a pan cost more as the cluster grows? (median sorts: copies) */
        double early[10], late[10];
        memcpy(early, total + 10, sizeof early);
        memcpy(late, total + pans - 10, sizeof late);
        const double me = median(early, 10), ml = median(late, 10);
        printf("median total of pans 11-20 %.1f ms, of pans %d-%d %.1f ms: ratio %.2f\n",
               1e3 * me, pans - 9, pans, 1e3 * ml, ml / me);
    }
    const double mc = median(pan, pans), mr = median(draw, pans), mt = median(total, pans);
    const double fc = median(full_compute, 3), ft = median(full, 3);
    printf("median pan: compute+join %.1f ms, render %.1f ms, total %.1f ms\n", 1e3 * mc, 1e3 * mr,
           1e3 * mt);
    printf("full recompute of the view: compute %.1f ms, with render %.1f ms\n", 1e3 * fc,
           1e3 * ft);
    printf("ratio pan/full: %.3f (with render in both), %.3f (compute only)\n", mt / ft, mc / fc);
    unlink(db);
    unlink(png);
    return 0;
}
