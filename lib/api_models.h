/* lib/api_models.h - libcellmap's model sets (cm_models of cellmap.h) and
 * a call's model as the drivers take it; private to lib/api*.c. */
#ifndef CM_LIB_API_MODELS_H
#define CM_LIB_API_MODELS_H

#include "lib/project.h"

struct cm_models {
    cm_model_set set;
};

/* The model_spec of a call: name (NULL: fallback), its parameters' text
 * (NULL or "": the defaults) and the set (NULL: built in). The texts
 * point into params. */
static inline model_spec api_model_spec(const struct cm_models *set, const char *name,
                                        const char *params, const char *fallback)
{
    model_spec mo = {.name = name ? name : fallback};
    if (params && params[0])
        mo.texts[mo.n_texts++] = params;
    if (set)
        mo.set = set->set;
    return mo;
}

#endif
