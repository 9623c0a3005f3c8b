/* lib/periodic.h - periodic orbits of any map model (a flow's section map
 * included) over models/map_periodic.h: a period-k point by Newton from a
 * start (or from where the orbit settles) with its multipliers; its
 * branch in one parameter with folds, period doublings and
 * Neimark-Sacker points; and a cascade: doubling after doubling, each
 * next branch switched to at the last doubling (thesis 3.2, Table 3.1),
 * with the Feigenbaum ratios and the accumulation point they give.
 * Written as CSV. Nothing is printed: calls return a status with the
 * problem in msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_PERIODIC_H
#define CM_LIB_PERIODIC_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/param_grid.h"
#include "models/map_periodic.h"

enum { PERIODIC_MAX_CASCADE = 12 };

typedef struct po_args {
    model_spec mo;
    branch_spec b; /* from: in the map's coordinates; a cascade needs a direction */
    int settle;    /* iterates of the map from b.from before Newton */
    int period;    /* 1.. */
    int cascade;   /* doublings to follow (0: none) */
    bool hopf;     /* start from the flow's first Hopf point on the branch of the
                      equilibrium near b.from (the flow's coordinates), b.direction's
                      way (default up); the section plane through it */
    const char *csv;
} po_args;

/* The command's defaults: chip-4d, period 1, no settling, both ways,
 * 10000 points a way. */
po_args periodic_defaults(void);

/* A fold, doubling or Neimark-Sacker point between pts[before - 1] and
 * pts[before]. */
typedef struct po_found {
    cm_po_event ev;
    size_t before;
} po_found;

typedef struct po_result {
    cm_model m;
    cm_periodic_point start;
    cm_periodic_point *pts; /* the branches in order (a cascade's one after another) */
    size_t n_pts, cap_pts;
    po_found *events;
    size_t n_events, cap_events;
    int why[2];              /* how each way of the (first) branch ended (CM_BRANCH_*) */
    double doublings[PERIODIC_MAX_CASCADE]; /* a cascade's doublings, in order */
    int n_doublings;
    bool tightened; /* a flow's tolerances were set to 1e-12 */
    bool from_hopf;
    double hopf_p, hopf_omega, level; /* the Hopf point and the section's level through it */
} po_result;

/* Checks the request (the start's dimension, the branch's parameter and
 * range holding the model's value, a cascade's direction) and computes.
 * For a flow's map the integrator's tolerances become 1e-12 unless the
 * parameters set them (multipliers by differences need them). r is freed
 * by periodic_result_free whatever the status; CM_ENOTFOUND when Newton
 * does not converge, or the next branch of a cascade is not found. */
cm_status periodic_compute(const po_args *a, po_result *r, char *msg, size_t msg_size);

/* The rows as CSV at a->csv (NULL: nothing): kind (point, fold, pd, ns),
 * period, the branch parameter's value, the state, the multipliers
 * (re_k, im_k by decreasing modulus) and how many lie outside the unit
 * circle. */
cm_status periodic_write(const po_args *a, const po_result *r, char *msg, size_t msg_size);

/* The result as text (the point and its multipliers, the Hopf point it
 * starts from, the branch's events, a cascade's Feigenbaum ratios and
 * accumulation) and as the JSON document of `cellmap periodic --json`
 * (docs/cellmap.schema.json), to f. */
void periodic_report(FILE *f, const po_args *a, const po_result *r);
void periodic_json(FILE *f, const po_args *a, const po_result *r);

void periodic_result_free(po_result *r);

/* "fold", "pd" or "ns". */
const char *periodic_event_name(int kind);

/* The onset of chaos a cascade's last two doublings give with
 * Feigenbaum's delta = 4.6692; NAN with fewer than 2. */
double periodic_accumulation(const po_result *r);

#endif
