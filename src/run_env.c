/* src/run_env.c - see run_env.h. */
#define _DEFAULT_SOURCE /* setenv */
#include "src/run_env.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* GLIBC_TUNABLES with the heap's huge pages added to what the user set;
 * false if the user chose either way, the kernel's mode is not "madvise"
 * ("always" gives them anyway, "never" not at all) or the build is
 * sanitized. */
static bool tunables_with_huge_pages(char *out, size_t size)
{
#ifdef __SANITIZE_ADDRESS__
    (void)out, (void)size;
    return false;
#else
    const char *now = getenv("GLIBC_TUNABLES");
    FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    char mode[128] = "";
    const bool on_request = f && fgets(mode, sizeof mode, f) && strstr(mode, "[madvise]");
    if (f)
        fclose(f);
    const int n = snprintf(out, size, "%s%sglibc.malloc.hugetlb=1", now ? now : "",
                           now && *now ? ":" : "");
    return on_request && !(now && strstr(now, "glibc.malloc.hugetlb")) && n > 0 &&
           (size_t)n < size;
#endif
}

void run_env_apply(char **argv, unsigned wishes)
{
    const bool wait = (wishes & RUN_ENV_PASSIVE_WAIT) && !getenv("OMP_WAIT_POLICY") &&
                      !getenv("GOMP_SPINCOUNT");
    char tunables[4096];
    const bool huge =
        (wishes & RUN_ENV_HUGE_PAGES) && tunables_with_huge_pages(tunables, sizeof tunables);
    const char *before = getenv("GLIBC_TUNABLES");
    char *saved = before ? strdup(before) : NULL;
    if ((wait || huge) && (!wait || setenv("OMP_WAIT_POLICY", "passive", 1) == 0) &&
        (!huge || setenv("GLIBC_TUNABLES", tunables, 1) == 0))
        execv("/proc/self/exe", argv);
    /* not run again: what the command starts keeps the user's environment */
    if (wait)
        unsetenv("OMP_WAIT_POLICY");
    if (huge && saved)
        setenv("GLIBC_TUNABLES", saved, 1);
    else if (huge)
        unsetenv("GLIBC_TUNABLES");
    free(saved);
}
