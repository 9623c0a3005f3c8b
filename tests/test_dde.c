/* Delay differential equations (models/dde): the method of steps against
 * x'(t) = -x(t - 1) with x = 1 before 0, whose solution is the
 * polynomial sum_k (-1)^k (t - k + 1)^k / k! over t >= k - 1 exactly;
 * bad requests; the synchronisation estimate against a linear equation
 * whose threshold is known exactly; and the built-up-edge model
 * chip-bue (thesis 3.4): the start-up segment, the H = 0 equilibrium it
 * settles to, the H = 0.1 bursts, and its sensitivity to the start. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "models/chip_formation.h"
#include "models/dde_lyapunov.h"

static int lag_field(const void *ctx, double t, const double *x, const double *xd, double *f)
{
    (void)ctx, (void)t, (void)x;
    f[0] = -xd[0];
    return 0;
}

static void one_before(const void *ctx, double t, double *x)
{
    (void)ctx, (void)t;
    x[0] = 1;
}

static double exact(double t)
{
    double sum = 0, fact = 1;
    for (int k = 0; t >= k - 1; k++) {
        if (k)
            fact *= k;
        sum += (k % 2 ? -1 : 1) * pow(t - k + 1, k) / fact;
    }
    return sum;
}

typedef struct worst {
    double err;
    int samples;
} worst;

static int compare(void *user, double t, const double *x)
{
    worst *w = user;
    w->err = fmax(w->err, fabs(x[0] - exact(t)));
    w->samples++;
    return 0;
}

static void test_exact(void)
{
    for (int method = CM_FLOW_RK8PD; method <= CM_FLOW_RKCK; method++) {
        cm_dde d = {.dim = 1, .delay = 1, .field = lag_field, .history = one_before,
                    .method = method, .abs_tol = 1e-11, .rel_tol = 1e-11};
        worst w = {0, 0};
        double x1;
        char msg[256];
        CHECK(cm_dde_solve(&d, 0, 10, 0.05, compare, &w, &x1, msg, sizeof msg) == CM_OK);
        printf("x' = -x(t-1), method %d: largest error %.3g over %d samples; x(10) = %.15g "
               "(exact %.15g)\n",
               method, w.err, w.samples, x1, exact(10));
        /* samples every 0.05 make every step at most 0.05 long, and the
         * continuous extension (cubic Hermite) errs by at most h^4/384
         * max|x''''| = 1.6e-8 with |x''''| <= 1 here: halving the sample
         * interval must cut the error about 16-fold (fourth order) */
        worst finer = {0, 0};
        CHECK(cm_dde_solve(&d, 0, 10, 0.025, compare, &finer, NULL, msg, sizeof msg) == CM_OK);
        printf("  with samples every 0.025: %.3g (%.1f times smaller)\n", finer.err,
               w.err / finer.err);
        CHECK(w.samples == 201);
        CHECK(w.err < 1.6e-8);
        CHECK(w.err / finer.err > 10);
        CHECK(fabs(exact(1) - 0) < 1e-15 && fabs(exact(2) + 0.5) < 1e-15);
    }
}

static int stop_at_one(void *user, double t, const double *x)
{
    (void)user, (void)x;
    return t >= 1;
}

static void test_bad(void)
{
    cm_dde d = {.dim = 1, .delay = 0, .field = lag_field, .history = one_before};
    char msg[256] = "";
    CHECK(cm_dde_solve(&d, 0, 10, 0.1, NULL, NULL, NULL, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "delay > 0") != NULL);
    d.delay = -1;
    CHECK(cm_dde_solve(&d, 0, 10, 0.1, NULL, NULL, NULL, msg, sizeof msg) == CM_EINVAL);
    d.delay = 1;
    CHECK(cm_dde_solve(&d, 5, 1, 0.1, NULL, NULL, NULL, msg, sizeof msg) == CM_EINVAL);
    d.method = CM_FLOW_MSBDF;
    CHECK(cm_dde_solve(&d, 0, 1, 0.1, NULL, NULL, NULL, msg, sizeof msg) == CM_EINVAL);
    d.method = CM_FLOW_RK8PD;
    CHECK(cm_dde_solve(&d, 0, 10, 0.1, stop_at_one, NULL, NULL, msg, sizeof msg) ==
          CM_ECANCELED);
}

