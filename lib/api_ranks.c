/* lib/api_ranks.c - see api_ranks.h. */
#define _GNU_SOURCE /* dladdr */
#include "lib/api_ranks.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/status.h"

struct cm_ranks {
    solve_ranks *mpi;     /* NULL: one rank, MPI not loaded */
    void *module;         /* libcellmap-mpi.so.0, kept loaded: MPI cannot be unloaded */
    ranks_close_fn close; /* the module's */
};

#define MODULE_NAME "libcellmap-mpi.so.0"

/* The file libcellmap's code is in (the shared library, or the program
 * that linked it statically) into path; false if it is not known. */
static const char anchor; /* an address in libcellmap's file */

static bool own_file(char *path, size_t size)
{
    Dl_info info;
    if (!dladdr(&anchor, &info) || !info.dli_fname ||
        (size_t)snprintf(path, size, "%s", info.dli_fname) >= size)
        return false;
    return true;
}

/* Loads the module from libcellmap's directory (MPI's own libraries
 * global, as Open MPI's components need them). */
static cm_status load_module(const char *own, void **module, char *msg, size_t msg_size)
{
    char dir[4096], path[4096 + sizeof MODULE_NAME];
    snprintf(dir, sizeof dir, "%s", own);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = 0;
    snprintf(path, sizeof path, "%s/%s", slash ? dir : ".", MODULE_NAME);
    *module = dlopen(path, RTLD_NOW | RTLD_GLOBAL);
    if (!*module)
        return cm_fail(CM_ENOTFOUND, msg, msg_size,
                       "running under mpirun, libcellmap needs %s (%s): build cellmap where MPI "
                       "is found (Debian: libopenmpi-dev) and install it beside libcellmap",
                       path, dlerror());
    return CM_OK;
}

cm_status cm_ranks_open(cm_ranks **out, char *msg, size_t msg_size)
{
    if (!out)
        return cm_fail(CM_EINVAL, msg, msg_size, "cm_ranks_open: out is NULL");
    *out = NULL;
    cm_ranks *r = calloc(1, sizeof *r);
    if (!r)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory");
    if (ranks_launched() <= 1) { /* one rank: nothing to load */
        *out = r;
        return CM_OK;
    }
    char own[4096];
    if (!own_file(own, sizeof own)) {
        free(r);
        return cm_fail(CM_ENOTFOUND, msg, msg_size, "libcellmap cannot find its own file");
    }
    cm_status st = load_module(own, &r->module, msg, msg_size);
    ranks_open_fn open = NULL;
    if (st == CM_OK) {
        *(void **)&open = dlsym(r->module, RANKS_OPEN_SYMBOL);
        *(void **)&r->close = dlsym(r->module, RANKS_CLOSE_SYMBOL);
        if (!open || !r->close)
            st = cm_fail(CM_EFORMAT, msg, msg_size, "%s lacks %s: install the one built with "
                         "this libcellmap", MODULE_NAME, RANKS_OPEN_SYMBOL);
    }
    if (st == CM_OK)
        st = open(own, &r->mpi, msg, msg_size);
    if (st != CM_OK) {
        if (r->mpi) /* every rank failed alike: MPI ends */
            r->close(r->mpi, false);
        free(r); /* the module stays: MPI cannot be unloaded */
        return st;
    }
    *out = r;
    return CM_OK;
}

int cm_ranks_rank(const cm_ranks *r) { return r && r->mpi ? r->mpi->rank : 0; }

int cm_ranks_size(const cm_ranks *r) { return r && r->mpi ? r->mpi->size : 1; }

void cm_ranks_close(cm_ranks *r)
{
    if (!r)
        return;
    if (r->mpi)
        r->close(r->mpi, true);
    free(r);
}

solve_ranks *api_ranks_solve(cm_ranks *r)
{
    return r && r->mpi && r->mpi->size > 1 ? r->mpi : NULL;
}
