/* src/run_env.h - settings that libraries read from the environment before
 * main, which a command asks for by executing itself once more (measured
 * in docs/engine.md). Passive waiting (explore, and every rank of a solve
 * under mpirun): libgomp's idle threads sleep rather than spin between
 * short parallel regions, which on 2 vCPUs sharing a core slowed the
 * serial work between them, and the ranks' threads share the cores. Huge
 * pages for the heap (commands that build many cells): glibc (2.35 and
 * later) asks for transparent huge pages for its heaps with the tunable
 * glibc.malloc.hugetlb=1, where the kernel gives them on request (mode
 * "madvise"), so that a split solve's node tables, exit lists and small
 * regions cost a page fault per 2 MiB rather than per 4 KiB. Neither is
 * set if the user set it (OMP_WAIT_POLICY or GOMP_SPINCOUNT;
 * glibc.malloc.hugetlb in GLIBC_TUNABLES, so =0 turns it off), nor huge
 * pages in a sanitizer build, whose allocator is not glibc's. */
#ifndef CM_SRC_RUN_ENV_H
#define CM_SRC_RUN_ENV_H

enum {
    RUN_ENV_PASSIVE_WAIT = 1, /* OMP_WAIT_POLICY=passive */
    RUN_ENV_HUGE_PAGES = 2    /* glibc.malloc.hugetlb=1 */
};

/* Runs the program again (/proc/self/exe, argv) with the settings of
 * `wishes` that the environment lacks. Returns only when it did not: none
 * was missing, or the exec failed (the environment is then as it was, and
 * the command goes on without them). */
void run_env_apply(char **argv, unsigned wishes);

#endif
