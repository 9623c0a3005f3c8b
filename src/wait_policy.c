/* src/wait_policy.c - see wait_policy.h. */
#include "src/wait_policy.h"

#include <stdlib.h>
#include <unistd.h>

void wait_passively(char **argv)
{
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT"))
        return;
    if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0)
        return;
    execv("/proc/self/exe", argv);
    unsetenv("OMP_WAIT_POLICY"); /* not run again: what the command starts keeps the user's */
}
