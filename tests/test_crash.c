/* Crash safety: `cellmap solve --db` killed with SIGKILL at 20 random
 * moments. After every kill the file must open as a consistent cluster;
 * resuming after the last kill must end with the same database as a run
 * that was never interrupted. And deterministically: a process that dies
 * right after the pager saved a region in the middle of a join leaves the
 * cluster of the last commit (the save belongs to the join's transaction).
 *
 * usage: test_crash CELLMAP_BINARY */
#include <dirent.h>
#include <signal.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cellmap/store.h"
#include "check.h"
#include "models/registry.h"
#include "cmdb_hash.h"
#include "mix.h"

enum { KILLS = 20 };

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Starts `cellmap solve` on db (resuming if it exists); returns its pid. */
static pid_t start_solve(const char *cellmap, const char *db, int resume)
{
    const pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout))
            _exit(3);
        char *argv[] = {(char *)cellmap,
                        "solve",
                        "--param",
                        "alpha=0.8,beta=0.3,P=0.7,D=0.6",
                        "--region",
                        "-13:13,-4:4",
                        "--cells",
                        "1200x800",
                        "--split",
                        "6x4",
                        "--mem",
                        "2M",
                        "--threads",
                        "2",
                        "--db",
                        (char *)db,
                        resume ? "--resume" : NULL,
                        NULL};
        execv(cellmap, argv);
        _exit(127);
    }
    return pid;
}

