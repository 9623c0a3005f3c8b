/* Equilibria of flows and their branches (models/flow_equilibria): the
 * Hopf normal form (Hopf at mu = 0, omega = 1), a saddle-node (fold at
 * mu = 0), and Palmai's chip formation flow (thesis (3.27)-(3.31), Sec.
 * 3.2; the model chip-4d's flow) against the thesis and an independent
 * implementation: at zeta = 21 its equilibrium loses and regains stability
 * in Hopf points at xi = 4.428083 and 11.803875 (thesis: 4.42808,
 * 11.8039) with eigenvalues +-28.00i and +-34.33i; at xi = 4.8, zeta = 40
 * its eigenvalues are -6.23 +- 30.14i, -35.9 and -123.3. Each located
 * point is checked again on its own: its residual, and the real part of
 * the pair on the axis recomputed at it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "models/flow_equilibria.h"
#include "models/ode_flow.h"
#include "models/registry.h"

/* ---- the flows ---------------------------------------------------------- */

/* x' = mu x - y - x r^2, y' = x + mu y - y r^2: Hopf at mu = 0. */
static int hopf_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)t;
    const double mu = *(const double *)m->ctx, r2 = x[0] * x[0] + x[1] * x[1];
    f[0] = mu * x[0] - x[1] - x[0] * r2;
    f[1] = x[0] + mu * x[1] - x[1] * r2;
    return 0;
}

/* x' = mu - x^2, y' = -y: a fold at mu = 0. */
static int fold_field(const cm_model *m, double t, const double *x, double *f)
{
    (void)t;
    const double mu = *(const double *)m->ctx;
    f[0] = mu - x[0] * x[0];
    f[1] = -x[1];
    return 0;
}

/* A model of field with its context copied (freed by cm_model_release). */
static cm_status model_of(const char *name, int dim,
                          int (*field)(const cm_model *, double, const double *, double *),
                          const void *ctx, size_t size, cm_model *m)
{
    memset(m, 0, sizeof *m);
    m->name = name;
    m->dim = dim;
    m->ctx = malloc(size);
    if (!m->ctx)
        return CM_ENOMEM;
    memcpy(m->ctx, ctx, size);
    m->destroy = free;
    m->flow.field = field;
    return CM_OK;
}

static cm_status hopf_at(void *user, double mu, cm_model *m, char *msg, size_t msg_size)
{
    (void)user, (void)msg, (void)msg_size;
    return model_of("hopf", 2, hopf_field, &mu, sizeof mu, m);
}

static cm_status fold_at(void *user, double mu, cm_model *m, char *msg, size_t msg_size)
{
    (void)user, (void)msg, (void)msg_size;
    return model_of("fold", 2, fold_field, &mu, sizeof mu, m);
}

/* The chip flow (model chip-4d, its flow in (tau2, T0, T1, T2)) at xi
 * (user: zeta). */
static cm_status chip_at(void *user, double xi, cm_model *m, char *msg, size_t msg_size)
{
    char text[96];
    snprintf(text, sizeof text, "xi=%.17g,zeta=%.17g", xi, *(const double *)user);
    const char *texts[] = {text};
    return cm_model_create("chip-4d", texts, 1, m, msg, msg_size);
}

/* ---- what a branch reports ---------------------------------------------- */

typedef struct seen {
    cm_eq_event ev[8];
    int n_events, points;
    double p_min, p_max;
} seen;

static int on_point(void *user, const cm_equilibrium *e)
{
    seen *s = user;
    s->p_min = s->points ? fmin(s->p_min, e->p) : e->p;
    s->p_max = s->points ? fmax(s->p_max, e->p) : e->p;
    s->points++;
    return 0;
}

static int on_event(void *user, const cm_eq_event *ev)
{
    seen *s = user;
    if (s->n_events < 8)
        s->ev[s->n_events] = *ev;
    s->n_events++;
    return 0;
}

/* The event checked on its own: the model at its p, its state an
 * equilibrium (residual), and for a Hopf point a pair with |re| tiny. */
static void check_independently(cm_model_at_fn at, void *user, const cm_eq_event *ev)
{
    cm_model m;
    char msg[256];
    CHECK(at(user, ev->at.p, &m, msg, sizeof msg) == CM_OK);
    double f[CM_MAX_DIM], J[CM_MAX_DIM * CM_MAX_DIM], re[CM_MAX_DIM], im[CM_MAX_DIM];
    CHECK(m.flow.field(&m, 0, ev->at.x, f) == 0);
    const int n = cm_flow_dim(&m);
    for (int i = 0; i < n; i++)
        CHECK(fabs(f[i]) < 1e-8);
    CHECK(cm_flow_jacobian(&m, ev->at.x, J) == CM_OK);
    CHECK(cm_eigenvalues(n, J, re, im) == CM_OK);
    double nearest = INFINITY;
    for (int i = 0; i < n; i++)
        if (ev->kind == CM_EQ_HOPF ? im[i] != 0 : im[i] == 0)
            nearest = fmin(nearest, fabs(re[i]));
    CHECK(nearest < 1e-6 * (1 + fabs(re[n - 1])));
    cm_model_release(&m);
}

