/* lib/lyapunov_sync.h - `lyapunov --method sync`: the synchronisation
 * estimate of the dry friction oscillator's largest Lyapunov exponent
 * (thesis 2.6.1, Fig. 2.23; models/fo_sync.h) over a range of couplings
 * q: the copy's distance from the oscillator after the transient at each
 * q, the smallest q from which every larger one synchronises, written as
 * CSV and as the thesis' Monte Carlo diagram (x1 - x3 at the section
 * instants against q). Nothing is printed. */
#ifndef CM_LIB_LYAPUNOV_SYNC_H
#define CM_LIB_LYAPUNOV_SYNC_H

#include <stdio.h>

#include "lib/lyapunov.h"

enum { SYNC_RECORD = 100 }; /* periods watched after the transient */

typedef struct sync_result {
    cm_params base;   /* S, S0, Omega, ... */
    int n;            /* couplings */
    double *largest;  /* per q: the largest |x1 - x3|, |x2 - x4| over the watched periods */
    double *gaps;     /* per q: x1 - x3 at the end of each watched period (n * SYNC_RECORD) */
    int first;        /* the index from which every q synchronises; -1: none */
    double seconds;
    uint64_t done;    /* couplings computed before a stop */
} sync_result;

/* The couplings a->q on a->threads threads, a->periods periods each (the
 * last SYNC_RECORD watched), progress in couplings through h.
 * CM_EINVAL for a model other than the friction oscillator, S > S0, or
 * fewer periods than SYNC_RECORD + 100. r is freed by
 * lyapunov_sync_free whatever the status. */
cm_status lyapunov_sync(const lyap_args *a, const work_hooks *h, sync_result *r, char *msg,
                        size_t msg_size);

/* The CSV (q, largest, synchronised) at a->csv and the diagram at a->png. */
cm_status lyapunov_sync_write(const lyap_args *a, const sync_result *r, char *msg,
                              size_t msg_size);

/* The estimate as a line of text, or as JSON when a->json. */
void lyapunov_sync_report(FILE *out, const lyap_args *a, const sync_result *r);

void lyapunov_sync_free(sync_result *r);

#endif
