/* cellmap/plugin.h - models from shared objects: `cellmap ... --model-lib
 * PATH.so --model NAME`. Installed with the other public headers; build a
 * plugin with `cc -shared -fPIC $(pkg-config --cflags cellmap) ...`.
 *
 * A plugin exports one function, cellmap_plugin(), returning a cm_plugin
 * that lives as long as the library is loaded. cellmap refuses a plugin
 * whose abi is not CM_PLUGIN_ABI_OLDEST..CM_PLUGIN_ABI (the layouts of
 * cm_model and the structs below changed), naming the versions.
 *
 * Each model's create() fills *m from the parameter values p (defaults of
 * params overridden by --param): name, dim (1..CM_MAX_DIM), params, values
 * (*p), step (or, for an ODE, flow: cellmap integrates it, see cm_flow
 * and CM_FLOW_PARAM_SPECS in model.h) and, if it needs them, ctx and
 * destroy, coord_names (names of the state coordinates, identifiers,
 * for CSV/JSON/SQL columns), and period/period_lo for a coordinate that is
 * an angle or a phase (cellmap takes every image into that period; boxes
 * hold at most one). step() (and a flow's field) must be pure
 * and thread-safe: cellmap calls it on every thread at once. It returns CM_STEP_OK with the image in y, CM_STEP_NO_IMAGE (the sink:
 * the orbit is lost) or CM_STEP_ABORT; any other code stops the run as
 * CM_STEP_ABORT does. On failure create() returns a
 * status (CM_EINVAL ...), writes the reason into msg with snprintf and
 * leaves *m zeroed. A plugin calls no function of cellmap's: it needs these
 * headers (their inline functions included) and nothing to link. */
#ifndef CM_PLUGIN_H
#define CM_PLUGIN_H

#include "cellmap/model.h"

#define CM_PLUGIN_ABI 5 /* 2: cm_model.flow; 3: cm_model.period (angles); 4: stiff
                          * integrators, sections on state planes, 24 parameters;
                          * 5: cm_model.equal_axes (plugins of ABI 4 still load) */
#define CM_PLUGIN_ABI_OLDEST 4 /* the oldest ABI whose plugins load */

typedef struct cm_plugin_model {
    const char *name;   /* as --model takes it */
    const char *state;  /* what the state vector holds, in words */
    const char *doc;    /* one line */
    const char *region; /* the default --region "LO:HI,...", or NULL (then required) */
    const cm_param_spec *params; /* ends with an entry whose name is NULL */
    cm_status (*create)(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
} cm_plugin_model;

typedef struct cm_plugin {
    int abi; /* CM_PLUGIN_ABI */
    int count;
    const cm_plugin_model *models;
} cm_plugin;

/* The entry point a plugin exports. */
typedef const cm_plugin *(*cm_plugin_entry)(void);
#define CM_PLUGIN_ENTRY_NAME "cellmap_plugin"

#endif
