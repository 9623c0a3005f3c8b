/* cellmap/clock.h - the one clock of timings: seconds of the monotonic
 * clock (never set back, unaffected by changes of the wall clock), for
 * the durations that summaries, benchmarks and statistics report. */
#ifndef CM_CLOCK_H
#define CM_CLOCK_H

/* Seconds since an arbitrary origin; differences are durations. Thread-safe. */
double cm_seconds(void);

#endif