static void test_hopf_normal_form(void)
{
    const double x0[2] = {0, 0};
    const cm_branch_options o = {.lo = -1, .hi = 1, .direction = 1};
    seen s = {0};
    int why = 0;
    char msg[256];
    CHECK(cm_flow_equilibrium_branch(hopf_at, NULL, -0.9, x0, &o, on_point, on_event, &s, &why,
                                     msg, sizeof msg) == CM_OK);
    CHECK_INT(why, CM_BRANCH_LEFT_RANGE);
    CHECK_INT(s.n_events, 1);
    CHECK_INT(s.ev[0].kind, CM_EQ_HOPF);
    CHECK(fabs(s.ev[0].at.p) < 1e-9);
    CHECK_NEAR(s.ev[0].omega, 1, 1e-7);
    CHECK(s.p_max > 0.95 && s.points > 10);
    check_independently(hopf_at, NULL, &s.ev[0]);
}

static void test_fold(void)
{
    /* from x = 1 at mu = 1 down to the fold at mu = 0, x = 0, and back up
     * on the other side, x = -sqrt(mu) */
    const double x0[2] = {1.2, 0.3};
    const cm_branch_options o = {.lo = -0.5, .hi = 1, .direction = -1};
    seen s = {0};
    int why = 0;
    char msg[256];
    CHECK(cm_flow_equilibrium_branch(fold_at, NULL, 1, x0, &o, on_point, on_event, &s, &why,
                                     msg, sizeof msg) == CM_OK);
    CHECK_INT(why, CM_BRANCH_LEFT_RANGE);
    CHECK_INT(s.n_events, 1);
    CHECK_INT(s.ev[0].kind, CM_EQ_FOLD);
    CHECK(fabs(s.ev[0].at.p) < 1e-9 && fabs(s.ev[0].at.x[0]) < 1e-4);
    CHECK(s.p_min > -1e-6); /* the fold turned the branch back */
    check_independently(fold_at, NULL, &s.ev[0]);
}

static void test_chip_equilibrium(void)
{
    double zeta = 40, z[4] = {1, 0.1, 0.3, 0.4};
    cm_model m;
    cm_equilibrium e;
    char msg[256];
    CHECK(chip_at(&zeta, 4.8, &m, msg, sizeof msg) == CM_OK);
    CHECK(cm_flow_equilibrium(&m, 4.8, z, &e, msg, sizeof msg) == CM_OK);
    cm_model_release(&m);
    /* -6.23 +- 30.14i, -35.9, -123.3 (the thesis' point a of Fig. 3.8) */
    CHECK_NEAR(e.re[0], -6.23, 2e-3);
    CHECK_NEAR(e.im[0], 30.14, 2e-3);
    CHECK_NEAR(e.re[1], -6.23, 2e-3);
    CHECK_NEAR(e.re[2], -35.9, 2e-3);
    CHECK_NEAR(e.re[3], -123.3, 2e-3);
    CHECK_INT(e.unstable, 0);
}

static void test_chip_hopf_points(void)
{
    double zeta = 21, z[4] = {1, 0.1, 0.3, 0.4};
    cm_model m;
    char msg[256];
    CHECK(chip_at(&zeta, 1, &m, msg, sizeof msg) == CM_OK);
    CHECK(cm_flow_equilibrium(&m, 1, z, NULL, msg, sizeof msg) == CM_OK);
    cm_model_release(&m);
    const cm_branch_options o = {.lo = 0.5, .hi = 15, .direction = 1};
    seen s = {0};
    int why = 0;
    CHECK(cm_flow_equilibrium_branch(chip_at, &zeta, 1, z, &o, on_point, on_event, &s, &why, msg,
                                     sizeof msg) == CM_OK);
    CHECK_INT(why, CM_BRANCH_LEFT_RANGE);
    CHECK_INT(s.n_events, 2);
    CHECK_INT(s.ev[0].kind, CM_EQ_HOPF);
    CHECK_INT(s.ev[1].kind, CM_EQ_HOPF);
    /* the thesis' 4.42808 and 11.8039 (+- 1e-4); independently 4.428083, 11.803875 */
    CHECK(fabs(s.ev[0].at.p - 4.428083) < 2e-5);
    CHECK(fabs(s.ev[1].at.p - 11.803875) < 2e-5);
    CHECK_NEAR(s.ev[0].omega, 28.00, 5e-4);
    CHECK_NEAR(s.ev[1].omega, 34.33, 5e-4);
    /* unstable between them: two eigenvalues with re > 0 */
    CHECK_INT(s.ev[0].at.unstable + s.ev[1].at.unstable >= 2, 1);
    printf("chip-4d, zeta = 21: Hopf points at xi = %.7f (omega %.4f) and %.7f (omega %.4f), "
           "%d branch points\n",
           s.ev[0].at.p, s.ev[0].omega, s.ev[1].at.p, s.ev[1].omega, s.points);
    for (int k = 0; k < 2; k++)
        check_independently(chip_at, &zeta, &s.ev[k]);
}

