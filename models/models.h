/* models/models.h - constructors of the models.
 *
 * Each constructor validates the parameter values (already range-checked
 * against the spec by models/params.c), precomputes the coefficients and
 * fills *m. On failure *m is left zeroed and msg says what to change.
 * Use the registry (models/registry.h) rather than calling these directly.
 */
#ifndef CM_MODELS_MODELS_H
#define CM_MODELS_MODELS_H

#include "cellmap/model.h"
#include "models/params.h" /* cm_model_setup */

typedef cm_status (*cm_model_create_fn)(const cm_params *p, cm_model *m, char *msg,
                                        size_t msg_size);

extern const cm_param_spec cm_microchaos_1d_spec[];
extern const cm_param_spec cm_microchaos_1d_friction_spec[];
extern const cm_param_spec cm_microchaos_delay_spec[];
extern const cm_param_spec cm_microchaos_pd_spec[];
extern const cm_param_spec cm_microchaos_pd_twofold_spec[];
extern const cm_param_spec cm_microchaos_pd_friction_spec[];
extern const cm_param_spec cm_microchaos_general_spec[];
extern const cm_param_spec cm_friction_oscillator_spec[];
extern const cm_param_spec cm_duffing_spec[];
extern const cm_param_spec cm_chip_4d_spec[];
extern const cm_param_spec cm_chip_workpiece_spec[];

cm_status cm_microchaos_1d_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_microchaos_1d_friction_create(const cm_params *p, cm_model *m, char *msg,
                                           size_t msg_size);
cm_status cm_microchaos_delay_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_microchaos_pd_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_microchaos_pd_twofold_create(const cm_params *p, cm_model *m, char *msg,
                                          size_t msg_size);
cm_status cm_microchaos_pd_friction_create(const cm_params *p, cm_model *m, char *msg,
                                           size_t msg_size);
cm_status cm_microchaos_general_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_friction_oscillator_create(const cm_params *p, cm_model *m, char *msg,
                                        size_t msg_size);
cm_status cm_duffing_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_chip_4d_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);
cm_status cm_chip_workpiece_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size);


#endif
