/* models/registry.h - the models by name, for the command line. */
#ifndef CM_MODELS_REGISTRY_H
#define CM_MODELS_REGISTRY_H

#include "cellmap/model.h"
#include "cellmap/plugin.h"

/* A model by name: built in, or from a plugin (the same record). */
typedef cm_plugin_model cm_model_entry;

/* The plugins a command loaded (--model-lib), besides the built-in models. */
enum { CM_MODEL_LIBS_MAX = 8, CM_MODEL_LIB_PATH = 1024 };
typedef struct cm_model_lib {
    void *handle;
    char path[CM_MODEL_LIB_PATH];
    char hash[24]; /* FNV-1a 64 of the file, hex: a changed plugin differs */
    const cm_plugin *plugin;
} cm_model_lib;
typedef struct cm_model_set {
    int n;
    cm_model_lib lib[CM_MODEL_LIBS_MAX];
} cm_model_set;

/* Loads a plugin (its ABI checked) into s; the message names the path and
 * the fix. Loading the same file twice adds it once. */
cm_status cm_model_set_load(cm_model_set *s, const char *path, char *msg, size_t msg_size);
/* Unloads the plugins of s (after every model made from them is released). */
void cm_model_set_close(cm_model_set *s);
/* The entry of `name`: built in first, then the plugins in load order (s
 * may be NULL: built-in only); *lib (if not NULL) gets its plugin or NULL. */
const cm_model_entry *cm_model_set_find(const cm_model_set *s, const char *name,
                                        const cm_model_lib **lib);
/* The built-in models, then each plugin's, in load order: how many, and
 * entry i. */
size_t cm_model_set_count(const cm_model_set *s);
const cm_model_entry *cm_model_set_at(const cm_model_set *s, size_t i);
/* cm_model_create over s's models too. */
cm_status cm_model_set_create(const cm_model_set *s, const char *name, const char *const *texts,
                              int n_texts, cm_model *m, char *msg, size_t msg_size);
/* The hash cm_model_lib.hash holds, of any file. */
cm_status cm_file_hash(const char *path, char out[24], char *msg, size_t msg_size);

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
