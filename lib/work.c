/* lib/work.c - progress from parallel loops (lib/work.h). */
#include "lib/work.h"

#include <omp.h>

void work_tick(const work_hooks *h, uint64_t *done)
{
    uint64_t now;
#pragma omp atomic capture
    now = ++*done;
    if (omp_get_thread_num() == 0)
        work_progress(h, now, NULL);
}
