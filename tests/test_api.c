/* libcellmap's public API (cellmap/cellmap.h), linked as the shared
 * library a user links: solving, splitting, cancelling, errors, figures,
 * and reading a database that `cellmap solve --db` wrote.
 * usage: test_api PATH/TO/cellmap */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/cellmap.h"
#include "check.h"

static const cm_grid pd_grid = {2, {0, -40}, {500, 40}, {400, 200}};
#define PD_PARAMS "alpha=0.078,beta=0,P=0.007,D=0.02"

/* Whether two labellings are the same up to the numbering of the groups. */
static bool same_partition(const uint32_t *a, const uint32_t *b, uint64_t n, uint32_t groups)
{
    uint32_t *map = calloc((size_t)groups + 1, sizeof *map); /* a's id -> b's id + 1 */
    bool same = map != NULL;
    for (uint64_t i = 0; i < n && same; i++) {
        if (a[i] == 0 || b[i] == 0) {
            same = a[i] == b[i];
        } else if (a[i] > groups) {
            same = false;
        } else if (map[a[i]] == 0) {
            map[a[i]] = b[i] + 1;
        } else {
            same = map[a[i]] == b[i] + 1;
        }
    }
    free(map);
    return same;
}

static int cancel_at_half(void *user, double fraction)
{
    (*(int *)user)++;
    return fraction >= 0.5;
}

static int record_largest(void *user, double fraction)
{
    double *largest = user;
    *largest = fraction > *largest ? fraction : *largest;
    return 0;
}

static void test_versions_and_errors(void)
{
    CHECK_INT(cm_version_number(), CELLMAP_VERSION_NUMBER);
    char text[32];
    snprintf(text, sizeof text, "%d.%d.%d", CELLMAP_VERSION_MAJOR, CELLMAP_VERSION_MINOR,
             CELLMAP_VERSION_PATCH);
    CHECK(strcmp(cm_version(), text) == 0);
    /* status codes: positive, described and named by the shared library */
    CHECK(CM_OK == 0 && CM_EINVAL > 0 && CM_ENOTFOUND > 0);
    CHECK(strcmp(cm_status_name(CM_EINVAL), "CM_EINVAL") == 0);
    CHECK(strcmp(cm_strerror(CM_ENOMEM), "out of memory") == 0);
    cm_system *s = (cm_system *)1;
    char msg[256];
    CHECK(cm_system_new(NULL, "no-such-model", NULL, &s, msg, sizeof msg) == CM_ENOTFOUND);
    CHECK(s == NULL && strstr(msg, "no-such-model") != NULL);
    CHECK(cm_system_new(NULL, "microchaos-pd", "alpha=oops", &s, msg, sizeof msg) != CM_OK);
    CHECK(s == NULL && strstr(msg, "alpha") != NULL);
    CHECK(cm_system_new(NULL, "microchaos-pd", PD_PARAMS, &s, msg, sizeof msg) == CM_OK);
    const cm_grid one_d = {1, {0}, {1}, {10}};
    cm_result *r = (cm_result *)1;
    CHECK(cm_solve(s, &one_d, NULL, &r, msg, sizeof msg) == CM_EINVAL);
    CHECK(r == NULL && strstr(msg, "dimension") != NULL);
    cm_system_free(s);
    cm_models *set;
    CHECK(cm_models_new(&set, msg, sizeof msg) == CM_OK);
    CHECK(cm_models_load(set, "/nonexistent/plugin.so", msg, sizeof msg) != CM_OK);
    CHECK(strstr(msg, "/nonexistent/plugin.so") != NULL);
    CHECK(cm_models_count(set) >= 9 && cm_models_name(set, cm_models_count(set)) == NULL);
    cm_models_free(set);
    cm_db *db = (cm_db *)1;
    CHECK(cm_db_open("/nonexistent.cmdb", &db, msg, sizeof msg) != CM_OK && db == NULL);
}

/* One region, 2x2 and 4x2 split regions and 1 or 2 threads give the same
 * labels (up to numbering) and the same steps. */
/* The system's attractors of a result: each group's cells share one
 * label, every attractor has cells, and a summary per id. */
static void check_attractors(const cm_result *r)
{
    const uint64_t n = cm_result_cells(r);
    const uint32_t na = cm_result_attractors(r), ng = cm_result_groups(r);
    uint32_t *g = malloc(n * sizeof *g);
    int32_t *a = malloc(n * sizeof *a), *of = calloc(ng + 1, sizeof *of);
    cm_result_labels(r, g);
    cm_result_attractor_labels(r, a);
    int mixed = 0;
    for (uint64_t i = 0; i < n; i++) {
        if (g[i] == 0) {
            mixed += a[i] != -2; /* the sink: outside */
            continue;
        }
        mixed += of[g[i]] && of[g[i]] != a[i] + 1000;
        of[g[i]] = a[i] + 1000;
        mixed += a[i] < -2 || a[i] > (int32_t)na;
    }
    CHECK_INT(mixed, 0);
    cm_attractor_summary s;
    CHECK(na > 0);
    for (uint32_t id = 1; id <= na; id++)
        CHECK(cm_result_attractor(r, id, &s) == CM_OK && s.id == id && s.basin_cells > 0 &&
              s.footprint_cells > 0 && (s.kind != 0 || s.period > 0));
    CHECK(cm_result_attractor(r, na + 1, &s) == CM_ENOTFOUND);
    free(g);
    free(a);
    free(of);
}

