/* Delay embedding (models/embedding) against series whose answers are
 * known: Henon's map's x (a = 1.4, b = 0.3; largest exponent 0.41922,
 * two dimensions embed it, one does not), the logistic map at r = 4
 * (exponent log 2), a quasi-periodic sum of sines (exponent 0), the
 * extrema of a sampled sine; the sorted neighbour search against brute
 * force; bad input. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "models/embedding.h"

#define PI 3.14159265358979323846

enum { N_HENON = 20000 };

static void henon_x(double *s, size_t n)
{
    double x = 0.1, y = 0.1;
    for (size_t i = 0; i < n + 1000; i++) {
        const double xn = 1 - 1.4 * x * x + y;
        y = 0.3 * x, x = xn;
        if (i >= 1000)
            s[i - 1000] = x;
    }
}

/* The fraction of false neighbours by comparing every pair. */
static double brute_fraction(const double *s, size_t n, int m, int lag, int max_dim, double ratio,
                             size_t theiler)
{
    const size_t nv = n - (size_t)max_dim * (size_t)lag;
    size_t counted = 0, false_ones = 0;
    for (size_t i = 0; i < nv; i++) {
        double best = INFINITY;
        size_t found = nv;
        for (size_t j = 0; j < nv; j++) {
            if ((i > j ? i - j : j - i) <= theiler)
                continue;
            double d = 0;
            for (int c = 0; c < m; c++)
                d = fmax(d, fabs(s[i + (size_t)(c * lag)] - s[j + (size_t)(c * lag)]));
            if (d > 0 && d < best)
                best = d, found = j;
        }
        if (found == nv)
            continue;
        counted++;
        const size_t next = (size_t)(m * lag);
        false_ones += fabs(s[i + next] - s[found + next]) > ratio * best;
    }
    return (double)false_ones / (double)counted;
}

static void test_henon(void)
{
    double *s = malloc(N_HENON * sizeof *s);
    henon_x(s, N_HENON);
    char msg[256];
    double fraction[4];
    const cm_fnn_options fo = {1, 4, 10, 0};
    CHECK(cm_false_neighbours(s, N_HENON, &fo, fraction, msg, sizeof msg) == CM_OK);
    printf("henon false neighbours: %.4f %.4f %.4f %.4f\n", fraction[0], fraction[1], fraction[2],
           fraction[3]);
    CHECK(fraction[0] > 0.3); /* the map folds: one coordinate does not embed it */
    CHECK(fraction[1] < 0.002);
    CHECK(fraction[2] < 0.002);
    /* the sorted search finds what comparing every pair finds */
    double small[3];
    const cm_fnn_options so = {2, 3, 5, 3};
    CHECK(cm_false_neighbours(s, 3000, &so, small, msg, sizeof msg) == CM_OK);
    for (int m = 1; m <= 3; m++)
        CHECK(small[m - 1] == brute_fraction(s, 3000, m, 2, 3, 5, 3));

    double S[9];
    size_t n_ref;
    const cm_kantz_options ko = {2, 1, 0.005, 0, 8};
    CHECK(cm_kantz_divergence(s, N_HENON, &ko, S, &n_ref, msg, sizeof msg) == CM_OK);
    const double slope = cm_index_slope(S, 1, 6);
    printf("henon divergence slope %.4f over %zu references (S0 %.3f, S8 %.3f)\n", slope, n_ref,
           S[0], S[8]);
    CHECK(n_ref > N_HENON / 2);
    CHECK_NEAR(slope, 0.41922, 0.03);
    free(s);
}

