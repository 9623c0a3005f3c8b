/* lib/map_bifurcation.h - Monte Carlo bifurcation diagrams of any map
 * model (a flow's section or stroboscopic map included; thesis Fig. 3.5
 * for chip-4d): for each value of the swept parameter, runs from random
 * starts in the model's example region iterated past a transient, one
 * coordinate of each recorded iterate kept; drawn with the branches of
 * `cellmap equilibria` and `cellmap periodic` (their CSV tables: stable
 * black, unstable red) over the points. The request is bifurcation's
 * (lib/bifurcation.h: sweep, runs, transient and record in iterates,
 * seed, threads, of, branches). Nothing is printed: calls return a status
 * with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_MAP_BIFURCATION_H
#define CM_LIB_MAP_BIFURCATION_H

#include "lib/bifurcation.h"

/* Whether the model spec names a map model (not friction-oscillator). */
bool map_bifurcation_model(const model_spec *mo);

typedef struct map_bif_result {
    cm_params base;
    int dim, of;       /* the map's dimension; the coordinate recorded */
    char of_name[32];
    double *points;    /* [value][run][record]; NAN where the run was lost or not built */
    bool *lost;        /* [value][run] */
    int n_valid;       /* values whose model could be built */
    uint64_t done, followed, n_lost;
    double seconds;
} map_bif_result;

/* Checks the request (a map model, its parameter, the branch tables'
 * columns) and follows every run on a->threads threads; progress in runs
 * through h, stopped by h (CM_ECANCELED, with r->done). The same seed gives
 * the same starts, and the result does not depend on the thread count. r
 * is freed by map_bifurcation_free whatever the status. */
cm_status map_bifurcation_compute(const bif_args *a, const work_hooks *h, map_bif_result *r,
                                  char *msg, size_t msg_size);

/* The points as CSV (NAME,run,COORD) at a->out.csv and the diagram with
 * the branches at a->out.png (either may be NULL). */
cm_status map_bifurcation_write(const bif_args *a, const map_bif_result *r, char *msg,
                                size_t msg_size);

/* The runs followed and lost as text, or (a->out.json) as the JSON
 * document of `cellmap bifurcation --json`, to f. */
void map_bifurcation_report(FILE *f, const bif_args *a, const map_bif_result *r);

void map_bifurcation_free(map_bif_result *r);

#endif