static void test_solve(cm_system *s, uint32_t *labels, uint32_t *steps)
{
    char msg[256];
    const uint64_t n = 400 * 200;
    cm_result *whole;
    CHECK(cm_solve(s, &pd_grid, NULL, &whole, msg, sizeof msg) == CM_OK);
    CHECK_INT(cm_result_cells(whole), n);
    cm_result_labels(whole, labels);
    cm_result_steps(whole, steps);
    const uint32_t groups = cm_result_groups(whole);
    CHECK(groups > 10);
    check_attractors(whole);
    uint64_t sink = 0, basins = 0;
    for (uint64_t i = 0; i < n; i++)
        sink += labels[i] == 0;
    CHECK_INT(cm_result_sink_cells(whole), sink);
    for (uint32_t g = 1; g <= groups; g++) {
        cm_group_summary gs;
        CHECK(cm_result_group(whole, g, &gs) == CM_OK && gs.id == g && gs.period >= 1);
        basins += gs.basin_cells;
    }
    CHECK_INT(basins + sink, n);
    cm_group_summary none;
    CHECK(cm_result_group(whole, groups + 1, &none) == CM_ENOTFOUND);
    cm_grid g;
    cm_result_grid(whole, &g);
    CHECK(g.dim == 2 && g.lo[0] == 0 && g.hi[1] == 40 && g.cells[0] == 400 && g.cells[1] == 200);

    uint32_t *other = malloc(n * sizeof *other), *other_steps = malloc(n * sizeof *other_steps);
    const cm_solve_options splits[] = {{.threads = 1, .split = {2, 2}},
                                       {.threads = 2, .split = {4, 2}},
                                       {.threads = 1}};
    for (size_t k = 0; k < sizeof splits / sizeof splits[0]; k++) {
        cm_result *r;
        CHECK(cm_solve(s, &pd_grid, &splits[k], &r, msg, sizeof msg) == CM_OK);
        cm_result_labels(r, other);
        cm_result_steps(r, other_steps);
        CHECK(same_partition(labels, other, n, groups));
        CHECK(memcmp(steps, other_steps, n * sizeof *steps) == 0);
        CHECK_INT(cm_result_groups(r), groups);
        cm_result_free(r);
    }
    free(other);
    free(other_steps);

    /* cancelled from the progress callback, one region or several */
    int calls = 0;
    cm_solve_options cancel = {.progress = cancel_at_half, .user = &calls, .split = {4, 4}};
    cm_result *r = (cm_result *)1;
    CHECK(cm_solve(s, &pd_grid, &cancel, &r, msg, sizeof msg) == CM_ECANCELED && r == NULL);
    CHECK(calls >= 1 && strstr(msg, "cancelled") != NULL);
    cancel.split[0] = cancel.split[1] = 0;
    CHECK(cm_solve(s, &pd_grid, &cancel, &r, msg, sizeof msg) == CM_ECANCELED && r == NULL);
    /* progress ends at 1, said on the calling thread even where the other
     * threads did every row (a busy machine): the cancel above cannot miss */
    for (int split = 0; split <= 4; split += 4) {
        double largest = -1;
        const cm_solve_options watch = {.progress = record_largest, .user = &largest,
                                        .split = {split, split}};
        CHECK(cm_solve(s, &pd_grid, &watch, &r, msg, sizeof msg) == CM_OK);
        CHECK(largest == 1.0);
        cm_result_free(r);
    }

    /* the figure */
    CHECK(cm_result_png(whole, "api.png", 600, 400, msg, sizeof msg) == CM_OK);
    FILE *f = fopen("api.png", "rb");
    unsigned char sig[8] = {0};
    CHECK(f && fread(sig, 1, 8, f) == 8 && memcmp(sig, "\x89PNG\r\n\x1a\n", 8) == 0);
    if (f)
        fclose(f);
    remove("api.png");
    CHECK(cm_result_png(whole, "no/such/dir/api.png", 600, 400, msg, sizeof msg) != CM_OK);
    CHECK(strstr(msg, "no/such/dir") != NULL);
    cm_result_free(whole);
}

/* A database of the same grid, solved as 3x2 regions by the command: every
 * label (up to numbering) and step as cm_solve gives them; a view reads
 * the cells that meet it. */
