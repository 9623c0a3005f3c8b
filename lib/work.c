/* lib/work.c - progress from parallel loops (lib/work.h). */
#include "lib/work.h"

#include <omp.h>

cm_status work_canceled(const work_hooks *h, char *msg, size_t msg_size)
{
    const char *why = work_stop(h);
    return cm_fail(CM_ECANCELED, msg, msg_size, "%s", why ? why : "stopped");
}

cm_status work_check(const work_hooks *h, char *msg, size_t msg_size)
{
    return work_stop(h) ? work_canceled(h, msg, msg_size) : CM_OK;
}

void work_tick(const work_hooks *h, uint64_t *done)
{
    uint64_t now;
#pragma omp atomic capture
    now = ++*done;
    if (omp_get_thread_num() == 0)
        work_progress(h, now, NULL);
}
