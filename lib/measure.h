/* lib/measure.h - measures of a .cmdb file's basins by attractors
 * (cellmap/basin_measure.h) over a window of its cells: the basins' shares
 * of the computed cells (each attractor's, the diverged and outside
 * cells'); basin entropy Sb and boundary basin entropy Sbb for a few box
 * sizes, with their mean and spread and the log 2 criterion; the fractions
 * of eps-uncertain cells for eps doubling over a range, the uncertainty
 * exponent fitted to them and the boundary's dimension; the Wada test;
 * and, given a second file solved on the same lattice (another parameter
 * value), the tipping probabilities: where each basin's cells lie in the
 * second file's basins; and, given a number of samples, the shares of
 * random states of the window by their true orbits
 * (cellmap/attractor_fates.h), with intervals that hold the true shares
 * together 95 times in 100, which the cells' shares are checked against.
 * The window's labels (4 bytes a cell, of both files with a second) are
 * held whole when they fit the budget, else read twice in slabs of rows
 * along dimension 0 with the rows the measures look at around them (at
 * most half the budget; the clusters' pages take the rest), the shares
 * counted on the first pass, the measures on the second: the same counts
 * either way (cm_label_grid). Written as text, JSON and CSV. Nothing is printed but by the report calls: calls return a
 * status with the problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_MEASURE_H
#define CM_LIB_MEASURE_H

#include <stdbool.h>
#include <stdio.h>

#include "cellmap/basin_measure.h"
#include "lib/work.h"

enum { MEASURE_MAX_BOXES = 8, MEASURE_MAX_EPS = 16 };
#define MEASURE_MAX_SAMPLES UINT64_C(100000000)

typedef struct measure_args {
    const char *file;
    const char *window;    /* "X0:X1[,Y0:Y1...]" in state units; NULL: every cell */
    uint64_t mem;          /* bytes for the labels and the clusters' pages, half each */
    int box[MEASURE_MAX_BOXES]; /* basin entropy's box sizes in cells (n_box 0: none) */
    int n_box;
    int eps_lo, eps_hi;    /* uncertain fractions for eps = lo, 2 lo, ... <= hi (hi 0: none) */
    int wada_radius;       /* the Wada test for r = 1 .. radius (0: none) */
    bool wada_asked;       /* fewer than 3 basins is then an error, else the test is skipped */
    const char *to;        /* a second file on the same lattice: the tipping probabilities
                              from the first's basins into its basins, or NULL */
    uint64_t samples;      /* random states of the window whose true orbits are followed to
                              their attractors (cellmap/attractor_fates.h), or 0 */
    uint64_t seed;         /* their stream (cm_sample_states) */
    uint64_t sample_steps; /* each one's budget of map steps (0: the default) */
    double orbit_eps_lo, orbit_eps_hi; /* with samples: eps-uncertain fractions by true orbits
                                          for eps = lo, 2 lo, ... <= hi cells (hi 0: none) */
    int threads;           /* OpenMP threads following them (0: the OpenMP default) */
    const char *csv;       /* measure,scale,value rows, or NULL */
    const char *png;       /* a 2-D window's figure: the entropy map in the first box size
                              over the uncertain fractions against eps, log-log; or NULL */
    int width, height;
} measure_args;

/* Every measure: boxes 3, 5, 7, 9 cells; eps 1 .. 16; Wada to r = 5; the
 * budget 256 MiB; the figure 800x1000. */
measure_args measure_defaults(void);

typedef struct measure_share {
    int32_t label;   /* an attractor's id, 0 diverged, -2 outside */
    uint64_t cells;
    double share;    /* of the computed cells */
    double half_width; /* the share's 95 % interval as if the cells were sampled */
    uint64_t sampled;  /* with samples: the states whose true orbits end here */
    double sampled_share, sampled_lo, sampled_hi; /* their share, its Wilson interval at
                                                     1 - 0.05 / (shares listed) */
    bool agrees;       /* share lies within that interval */
} measure_share;

/* Of the cells of basin `from` in the first file, the share that lies in
 * basin `to` of the second (among the cells computed in both). */
typedef struct measure_tip {
    int32_t from, to;
    uint64_t cells;
    double probability;
} measure_tip;

typedef struct measure_result {
    char model[64];
    char names[2][32];         /* the first two state coordinates' */
    int dim;
    int64_t n[CM_MAX_DIM];     /* the window's cells per dimension */
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM]; /* its extent in state units */
    uint64_t cells, computed;
    measure_share *shares;     /* by label, the attractors first */
    int n_shares;
    cm_entropy entropy[MEASURE_MAX_BOXES];
    int n_entropy;
    double sb_mean, sb_spread, sbb_mean, sbb_spread;
    double eps[MEASURE_MAX_EPS], uncertain[MEASURE_MAX_EPS];
    uint64_t counted[MEASURE_MAX_EPS];
    int n_eps;
    double alpha, alpha_r2;    /* NAN with fewer than 2 fractions above 0 */
    /* by true orbits: of the sampled states whose fate is decided, the share
     * with a state eps cells away along an axis that goes elsewhere */
    double orbit_eps[MEASURE_MAX_EPS], orbit_uncertain[MEASURE_MAX_EPS];
    uint64_t orbit_counted[MEASURE_MAX_EPS];
    int n_orbit_eps;
    double orbit_alpha, orbit_alpha_r2;
    bool has_wada;
    cm_wada wada;
    char to_model[64];         /* the second file's model ("" without one) */
    measure_tip *tips;         /* by source basin, the probabilities summing to 1 */
    int n_tips;
    uint64_t samples;          /* states drawn (0: none) */
    uint64_t sampled;          /* of them, those in computed cells (the shares' base) */
    uint64_t sample_steps;     /* map steps their orbits took */
    uint64_t sample_same;      /* of the sampled, those whose fate is their cell's label */
    bool samples_agree;        /* every share within its sampled interval */
    int64_t slabs;             /* the window read whole (1) or in this many slabs */
    double seconds_read, seconds_sample, seconds_entropy, seconds_uncertain, seconds_wada;
    double *entropy_map;       /* with a->png: the first box size's boxes, x fastest */
    int64_t map_n[2];          /* boxes along x and y */
} measure_result;

/* Checks the request, reads the window's labels (hooks count cells) and
 * measures. r is freed by measure_result_free whatever the status. */
cm_status measure_compute(const measure_args *a, const work_hooks *hooks, measure_result *r,
                          char *msg, size_t msg_size);

/* The rows measure,scale,value at a->csv (NULL: nothing): share (scale:
 * the label), sb and sbb (the box), uncertain (eps), wada (r), tipping
 * (FROM>TO); the figure at a->png (NULL: none). */
cm_status measure_write(const measure_args *a, const measure_result *r, char *msg,
                        size_t msg_size);

/* The result as text and as the JSON document of `cellmap measure --json`
 * (docs/cellmap.schema.json), to f. */
void measure_report(FILE *f, const measure_result *r);
void measure_json(FILE *f, const measure_result *r);

void measure_result_free(measure_result *r);

#endif
