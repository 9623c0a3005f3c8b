#include "src/dbfile.h"

#include <stdio.h>

#include "src/args.h"

int open_cluster_file(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
                      cm_store_info *info, cm_cluster *c)
{
    char msg[1024];
    cm_cluster_init(c, &(cm_lattice){1, {0}, {1}});
    cm_status st = cm_store_open(path, 0, s, msg, sizeof msg);
    if (st == CM_OK)
        st = cm_store_read_info(*s, info, msg, sizeof msg);
    if (st == CM_OK)
        st = cm_store_load_cluster(*s, c, msg, sizeof msg);
    if (st == CM_OK && c->nregions == 0)
        st = cm_fail(CM_EINVAL, msg, sizeof msg, "%s holds no region yet", path);
    if (st != CM_OK) {
        fprintf(stderr, "cellmap %s: %s\n", cmd, msg);
        close_cluster_file(*s, c);
        *s = NULL;
        return EXIT_FAIL;
    }
    c->mem_budget = mem_budget;
    return EXIT_OK;
}

void close_cluster_file(cm_store *s, cm_cluster *c)
{
    char msg[256];
    cm_cluster_free(c);
    cm_store_close(s, msg, sizeof msg);
}

const char *axis_name(int d)
{
    static const char *const names[CM_MAX_DIM] = {"x", "y", "z", "w", "v", "u"};
    return d >= 0 && d < CM_MAX_DIM ? names[d] : "?";
}
