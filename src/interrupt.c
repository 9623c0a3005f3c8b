#include "src/interrupt.h"

#include "src/args.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

/* The one thing a signal handler may set: the process's own request. */
static volatile sig_atomic_t requested;

static void on_sigint(int sig)
{
    (void)sig;
    requested = 1;
}

void interrupt_catch(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sa.sa_flags = SA_RESETHAND; /* the next SIGINT has its default effect */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
}

bool interrupt_requested(void) { return requested != 0; }

void interrupt_clear(void) { requested = 0; }

int interrupt_stopped(const char *cmd, uint64_t done, uint64_t total, const char *unit)
{
    fprintf(stderr, "cellmap %s: interrupted (Ctrl-C) after %llu of %llu %s; nothing written\n",
            cmd, (unsigned long long)done, (unsigned long long)total, unit);
    return EXIT_INTERRUPTED;
}