/* x' = a x + b x(t - 1): the copies' difference obeys e' = (a - q) e
 * whatever x does, so they synchronise exactly for q > a. */
static int linear_field(const void *ctx, double t, const double *x, const double *xd, double *f)
{
    (void)t;
    const double *ab = ctx;
    f[0] = ab[0] * x[0] + ab[1] * xd[0];
    return 0;
}

static void test_sync(void)
{
    const double ab[2] = {0.5, -1}; /* a stable equation: x stays small */
    cm_dde d = {.dim = 1, .delay = 1, .field = linear_field, .history = one_before, .ctx = ab};
    const cm_sync_options o = {.t0 = 0, .t1 = 100, .offset = 1e-3, .lo = 0, .hi = 5,
                               .q_tol = 1e-3};
    double q;
    char msg[256];
    CHECK(cm_dde_sync_estimate(&d, &o, &q, msg, sizeof msg) == CM_OK);
    /* |e| = 1e-3 exp((a - q) t) is below 1e-3 x 1e-3 from t = 90 on (the
     * last tenth) exactly when q > a + ln(1000)/90 */
    printf("linear sync threshold %.5f (exact 0.5 + ln(1000)/90 = %.5f)\n", q,
           0.5 + log(1000) / 90);
    CHECK(fabs(q - (0.5 + log(1000) / 90)) < 2e-3);
    const cm_sync_options high = {.t0 = 0, .t1 = 100, .offset = 1e-3, .lo = 1, .hi = 5,
                                  .q_tol = 1e-3};
    CHECK(cm_dde_sync_estimate(&d, &high, &q, msg, sizeof msg) == CM_ERANGE);
}

/* Farmer's map of x' = a x + b x(t - 1), a = -2, b = 1: the exponents are
 * the real parts of the characteristic roots of mu = a + b exp(-mu), the
 * rightmost real (mu = -0.44285...); the discretised map's largest
 * converges to it at second order in the sample spacing. */
static void test_farmer(void)
{
    const double ab[2] = {-2, 1};
    cm_dde d = {.dim = 1, .delay = 1, .field = linear_field, .history = one_before, .ctx = ab,
                .abs_tol = 1e-12, .rel_tol = 1e-12};
    double mu = -0.4;
    for (int i = 0; i < 50; i++) /* Newton on mu - a - b exp(-mu) */
        mu -= (mu - ab[0] - ab[1] * exp(-mu)) / (1 + ab[1] * exp(-mu));
    double err[2];
    char msg[256];
    for (int k = 0; k < 2; k++) {
        const cm_farmer_options o = {.samples = 10 << k, .gs = 5, .count = 3, .transient = 12,
                                     .time = 40};
        cm_farmer_result r;
        CHECK(cm_dde_farmer(&d, &o, NULL, NULL, &r, msg, sizeof msg) == CM_OK);
        err[k] = fabs(r.lambda[0] - mu);
        printf("farmer N = %d: %.6f %.6f %.6f (root %.6f), %ld coordinates\n", o.samples,
               r.lambda[0], r.lambda[1], r.lambda[2], mu, r.dim);
        CHECK(r.dim == o.samples + 1 && r.count == 3);
        CHECK(r.lambda[0] >= r.lambda[1] && r.lambda[1] >= r.lambda[2]);
    }
    CHECK(err[1] < 2e-3);
    CHECK(err[0] / err[1] > 3); /* second order: about 4 */
    const cm_farmer_options bad[] = {
        {.samples = 0, .gs = 1, .count = 1, .transient = 2, .time = 1},
        {.samples = 10, .gs = 1, .count = 20, .transient = 2, .time = 1},
        {.samples = 10, .gs = 1, .count = 1, .transient = 0.5, .time = 1}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cm_farmer_result r;
        CHECK(cm_dde_farmer(&d, &bad[i], NULL, NULL, &r, msg, sizeof msg) == CM_EINVAL);
    }
}

static int keep(void *user, double t, const double *x)
{
    (void)t;
    memcpy(user, x, 4 * sizeof *x);
    return 0;
}

