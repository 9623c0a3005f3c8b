#define _DEFAULT_SOURCE
/* bench_start: how fast commands that draw nothing start and end, from the
 * command line (issue: commands that start in milliseconds). Runs each
 * command RUNS times, in turns, and prints its median wall time and
 * median peak RSS: `solve --cells 10x10` (no PNG), `info` of a small
 * database and of one of 1 M cells in 4 regions (info reads the file's
 * records, so it should not grow with the file), `models`, `orbit`,
 * `export --groups`, and for comparison a `solve --cells 10x10 --png` that
 * loads OSMesa; and the machine's own floor, an empty process (/bin/true),
 * run in the same turns.
 * usage: bench_start PATH/TO/cellmap [DIR] [RUNS]   (DIR default /tmp, RUNS 20) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#define CM_BENCH_RUN_COMMAND
#include "bench_util.h"

enum { COMMANDS = 8, MAX_RUNS = 200 };

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_start PATH/TO/cellmap [DIR] [RUNS]\n");
        return 2;
    }
    const char *cm = argv[1], *dir = argc > 2 ? argv[2] : "/tmp";
    const int runs = argc > 3 ? atoi(argv[3]) : 20;
    if (runs < 1 || runs > MAX_RUNS) {
        fprintf(stderr, "bench_start: RUNS must be 1..%d\n", MAX_RUNS);
        return 2;
    }
    char db[4096], big[4096], csv[4096], png[4096];
    snprintf(db, sizeof db, "%s/bench_start-%d.cmdb", dir, (int)getpid());
    snprintf(big, sizeof big, "%s/bench_start-%d-1M.cmdb", dir, (int)getpid());
    snprintf(csv, sizeof csv, "%s/bench_start-%d.csv", dir, (int)getpid());
    snprintf(png, sizeof png, "%s/bench_start-%d.png", dir, (int)getpid());
    const char *make[] = {cm, "solve", "--cells", "200x100", "--split", "2x1", "--db", db, NULL};
    double wall, rss;
    const char *make_big[] = {cm, "solve", "--cells", "2000x500", "--split", "2x2",
                              "--db", big, NULL};
    if (run_command(make, &wall, &rss) != 0 || run_command(make_big, &wall, &rss) != 0) {
        fprintf(stderr, "bench_start: cannot make %s and %s with %s\n", db, big, cm);
        return 1;
    }
    const char *const commands[COMMANDS][12] = {
        {cm, "solve", "--cells", "10x10", NULL},
        {cm, "info", db, NULL},
        {cm, "info", big, NULL},
        {cm, "models", NULL},
        {cm, "orbit", "--from", "100,0", "--steps", "10", NULL},
        {cm, "export", db, "--groups", csv, NULL},
        {cm, "solve", "--cells", "10x10", "--png", png, NULL},
        {"/bin/true", NULL},
    };
    const char *const names[COMMANDS] = {"solve --cells 10x10", "info FILE",
                                         "info FILE (1 M cells)", "models",
                                         "orbit --steps 10", "export --groups",
                                         "solve 10x10 --png", "/bin/true (machine)"};
    static double walls[COMMANDS][MAX_RUNS], rsss[COMMANDS][MAX_RUNS];
    for (int r = 0; r < runs; r++)
        for (int c = 0; c < COMMANDS; c++)
            if (run_command(commands[c], &walls[c][r], &rsss[c][r]) != 0) {
                fprintf(stderr, "bench_start: %s failed\n", names[c]);
                return 1;
            }
    printf("%-22s %10s %10s   (medians of %d runs)\n", "command", "wall_ms", "rss_MiB", runs);
    for (int c = 0; c < COMMANDS; c++)
        printf("%-22s %10.2f %10.2f\n", names[c], 1e3 * median(walls[c], runs),
               median(rsss[c], runs));
    unlink(db);
    unlink(big);
    unlink(csv);
    unlink(png);
    return 0;
}
