#include "cellmap/model.h"

#include <stdio.h>
#include <string.h>

const char *cm_model_coord_name(const cm_model *m, int d)
{
    static const char *const generic[CM_MAX_DIM] = {"x0", "x1", "x2", "x3", "x4", "x5"};
    if (d < 0 || d >= CM_MAX_DIM)
        return "?";
    return m->coord_names && d < m->dim ? m->coord_names[d] : generic[d];
}

void cm_param_choice_name(const char *choices, int k, char *buf, size_t size)
{
    const char *c = choices;
    for (int i = 0; i < k && c; i++) {
        c = strchr(c, '|');
        if (c)
            c++;
    }
    if (!c) {
        snprintf(buf, size, "%d", k);
        return;
    }
    const char *end = strchr(c, '|');
    snprintf(buf, size, "%.*s", (int)(end ? (size_t)(end - c) : strlen(c)), c);
}

void cm_model_release(cm_model *m)
{
    if (!m)
        return;
    if (m->destroy && m->ctx)
        m->destroy(m->ctx);
    memset(m, 0, sizeof *m);
}
