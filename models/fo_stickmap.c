#include "models/fo_stickmap.h"

#include <stddef.h>

typedef struct stick_log {
    double t_section; /* the period's start: events come in its local time */
    cm_fo_stick *out;
    int n, cap;
} stick_log;

static void log_stick(void *user, const cm_fo_event *e)
{
    stick_log *log = user;
    if (e->kind == CM_FO_EV_STICK && log->n < log->cap)
        log->out[log->n++] = (cm_fo_stick){log->t_section + e->s, e->x};
}

int cm_fo_sticks(const cm_fo *o, double t0, double x, double v, int periods, cm_fo_stick *out,
                 int cap)
{
    cm_fo_run run;
    cm_fo_run_start(o, t0, x, v, &run);
    stick_log log = {0, out, 0, cap};
    for (int p = 0; p < periods && log.n < cap; p++) {
        log.t_section = run.t_section;
        if (!cm_fo_run_period(o, &run, NULL, log_stick, &log))
            return -1;
    }
    return log.n;
}

bool cm_fo_stick_after(const cm_fo *o, double t, double x, int k, int max_periods,
                       cm_fo_stick *out)
{
    cm_fo_stick sticks[64];
    if (k < 1 || k > 64)
        return false;
    /* at rest at x: the run starts stuck (its force is within S0 where it
     * stuck), so its own stick is not counted */
    const int n = cm_fo_sticks(o, t, x, 0, max_periods, sticks, k);
    if (n < k)
        return false;
    *out = sticks[k - 1];
    return true;
}
