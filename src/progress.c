/* src/progress.c - the progress line (src/progress.h). */
#include "src/progress.h"

#include "src/interrupt.h"

#include "lib/work.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

void progress_start(progress *p, const char *cmd, const char *unit, uint64_t total, bool quiet)
{
    *p = (progress){cmd, unit, total, !quiet && isatty(STDERR_FILENO), 0, cm_seconds(), 0};
}

/* n units as people read them: 950, 12.3 k, 1.2 M */
static void amount(double n, char *out, size_t size)
{
    if (n >= 1e6)
        snprintf(out, size, "%.1f M", n / 1e6);
    else if (n >= 1e4)
        snprintf(out, size, "%.1f k", n / 1e3);
    else
        snprintf(out, size, "%.0f", n);
}

void progress_say(progress *p, uint64_t done, const char *what)
{
    const double t = cm_seconds();
    if (!p->show || t - p->last < 0.2)
        return;
    p->last = t;
    const double rate = (double)done / (t - p->t0 + 1e-9);
    char count[32], speed[32], total[48] = "", eta[64] = "";
    amount((double)done, count, sizeof count);
    amount(rate, speed, sizeof speed);
    if (p->total > done && p->total > 0) {
        char all[32];
        amount((double)p->total, all, sizeof all);
        snprintf(total, sizeof total, " of %s", all);
        if (rate > 0)
            snprintf(eta, sizeof eta, ", about %.0f s left", (double)(p->total - done) / rate);
    }
    char line[512];
    const int n = snprintf(line, sizeof line, "%s: %s%s%s%s %s, %s %s/s%s", p->cmd,
                           what ? what : "", what ? ", " : "", count, total, p->unit, speed,
                           p->unit, eta);
    /* pad over a longer previous line */
    fprintf(stderr, "\r%s%*s", line, p->width > n ? p->width - n : 0, "");
    fflush(stderr);
    p->width = n > p->width ? n : p->width;
}

void progress_end(progress *p)
{
    if (p->width > 0)
        fprintf(stderr, "\r%*s\r", p->width, "");
    fflush(stderr);
    p->width = 0;
}

static void said_done(void *user, uint64_t done, const char *what)
{
    progress_say(user, done, what);
}

static const char *ctrl_c(void *user)
{
    (void)user;
    return interrupt_requested() ? "interrupted (Ctrl-C)" : NULL;
}

work_hooks progress_hooks(progress *p) { return (work_hooks){said_done, ctrl_c, p}; }
