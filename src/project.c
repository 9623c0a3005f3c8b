#include "src/project.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models/registry.h"
#include "src/args.h"

int project_open_read(const char *cmd, const char *path, uint64_t mem_budget, cm_store **s,
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
        project_close(*s, c);
        *s = NULL;
        return EXIT_FAIL;
    }
    c->mem_budget = mem_budget;
    return EXIT_OK;
}

void project_close(cm_store *s, cm_cluster *c)
{
    char msg[256];
    cm_cluster_free(c);
    cm_store_close(s, msg, sizeof msg);
}

cm_status project_create(const char *path, const cm_model *m, const cm_lattice *lat,
                         const char *command, const char *plan, cm_store **s, cm_cluster *c,
                         char *msg, size_t msg_size)
{
    const char *epoch = getenv("SOURCE_DATE_EPOCH"); /* reproducible files */
    const cm_store_meta meta = {m, lat, command, plan, CELLMAP_VERSION, epoch ? atoll(epoch) : 0};
    cm_cluster_init(c, lat);
    cm_status st = cm_store_create(path, &meta, s, msg, msg_size);
    if (st == CM_OK) {
        cm_store_attach(*s, c);
        cm_store_set_model(*s, m);
    }
    return st;
}

cm_status project_resume(const char *cmd, const char *path, project_fits_fn fits, void *user,
                         cm_store **s, cm_store_info *info, cm_cluster *c, char *msg,
                         size_t msg_size)
{
    /* read-only until the file proves to be the caller's: a refused file
     * is never written */
    cm_store *check = NULL;
    const cm_model *model = NULL;
    cm_status st = cm_store_open(path, 0, &check, msg, msg_size);
    if (st == CM_OK)
        st = cm_store_read_info(check, info, msg, msg_size);
    cm_store_close(check, NULL, 0);
    if (st == CM_OK)
        st = fits(user, info, &model, msg, msg_size);
    int upgraded = 0;
    if (st == CM_OK && info->version < CM_STORE_VERSION) {
        st = cm_store_upgrade(path, model, &upgraded, msg, msg_size);
        if (st == CM_OK && upgraded)
            fprintf(stderr,
                    "cellmap %s: upgraded %s from format version %d to %d (older cellmap "
                    "versions cannot open it any more)\n",
                    cmd, path, info->version, CM_STORE_VERSION);
    }
    if (st == CM_OK)
        st = cm_store_open(path, 1, s, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_store_set_model(*s, model);
    return cm_store_load_cluster(*s, c, msg, msg_size);
}

const char *axis_name(int d)
{
    static const char *const names[CM_MAX_DIM] = {"x", "y", "z", "w", "v", "u"};
    return d >= 0 && d < CM_MAX_DIM ? names[d] : "?";
}

/* The parameters JSON of a file ({"k":1.5,"mode":"output","K":[1,2]}) as
 * the "k=v,..." text models are built from. False if it is not such JSON. */
static bool params_text(const char *json, char *out, size_t size)
{
    size_t used = 0;
    const char *p = json;
    if (*p++ != '{')
        return false;
    while (*p && *p != '}') {
        const char *key = p + 1, *end = *p == '"' ? strchr(key, '"') : NULL;
        if (!end || end[1] != ':')
            return false;
        used += (size_t)snprintf(out + used, size > used ? size - used : 0,
                                 "%s%.*s=", used ? "," : "", (int)(end - key), key);
        p = end + 2;
        const char *stop = *p == '[' ? "]" : *p == '"' ? "\"" : ",}";
        if (*p == '[' || *p == '"')
            p++;
        const size_t len = strcspn(p, stop);
        for (size_t i = 0; i < len && used + 1 < size; i++)
            out[used++] = p[i] == ',' ? ':' : p[i];
        out[used < size ? used : size - 1] = 0;
        p += len;
        if (*stop != ',' && *p++ == 0)
            return false;
        if (*p == ',')
            p++;
    }
    return *p == '}' && used < size;
}

cm_status model_of_store(const cm_store_info *info, cm_model *m, char *msg, size_t msg_size)
{
    char text[4096], again[4096];
    const char *texts[1] = {text};
    if (!params_text(info->params, text, sizeof text))
        return cm_fail(CM_EINVAL, msg, msg_size, "its parameters '%s' are not readable",
                       info->params);
    cm_status st = cm_model_create(info->model, texts, 1, m, msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_params_json(&m->values, again, sizeof again);
    if (strcmp(again, info->params) != 0) {
        cm_model_release(m);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "its parameters %s do not rebuild exactly; this cellmap reads them as "
                       "something else",
                       info->params);
    }
    return CM_OK;
}
