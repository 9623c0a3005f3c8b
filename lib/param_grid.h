/* lib/param_grid.h - the parameter axes of the commands that vary a
 * model's parameters (lyapunov's --grid, bifurcation's --sweep, sweep's
 * --vary), in one syntax: "NAME=LO:HI:N" is N values at the centres of N
 * equal cells of LO..HI; "NAME=V1,V2,..." lists increasing values. */
#ifndef CM_LIB_PARAM_GRID_H
#define CM_LIB_PARAM_GRID_H

#include <stdbool.h>
#include <stddef.h>

#include "cellmap/model.h"
#include "models/params.h"
#include "lib/project.h"
#include "lib/json.h"

#define PARAM_AXIS_MAX 2000

typedef struct param_axis {
    char name[32];
    double lo, hi; /* the span the values' cells cover: a picture's axis */
    int n;
    bool listed;                   /* given as NAME=V1,V2,... */
    double values[PARAM_AXIS_MAX]; /* the listed values */
} param_axis;

/* Parses the len characters at s as NAME=LO:HI:N (LO < HI, 1 <= N <=
 * PARAM_AXIS_MAX) or NAME=V1,V2,... (increasing, finite). A list's span
 * reaches half a spacing beyond its ends. */
bool param_axis_parse(const char *s, size_t len, param_axis *a);

/* Splits "X=...,Y=..." (two axes, either syntax) at the comma before the
 * second name. */
bool param_axes_parse2(const char *s, param_axis ax[2]);

/* The value of point i: the centre of cell i, or the i-th listed value. */
double param_axis_value(const param_axis *a, int i);

/* Whether the values are evenly spaced (a list may be): a heat map's cells
 * are then where its values are. */
bool param_axis_even(const param_axis *a);

/* "NAME=LO:HI:N" or "NAME=V1,V2,..." joined by commas, for messages and
 * PNG texts. */
void param_axes_format(const param_axis *ax, int n_ax, char *out, size_t size);

/* key: [{"name", "lo", "hi", "n"}, ...] for --json. */
void param_axes_json(json *j, const char *key, const param_axis *ax, int n_ax);

/* "model":NAME,"params":{...}: the parameters besides the axes'. */
void param_base_json(json *j, const char *model, const cm_params *base);

/* Checks a model named for a sweep of its parameters: it exists (and is
 * one of `only`, "a or b", unless that is NULL), the parameter texts are valid and each
 * axis names a parameter (CM_EINVAL, the problem in msg). *base receives
 * the parameters without the axes' values (for the PNG texts). */
cm_status param_sweep_base(const model_spec *mo, const char *only, const param_axis *ax,
                           int n_ax, cm_params *base, char *msg, size_t msg_size);

/* The model of the command's --model and --param with parameters names[k]
 * set to values[k] (n <= 2); false, with the reason in msg, where it
 * cannot be built (e.g. S > S0). */
bool model_with_values(const model_spec *mo, const char *const *names, const double *values, int n,
                       cm_model *m, char *msg, size_t msg_size);

/* A branch to follow in one parameter (equilibria, periodic orbits):
 * the start and, when name is not "", the parameter, its range and how
 * the continuation steps. */
typedef struct branch_spec {
    double from[CM_MAX_DIM]; /* the start, in the coordinates the driver says */
    int n_from;
    char name[32];  /* the parameter; "": no branch */
    double lo, hi;  /* its range, holding the model's value */
    int direction;  /* +1 or -1: that way only; 0: both */
    double ds_max;  /* the longest arclength step; 0: (hi - lo) / 50 */
    int max_points; /* per way */
} branch_spec;

/* m's value of its number parameter name into *v; CM_EINVAL naming the
 * parameter (as `what`: "the branch's parameter") when m has none such. */
cm_status param_number(const cm_model *m, const char *name, const char *what, double *v,
                       char *msg, size_t msg_size);

/* Checks a branch against model m: the parameter is one of m's numbers
 * and the range (finite, LO < HI) holds m's value of it, into *p0 (NAN
 * without a branch). CM_EINVAL naming the fix. */
cm_status branch_spec_check(const branch_spec *b, const cm_model *m, double *p0, char *msg,
                            size_t msg_size);

/* Builders of the model of mo with one or two parameters (names[0],
 * names[1]) set, for the continuation kernels (models/arclength.h's
 * cm_model_at_fn; user: a param_builder). */
typedef struct param_builder {
    const model_spec *mo;
    const char *names[2];
} param_builder;
cm_status param_model_at(void *user, double p, cm_model *m, char *msg, size_t msg_size);
cm_status param_model_at2(void *user, double p, double q, cm_model *m, char *msg,
                          size_t msg_size);

/* The model at axis point idx[k] of each axis k (n_ax <= 2). */
bool model_at_point(const model_spec *mo, const param_axis *ax, const int *idx, int n_ax,
                    cm_model *m);

#endif
