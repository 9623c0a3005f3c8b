/* lib/lyapunov_method.c - the other estimators behind one call
 * (lib/lyapunov_method.h). */
#include "lib/lyapunov_method.h"

#include <string.h>

int lyapunov_method_of(const char *name)
{
    static const char *const names[] = {"direct", "sync", "stickmap"}; /* LYAP_* order */
    for (int k = 0; k < 3; k++)
        if (strcmp(name, names[k]) == 0)
            return k;
    return -1;
}

cm_status lyapunov_method_compute(const lyap_args *a, const work_hooks *h, lyap_method_result *r,
                                  char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    cm_status st = a->method == LYAP_SYNC ? lyapunov_sync(a, h, &r->sync, msg, msg_size)
                                          : stick_map_compute(a, h, &r->stick, msg, msg_size);
    r->done = a->method == LYAP_SYNC ? r->sync.done : r->stick.done;
    return st;
}

void lyapunov_method_report(FILE *out, const lyap_args *a, const lyap_method_result *r)
{
    if (a->method == LYAP_SYNC)
        lyapunov_sync_report(out, a, &r->sync);
    else
        stick_map_report(out, a, &r->stick);
}

cm_status lyapunov_method_write(const lyap_args *a, const lyap_method_result *r, char *msg,
                                size_t msg_size)
{
    return a->method == LYAP_SYNC ? lyapunov_sync_write(a, &r->sync, msg, msg_size)
                                  : stick_map_write(a, &r->stick, msg, msg_size);
}

void lyapunov_method_free(lyap_method_result *r)
{
    lyapunov_sync_free(&r->sync);
    stick_map_free(&r->stick);
}
