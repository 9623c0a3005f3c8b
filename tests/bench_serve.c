/* bench_serve: issue 49's latency benchmark of `cellmap serve`, over HTTP.
 *
 *   bench_serve PATH/TO/cellmap [DIR] [THREADS]
 *
 * Solves the README's quick start (`cellmap solve --db`, 1000 x 1000 cells
 * of microchaos-pd), serves it (THREADS threads, default 2) and asks, each
 * request on a new connection as a browser's first look makes them:
 * - the 9 zoom-0 tiles inside the solved cells, drawn for the first time;
 * - one of them 200 times again (kept);
 * - 8 zoom-0 tiles beside the solved box, each computing 65 536 new cells
 *   (solved, joined, committed) before it is drawn;
 * - 50 tile requests sent at once (zoom 0 and -1), all answered 200.
 * Prints medians, 95th percentiles and maxima in ms; the server is ended
 * by SIGTERM and the file checked with `cellmap info`. */
#define _DEFAULT_SOURCE
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#define CM_BENCH_RUN_COMMAND
#include "bench_util.h"

enum { AT_ONCE = 50, KEPT_ASKS = 200 };

/* A connection to 127.0.0.1:port with the request for path sent; -1 if
 * it failed. */
static int send_get(int port, const char *path)
{
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    char req[512];
    const int n = snprintf(req, sizeof req, "GET %s HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n", path);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        write(fd, req, (size_t)n) != n) {
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

/* Reads the answer to its end: its HTTP status (0 if none). */
static int read_answer(int fd)
{
    char buf[65536], head[16] = {0};
    size_t got = 0;
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0) {
        if (got < sizeof head - 1)
            memcpy(head + got, buf, (size_t)n < sizeof head - 1 - got ? (size_t)n : sizeof head - 1 - got);
        got += (size_t)n;
    }
    close(fd);
    int status = 0;
    return sscanf(head, "HTTP/1.%*d %d", &status) == 1 ? status : 0;
}

/* One request: its status, its time into *ms. */
static int get(int port, const char *path, double *ms)
{
    const double t0 = now();
    const int fd = send_get(port, path);
    const int status = fd < 0 ? 0 : read_answer(fd);
    *ms = (now() - t0) * 1e3;
    return status;
}

/* The 95th percentile of v[0..n) (sorts it). */
static double p95(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_doubles);
    return v[(int)(0.95 * (n - 1) + 0.5)];
}

static void report(const char *what, double *v, int n, int bad)
{
    const double p = p95(v, n), mid = median(v, n); /* both sort v */
    printf("%-44s n %3d  median %7.1f ms  p95 %7.1f ms  max %7.1f ms  failed %d\n", what, n, mid,
           p, v[n - 1], bad);
}

/* Starts `cellmap serve db --port 0`; its port (0 if it did not start). */
static int start_server(const char *cellmap, const char *db, const char *threads, pid_t *pid)
{
    int out[2];
    if (pipe(out) != 0)
        return 0;
    *pid = fork();
    if (*pid == 0) {
        dup2(out[1], STDOUT_FILENO);
        close(out[0]);
        execl(cellmap, cellmap, "serve", db, "--port", "0", "--threads", threads, (char *)NULL);
        _exit(127);
    }
    close(out[1]);
    char line[512] = {0};
    FILE *f = fdopen(out[0], "r");
    int port = 0;
    if (f && fgets(line, sizeof line, f)) {
        const char *colon = strstr(line, "127.0.0.1:");
        port = colon ? atoi(colon + strlen("127.0.0.1:")) : 0;
    }
    return port; /* the pipe stays open: the server's last line goes there */
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_serve PATH/TO/cellmap [DIR] [THREADS]\n");
        return 2;
    }
    const char *cellmap = argv[1], *dir = argc > 2 ? argv[2] : ".";
    const char *threads = argc > 3 ? argv[3] : "2";
    char db[4096];
    snprintf(db, sizeof db, "%s/bench_serve.cmdb", dir);
    unlink(db);
    double wall, rss;
    const char *solve[] = {cellmap, "solve", "--db", db, "--threads", threads, NULL};
    if (run_command(solve, &wall, &rss) != 0) {
        fprintf(stderr, "bench_serve: %s solve --db %s failed\n", cellmap, db);
        return 1;
    }
    printf("quick start solved in %.2f s; serving it with %s threads\n", wall, threads);
    pid_t pid;
    const int port = start_server(cellmap, db, threads, &pid);
    if (!port) {
        fprintf(stderr, "bench_serve: the server did not start\n");
        return 1;
    }
    double t[KEPT_ASKS];
    char path[128];
    int n = 0, bad = 0;
    /* the solved box, cells 0..1000 x 0..1000 (origin 0, -40): tiles x 0..2, y -3..-1 */
    for (int y = -3; y <= -1; y++)
        for (int x = 0; x <= 2; x++) {
            snprintf(path, sizeof path, "/tiles/0/%d/%d.png", x, y);
            bad += get(port, path, &t[n++]) != 200;
        }
    report("tile of solved cells, first time", t, n, bad);
    n = bad = 0;
    for (int k = 0; k < KEPT_ASKS; k++)
        bad += get(port, "/tiles/0/1/-2.png", &t[n++]) != 200;
    report("tile asked again (kept)", t, n, bad);
    n = bad = 0;
    for (int x = 4; x < 12; x++) { /* x 512..1536, v -40..-19.52 */
        snprintf(path, sizeof path, "/tiles/0/%d/-1.png", x);
        bad += get(port, path, &t[n++]) != 200;
    }
    report("tile over 65536 new cells (compute+draw)", t, n, bad);
    int fd[AT_ONCE];
    const double t0 = now();
    for (int k = 0; k < AT_ONCE; k++) {
        snprintf(path, sizeof path, "/tiles/%d/%d/%d.png", -(k % 2), k % 4, -1 - k % 3);
        fd[k] = send_get(port, path);
    }
    int ok = 0;
    for (int k = 0; k < AT_ONCE; k++)
        ok += fd[k] >= 0 && read_answer(fd[k]) == 200;
    printf("%d requests at once: %d answered 200 in %.1f ms\n", AT_ONCE, ok, (now() - t0) * 1e3);
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    const char *info[] = {cellmap, "info", db, NULL};
    const bool whole = WIFEXITED(status) && WEXITSTATUS(status) == 0 &&
                       run_command(info, &wall, &rss) == 0;
    printf("server ended by SIGTERM: %s\n", whole ? "exit 0, info passes" : "FAILED");
    return whole && ok == AT_ONCE ? 0 : 1;
}
