/* models/registry.h - the models by name, for the command line. */
#ifndef CM_MODELS_REGISTRY_H
#define CM_MODELS_REGISTRY_H

#include "cellmap/model.h"

typedef struct cm_model_entry {
    const char *name;
    const char *state;   /* what the state vector holds, by its coordinates' names */
    const char *doc;     /* one line, with the thesis equation */
    const char *region;  /* default region LO:HI,... for the defaults, or NULL */
    const cm_param_spec *params;
    cm_status (*create)(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
} cm_model_entry;

/* Number of registered models and entry i (0-based). */
size_t cm_model_count(void);
const cm_model_entry *cm_model_at(size_t i);
/* Entry by name, or NULL. */
const cm_model_entry *cm_model_find(const char *name);

/* Builds model `name` from its defaults overridden by each of the n_texts
 * "k=v,..." strings. On failure msg names the problem. */
cm_status cm_model_create(const char *name, const char *const *texts, int n_texts, cm_model *m,
                          char *msg, size_t msg_size);

#endif
