#include "cellmap/model.h"

#include <string.h>

const char *cm_model_coord_name(const cm_model *m, int d)
{
    static const char *const generic[CM_MAX_DIM] = {"x0", "x1", "x2", "x3", "x4", "x5"};
    if (d < 0 || d >= CM_MAX_DIM)
        return "?";
    return m->coord_names && d < m->dim ? m->coord_names[d] : generic[d];
}

void cm_model_release(cm_model *m)
{
    if (!m)
        return;
    if (m->destroy && m->ctx)
        m->destroy(m->ctx);
    memset(m, 0, sizeof *m);
}
