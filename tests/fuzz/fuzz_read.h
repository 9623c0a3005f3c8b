/* tests/fuzz/fuzz_read.h - what the .cmdb fuzz targets do with a file:
 * everything a reader does (info, load, groups, flatten every cell, a
 * second pass under a paging budget), checking what it gets back. */
#ifndef CM_FUZZ_READ_H
#define CM_FUZZ_READ_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "cellmap/store.h"

/* Most cells a file may claim before the target skips reading its pages
 * (decompression makes a few bytes claim gigabytes; readers then stop at
 * malloc, which is not what these targets look for). */
#define FUZZ_MAX_CELLS (UINT64_C(1) << 18)

static void fuzz_fail(const char *what)
{
    fprintf(stderr, "fuzz target: %s\n", what);
    abort();
}

/* A temporary file's name in path, made at the first call. */
static void fuzz_temp_path(char path[64])
{
    if (path[0])
        return;
    snprintf(path, 64, "/tmp/cellmap-fuzz-XXXXXX");
    const int fd = mkstemp(path);
    if (fd < 0)
        fuzz_fail("cannot create a temporary file");
    close(fd);
}

/* Every cell of the cluster resolved: groups in range, steps of the sink's
 * and of periodic cells as the format says. */
static void fuzz_flatten(cm_cluster *c)
{
    char msg[1024];
    cm_box all;
    cm_region flat;
    cm_cluster_bounds(c, &all);
    if (cm_box_cells(&all) > 4 * FUZZ_MAX_CELLS)
        return;
    if (cm_cluster_flatten(c, &all, &flat, msg, sizeof msg) != CM_OK)
        return;
    for (uint64_t i = 0; i < flat.ncells; i++)
        if (flat.group[i] != CM_GROUP_NONE && flat.group[i] > c->ngroups)
            fuzz_fail("a resolved cell names a group the cluster does not have");
    cm_region_free(&flat);
}

static void fuzz_read_file(const char *path)
{
    char msg[1024];
    for (int pass = 0; pass < 2; pass++) {
        cm_store *s = NULL;
        cm_store_info info;
        cm_cluster c;
        cm_cluster_init(&c, &(cm_lattice){1, {0}, {1}});
        if (cm_store_open(path, 0, &s, msg, sizeof msg) == CM_OK &&
            cm_store_read_info(s, &info, msg, sizeof msg) == CM_OK && info.cells <= FUZZ_MAX_CELLS &&
            cm_store_load_cluster(s, &c, msg, sizeof msg) == CM_OK) {
            cm_group_info *g = calloc((size_t)info.groups + 1, sizeof *g);
            uint64_t sink = 0;
            if (g)
                cm_store_groups(s, g, info.groups, &sink, msg, sizeof msg);
            free(g);
            c.mem_budget = pass ? (UINT64_C(1) << 16) : 0; /* the second pass pages */
            fuzz_flatten(&c);
        }
        cm_cluster_free(&c);
        cm_store_close(s, msg, sizeof msg);
    }
}

#endif