/* x' = (mu - nu) x - y - x r^2, ...: the Hopf curve mu = nu. */
static cm_status hopf2_at(void *user, double mu, double nu, cm_model *m, char *msg,
                          size_t msg_size)
{
    (void)user, (void)msg, (void)msg_size;
    const double shifted = mu - nu;
    return model_of("hopf", 2, hopf_field, &shifted, sizeof shifted, m);
}

static cm_status chip2_at(void *user, double xi, double zeta, cm_model *m, char *msg,
                          size_t msg_size)
{
    (void)user;
    return chip_at(&zeta, xi, m, msg, msg_size);
}

typedef struct curve {
    double q[16], p[16];
    int n;
} curve;

static int on_hopf(void *user, double q, const cm_eq_event *ev)
{
    curve *c = user;
    if (c->n < 16)
        c->q[c->n] = q, c->p[c->n] = ev->at.p;
    c->n++;
    return 0;
}

static void test_hopf_curves(void)
{
    const double nu[] = {-0.5, 0, 0.3}, x0[2] = {0, 0};
    const cm_branch_options o = {.lo = -1, .hi = 1, .direction = 1};
    curve c = {0};
    char msg[256];
    CHECK(cm_flow_hopf_curve(hopf2_at, NULL, -0.9, x0, nu, 3, &o, on_hopf, &c, msg,
                             sizeof msg) == CM_OK);
    CHECK_INT(c.n, 3);
    for (int k = 0; k < 3 && k < c.n; k++)
        CHECK(c.q[k] == nu[k] && fabs(c.p[k] - nu[k]) < 1e-9);
    /* the chip flow's curve through zeta = 21 meets the branch's points
     * there; the oscillating range of xi narrows as zeta grows (it closes
     * between 21 and 22: no Hopf point on [0.5, 15] at 22) */
    const double zeta[] = {20, 20.5, 21};
    double z[4] = {1, 0.1, 0.3, 0.4};
    const cm_branch_options oc = {.lo = 0.5, .hi = 15, .direction = 1};
    curve cc = {0};
    CHECK(cm_flow_hopf_curve(chip2_at, NULL, 1, z, zeta, 3, &oc, on_hopf, &cc, msg,
                             sizeof msg) == CM_OK);
    CHECK_INT(cc.n, 6);
    CHECK(cc.n == 6 && cc.q[4] == 21 && fabs(cc.p[4] - 4.428083) < 2e-5 &&
          fabs(cc.p[5] - 11.803875) < 2e-5);
    CHECK(cc.p[0] < cc.p[2] && cc.p[2] < cc.p[4] && cc.p[5] < cc.p[3] && cc.p[3] < cc.p[1]);
    printf("chip-4d Hopf curve: zeta = 20: xi = %.6f, %.6f; 20.5: %.6f, %.6f; 21: %.6f, %.6f\n",
           cc.p[0], cc.p[1], cc.p[2], cc.p[3], cc.p[4], cc.p[5]);
    const double beyond[] = {22};
    curve none = {0};
    CHECK(cm_flow_hopf_curve(chip2_at, NULL, 1, z, beyond, 1, &oc, on_hopf, &none, msg,
                             sizeof msg) == CM_OK);
    CHECK_INT(none.n, 0);
}

static void test_bad_input(void)
{
    /* Newton from far away on the fold's flow at mu < 0 (no equilibrium) */
    cm_model m;
    char msg[256] = "";
    double x[2] = {3, 1};
    CHECK(fold_at(NULL, -1, &m, msg, sizeof msg) == CM_OK);
    CHECK(cm_flow_equilibrium(&m, -1, x, NULL, msg, sizeof msg) == CM_ENOTFOUND);
    CHECK(strstr(msg, "start nearer one") != NULL);
    cm_model_release(&m);
    const cm_branch_options bad = {.lo = 1, .hi = 0, .direction = 1};
    int why;
    CHECK(cm_flow_equilibrium_branch(fold_at, NULL, 0.5, x, &bad, NULL, NULL, NULL, &why, msg,
                                     sizeof msg) == CM_EINVAL);
}

int main(void)
{
    test_hopf_normal_form();
    test_fold();
    test_chip_equilibrium();
    test_chip_hopf_points();
    test_hopf_curves();
    test_bad_input();
    return check_failures;
}
