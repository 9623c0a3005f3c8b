/* Lyapunov spectra (models/lyapunov_spectrum) against systems whose
 * spectra are known: Lorenz' flow at sigma = 10, rho = 28, beta = 8/3
 * (0.9056, 0, -14.5723; Sprott, "Chaos and Time-Series Analysis", and
 * the sum is the field's constant divergence -(sigma + 1 + beta)
 * exactly), Henon's map at a = 1.4, b = 0.3 (0.41922, -1.62319, summing
 * to log b exactly), and a linear flow and map whose exponents are their
 * eigenvalues' real parts and log moduli; the Kaplan-Yorke dimension
 * (Lorenz 2.062, Henon 1.258); Gram-Schmidt itself; and the flow's
 * spectrum against its own stroboscopic map's (the same exponents, per
 * period). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "models/lyapunov_spectrum.h"
#include "models/ode_flow.h"
#include "models/power_spectrum.h"

#define TWO_PI 6.283185307179586476925286766559

static int lorenz_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m, (void)t;
    f[0] = 10 * (x[1] - x[0]);
    f[1] = x[0] * (28 - x[2]) - x[1];
    f[2] = x[0] * x[1] - 8.0 / 3.0 * x[2];
    return 0;
}

/* x' = A x with A upper triangular: exponents -0.5, -1, -3 (t-periodic
 * forcing added along x0 changes none of them). */
static int linear_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)m;
    f[0] = -0.5 * x[0] + 2 * x[1] + x[2] + cos(t);
    f[1] = -1.0 * x[1] + 3 * x[2];
    f[2] = -3.0 * x[2];
    return 0;
}

static int henon_step(const cm_model *m, const double *x, double *y)
{
    (void)m;
    y[0] = 1 - 1.4 * x[0] * x[0] + x[1];
    y[1] = 0.3 * x[0];
    return CM_STEP_OK;
}

static cm_model flow_model(const char *name, int dim,
                           int (*field)(const cm_model *, double, const double *, double *),
                           double period)
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = name;
    m.dim = dim;
    m.flow.field = field;
    m.flow.period = period;
    char msg[256];
    CHECK(cm_flow_attach(&m, msg, sizeof msg) == CM_OK);
    return m;
}

static int traced;
static int count_trace(void *user, double t, const double *lambda, int count)
{
    (void)user, (void)t, (void)lambda, (void)count;
    traced++;
    return 0;
}

static int stop_trace(void *user, double t, const double *lambda, int count)
{
    (void)user, (void)lambda, (void)count;
    return t >= 1;
}

static void test_gram_schmidt(void)
{
    double v[6] = {3, 4, 0, 1, 1, 0}, logs[2];
    CHECK(cm_gram_schmidt(3, 2, v, logs));
    CHECK(fabs(logs[0] - log(5)) < 1e-15);
    CHECK(fabs(v[0] * v[3] + v[1] * v[4] + v[2] * v[5]) < 1e-15);
    CHECK(fabs(hypot(v[3], v[4]) - 1) < 1e-15);
    /* the second's part across the first: (1,1) - 7/25 (3,4) = (-0.16, -0.12) */
    CHECK(fabs(logs[1] - log(0.2)) < 1e-14);
    double flat[6] = {1, 0, 0, 2, 0, 0};
    CHECK(!cm_gram_schmidt(3, 2, flat, logs));
}

static void test_kaplan_yorke(void)
{
    CHECK(fabs(cm_kaplan_yorke((const double[]){0.9056, 0, -14.5723}, 3) - 2.0621) < 1e-4);
    CHECK(cm_kaplan_yorke((const double[]){-0.1, -1}, 2) == 0);
    CHECK(isnan(cm_kaplan_yorke((const double[]){1, 0.5}, 2)));
    CHECK(fabs(cm_kaplan_yorke((const double[]){0.41922, -1.62319}, 2) - 1.25827) < 1e-4);
}

