/* tests/bench_util.h - clock, median and command runs for the benchmark programs. */
#ifndef CM_TESTS_BENCH_UTIL_H
#define CM_TESTS_BENCH_UTIL_H

#include <stdlib.h>
#include <time.h>

static inline double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline int compare_doubles(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of v[0..n-1]; sorts v. */
static inline double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Runs argv (argv[0] a path) with stdout and stderr to /dev/null: its wall
 * seconds and peak RSS in MiB; -1 if it could not run or did not exit 0.
 * Needs _DEFAULT_SOURCE (wait4) and <sys/resource.h>, <sys/wait.h>,
 * <unistd.h>, <stdio.h> before this header. */
#ifdef CM_BENCH_RUN_COMMAND
static inline int run_command(const char *const *argv, double *wall, double *rss_mib)
{
    fflush(stdout); /* the child must not inherit unwritten lines */
    const double t0 = now();
    const pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))
            _exit(127);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    if (pid < 0 || wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0)
        return -1;
    *wall = now() - t0;
    *rss_mib = (double)ru.ru_maxrss / 1024.0;
    return 0;
}
#endif

#endif
