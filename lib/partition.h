/* lib/partition.h - the Markov partition of the delayed micro-chaos map
 * (thesis 4.4, Fig. 4.11) over models/delay_partition.h, written as CSV
 * (its transition matrix row by row) and as the chart of its intervals.
 * Nothing is printed: a failed write returns false with the problem in
 * msg. */
#ifndef CM_LIB_PARTITION_H
#define CM_LIB_PARTITION_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/project.h"
#include "models/delay_partition.h"

/* The model and the outputs (the command's options). */
typedef struct part_args {
    model_spec mo;
    chart_outputs out;
} part_args;

/* Row i of the transition matrix as text ("0 1 1 0 ..."; out: at least
 * 4 * p->r characters). */
void partition_row_text(const cm_delay_partition *p, int i, char *out);

/* The intervals and their rows as CSV at a->out.csv. */
bool partition_write_csv(const part_args *a, const cm_delay_partition *p, char *msg,
                         size_t msg_size);

/* The chart of the intervals at a->out.png. */
bool partition_write_png(const part_args *a, const cm_delay_partition *p, const char *params,
                         char *msg, size_t msg_size);

#endif