static void test_lorenz(void)
{
    cm_model m = flow_model("lorenz", 3, lorenz_field, 1);
    cm_spectrum s;
    char msg[256];
    const cm_spectrum_options o = {.transient = 20, .time = 2000, .renorm = 0.5};
    traced = 0;
    CHECK(cm_flow_spectrum(&m, (const double[]){1, 1, 20}, &o, count_trace, NULL, &s, msg,
                           sizeof msg) == CM_OK);
    printf("lorenz: %.5f %.5f %.5f (sum %.6f), D_KY %.4f, %d traces\n", s.lambda[0],
           s.lambda[1], s.lambda[2], s.lambda[0] + s.lambda[1] + s.lambda[2], s.kaplan_yorke,
           traced);
    CHECK(s.count == 3 && traced == 4000);
    CHECK(fabs(s.lambda[0] - 0.9056) < 0.02);
    CHECK(fabs(s.lambda[1]) < 0.005);
    CHECK(fabs(s.lambda[2] + 14.5723) < 0.02);
    CHECK(fabs(s.lambda[0] + s.lambda[1] + s.lambda[2] + 10 + 1 + 8.0 / 3.0) < 1e-4);
    CHECK(fabs(s.kaplan_yorke - 2.062) < 0.003);

    /* the largest alone: the first vector does not see the others, but the
     * error control does (the steps, hence the chaotic orbit, differ), so
     * the same number within the estimate's spread */
    cm_spectrum one;
    const cm_spectrum_options o1 = {.count = 1, .transient = 20, .time = 2000, .renorm = 0.5};
    CHECK(cm_flow_spectrum(&m, (const double[]){1, 1, 20}, &o1, NULL, NULL, &one, msg,
                           sizeof msg) == CM_OK);
    CHECK(one.count == 1 && fabs(one.lambda[0] - s.lambda[0]) < 0.02);

    /* an implicit stepper gives the same exponents */
    cm_model imp = flow_model("lorenz", 3, lorenz_field, 1);
    imp.flow.method = CM_FLOW_RK4IMP;
    cm_spectrum si;
    const cm_spectrum_options oi = {.transient = 20, .time = 200, .renorm = 0.5};
    CHECK(cm_flow_spectrum(&imp, (const double[]){1, 1, 20}, &oi, NULL, NULL, &si, msg,
                           sizeof msg) == CM_OK);
    CHECK(fabs(si.lambda[0] + si.lambda[1] + si.lambda[2] + 10 + 1 + 8.0 / 3.0) < 1e-3);
    CHECK(fabs(si.lambda[0] - 0.9056) < 0.1);

    /* bad options and a stop */
    const cm_spectrum_options bad[] = {{.time = 0, .renorm = 1},
                                       {.time = 10, .renorm = 20},
                                       {.time = 10, .renorm = 1, .transient = -1},
                                       {.count = 4, .time = 10, .renorm = 1}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        msg[0] = 0;
        CHECK(cm_flow_spectrum(&m, (const double[]){1, 1, 20}, &bad[i], NULL, NULL, &s, msg,
                               sizeof msg) == CM_EINVAL);
        CHECK(msg[0] != 0);
    }
    CHECK(cm_flow_spectrum(&m, (const double[]){1, 1, 20}, &o, stop_trace, NULL, &s, msg,
                           sizeof msg) == CM_ECANCELED);
    cm_model_release(&m);
    cm_model_release(&imp);
}

static void test_linear(void)
{
    /* the flow, and its stroboscopic map over 2 pi: log moduli 2 pi times the exponents */
    cm_model m = flow_model("linear", 3, linear_field, TWO_PI);
    cm_spectrum s, map;
    char msg[256];
    const cm_spectrum_options o = {.transient = 5, .time = 200, .renorm = 1};
    CHECK(cm_flow_spectrum(&m, (const double[]){1, 2, 3}, &o, NULL, NULL, &s, msg,
                           sizeof msg) == CM_OK);
    printf("linear flow: %.6f %.6f %.6f\n", s.lambda[0], s.lambda[1], s.lambda[2]);
    CHECK(fabs(s.lambda[0] + 0.5) < 0.01 && fabs(s.lambda[1] + 1) < 0.01 &&
          fabs(s.lambda[2] + 3) < 0.01);
    const cm_spectrum_options om = {.iterations = 40, .skip = 2};
    CHECK(cm_map_spectrum(&m, (const double[]){1, 2, 3}, &om, NULL, NULL, &map, msg,
                          sizeof msg) == CM_OK);
    printf("linear map: %.6f %.6f %.6f per period, %.6f time\n", map.lambda[0], map.lambda[1],
           map.lambda[2], map.time);
    CHECK(fabs(map.time - 40 * TWO_PI) < 1e-9);
    CHECK(fabs(map.lambda[0] / (TWO_PI) + 0.5) < 0.01);
    CHECK(fabs(map.lambda[1] / (TWO_PI) + 1) < 0.01);
    /* exp(-3 * 2 pi) = 6.5e-9 is the differences' noise: only its sign and size */
    CHECK(map.lambda[2] / (TWO_PI) < -2);
    cm_model_release(&m);
}