static int run_to_end(const char *cellmap, const char *db, int resume)
{
    int status = 0;
    waitpid(start_solve(cellmap, db, resume), &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Opens the file as a cluster and checks it cell by cell: every region
 * resolves, the group counts match its cells, every group id is known,
 * and every group's periodic cells are periodic cells of that group.
 * Returns the number of regions. */
static uint32_t check_consistent(const char *path)
{
    char msg[512];
    cm_store *s = NULL;
    cm_cluster c;
    memset(&c, 0, sizeof c);
    CHECK(cm_store_open(path, 0, &s, msg, sizeof msg) == CM_OK);
    if (!s) {
        fprintf(stderr, "%s\n", msg);
        return 0;
    }
    CHECK(cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK);
    c.mem_budget = 1; /* one region at a time */
    cm_store_info info;
    CHECK(cm_store_read_info(s, &info, msg, sizeof msg) == CM_OK);
    CHECK_INT(info.groups, c.ngroups);
    uint64_t periodic = 0, *counted = calloc(c.ngroups + 1, sizeof *counted);
    for (uint32_t k = 0; k < c.nregions; k++) { /* each region resolved on its own */
        cm_region flat;
        const cm_box box = c.regions[k].r.box;
        CHECK(cm_cluster_flatten(&c, &box, &flat, msg, sizeof msg) == CM_OK);
        for (uint64_t i = 0; flat.group && i < flat.ncells; i++) {
            CHECK(flat.group[i] <= c.ngroups);
            if (flat.group[i] <= c.ngroups)
                counted[flat.group[i]]++;
            periodic += cm_is_periodic(&flat, i);
        }
        cm_region_free(&flat);
    }
    cm_group_info *g = calloc(c.ngroups + 1, sizeof *g);
    uint64_t sink = 0, cells = 0, period = 0;
    CHECK(cm_store_groups(s, g, c.ngroups, &sink, msg, sizeof msg) == CM_OK);
    cells = sink;
    CHECK_INT(sink, counted[0]);
    for (uint32_t k = 0; k < c.ngroups; k++) {
        cells += g[k].basin_cells;
        period += g[k].period;
        CHECK_INT(g[k].basin_cells, counted[k + 1]);
        CHECK(g[k].period >= 1 && g[k].basin_cells >= g[k].period);
    }
    free(counted);
    CHECK_INT(cells, info.cells);
    CHECK_INT(period, periodic);
    free(g);
    const uint32_t n = c.nregions;
    cm_cluster_free(&c);
    CHECK(cm_store_close(s, msg, sizeof msg) == CM_OK);
    return n;
}

/* Removes the directory and what the runs left in it (WAL files, and the
 * temporary file of a run killed while creating the database). */
static void remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char path[512];
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    if (d)
        closedir(d);
    rmdir(dir);
}

/* ---- a death right after an eviction's write ---------------------------------- */

typedef struct dying_pager {
    cm_page_out_fn save; /* the store's */
    void *store;
    uint32_t commits;
} dying_pager;

static dying_pager pager; /* the child's: the hooks below have no other way to it */

static cm_status save_then_die(void *user, const cm_cluster *c, uint32_t k, char *msg,
                               size_t msg_size)
{
    const cm_status st = pager.save(user, c, k, msg, msg_size);
    _exit(st == CM_OK ? 40 + (int)pager.commits % 40 : 3); /* as a kill would, before the commit */
}

static cm_status count_commit(void *user, cm_cluster *c, uint32_t box, const cm_join_stats *stats,
                              char *msg, size_t msg_size)
{
    const cm_status st = cm_store_commit_join(user, c, box, stats, msg, msg_size);
    pager.commits += st == CM_OK;
    return st;
}

/* In a child: solves 16 boxes into db with a budget of about one region,
 * dying at the first save of a region never saved (in a join). Exits 40 +
 * the number of commits done. */
static void solve_until_eviction(const char *db)
{
    char msg[512];
    cm_model m;
    const char *params[1] = {"alpha=0.8,beta=0.3,P=0.7,D=0.6"};
    const cm_lattice lat = {2, {-13, -4}, {26.0 / 400, 8.0 / 400}};
    if (cm_model_create("microchaos-pd", params, 1, &m, msg, sizeof msg) != CM_OK)
        _exit(4);
    const cm_store_meta meta = {&m, &lat, "test", "test", "test", 0, NULL, NULL};
    cm_store *s = NULL;
    cm_cluster c;
    cm_cluster_init(&c, &lat);
    if (cm_store_create(db, &meta, &s, msg, sizeof msg) != CM_OK)
        _exit(5);
    cm_store_attach(s, &c);
    pager.save = c.page_out;
    c.page_out = save_then_die;
    c.mem_budget = 1; /* every other region is evicted before a join reads */
    c.threads = 1;
    cm_box boxes[16];
    for (int k = 0; k < 16; k++)
        boxes[k] = (cm_box){2, {100 * (k % 4), 100 * (k / 4)}, {100 * (k % 4) + 100, 100 * (k / 4) + 100}};
    const cm_scm_options opt = {.max_steps = 1, .threads = 1, .record_exits = 1};
    cm_cluster_solve_boxes(&c, &m, boxes, 16, &opt, count_commit, s, NULL, msg, sizeof msg);
    _exit(2); /* no region was ever saved in a join: the test cannot run */
}

static void test_death_after_eviction(const char *dir)
{
    char db[256];
    snprintf(db, sizeof db, "%s/evicted.cmdb", dir);
    const pid_t pid = fork();
    if (pid == 0)
        solve_until_eviction(db);
    int status = 0;
    waitpid(pid, &status, 0);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    CHECK(code >= 40 && code < 80);
    if (code < 40 || code >= 80)
        return;
    /* the regions of the commits made, consistent; the saved region is not there */
    CHECK_INT(check_consistent(db), (uint32_t)(code - 40));
    printf("a death right after a save in a join left the %d regions of its commits\n",
           code - 40);
    fflush(stdout); /* before the next children inherit the buffer */
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_crash CELLMAP_BINARY\n");
        return 2;
    }
    char dir[] = "/tmp/cellmap-crash-XXXXXX", ref[256], db[256];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(ref, sizeof ref, "%s/ref.cmdb", dir);
    snprintf(db, sizeof db, "%s/killed.cmdb", dir);

    const double t0 = now();
    CHECK_INT(run_to_end(argv[1], ref, 0), 0);
    const double whole = now() - t0;
    const uint64_t want = cmdb_content_hash(ref);
    CHECK_INT(check_consistent(ref), 24);
    test_death_after_eviction(dir);

    /* Kill moments spread over a fifteenth of a whole run each, so that
     * together they fall all along the solve: creation, solving, commits. */
    int interrupted = 0;
    for (int k = 0; k < KILLS; k++) {
        struct stat sb;
        const int exists = stat(db, &sb) == 0;
        const pid_t pid = start_solve(argv[1], db, exists);
        const double delay = whole / 15 * (double)(mix((uint64_t)k + 77) % 1000) / 1000.0;
        struct timespec ts = {(time_t)delay, (long)((delay - (double)(time_t)delay) * 1e9)};
        nanosleep(&ts, NULL);
        kill(pid, SIGKILL);
        int status = 0;
        waitpid(pid, &status, 0);
        interrupted += WIFSIGNALED(status);
        if (stat(db, &sb) == 0) /* killed before the empty file appeared: nothing to check */
            check_consistent(db);
    }
    struct stat sb;
    CHECK_INT(run_to_end(argv[1], db, stat(db, &sb) == 0), 0);
    CHECK(cmdb_content_hash(db) == want);
    printf("%d of %d kills interrupted the solve (whole run %.3f s); the resumed file equals "
           "the uninterrupted one\n",
           interrupted, KILLS, whole);
    CHECK(interrupted >= KILLS / 2);
    remove_dir(dir);
    CHECK_DONE();
}
