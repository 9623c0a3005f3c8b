/* src/progress.h - the progress line of long commands: on stderr, only
 * when stderr is a terminal and --quiet was not given, at most five times
 * a second, rewritten in place ("solve: 3 regions joined, 1.2 M cells,
 * 40.1 M cells/s, about 2 s left"). It never changes a command's results
 * or its other output. */
#ifndef CM_SRC_PROGRESS_H
#define CM_SRC_PROGRESS_H

#include <stdbool.h>
#include <stdint.h>

#include "lib/work.h"

typedef struct progress {
    const char *cmd;  /* "solve" */
    const char *unit; /* what is counted: "cells", "grid points", "runs" */
    uint64_t total;   /* units the command will do (0: unknown; more may come) */
    bool show;
    int width;  /* the characters of the line on the terminal (0: none) */
    double t0, last;
} progress;

/* Starts the clock; the line shows only where stderr is a terminal. */
void progress_start(progress *p, const char *cmd, const char *unit, uint64_t total, bool quiet);
/* Says that `done` units are done (what: an optional note, e.g. a phase). */
void progress_say(progress *p, uint64_t done, const char *what);

/* Erases the line, if one is shown, so that what follows (a report line,
 * an error) starts at the left; the next progress_say draws it again. */
void progress_end(progress *p);

/* The library's hooks (lib/work.h) for a command's long call: progress
 * said on p, and Ctrl-C (src/interrupt.h) as the request to stop, with
 * the reason "interrupted (Ctrl-C)". p must outlive the call. */
work_hooks progress_hooks(progress *p);

#endif
