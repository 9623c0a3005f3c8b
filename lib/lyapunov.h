/* lib/lyapunov.h - maps of the largest Lyapunov exponent over a grid of
 * two parameters (thesis 2.6, Fig. 2.22; any map model, the friction
 * oscillator by its own estimator) over models/map_lyapunov.h and
 * models/friction_oscillator.h, with the fold and period-doubling curves
 * of `continue --curves` drawn over the map; written as CSV and as the
 * heat map. Nothing is printed: calls return the problem in msg. */
#ifndef CM_LIB_LYAPUNOV_H
#define CM_LIB_LYAPUNOV_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "render/chart.h"

/* The most --curves files a map takes. */
enum { MAX_CURVE_FILES = 8 };

/* The grid, the estimator's settings and the outputs (the command's options). */
typedef struct lyap_args {
    model_spec mo;
    param_axis ax[2];
    int has_grid, periods, threads, width, height, n_from;
    double d0, from[CM_MAX_DIM];
    const char *csv, *png, *curves[MAX_CURVE_FILES];
    int n_curves;
    bool json, quiet;
} lyap_args;

/* The curves of `continue --curves` (curve,label,P,P2,x,v) in the grid's
 * axes, as one polyline broken by NaN between curves, and a label at each
 * curve's start. */
typedef struct overlay {
    double *x, *y;
    size_t n;
    cm_chart_label labels[64];
    char texts[64][32];
    int n_labels;
} overlay;

/* The exponent at grid point (i, j); NaN where the model cannot be built
 * (S > S0) or no sample was accepted. */
double lyapunov_point(const lyap_args *a, int i, int j, int *invalid);

/* The map's values (v[j * nx + i]) as CSV at a->csv. */
bool lyapunov_write_csv(const lyap_args *a, const double *v, char *msg, size_t msg_size);

/* Every --curves file, read before the grid is computed (ov is the
 * caller's to free with lyapunov_overlay_free, whatever the result):
 * CM_EINVAL when a file is not curves in the grid's parameters. */
cm_status lyapunov_read_curves(const lyap_args *a, overlay *ov, char *msg, size_t msg_size);

void lyapunov_overlay_free(overlay *ov);

/* The heat map with the curves at a->png. */
bool lyapunov_write_png(const lyap_args *a, const char *model, const cm_params *p, const double *v,
                        overlay *ov, char *msg, size_t msg_size);

#endif
