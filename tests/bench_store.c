/* Benchmark of a cluster that outgrows its memory budget: the Fig. 4.21
 * region of the PD micro-chaos map (alpha = 6.8511e-3, beta = 0,
 * P = 5.4997e-5, D = 2.5665e-3; x in [-125000, 125000], x' in [-600, 600],
 * re-stepping up to 100000 times as in the figure) cut into TX x TY regions
 * of SIDE x SIDE cells, solved two at a time and joined as solve --split
 * joins more than 64 regions (scanned along the short side of the grid).
 *
 * Four runs (RUNS, a comma-separated choice of them), each in its own
 * process so each has its own peak RSS:
 *   paged   --db with a budget of MEM MiB for the cell arrays
 *   db      --db without a budget (every region stays in memory)
 *   memory  no database
 *   scm     the regions' SCM alone (a region per thread), no join, no file
 * Each prints total time, time paging (reading regions back, saving dirty
 * ones evicted in a join), time in commits, regions read and evicted, ns/cell, peak RSS, the
 * database's bytes per cell, and the bytes of cell pages written and stored
 * (equal when every page is written once). The paged and db files must hold the same cluster (tests/cmdb_hash.h):
 * a budget changes the order of writes in the file, never its rows.
 *
 * usage: bench_store [TX TY SIDE MEM_MiB DIR [RUNS]]
 *        (default 20 10 1000 256 /tmp paged,db,memory,scm) */
#define _DEFAULT_SOURCE /* wait4: the peak RSS of one child */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_util.h"
#include "cellmap/cover.h"
#include "cellmap/store.h"
#include "cmdb_hash.h"
#include "models/registry.h"

typedef struct config {
    int tx, ty;
    int64_t side;
    uint64_t mem;
    const char *dir;
} config;

static void die(const char *what, const char *msg)
{
    fprintf(stderr, "bench_store: %s: %s\n", what, msg);
    exit(1);
}

/* Bytes of the cell pages a file holds. */
static uint64_t page_bytes_stored(const char *path)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    int64_t bytes = -1;
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK &&
        sqlite3_prepare_v2(db,
                           "SELECT SUM(length(image) + length(grp) + length(step)) FROM pages",
                           -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        bytes = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    sqlite3_close(db);
    if (bytes < 0)
        die(path, "cannot count its pages");
    return (uint64_t)bytes;
}

/* The Fig. 4.21 model, its lattice for the configuration, and box k of
 * its TX x TY regions (in row order). */
static void setup(const config *cf, cm_model *m, cm_lattice *lat)
{
    char msg[1024];
    const char *params[1] = {"alpha=6.8511e-3,beta=0,P=5.4997e-5,D=2.5665e-3"};
    if (cm_model_create("microchaos-pd", params, 1, m, msg, sizeof msg) != CM_OK)
        die("model", msg);
    const double nx = (double)(cf->tx * cf->side), ny = (double)(cf->ty * cf->side);
    *lat = (cm_lattice){2, {-125000, -600}, {250000.0 / nx, 1200.0 / ny}};
}

static cm_box box_of(const config *cf, int64_t k)
{
    const int64_t i = k % cf->tx, j = k / cf->tx;
    return (cm_box){2, {i * cf->side, j * cf->side}, {(i + 1) * cf->side, (j + 1) * cf->side}};
}

/* One run (in a child process): prints its figures. */
static void run(const config *cf, const char *name, const char *db, uint64_t budget)
{
    char msg[1024];
    cm_model m;
    cm_lattice lat;
    setup(cf, &m, &lat);
    const int64_t nx = cf->tx * cf->side, ny = cf->ty * cf->side;
    const uint32_t n = (uint32_t)(cf->tx * cf->ty);
    cm_box *boxes = malloc(n * sizeof *boxes);
    for (uint32_t k = 0; k < n; k++)
        boxes[k] = box_of(cf, k);
    if (n > 64)
        cm_boxes_scan_order(boxes, n); /* as solve --split orders more than 64 regions */
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    c.threads = 2;
    c.mem_budget = budget;
    cm_store *s = NULL;
    if (db) {
        const cm_store_meta meta = {&m, &lat, "bench_store", "bench", "bench", 0, NULL, NULL};
        if (cm_store_create(db, &meta, &s, msg, sizeof msg) != CM_OK)
            die("create", msg);
        cm_store_attach(s, &c);
    }
    const cm_scm_options opt = {.max_steps = 100000, .threads = 2, .record_exits = 1};
    const double t0 = now();
    if (cm_cluster_solve_boxes(&c, &m, boxes, n, &opt, s ? cm_store_commit_join : NULL, s, NULL, msg,
                               sizeof msg) != CM_OK)
        die("solve", msg);
    const double total = now() - t0;
    cm_store_stats ss;
    memset(&ss, 0, sizeof ss);
    if (s)
        cm_store_get_stats(s, &ss);
    const double cells = (double)nx * (double)ny;
    printf("%-7s %10.0f %9.2f %9.2f %9.2f %9.1f %6u %9llu %7llu", name, cells, total,
           ss.read_seconds + ss.evict_seconds, ss.commit_seconds, 1e9 * total / cells, c.ngroups,
           (unsigned long long)ss.regions_read, (unsigned long long)ss.regions_evicted);
    if (s && cm_store_close(s, msg, sizeof msg) != CM_OK)
        die("close", msg);
    if (db) {
        struct stat sb;
        stat(db, &sb);
        printf(" %9.3f %10.2f %10.2f", (double)sb.st_size / cells,
               (double)ss.page_bytes_written / 1048576.0, (double)page_bytes_stored(db) / 1048576.0);
    } else {
        printf(" %9s %10s %10s", "-", "-", "-");
    }
    fflush(stdout);
    cm_cluster_free(&c);
    free(boxes);
    cm_model_release(&m);
}

