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

/* Runs shell command cmd and keeps its standard output (a JSON document,
 * at most size - 1 bytes) in out, with the spaces after colons taken out,
 * so that json_number finds keys as `cellmap --json` writes them; its wall
 * seconds in *wall (may be NULL). 0, or -1 if it did not exit 0. Needs
 * <stdio.h> and <string.h> before this header. */
#ifdef CM_BENCH_COMMAND_JSON
static inline int command_json(const char *cmd, char *out, size_t size, double *wall)
{
    const double t0 = now();
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    const size_t n = fread(out, 1, size - 1, p);
    out[n] = '\0';
    if (pclose(p) != 0)
        return -1;
    if (wall)
        *wall = now() - t0;
    char *w = out;
    for (const char *r = out; *r; r++)
        if (!(*r == ' ' && r > out && r[-1] == ':'))
            *w++ = *r;
    *w = '\0';
    return 0;
}

/* The number after "key": in text that command_json gave, or -1. */
static inline double json_number(const char *text, const char *key)
{
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\":", key);
    const char *at = strstr(text, quoted);
    return at ? strtod(at + strlen(quoted), NULL) : -1;
}
#endif

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