static void test_henon(void)
{
    cm_model m;
    memset(&m, 0, sizeof m);
    m.name = "henon";
    m.dim = 2;
    m.step = henon_step;
    cm_spectrum s;
    char msg[256];
    const cm_spectrum_options o = {.iterations = 200000, .skip = 100};
    CHECK(cm_map_spectrum(&m, (const double[]){0.1, 0.1}, &o, NULL, NULL, &s, msg, sizeof msg) ==
          CM_OK);
    printf("henon: %.5f %.5f, D_KY %.4f\n", s.lambda[0], s.lambda[1], s.kaplan_yorke);
    CHECK(fabs(s.lambda[0] - 0.41922) < 0.003);
    CHECK(fabs(s.lambda[0] + s.lambda[1] - log(0.3)) < 1e-6);
    CHECK(fabs(s.kaplan_yorke - 1.258) < 0.003);
    CHECK(s.time == 0);
    /* a flow's spectrum of a map is refused */
    const cm_spectrum_options flow = {.time = 1, .renorm = 1};
    CHECK(cm_flow_spectrum(&m, (const double[]){0.1, 0.1}, &flow, NULL, NULL, &s, msg,
                           sizeof msg) == CM_EINVAL);
    /* an orbit that escapes is an error with the iterate */
    CHECK(cm_map_spectrum(&m, (const double[]){5, 5}, &o, NULL, NULL, &s, msg, sizeof msg) ==
          CM_EMODEL);
    CHECK(strstr(msg, "iterate") != NULL);
}

/* Two sines on bins of a 4096-sample series and a constant: the two peaks
 * at their frequencies, first the stronger, with A^2/4 each (Hann on a
 * bin), the mean gone; bad input refused. */
static void test_power_spectrum(void)
{
    enum { N = 4096 };
    static double x[N], f[N / 2 + 1], p[N / 2 + 1];
    const double dt = 0.01, f1 = 100.0 / (N * dt), f2 = 700.0 / (N * dt);
    for (int i = 0; i < N; i++)
        x[i] = 5 + 2 * sin(TWO_PI * f1 * i * dt) + 0.5 * cos(TWO_PI * f2 * i * dt);
    char msg[256];
    CHECK(cm_power_spectrum(x, N, dt, f, p, msg, sizeof msg) == CM_OK);
    size_t peaks[4];
    const size_t n = cm_spectrum_peaks(p, N / 2 + 1, 4, peaks);
    printf("spectrum: peaks at %.6g (%.4g) and %.6g (%.4g); f1 %.6g f2 %.6g; p[0] %.3g\n",
           f[peaks[0]], p[peaks[0]], f[peaks[1]], p[peaks[1]], f1, f2, p[0]);
    CHECK(n >= 2);
    CHECK(peaks[0] == 100 && peaks[1] == 700);
    CHECK(fabs(f[peaks[0]] - f1) < 1e-12 && fabs(f[peaks[1]] - f2) < 1e-12);
    /* the window's sum differs from N/2 by 1/(N-1) of it */
    CHECK(fabs(p[peaks[0]] - 1.0) < 2e-3 && fabs(p[peaks[1]] - 0.0625) < 2e-4);
    CHECK(p[0] < 1e-6);
    x[7] = NAN;
    CHECK(cm_power_spectrum(x, N, dt, f, p, msg, sizeof msg) == CM_EINVAL);
    CHECK(cm_power_spectrum(x, 3, dt, f, p, msg, sizeof msg) == CM_EINVAL);
}

int main(void)
{
    test_power_spectrum();
    test_gram_schmidt();
    test_kaplan_yorke();
    test_lorenz();
    test_linear();
    test_henon();
    CHECK_DONE();
}
