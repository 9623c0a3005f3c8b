/* libFuzzer target: libcellmap's calls as the Python module makes them
 * (cellmap/cellmap.h). The first byte chooses the call, the rest is its
 * arguments, one per line:
 *   0 System(name, params).step(state): the model, then one step from the
 *     state (the module passes exactly dim values);
 *   1 solve(System(name, params), region LO:HI,..., cells NxM..., split
 *     AxB..., max_steps): every result accessor, each group and attractor
 *     id and one past the last; grids of at most 2^14 cells;
 *   2 open(seed.cmdb).read(view LO:HI,...): the same accessors on the view.
 * Every status must be CM_OK or a failure with a message; a result's
 * labels must name its groups. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/cellmap.h"
#include "src/args.h"

static cm_db *db;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    char msg[512];
    if (cm_db_open(FUZZ_SEED_CMDB, &db, msg, sizeof msg) != CM_OK)
        abort();
    return 0;
}

/* Splits text at newlines into at most n fields (missing ones ""). */
static void fields(char *text, char **out, int n)
{
    for (int k = 0; k < n; k++) {
        out[k] = text ? text : "";
        char *nl = text ? strchr(text, '\n') : NULL;
        if (nl)
            *nl++ = '\0';
        text = nl;
    }
}

static void failed_with_message(cm_status st, const char *msg)
{
    if (st != CM_OK && !msg[0]) /* a failure must say why */
        abort();
}

static void read_result(const cm_result *r)
{
    const uint64_t n = cm_result_cells(r);
    if (n > (UINT64_C(1) << 22))
        return;
    uint32_t *labels = malloc((n + 1) * sizeof *labels), *steps = malloc((n + 1) * sizeof *steps);
    int32_t *att = malloc((n + 1) * sizeof *att);
    if (!labels || !steps || !att)
        abort();
    cm_result_labels(r, labels);
    cm_result_steps(r, steps);
    cm_result_attractor_labels(r, att);
    const uint32_t groups = cm_result_groups(r);
    for (uint64_t i = 0; i < n; i++)
        if (labels[i] != CM_LABEL_NONE && labels[i] > groups)
            abort();
    cm_group_summary g;
    for (uint32_t id = 0; id <= groups + 1 && id < 4096; id++)
        (void)cm_result_group(r, id, &g);
    cm_attractor_summary a;
    const uint32_t na = cm_result_attractors(r);
    for (uint32_t id = 0; id <= na + 1 && id < 4096; id++)
        (void)cm_result_attractor(r, id, &a);
    (void)cm_result_sink_cells(r);
    cm_grid grid;
    cm_result_grid(r, &grid);
    free(labels);
    free(steps);
    free(att);
}

static void system_step(char **f)
{
    cm_system *s;
    char msg[512] = "";
    const cm_status st = cm_system_new(NULL, f[0], f[1], &s, msg, sizeof msg);
    failed_with_message(st, msg);
    if (st != CM_OK)
        return;
    double x[CM_MAX_DIM] = {0}, y[CM_MAX_DIM];
    int n = 0;
    parse_doubles(f[2], x, &n, CM_MAX_DIM);
    (void)cm_system_step(s, x, y);
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    (void)cm_system_region(s, lo, hi);
    for (int d = 0; d < cm_system_dim(s); d++)
        (void)cm_system_coord(s, d);
    cm_system_free(s);
}

static void solve(char **f)
{
    cm_system *s;
    char msg[512] = "";
    cm_status st = cm_system_new(NULL, f[0], f[1], &s, msg, sizeof msg);
    failed_with_message(st, msg);
    if (st != CM_OK)
        return;
    cm_grid g;
    memset(&g, 0, sizeof g);
    int n = 0, nc = 0, ns = 0;
    cm_solve_options opt;
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    if (!parse_ranges(f[2], g.lo, g.hi, &n, CM_MAX_DIM) ||
        !parse_counts(f[3], g.cells, &nc, CM_MAX_DIM) || nc != n) {
        cm_system_free(s);
        return;
    }
    g.dim = n;
    uint64_t cells = 1;
    for (int d = 0; d < n; d++)
        cells = g.cells[d] > 0 && g.cells[d] <= (1 << 14) ? cells * (uint64_t)g.cells[d] : UINT64_MAX;
    if (f[4][0] && (!parse_counts(f[4], opt.split, &ns, CM_MAX_DIM) || ns != n))
        memset(opt.split, 0, sizeof opt.split);
    int64_t steps = 0;
    if (f[5][0] && parse_int64(f[5], &steps) && steps >= 0 && steps <= 64)
        opt.max_steps = (int)steps;
    if (cells <= (1 << 14)) {
        cm_result *r = NULL;
        msg[0] = '\0';
        st = cm_solve(s, &g, &opt, &r, msg, sizeof msg);
        failed_with_message(st, msg);
        if (st == CM_OK)
            read_result(r);
        cm_result_free(r);
    }
    cm_system_free(s);
}

static void db_read(char **f)
{
    double lo[CM_MAX_DIM], hi[CM_MAX_DIM];
    int n = 0;
    const bool whole = !f[0][0];
    if (!whole && !parse_ranges(f[0], lo, hi, &n, CM_MAX_DIM))
        return;
    cm_result *r = NULL;
    char msg[512] = "";
    const cm_status st = cm_db_read(db, whole ? NULL : lo, whole ? NULL : hi, &r, msg, sizeof msg);
    failed_with_message(st, msg);
    if (st == CM_OK)
        read_result(r);
    cm_result_free(r);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 1024)
        return 0;
    char *text = malloc(size), *f[6];
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';
    fields(text, f, 6);
    switch (data[0] % 3) {
    case 0:
        system_step(f);
        break;
    case 1:
        solve(f);
        break;
    default:
        db_read(f);
    }
    free(text);
    return 0;
}
