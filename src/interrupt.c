#include "src/interrupt.h"

#include <signal.h>
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