typedef struct extremes {
    double tau_max, T_max, gamma_max;
} extremes;

static int extreme(void *user, double t, const double *x)
{
    (void)t;
    extremes *e = user;
    e->gamma_max = fmax(e->gamma_max, x[2]);
    e->T_max = fmax(e->T_max, x[1]);
    e->tau_max = fmax(e->tau_max, x[3]);
    return 0;
}

static void test_chip_bue(void)
{
    cm_chip_bue c = cm_chip_bue_defaults();
    cm_dde d;
    char msg[256];
    double x[4];
    /* the start-up: only tau moves until dt */
    c.H = 0;
    cm_chip_bue_dde(&c, &d);
    CHECK(cm_dde_solve(&d, 0, 0.39, 0.39, NULL, NULL, x, msg, sizeof msg) == CM_OK);
    CHECK(x[0] == 0 && x[1] == 0 && x[2] == 0 && x[3] > 0.3);
    /* H = 0: settled by t = 10 where F = 1 (tau' = 0), T0' = 0 and T' = 0 */
    CHECK(cm_dde_solve(&d, 0, 10, 10, keep, x, NULL, msg, sizeof msg) == CM_OK);
    const double F = cm_chip_bue_rate(&c, x[1], x[3], x[2]);
    printf("chip-bue H = 0 at t = 10: T0 %.6f T %.6f gamma %.6f tau %.6f, F %.8f\n", x[0], x[1],
           x[2], x[3], F);
    /* F is 64 times as sensitive as tau (1/(b (T + 1))): 2e-4 in F is 3e-6 in tau */
    CHECK(fabs(F - 1) < 5e-4);
    CHECK(fabs(c.zeta * (x[1] - 2 * x[0]) - x[0] / c.dt) < 1e-3);
    CHECK(fabs(c.eta * x[3] * F - c.zeta * (x[1] - x[0]) - (x[1] - x[0]) / c.dt) < 1e-3);
    CHECK(fabs(x[2] - 1) < 1e-3);
    /* but the equilibrium is unstable: the start-up's remnant grows from
     * t = 16 into an oscillation (about tenfold per 4 time units), the
     * same whatever the tolerance (1e-7 .. 1e-13) and in an independent
     * fixed-step Heun method of steps (h = 1e-4): tau = 1.27285 at t = 28
     * and 1.28816 at t = 32 there */
    CHECK(cm_dde_solve(&d, 0, 32, 4, keep, x, NULL, msg, sizeof msg) == CM_OK);
    printf("chip-bue H = 0 at t = 32: tau %.6f (Heun: 1.28816)\n", x[3]);
    CHECK(fabs(x[3] - 1.28816) < 1e-3);

    /* H = 0.1: bursts whose strain far exceeds the equilibrium's, and two
     * starts 1e-9 apart in tau's rate part ways (chaos) */
    c.H = 0.1;
    extremes e = {0, 0, 0};
    CHECK(cm_dde_solve(&d, 0, 300, 0.01, extreme, &e, x, msg, sizeof msg) == CM_OK);
    printf("chip-bue H = 0.1 up to t = 300: T up to %.3f, gamma up to %.3f, tau up to %.3f\n",
           e.T_max, e.gamma_max, e.tau_max);
    CHECK(e.T_max > 1 && e.gamma_max > 1.5);
    cm_chip_bue c2 = c;
    c2.eta = c.eta * (1 + 1e-9);
    cm_dde d2;
    cm_chip_bue_dde(&c2, &d2);
    double y[4];
    CHECK(cm_dde_solve(&d2, 0, 300, 300, NULL, NULL, y, msg, sizeof msg) == CM_OK);
    double apart = 0;
    for (int i = 0; i < 4; i++)
        apart = fmax(apart, fabs(x[i] - y[i]));
    printf("chip-bue H = 0.1: eta changed by 1e-9 puts the state %.3g apart at t = 300\n", apart);
    CHECK(apart > 1e-3);
}

int main(void)
{
    test_exact();
    test_bad();
    test_sync();
    test_farmer();
    test_chip_bue();
    CHECK_DONE();
}
