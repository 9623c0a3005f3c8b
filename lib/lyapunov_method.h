/* lib/lyapunov_method.h - `lyapunov --method sync|stickmap`: the
 * estimates other than the grid's map (lib/lyapunov_sync.h,
 * lib/stick_map.h) behind one call each for the command. Nothing is
 * printed but by lyapunov_method_report. */
#ifndef CM_LIB_LYAPUNOV_METHOD_H
#define CM_LIB_LYAPUNOV_METHOD_H

#include "lib/lyapunov_sync.h"
#include "lib/stick_map.h"

/* "direct", "sync" or "stickmap" as LYAP_*; -1 for any other word. */
int lyapunov_method_of(const char *name);

typedef struct lyap_method_result {
    sync_result sync;        /* LYAP_SYNC */
    stick_map_result stick;  /* LYAP_STICKMAP */
    uint64_t done;           /* units (couplings, runs) done before a stop */
} lyap_method_result;

/* The estimate of a->method (not LYAP_DIRECT), progress through h; r is
 * freed by lyapunov_method_free whatever the status. */
cm_status lyapunov_method_compute(const lyap_args *a, const work_hooks *h, lyap_method_result *r,
                                  char *msg, size_t msg_size);
/* The estimate as text, or JSON when a->json. */
void lyapunov_method_report(FILE *out, const lyap_args *a, const lyap_method_result *r);
/* a->csv and a->png. */
cm_status lyapunov_method_write(const lyap_args *a, const lyap_method_result *r, char *msg,
                                size_t msg_size);
void lyapunov_method_free(lyap_method_result *r);

#endif