/* Whether labels equal those `cellmap export FILE --labels` writes (the
 * .npy's int32 cells after its header, in C order: x slowest; labels have
 * x fastest, 400 x 200 cells). */
static bool same_attractor_labels(const int32_t *labels, uint64_t n, const char *file,
                                  const char *cellmap)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' export '%s' --labels api-att.npy --quiet > /dev/null", cellmap,
             file);
    if (system(cmd) != 0)
        return false;
    FILE *f = fopen("api-att.npy", "rb");
    unsigned char head[10];
    bool same = f && fread(head, 1, 10, f) == 10 &&
                fseek(f, 10 + head[8] + 256 * head[9], SEEK_SET) == 0;
    for (uint64_t x = 0; same && x < 400; x++)
        for (uint64_t y = 0; same && y < 200; y++) {
            int32_t v;
            same = fread(&v, 4, 1, f) == 1 && y * 400 + x < n && v == labels[y * 400 + x];
        }
    if (f)
        fclose(f);
    remove("api-att.npy");
    remove("api-att.json");
    return same;
}

static void test_db(const char *cellmap, const uint32_t *labels, const uint32_t *steps)
{
    char cmd[1024], msg[256];
    snprintf(cmd, sizeof cmd,
             "'%s' solve --param " PD_PARAMS " --region 0:500,-40:40 --cells 400x200 "
             "--split 3x2 --db api.cmdb --quiet > /dev/null",
             cellmap);
    CHECK(system(cmd) == 0);
    cm_db *db;
    CHECK(cm_db_open("api.cmdb", &db, msg, sizeof msg) == CM_OK);
    if (!db) {
        fprintf(stderr, "%s\n", msg);
        return;
    }
    CHECK(strcmp(cm_db_model(db), "microchaos-pd") == 0);
    CHECK(strstr(cm_db_params(db), "\"alpha\":0.078") != NULL);
    cm_grid g;
    cm_db_grid(db, &g);
    CHECK(g.cells[0] == 400 && g.cells[1] == 200 && g.lo[0] == 0 && g.hi[0] == 500);
    cm_result *r;
    CHECK(cm_db_read(db, NULL, NULL, &r, msg, sizeof msg) == CM_OK);
    const uint64_t n = cm_result_cells(r);
    CHECK_INT(n, 400 * 200);
    uint32_t *l = malloc(n * sizeof *l), *st = malloc(n * sizeof *st);
    cm_result_labels(r, l);
    cm_result_steps(r, st);
    CHECK(same_partition(labels, l, n, cm_result_groups(r)));
    CHECK(memcmp(steps, st, n * sizeof *st) == 0);
    /* the attractors the file stores are those of the same cells solved
     * here, label for label, and `export --labels` writes the same */
    int32_t *att = malloc(n * sizeof *att);
    cm_result_attractor_labels(r, att);
    CHECK(same_attractor_labels(att, n, "api.cmdb", cellmap));
    free(att);
    cm_result_free(r);
    /* cells 100..199 x 50..149 (x 125:250, v -20:20) */
    const double lo[2] = {125, -20}, hi[2] = {250, 20};
    CHECK(cm_db_read(db, lo, hi, &r, msg, sizeof msg) == CM_OK);
    cm_result_grid(r, &g);
    CHECK(g.cells[0] == 100 && g.cells[1] == 100 && g.lo[0] == 125 && g.hi[1] == 20);
    cm_result_labels(r, l);
    int same = 1;
    for (int y = 0; y < 100; y++)
        for (int x = 0; x < 100; x++)
            same &= (l[y * 100 + x] == 0) == (labels[(y + 50) * 400 + x + 100] == 0);
    CHECK(same);
    cm_result_free(r);
    const double far_lo[2] = {900, 0}, far_hi[2] = {1000, 1};
    CHECK(cm_db_read(db, far_lo, far_hi, &r, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "misses the cluster") != NULL);
    free(l);
    free(st);
    cm_db_close(db);
    remove("api.cmdb");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_api PATH/TO/cellmap\n");
        return 2;
    }
    test_versions_and_errors();
    cm_system *s;
    char msg[256];
    CHECK(cm_system_new(NULL, "microchaos-pd", PD_PARAMS, &s, msg, sizeof msg) == CM_OK);
    CHECK(cm_system_dim(s) == 2 && strcmp(cm_system_coord(s, 1), "v") == 0);
    double lo[2], hi[2], y[2];
    CHECK(cm_system_region(s, lo, hi) == CM_OK && lo[0] == 0 && hi[1] == 40);
    CHECK(cm_system_step(s, (double[2]){10.5, 0.25}, y) == CM_STEP_OK);
    uint32_t *labels = malloc(400 * 200 * sizeof *labels), *steps = malloc(400 * 200 * sizeof *steps);
    test_solve(s, labels, steps);
    test_db(argv[1], labels, steps);
    free(labels);
    free(steps);
    cm_system_free(s);
    CHECK_DONE();
}
