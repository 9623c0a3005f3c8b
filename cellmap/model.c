#include "cellmap/model.h"

#include <string.h>

void cm_model_release(cm_model *m)
{
    if (!m)
        return;
    if (m->destroy && m->ctx)
        m->destroy(m->ctx);
    memset(m, 0, sizeof *m);
}
