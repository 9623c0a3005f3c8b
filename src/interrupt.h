/* src/interrupt.h - Ctrl-C as a request to stop cleanly: a long command
 * checks for it between units of work (a region joined and committed, a
 * row of images), stops there and says how to go on. A second Ctrl-C ends
 * the process at once, as usual. */
#ifndef CM_SRC_INTERRUPT_H
#define CM_SRC_INTERRUPT_H

#include <stdbool.h>
#include <stdint.h>

/* From now on SIGINT sets the request instead of ending the process (once). */
void interrupt_catch(void);

/* Whether SIGINT came since interrupt_catch. */
bool interrupt_requested(void);

/* Forgets a request, for a process that runs commands one after another
 * (the fuzz harness of whole commands); the commands never call it. */
void interrupt_clear(void);

/* Says that CMD stopped after `done` of `total` UNITs and wrote nothing;
 * returns EXIT_INTERRUPTED. */
int interrupt_stopped(const char *cmd, uint64_t done, uint64_t total, const char *unit);

#endif
