/* lib/embedding.h - the largest Lyapunov exponent and the embedding
 * dimension of one scalar series, as the thesis measured the workpiece's
 * chaos with TISEAN (3.3, Figs. 3.12 and 3.15), over models/embedding.h:
 * the series is a coordinate of a model's simulated orbit (lib/series.h)
 * or a column of a CSV file (a measurement), every sample or only its
 * successive maxima or minima; false nearest neighbours per dimension;
 * Kantz's divergence curves for a few dimensions and radii, their slopes
 * fitted where they rise, the exponent per value of the series and, given
 * the time between values, per unit time (and per second given the time
 * unit). Written as CSV and as the figure of the thesis: the series'
 * delay projection over the curves. Nothing is printed but by the report
 * calls: calls return a status with the problem in msg (CM_EINVAL: the
 * request's). */
#ifndef CM_LIB_EMBEDDING_H
#define CM_LIB_EMBEDDING_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/exponents.h"
#include "lib/series.h"
#include "models/embedding.h"

enum { EMBED_MAX_RADII = 8, EMBED_MAX_DIMS = 8, EMBED_MAX_CURVES = 64 };

typedef struct embed_args {
    series_args sim;     /* the model's run (sim.of: the coordinate), unless input */
    const char *input;   /* else a CSV file with a header; a column "t" gives the times */
    const char *column;  /* the file's column (NULL: the first that is not t) */
    int extrema;         /* +1: the successive maxima, -1: minima, 0: every value */
    int dim_lo, dim_hi;  /* the curves' dimensions (0: from the false neighbours) */
    int lag, steps, fnn_dim;
    int theiler;         /* neighbours within this many values are left out */
    double radius[EMBED_MAX_RADII]; /* the neighbourhoods, as fractions of the series' range */
    int n_radius;
    int fit_lo, fit_hi;  /* the steps fitted (fit_hi 0: each curve's rise, chosen) */
    double ratio;        /* false neighbours' threshold */
    double time_unit;    /* seconds per unit of time (0: no 1/s) */
    const char *csv, *png;
    int width, height;
} embed_args;

/* The command's defaults: the model's run as series_defaults; maxima; lag
 * 1; false neighbours up to dimension 14 with threshold 10; the curves in
 * the 3 dimensions from the least that embeds, radii 0.5, 1 and 2 % of the
 * range, 40 steps; the figure 900x900. */
embed_args embedding_defaults(void);

/* "max", "min" or "all" -> extrema (+1, -1, 0); false for other words. */
bool embedding_values(const char *word, int *extrema);

/* The model's run (model, start, transient and time), the outputs and the
 * size from the request of the spectrum, whose options the two share. */
void embedding_take_run(embed_args *e, const exp_args *a);

typedef struct embed_curve {
    int dim;
    double radius; /* in the series' units */
    size_t n_ref;
    int fit_lo, fit_hi;
    double slope;  /* per value of the series; NaN without references */
    double *S;     /* steps + 1 */
} embed_curve;

typedef struct embed_result {
    char source[600];   /* the model and its parameters, or the file and column */
    char name[64];      /* the series' quantity */
    double *s, *ts;     /* the series and its times (ts NULL: a file without t) */
    size_t n;
    double lo, hi;
    double interval;    /* the mean time between values; NaN when unknown */
    double fnn[CM_EMBED_MAX_DIM];
    int fnn_dim, embeds; /* embeds: the least dimension with < 1 % false (0: none) */
    embed_curve curve[EMBED_MAX_CURVES];
    int n_curves, steps;
    double lambda;      /* the mean of the curves' slopes, per value */
    double spread;      /* their standard deviation */
} embed_result;

/* Checks the request, makes or reads the series, and analyses it. r is
 * freed by embedding_result_free whatever the status; CM_EMODEL when the
 * model's orbit is lost. */
cm_status embedding_compute(const embed_args *a, embed_result *r, char *msg, size_t msg_size);

/* The curves as CSV at a->csv (dim, radius, k, S: a row per curve and
 * step), the figure at a->png (either NULL: nothing). */
cm_status embedding_write(const embed_args *a, const embed_result *r, char *msg, size_t msg_size);

/* The result as text and as the JSON document of `cellmap exponents
 * --series --json` (docs/cellmap.schema.json), to f. */
void embedding_report(FILE *f, const embed_args *a, const embed_result *r);
void embedding_json(FILE *f, const embed_args *a, const embed_result *r);

void embedding_result_free(embed_result *r);

#endif