/* The regions' simple cell mapping alone, as cm_cluster_solve_boxes does
 * it (a region per thread, two threads), without joins or a file: what the
 * cluster's total is measured against. Prints its time. */
static void run_scm(const config *cf)
{
    cm_model m;
    cm_lattice lat;
    setup(cf, &m, &lat);
    const int64_t nx = cf->tx * cf->side, ny = cf->ty * cf->side;
    const int64_t n = cf->tx * cf->ty;
    const cm_scm_options opt = {.max_steps = 100000, .threads = 1, .record_exits = 1};
    int failed = 0;
    const double t0 = now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(2) reduction(| : failed)
    for (int64_t k = 0; k < n; k++) {
        char why[256];
        const cm_box box = box_of(cf, k);
        cm_region r;
        failed |= cm_region_alloc(&r, &box, why, sizeof why) != CM_OK ||
                  cm_scm_solve(&m, &lat, &opt, &r, why, sizeof why) != CM_OK;
        cm_region_free(&r);
    }
    const double total = now() - t0;
    if (failed)
        die("scm", "a region failed");
    printf("%-7s %10.0f %9.2f %9s %9s %9.1f %6s %9s %7s %9s %10s %10s", "scm",
           (double)nx * (double)ny, total, "-", "-", 1e9 * total / ((double)nx * (double)ny), "-",
           "-", "-", "-", "-", "-");
    fflush(stdout);
    cm_model_release(&m);
}

/* Runs one configuration in a child process and prints its peak RSS. */
static void run_child(const config *cf, const char *name, const char *db, uint64_t budget)
{
    fflush(stdout);
    const pid_t pid = fork();
    if (pid == 0) {
        if (strcmp(name, "scm") == 0)
            run_scm(cf);
        else
            run(cf, name, db, budget);
        _exit(0);
    }
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        die(name, "the run failed");
    printf(" %9.1f\n", (double)ru.ru_maxrss / 1024.0);
}

int main(int argc, char **argv)
{
    config cf = {20, 10, 1000, 256, "/tmp"};
    if (argc > 1 && argc != 6 && argc != 7)
        die("usage", "bench_store [TX TY SIDE MEM_MiB DIR [RUNS]]");
    const char *runs = argc == 7 ? argv[6] : "paged,db,memory,scm";
    if (argc >= 6)
        cf = (config){atoi(argv[1]), atoi(argv[2]), atoll(argv[3]), strtoull(argv[4], NULL, 10),
                      argv[5]};
    if (cf.tx < 1 || cf.ty < 1 || cf.side < 2 || cf.mem < 1)
        die("usage", "TX, TY >= 1, SIDE >= 2, MEM_MiB >= 1");
    char paged[4096], whole[4096];
    snprintf(paged, sizeof paged, "%s/bench-paged.cmdb", cf.dir);
    snprintf(whole, sizeof whole, "%s/bench-db.cmdb", cf.dir);
    printf("%d x %d regions of %lld x %lld cells, budget %llu MiB, 2 threads\n", cf.tx, cf.ty,
           (long long)cf.side, (long long)cf.side, (unsigned long long)cf.mem);
    printf("%-7s %10s %9s %9s %9s %9s %6s %9s %7s %9s %10s %10s %9s\n", "run", "cells", "total_s",
           "paging_s", "commit_s", "ns/cell", "groups", "reads", "evicted", "disk_B/c",
           "pgw_MiB", "pgs_MiB", "rss_MiB");
    if (strstr(runs, "paged"))
        run_child(&cf, "paged", paged, cf.mem << 20);
    if (strstr(runs, "db"))
        run_child(&cf, "db", whole, 0);
    if (strstr(runs, "memory"))
        run_child(&cf, "memory", NULL, 0);
    if (strstr(runs, "scm"))
        run_child(&cf, "scm", NULL, 0);
    if (strstr(runs, "paged") && strstr(runs, "db"))
        printf("paged and db clusters %s\n",
               cmdb_content_hash(paged) == cmdb_content_hash(whole) ? "identical" : "DIFFER");
    printf("RSS target of paged: %llu MiB (2 x budget + 100)\n",
           (unsigned long long)(2 * cf.mem + 100));
    unlink(paged);
    unlink(whole);
    return 0;
}
