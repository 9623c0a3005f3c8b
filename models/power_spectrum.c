/* Power spectra through FFTW (models/power_spectrum.h). */
#include "models/power_spectrum.h"

#include <fftw3.h>
#include <math.h>
#include <stdlib.h>

#define TWO_PI 6.283185307179586476925286766559

cm_status cm_power_spectrum(const double *x, size_t n, double dt, double *freq, double *power,
                            char *msg, size_t msg_size)
{
    if (n < 4 || !(dt > 0) || !isfinite(dt) || n > (size_t)1 << 30)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "a spectrum needs 4 .. 2^30 samples a positive interval apart (%zu, %g)", n,
                       dt);
    double mean = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(x[i]))
            return cm_fail(CM_EINVAL, msg, msg_size, "sample %zu is not finite", i);
        mean += x[i];
    }
    mean /= (double)n;
    const size_t m = n / 2 + 1;
    double *in = fftw_malloc(n * sizeof *in);
    fftw_complex *out = fftw_malloc(m * sizeof *out);
    /* FFTW_ESTIMATE: the plan (hence the bytes of the result) does not
     * depend on timing measurements */
    fftw_plan plan = in && out ? fftw_plan_dft_r2c_1d((int)n, in, out, FFTW_ESTIMATE) : NULL;
    if (!plan) {
        fftw_free(in);
        fftw_free(out);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for a spectrum of %zu samples", n);
    }
    double window_sum = 0;
    for (size_t i = 0; i < n; i++) {
        const double w = 0.5 * (1 - cos(TWO_PI * (double)i / (double)(n - 1)));
        in[i] = (x[i] - mean) * w;
        window_sum += w;
    }
    fftw_execute(plan);
    for (size_t k = 0; k < m; k++) {
        freq[k] = (double)k / ((double)n * dt);
        /* one-sided, normalised by the window's sum: a sine of amplitude
         * A on a bin gives A^2/4 */
        const double re = out[k][0], im = out[k][1];
        power[k] = (re * re + im * im) / (window_sum * window_sum) * (k && 2 * k != n ? 2 : 1) /
                   2;
    }
    fftw_destroy_plan(plan);
    fftw_free(in);
    fftw_free(out);
    return CM_OK;
}

size_t cm_spectrum_peaks(const double *power, size_t m, size_t k, size_t *peaks)
{
    size_t found = 0;
    for (size_t i = 1; i + 1 < m; i++) {
        if (!(power[i] > power[i - 1] && power[i] >= power[i + 1]))
            continue;
        /* insert by decreasing power, keeping the k largest */
        size_t at = found < k ? found++ : k;
        if (at == k && !(power[i] > power[peaks[k - 1]]))
            continue;
        if (at == k)
            at = k - 1;
        while (at > 0 && power[peaks[at - 1]] < power[i]) {
            peaks[at] = peaks[at - 1];
            at--;
        }
        peaks[at] = i;
    }
    return found;
}
