/* lib/work.h - what a caller of the library's long drivers (exports,
 * solves, sessions) may hook into them: a progress count and a request to
 * stop. Both are optional, called on the thread that called the driver,
 * between units of work (a slab of cells, a region joined): never inside
 * a parallel loop. A driver that stops writes no partial output. */
#ifndef CM_LIB_WORK_H
#define CM_LIB_WORK_H

#include <stddef.h>
#include <stdint.h>

/* The one clock callers time work with: cm_seconds, monotonic seconds. */
#include "cellmap/clock.h"
#include "cellmap/status.h"

typedef struct work_hooks {
    /* units of work done so far (cells, regions: the driver's header
     * says) and what is being done (a phase, "3 regions joined"; may be
     * NULL); NULL: not told */
    void (*progress)(void *user, uint64_t done, const char *what);
    /* NULL to go on, else why to stop now ("interrupted (Ctrl-C)"); the
     * driver then returns CM_ECANCELED with that reason first in its
     * message. NULL: never stops. */
    const char *(*stop)(void *user);
    void *user;
} work_hooks;

/* The hooks' calls, for drivers; h may be NULL. */
static inline void work_progress(const work_hooks *h, uint64_t done, const char *what)
{
    if (h && h->progress)
        h->progress(h->user, done, what);
}

static inline const char *work_stop(const work_hooks *h)
{
    return h && h->stop ? h->stop(h->user) : NULL;
}

/* CM_ECANCELED, the hooks' reason to stop first in msg ("stopped" when
 * they no longer give one): for a driver whose work was stopped. */
cm_status work_canceled(const work_hooks *h, char *msg, size_t msg_size);

/* work_canceled when the hooks ask to stop now, else CM_OK: for a driver
 * between two units of work. */
cm_status work_check(const work_hooks *h, char *msg, size_t msg_size);

/* In a parallel loop: counts one unit more in *done (atomically) and, on
 * the loop's first thread only (the hooks need not be thread-safe), says
 * so through h. */
void work_tick(const work_hooks *h, uint64_t *done);

#endif
