/* lib/simulate.h - a trajectory of the friction oscillator followed
 * through its stick and slip phases (thesis Ch. 2) over
 * models/friction_oscillator.h: its events (sticks, breaks, turns, the
 * Poincare section) and samples recorded, written as CSV and as the time
 * history and phase portrait with the sticking band. Nothing is printed:
 * calls return a status with the problem in msg (CM_EINVAL: the
 * request's). */
#ifndef CM_LIB_SIMULATE_H
#define CM_LIB_SIMULATE_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/project.h"
#include "models/friction_oscillator.h"

typedef struct sim_args {
    model_spec mo;
    double from[2], t0;
    int has_t0, periods, skip;
    chart_outputs out;
} sim_args;

enum row_kind { ROW_START, ROW_STICK, ROW_BREAK, ROW_TURN, ROW_SECTION };

typedef struct row {
    double t, x, v;
    int kind;
} row;

typedef struct sample {
    double t, x, v;
    int stuck;
} sample;

typedef struct track {
    const cm_fo_run *run;
    int recording;
    row *rows;
    uint64_t n_rows, cap_rows;
    sample *samples;
    uint64_t n_samples, cap_samples;
    double psi_sum; /* x at the velocity zeros while recording (Psi, thesis 2.6.1) */
    bool out_of_memory;
} track;

/* Follows the run for the requested periods, recording those after the
 * skipped ones; *last receives the last period's tally and z_prev the
 * section point before the last one. False when the motion is lost. */
/* The model mo names, built, which must be the friction oscillator (*o:
 * its oscillator); what: the driver, for the message. *m is the caller's
 * to release whatever the status. */
cm_status simulate_oscillator(const model_spec *mo, const char *what, cm_model *m,
                              const cm_fo **o, char *msg, size_t msg_size);

/* The command's defaults: friction-oscillator, from (0, 0), 20 periods,
 * 900x1000 pixels; t0 (unless a->has_t0): the section's phase phi/Omega. */
sim_args simulate_defaults(void);

/* The model, the motion followed and what it recorded. */
typedef struct sim_result {
    cm_model m;
    const cm_fo *o; /* m's oscillator */
    cm_fo_run r;    /* at the end */
    track tr;
    cm_fo_tally last; /* the last period's */
    double z_prev[2]; /* the section point a period before the end */
} sim_result;

/* Builds the model and follows the motion from a->from at a->t0 for
 * a->periods periods, recording those after a->skip; r is freed by
 * simulate_result_free whatever the status (CM_EIO: the motion is lost,
 * more than CM_FO_MAX_EVENTS events in a period). */
cm_status simulate_compute(sim_args *a, sim_result *r, char *msg, size_t msg_size);

/* The recorded rows as CSV at a->out.csv and the time history and phase
 * portrait at a->out.png (either may be NULL). */
cm_status simulate_write(const sim_args *a, const sim_result *r, char *msg, size_t msg_size);

void simulate_result_free(sim_result *r);

#endif
