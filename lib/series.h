/* lib/series.h - time series of any flow model (chip-4d, chip-workpiece,
 * duffing, a plugin's flow) over models/ode_flow.h, and of the delay
 * model chip-bue over models/dde.h: samples every dt after a transient,
 * a coordinate's power spectrum through FFTW (models/power_spectrum.h)
 * with its largest peaks, in the model's time unit and, given the unit in
 * seconds, in Hz (thesis 3.3: K0 = 1.64e-4 s for the chip models);
 * written as CSV and as the time history over the spectrum. Nothing is
 * printed: calls return a status with the problem in msg (CM_EINVAL: the
 * request's). */
#ifndef CM_LIB_SERIES_H
#define CM_LIB_SERIES_H

#include <stdbool.h>
#include <stdio.h>

#include "lib/outfile.h"
#include "lib/project.h"
#include "models/chip_formation.h"

enum { SERIES_MAX_DIM = CM_DDE_MAX_DIM, SERIES_PEAKS = 8 };

typedef struct series_args {
    model_spec mo;                /* a flow model, or chip-bue */
    double from[SERIES_MAX_DIM];  /* the flow's coordinates */
    int n_from;                   /* 0: the centre of the example region (chip-bue: its start-up) */
    double time, skip, dt;        /* followed to `time`, recorded after `skip`, every dt */
    const char *of;               /* the coordinate drawn and transformed (NULL: the first) */
    double time_unit;             /* seconds per unit of the model's time (0: no Hz) */
    double fmax;                  /* the spectrum drawn up to this (0: Nyquist; Hz given the unit) */
    const char *spectrum_csv;
    bool returns;                 /* the figure adds the return map at the section */
    chart_outputs out;            /* csv: the samples; png: history over spectrum */
} series_args;

/* The command's defaults: 100 time units sampled every 0.01, none
 * skipped, 900x800 pixels. */
series_args series_defaults(void);

/* Whether the model spec names a model series follows rather than the
 * friction oscillator's simulation (a flow, or chip-bue). */
bool series_model(const model_spec *mo);

typedef struct series_result {
    char model[64], params[512];
    int dim, of;                           /* coordinates; the one transformed */
    char names[SERIES_MAX_DIM][32];
    double start[SERIES_MAX_DIM];
    double *t, *x;                          /* samples: t[i], x[i * dim + d] */
    size_t n, cap;
    double *freq, *power;                   /* the spectrum of coordinate `of` */
    size_t m;
    size_t peaks[SERIES_PEAKS], n_peaks;
    double lo, hi, mean;                    /* of coordinate `of` over the samples */
    double *cross;                          /* a flow's section crossings after the transient:
                                               coordinate `of` at each (the return map) */
    size_t n_cross, cap_cross;
    double mean_return;                     /* the mean time between them; NAN with < 2 */
} series_result;

/* Checks the request and follows the model. r is freed by
 * series_result_free whatever the status; CM_EMODEL when the orbit is
 * lost (msg: when). */
cm_status series_compute(const series_args *a, series_result *r, char *msg, size_t msg_size);

/* The samples (t and every coordinate) at a->out.csv, the spectrum
 * (frequency, [frequency_hz,] power) at a->spectrum_csv, the figure at
 * a->out.png (any may be NULL): the history over the spectrum and, with
 * a->returns, the return map of the coordinate at the section's crossings
 * below them (Fig. 3.6; CM_EINVAL with fewer than 3 crossings). */
cm_status series_write(const series_args *a, const series_result *r, char *msg, size_t msg_size);

/* The run as text (samples, the coordinate's range and mean, the
 * spectrum's peaks) and as the JSON document of `cellmap simulate --json`
 * for a flow (docs/cellmap.schema.json), to f. */
void series_report(FILE *f, const series_args *a, const series_result *r);
void series_json(FILE *f, const series_args *a, const series_result *r);

void series_result_free(series_result *r);

#endif
