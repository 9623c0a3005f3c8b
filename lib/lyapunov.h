/* lib/lyapunov.h - maps of the largest Lyapunov exponent over a grid of
 * two parameters (thesis 2.6, Fig. 2.22; any map model, the friction
 * oscillator by its own estimator) over models/map_lyapunov.h and
 * models/friction_oscillator.h, with the fold and period-doubling curves
 * of `continue --curves` drawn over the map; written as CSV and as the
 * heat map. Nothing is printed: calls return a status with the problem in
 * msg (CM_EINVAL: the request's). */
#ifndef CM_LIB_LYAPUNOV_H
#define CM_LIB_LYAPUNOV_H

#include <stdbool.h>

#include "lib/outfile.h"
#include "lib/param_grid.h"
#include "lib/work.h"
#include "render/chart.h"

/* The most --curves files a map takes. */
enum { MAX_CURVE_FILES = 8 };

enum { LYAP_DIRECT = 0, LYAP_SYNC, LYAP_STICKMAP };

/* The grid, the estimator's settings and the outputs (the command's options). */
typedef struct lyap_args {
    model_spec mo;
    param_axis ax[2];
    int has_grid, periods, threads, width, height, n_from;
    int method;       /* LYAP_DIRECT, LYAP_SYNC (lib/lyapunov_sync.h) or LYAP_STICKMAP
                         (lib/stick_map.h) */
    param_axis q;     /* --method sync: the couplings */
    int every, runs;  /* --method stickmap: every k-th stick, from so many starts */
    long long seed;
    double escape;
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

/* The command's defaults: friction-oscillator, 600 periods, d0 = 1e-8,
 * 900x700 pixels; a->ax must be given. */
lyap_args lyapunov_defaults(void);

/* The model's parameters, the map and what it holds. */
typedef struct lyap_result {
    cm_params base;
    double *v;     /* the exponents, v[j * nx + i]; NaN where not computed */
    overlay ov;    /* the curves drawn over the heat map */
    size_t points, computed, positive, best; /* best: the index of the largest */
    uint64_t done; /* points computed before a stop */
    double seconds;
    bool invalid;  /* some points could not be built (S > S0) */
} lyap_result;

/* Checks the request (a model other than the friction oscillator starts
 * at a->from, or the centre of its example region, set here), reads the
 * curves and computes the map on a->threads threads (0: all), progress in
 * grid points through h, stopped by h (CM_ECANCELED, with r->done). r is
 * freed by lyapunov_result_free whatever the status. */
cm_status lyapunov_compute(lyap_args *a, const work_hooks *h, lyap_result *r, char *msg,
                           size_t msg_size);

/* The map as CSV at a->csv and the heat map with the curves at a->png
 * (either may be NULL; the curves' labels are joined in place); CM_ERANGE when no point could be computed. */
cm_status lyapunov_write(const lyap_args *a, lyap_result *r, char *msg, size_t msg_size);

void lyapunov_result_free(lyap_result *r);

/* For --method `method` (sync, stickmap): the friction oscillator's
 * parameters of a->mo into base; CM_EINVAL for another model or S > S0. */
cm_status lyapunov_fo_base(const lyap_args *a, const char *method, cm_params *base, char *msg,
                           size_t msg_size);

/* Every curves file of a, read into ov (the caller's to free with
 * lyapunov_overlay_free, whatever the result): CM_EINVAL when a file is
 * not curves in the grid's parameters. lyapunov_compute reads them; the
 * fuzz target of files reads them alone. */
cm_status lyapunov_read_curves(const lyap_args *a, overlay *ov, char *msg, size_t msg_size);
void lyapunov_overlay_free(overlay *ov);

#endif
