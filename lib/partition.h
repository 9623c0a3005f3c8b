/* lib/partition.h - the Markov partition of the delayed micro-chaos map
 * (thesis 4.4, Fig. 4.11) over models/delay_partition.h, written as CSV
 * (its transition matrix row by row) and as the chart of its intervals.
 * Nothing is printed: calls return a status with the problem in msg
 * (CM_EINVAL: the request's). */
#ifndef CM_LIB_PARTITION_H
#define CM_LIB_PARTITION_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "models/delay_partition.h"

/* The model and the outputs (the command's options). */
typedef struct part_args {
    model_spec mo;
    chart_outputs out;
} part_args;

/* Row i of the transition matrix as text ("0 1 1 0 ..."; out: at least
 * 4 * p->r characters). */
void partition_row_text(const cm_delay_partition *p, int i, char *out);

/* The command's defaults: microchaos-delay, 900x700 pixels. */
part_args partition_defaults(void);

/* The model's parameters and its partition. */
typedef struct part_result {
    cm_params base;
    cm_delay_partition p;
} part_result;

/* Checks the model and finds its partition of (0, 1); CM_EINVAL when
 * there is none at its parameters (the message says why). */
cm_status partition_compute(const part_args *a, part_result *r, char *msg, size_t msg_size);

/* The intervals and their rows as CSV at a->out.csv and their chart at
 * a->out.png (either may be NULL). */
cm_status partition_write(const part_args *a, const part_result *r, char *msg, size_t msg_size);

/* The summary (the regions, their rows, primitivity) as text to f; the
 * partition as a JSON document on standard output. */
void partition_report(FILE *f, const cm_delay_partition *p);
void partition_json(const part_args *a, const part_result *r);

#endif
