/* tests/rank_witness.c - a model plugin for the tests of solves on MPI
 * ranks through libcellmap: the map x' = x / 2 + 1, y' = y / 2 (one fixed
 * point), which notes each process that steps it by creating the file
 * $CELLMAP_WITNESS/PID at its first step there. A worker of a solve steps
 * the map only when it solves a region, so the files say which ranks did.
 * With abort_above = a, a state with x > a aborts the computation: a
 * region that fails, on whichever rank solves it.
 * Build: cc -shared -fPIC $(pkg-config --cflags cellmap) -o librank_witness.so rank_witness.c */
#include <cellmap/plugin.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const cm_param_spec witness_params[] = {
    {"abort_above", "1e300", -1e300, 1e300, 1, NULL, "states with x above it abort"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};
static const char *const witness_state[] = {"x", "y"};
static atomic_int noted;

static void note_process(void)
{
    const char *dir = getenv("CELLMAP_WITNESS");
    if (!dir || atomic_exchange(&noted, 1))
        return;
    char path[4096];
    snprintf(path, sizeof path, "%s/%ld", dir, (long)getpid());
    const int fd = open(path, O_CREAT | O_WRONLY, 0644);
    if (fd >= 0)
        close(fd);
}

static int witness_step(const cm_model *m, const double *x, double *y)
{
    note_process();
    if (x[0] > m->values.value[0].v[0])
        return CM_STEP_ABORT;
    y[0] = x[0] / 2 + 1;
    y[1] = x[1] / 2;
    return CM_STEP_OK;
}

static cm_status witness_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    (void)msg, (void)msg_size;
    memset(m, 0, sizeof *m);
    m->name = "witness";
    m->dim = 2;
    m->params = witness_params;
    m->values = *p;
    m->step = witness_step;
    m->coord_names = witness_state;
    return CM_OK;
}

static const cm_plugin_model models[] = {
    {"witness", "x, y", "x' = x / 2 + 1, y' = y / 2, noting the processes that step it",
     "-4:4,-4:4", witness_params, witness_create},
};
static const cm_plugin plugin = {CM_PLUGIN_ABI, 1, models};

const cm_plugin *cellmap_plugin(void) { return &plugin; }
