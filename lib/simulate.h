/* lib/simulate.h - a trajectory of the friction oscillator followed
 * through its stick and slip phases (thesis Ch. 2) over
 * models/friction_oscillator.h: its events (sticks, breaks, turns, the
 * Poincare section) and samples recorded, written as CSV and as the time
 * history and phase portrait with the sticking band. Nothing is printed: a
 * failed write returns false with the problem in msg. */
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
/* Follows the motion from r's state for a->periods periods (after
 * a->skip), recording its events and samples in tr (rows and samples
 * freed by the caller; tr->out_of_memory says if they ran out), the last
 * period's tally in *last and the state a period before the end in
 * z_prev. False when a period has more than CM_FO_MAX_EVENTS events. */
bool simulate_follow(const cm_fo *o, const sim_args *a, cm_fo_run *r, track *tr, cm_fo_tally *last,
                   double z_prev[2]);

/* The recorded rows as CSV at path. */
bool simulate_write_csv(const char *path, const track *tr, char *msg, size_t msg_size);

/* The time history and the phase portrait at a->out.png. */
bool simulate_write_png(const sim_args *a, const cm_model *m, const cm_fo *o, const track *tr,
                        char *msg, size_t msg_size);

#endif