static void test_logistic_and_quasiperiodic(void)
{
    enum { N = 20000 };
    double *s = malloc(N * sizeof *s), S[41];
    double x = 0.3;
    for (int i = 0; i < N; i++)
        s[i] = x = 4 * x * (1 - x);
    char msg[256];
    size_t n_ref;
    const cm_kantz_options ko = {1, 1, 1e-4, 0, 6};
    CHECK(cm_kantz_divergence(s, N, &ko, S, &n_ref, msg, sizeof msg) == CM_OK);
    const double slope = cm_index_slope(S, 0, 5);
    printf("logistic divergence slope %.4f over %zu references\n", slope, n_ref);
    CHECK_NEAR(slope, log(2.0), 0.04);

    /* two incommensurate frequencies: neighbours keep their distance */
    for (int i = 0; i < N; i++)
        s[i] = sin(0.3 * i) + 0.5 * sin(0.3 * sqrt(2.0) * i);
    const cm_kantz_options kq = {4, 3, 0.02, 10, 40};
    CHECK(cm_kantz_divergence(s, N, &kq, S, &n_ref, msg, sizeof msg) == CM_OK);
    const double flat = cm_index_slope(S, 0, 40);
    printf("quasi-periodic divergence slope %.5f over %zu references (S0 %.3f, S40 %.3f)\n",
           flat, n_ref, S[0], S[40]);
    CHECK(n_ref > 100);
    CHECK(fabs(flat) < 0.01);
    /* no neighbour within a tiny radius: no reference, S NaN, no error */
    const cm_kantz_options kt = {4, 3, 1e-12, 10, 6};
    CHECK(cm_kantz_divergence(s, N, &kt, S, &n_ref, msg, sizeof msg) == CM_OK);
    CHECK(n_ref == 0 && isnan(S[0]));
    free(s);
}

static void test_extrema(void)
{
    enum { N = 1000 };
    double t[N], x[2 * N], te[N], xe[N];
    for (int i = 0; i < N; i++)
        t[i] = 0.1 * i, x[2 * i] = 2 * sin(t[i]), x[2 * i + 1] = 0;
    const size_t nmax = cm_series_extrema(t, x, 2, N, 1, te, xe);
    CHECK_INT(nmax, 16); /* pi/2 + 2 pi k below 99.9 */
    for (size_t k = 0; k < nmax; k++) {
        CHECK_NEAR(te[k], PI / 2 + 2 * PI * (double)k, 3e-4);
        CHECK_NEAR(xe[k], 2, 1e-4);
    }
    const size_t nmin = cm_series_extrema(t, x, 2, N, -1, te, xe);
    CHECK_INT(nmin, 16);
    CHECK_NEAR(te[0], 1.5 * PI, 3e-4);
    CHECK_NEAR(xe[0], -2, 1e-4);
}

static void test_bad_input(void)
{
    double s[100], fraction[3], S[5];
    for (int i = 0; i < 100; i++)
        s[i] = i % 7;
    char msg[256];
    size_t n_ref;
    const cm_fnn_options fo = {1, 3, 10, 0};
    const cm_fnn_options no_lag = {0, 3, 10, 0};
    CHECK(cm_false_neighbours(s, 100, &no_lag, fraction, msg, sizeof msg) == CM_EINVAL);
    CHECK(cm_false_neighbours(s, 12, &fo, fraction, msg, sizeof msg) == CM_EINVAL);
    const cm_kantz_options long_run = {3, 1, 0.5, 0, 200};
    CHECK(cm_kantz_divergence(s, 100, &long_run, S, &n_ref, msg, sizeof msg) == CM_EINVAL);
    const cm_kantz_options no_radius = {3, 1, 0, 0, 4};
    CHECK(cm_kantz_divergence(s, 100, &no_radius, S, &n_ref, msg, sizeof msg) == CM_EINVAL);
    s[50] = NAN;
    CHECK(cm_false_neighbours(s, 100, &fo, fraction, msg, sizeof msg) == CM_EINVAL);
    const cm_kantz_options ko = {3, 1, 0.5, 0, 4};
    CHECK(cm_kantz_divergence(s, 100, &ko, S, &n_ref, msg, sizeof msg) == CM_EINVAL);
}

int main(void)
{
    test_henon();
    test_logistic_and_quasiperiodic();
    test_extrema();
    test_bad_input();
    CHECK_DONE();
}
