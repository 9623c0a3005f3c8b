/* models/power_spectrum.h - the power spectrum of an evenly sampled
 * series through FFTW (its real-to-complex transform): the mean taken
 * out, a Hann window, |X_k|^2 scaled so that a sine of amplitude A
 * between bins shows a peak near A^2/4 ... A^2/2 (the window's spread), at
 * the frequencies k / (n dt), k = 0 .. n/2; and its largest local maxima.
 *
 * Not thread-safe: FFTW's planner is not; call from one thread at a time. */
#ifndef CM_MODELS_POWER_SPECTRUM_H
#define CM_MODELS_POWER_SPECTRUM_H

#include <stddef.h>

#include "cellmap/status.h"

/* x: n >= 4 samples dt apart. freq and power (n/2 + 1 entries, the
 * caller's) get the spectrum. CM_EINVAL for too few samples or a
 * non-finite one, CM_ENOMEM. */
cm_status cm_power_spectrum(const double *x, size_t n, double dt, double *freq, double *power,
                            char *msg, size_t msg_size);

/* The indices of the (at most) k largest local maxima of power[1 .. m-2]
 * (m entries), by decreasing power, into peaks; returns how many. */
size_t cm_spectrum_peaks(const double *power, size_t m, size_t k, size_t *peaks);

#endif
