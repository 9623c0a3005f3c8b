/* models/params.h - parameter values from command-line text.
 *
 * Text syntax: "name=value[,name=value...]". A vector value is written
 * v1:v2:...; a choice parameter takes one of its words. Unknown names,
 * malformed numbers, values out of range and too many entries are errors
 * whose message names the parameter and the accepted range.
 */
#ifndef CM_MODELS_PARAMS_H
#define CM_MODELS_PARAMS_H

#include "cellmap/model.h"

/* Fills p with the spec's defaults. */
cm_status cm_params_defaults(const cm_param_spec *spec, cm_params *p, char *msg, size_t msg_size);

/* Overrides values from text (may be called repeatedly). */
cm_status cm_params_set(cm_params *p, const char *text, char *msg, size_t msg_size);

/* Index of a parameter by name, or -1. */
int cm_params_find(const cm_params *p, const char *name);

/* Scalar value of parameter `name` (first element). The name must exist. */
double cm_params_get(const cm_params *p, const char *name);

/* Writes the values as "name=value,..." into buf, each number the shortest
 * text that reads back as the same double (cm_num_text). */
void cm_params_format(const cm_params *p, char *buf, size_t size);

/* The same, leaving out the parameters named in skip, a NULL-terminated
 * list (the swept ones; skip itself may be NULL). */
void cm_params_format_with(const cm_params *p, const char *const *skip, char *buf, size_t size);

/* Shared by the constructors: allocates a zeroed context of `size` bytes and
 * fills the common fields of *m. */
cm_status cm_model_setup(cm_model *m, const char *name, int dim, const cm_params *p,
                         size_t ctx_size, char *msg, size_t msg_size);

#endif
