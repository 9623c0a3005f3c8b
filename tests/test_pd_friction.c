/* Tests of the hybrid micro-chaos map with dry friction (docs/models.md 8):
 * without friction it is the PD map (4.66); with friction it agrees with an
 * independent fine-step integration of the equation of motion, written
 * here (RK4 with a bisected velocity zero and the stick/slide rule of 8.1),
 * on random states that slide, stick, reverse and graze. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "check.h"
#include "mix.h"
#include "models/microchaos_pd_friction.h"
#include "models/registry.h"

typedef struct params {
    double alpha, beta, P, D, mu, mu_s;
} params;

/* Fig. 4.30, and the C-SCM example (4.6.3) with damping and a static
 * coefficient above the kinetic one: many events per sampling interval. */
static const params fig430 = {6.53e-3, 0, 5.5e-5, 2.5e-3, 0.095, 0.095};
static const params damped = {0.078, 0.05, 0.007, 0.02, 0.3, 0.45};

static double uniform(uint64_t *seed, double lo, double hi)
{
    *seed = mix(*seed + 1);
    return lo + (hi - lo) * (double)(*seed >> 11) * 0x1.0p-53;
}

/* ---- the reference: RK4 on x'' = alpha^2 x - 2 beta x' - m - mu sgn(x') ---- */

typedef struct ode {
    params p;
    double m, sigma; /* control level of the interval; sliding direction */
} ode;

static void rk4(const ode *o, double h, double *x, double *v)
{
    const double a2 = o->p.alpha * o->p.alpha, f = -o->m - o->p.mu * o->sigma;
#define ACC(X, V) (a2 * (X)-2 * o->p.beta * (V) + f)
    const double k1x = *v, k1v = ACC(*x, *v);
    const double k2x = *v + 0.5 * h * k1v, k2v = ACC(*x + 0.5 * h * k1x, *v + 0.5 * h * k1v);
    const double k3x = *v + 0.5 * h * k2v, k3v = ACC(*x + 0.5 * h * k2x, *v + 0.5 * h * k2v);
    const double k4x = *v + h * k3v, k4v = ACC(*x + h * k3x, *v + h * k3v);
#undef ACC
    *x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    *v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
}

/* At rest at (x, 0): stays (returns 1) or picks the sliding direction. */
static int holds(ode *o, double x)
{
    const double F = o->p.alpha * o->p.alpha * x - o->m;
    if (fabs(F) <= o->p.mu_s)
        return 1;
    o->sigma = F > 0 ? 1 : -1;
    return 0;
}

enum { SUBSTEPS = 512 };

typedef struct reference {
    double x, v;
    int events; /* velocity zeros met */
    int stuck;
} reference;

/* One sampling interval from (x, v), integrated in SUBSTEPS steps; a step
 * in which the velocity changes sign is cut at its zero (bisection on the
 * step length) and the friction rule decides there. */
static reference integrate(const params *p, double x, double v)
{
    ode o = {*p, 0, 0};
    double level;
    reference r = {x, v, 0, 0};
    if (!cm_int_part(p->P * x + p->D * v, &level))
        return r;
    o.m = level;
    const double h = 1.0 / SUBSTEPS;
    if (v == 0 && holds(&o, x)) {
        r.stuck = 1;
        return r;
    }
    if (v != 0)
        o.sigma = v > 0 ? 1 : -1;
    double t = 0;
    while (t < 1 && !r.stuck) {
        const double step = fmin(h, 1 - t);
        double x1 = x, v1 = v;
        rk4(&o, step, &x1, &v1);
        if (v1 * o.sigma > 0) {
            x = x1, v = v1, t += step;
            continue;
        }
        double lo = 0, hi = step; /* v keeps sigma's sign at lo, not at hi */
        for (int it = 0; it < 200 && hi - lo > 1e-17; it++) {
            const double mid = 0.5 * (lo + hi);
            double xm = x, vm = v;
            rk4(&o, mid, &xm, &vm);
            if (vm * o.sigma > 0)
                lo = mid;
            else
                hi = mid;
        }
        rk4(&o, hi, &x, &v);
        v = 0;
        t += hi;
        r.events++;
        r.stuck = holds(&o, x);
    }
    r.x = x;
    r.v = v;
    return r;
}

/* ---- checks ---- */

static cm_pdf_coef coef(const params *p)
{
    cm_pdf_coef c;
    cm_pdf_coefficients(p->alpha, p->beta, p->P, p->D, p->mu, p->mu_s, &c);
    return c;
}

/* Difference of two states relative to the state's size, velocities
 * measured in the natural unit gamma (the map's rate) so that neither
 * coordinate hides the other's error. */
static double state_error(const cm_pdf_coef *c, double x, double v, double rx, double rv)
{
    const double dx = fabs(x - rx), dv = fabs(v - rv) / c->gamma;
    const double size = fmax(fmax(fabs(rx), fabs(rv) / c->gamma), 1.0);
    return fmax(dx, dv) / size;
}

/* mu = 0: the map is (4.66), and the event path (a velocity zero splits
 * the interval) changes nothing beyond rounding. */
static void test_frictionless_equals_pd(void)
{
    const params p = {6.53e-3, 0, 5.5e-5, 2.5e-3, 0, 0};
    const cm_pdf_coef c = coef(&p);
    cm_model pd;
    char msg[256];
    const char *text = "alpha=6.53e-3,beta=0,P=5.5e-5,D=2.5e-3";
    CHECK(cm_model_create("microchaos-pd", &text, 1, &pd, msg, sizeof msg) == CM_OK);
    uint64_t seed = 1;
    double worst = 0;
    long zeros = 0;
    for (int k = 0; k < 1000000; k++) {
        const double x[2] = {uniform(&seed, -1.2e5, 1.2e5),
                             k % 2 ? uniform(&seed, -600, 600) : uniform(&seed, -3, 3)};
        double y[2];
        cm_pdf_result r;
        CHECK(pd.step(&pd, x, y) == CM_STEP_OK);
        CHECK(cm_pdf_step(&c, x[0], x[1], &r));
        zeros += r.event == CM_PDF_REVERSE;
        worst = fmax(worst, state_error(&c, r.x, r.v, y[0], y[1]));
    }
    printf("mu = 0 vs microchaos-pd: 1e6 states, %ld with a velocity zero, worst relative "
           "difference %.3g\n",
           zeros, worst);
    CHECK(worst <= 1e-14);
    CHECK(zeros > 10000); /* the split path is exercised */
    cm_model_release(&pd);
}

/* The map against the reference on random states; counts what happened. */
static void compare_random(const params *p, double xmax, double vmax, int n)
{
    const cm_pdf_coef c = coef(p);
    uint64_t seed = 7;
    long kinds[4] = {0}, other_events = 0;
    double worst = 0;
    for (int k = 0; k < n; k++) {
        const double x = uniform(&seed, -xmax, xmax);
        const double v = k % 10 == 0 ? 0 : uniform(&seed, -vmax, vmax);
        cm_pdf_result r;
        if (!cm_pdf_step(&c, x, v, &r))
            r.event = -1;
        const reference ref = integrate(p, x, v);
        if (r.event < 0 || ref.events != (r.event == CM_PDF_STICK || r.event == CM_PDF_REVERSE) ||
            ref.stuck != (r.event == CM_PDF_STICK || r.event == CM_PDF_STUCK_WHOLE)) {
            other_events++;
            continue;
        }
        kinds[r.event]++;
        worst = fmax(worst, state_error(&c, r.x, r.v, ref.x, ref.v));
    }
    printf("alpha %g beta %g mu %g mu_s %g: %d states (%ld slide, %ld stay stuck, %ld stick, "
           "%ld reverse), worst relative difference from RK4 %.3g\n",
           p->alpha, p->beta, p->mu, p->mu_s, n, kinds[CM_PDF_NONE], kinds[CM_PDF_STUCK_WHOLE],
           kinds[CM_PDF_STICK], kinds[CM_PDF_REVERSE], worst);
    CHECK_INT(other_events, 0); /* states where the events differ from the reference's */
    CHECK(worst <= 1e-9);
    for (int kind = 0; kind < 4; kind++)
        CHECK(kinds[kind] >= n / 1000);
}

/* A state whose velocity reaches zero at local time `at` while sliding
 * (docs/models.md 8.2 solved for v0), or 0 if none is consistent with its band. */
static int state_with_zero_at(const cm_pdf_coef *c, double x, double sigma, double at, double *v)
{
    const double th = tanh(c->gamma * at);
    for (int it = 0; it < 4; it++) {
        double level;
        if (!cm_int_part(c->P * x + c->D * *v, &level))
            return 0;
        const double xi = x - (level + c->mu * sigma) / c->alpha2;
        *v = th * c->alpha2 * xi / (c->beta * th - c->gamma);
    }
    double level;
    const double q = (cm_int_part(c->P * x + c->D * *v, &level) ? level : 0) + c->mu * sigma;
    const double xi = x - q / c->alpha2;
    return *v * sigma > 0 && fabs(*v * (c->beta * th - c->gamma) - th * c->alpha2 * xi) <=
                                 1e-12 * fabs(*v * c->gamma);
}

/* Grazing: the velocity zero at the very end of the interval, or just
 * before it; the map and the reference agree, and a zero at the sample
 * leaves the block at rest there. */
static void test_grazing(const params *p)
{
    const cm_pdf_coef c = coef(p);
    uint64_t seed = 11;
    int tried = 0, at_end = 0, wrong_time = 0;
    double worst = 0;
    for (int k = 0; k < 4000; k++) {
        const double at = k % 2 ? 1.0 : 1.0 - uniform(&seed, 0, 1e-6);
        const double x = uniform(&seed, -5 / p->P, 5 / p->P);
        double v = x > 0 ? -1 : 1;
        if (!state_with_zero_at(&c, x, v > 0 ? 1 : -1, at, &v))
            continue;
        cm_pdf_result r;
        CHECK(cm_pdf_step(&c, x, v, &r));
        const reference ref = integrate(p, x, v);
        tried++;
        /* a zero at the sample may round just past it: no event, v ~ 0 */
        wrong_time += r.event == CM_PDF_NONE ? !(at == 1 && fabs(r.v) <= 1e-9 * fabs(v))
                                             : !(fabs(r.event_time - at) <= 1e-9);
        if (r.event && r.event_time == 1) {
            at_end++;
            wrong_time += r.v != 0;
        }
        worst = fmax(worst, state_error(&c, r.x, r.v, ref.x, ref.v));
    }
    printf("grazing: %d states (%d with the zero exactly at the sample), worst relative "
           "difference from RK4 %.3g\n",
           tried, at_end, worst);
    CHECK(tried >= 1000);
    CHECK(at_end >= 100);
    CHECK_INT(wrong_time, 0);
    CHECK(worst <= 1e-9);
}

/* Sticking fixed points: the rest states held by static friction, on the
 * zones of docs/models.md 8.3; the fixed points x_m* lie inside them. */
static void test_sticking_zones(void)
{
    const cm_pdf_coef c = coef(&fig430);
    for (int64_t m = -4; m <= 4; m++) {
        double lo, hi;
        /* x_4* is virtual (m_fix,max = 3): level 4 has no rest states */
        CHECK(cm_pdf_sticking_zone(&c, m, &lo, &hi) == (m >= -3 && m <= 3));
        if (m < -3 || m > 3)
            continue;
        const double xm = (double)m / c.alpha2; /* a regular fixed point (4.75) */
        CHECK(lo <= xm && xm <= hi);
        const double inside[3] = {lo, 0.5 * (lo + hi), hi};
        for (int i = 0; i < 3; i++) {
            cm_pdf_result r;
            CHECK(cm_pdf_at_rest(&c, inside[i], 0));
            CHECK(cm_pdf_step(&c, inside[i], 0, &r));
            CHECK(r.event == CM_PDF_STUCK_WHOLE && r.x == inside[i] && r.v == 0);
        }
        /* friction bounds these zones: just beyond them the block slides */
        CHECK(!cm_pdf_at_rest(&c, hi + 1e-6 * (hi - lo), 0));
        CHECK(!cm_pdf_at_rest(&c, lo - 1e-6 * (hi - lo), 0));
        CHECK(!cm_pdf_at_rest(&c, 0.5 * (lo + hi), 1e-9));
    }
    /* mu < |F| <= mu_s: static friction holds what kinetic friction would not */
    const cm_pdf_coef s = coef(&(params){6.53e-3, 0, 5.5e-5, 2.5e-3, 0.05, 0.2});
    const double x = (1 + 0.1) / s.alpha2; /* F = 0.1 in band 1 */
    CHECK(cm_pdf_at_rest(&s, x, 0));
    const cm_pdf_coef k = coef(&(params){6.53e-3, 0, 5.5e-5, 2.5e-3, 0.05, 0.05});
    CHECK(!cm_pdf_at_rest(&k, x, 0));
}

/* The model through the registry: parameters, mu_s defaults to mu and may
 * not be below it. */
static void test_registry(void)
{
    cm_model m;
    char msg[256];
    const char *ok = "mu=0.1";
    CHECK(cm_model_create("microchaos-pd-friction", &ok, 1, &m, msg, sizeof msg) == CM_OK);
    const double rest[2] = {2 / (6.53e-3 * 6.53e-3), 0};
    double y[2];
    CHECK(m.step(&m, rest, y) == CM_STEP_OK && y[0] == rest[0] && y[1] == 0);
    CHECK(m.at_rest && m.at_rest(&m, rest));
    cm_model_release(&m);
    const char *bad = "mu=0.1,mu_s=0.05";
    CHECK(cm_model_create("microchaos-pd-friction", &bad, 1, &m, msg, sizeof msg) == CM_EINVAL);
    CHECK(strstr(msg, "mu_s") != NULL);
}

/* Cell mapping with the Fig. 4.30 parameters: the groups labelled sticking
 * zones are exactly those whose periodic cells lie on the x-axis inside the
 * analytic sticking zones; without friction there are none. */
static void test_sticking_groups(void)
{
    const cm_lattice lat = {2, {-1e5, -601.5}, {250, 3}}; /* a row centred on x' = 0 */
    const cm_box box = {2, {0, 0}, {800, 401}};
    const char *texts[2] = {"mu=0", "mu=0.095"};
    for (int t = 0; t < 2; t++) {
        cm_model m;
        cm_region r;
        char msg[256];
        const cm_scm_options opt = {.max_steps = 100000};
        CHECK(cm_model_create("microchaos-pd-friction", &texts[t], 1, &m, msg, sizeof msg) ==
              CM_OK);
        CHECK(cm_region_alloc(&r, &box, msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(&m, &lat, &opt, &r, msg, sizeof msg) == CM_OK);
        cm_group_info *g = calloc(r.ngroups + 1, sizeof *g);
        CHECK(g != NULL);
        cm_scm_groups(&r, &lat, g, NULL);
        CHECK(cm_scm_label_groups(&m, &lat, &r, g, r.ngroups, msg, sizeof msg) == CM_OK);
        const cm_pdf_coef c = coef(t ? &fig430 : &(params){6.53e-3, 0, 5.5e-5, 2.5e-3, 0, 0});
        long sticking = 0, misplaced = 0;
        for (uint64_t i = 0; i < r.ncells; i++) {
            if (!cm_is_periodic(&r, i))
                continue;
            int64_t cell[2];
            double x[2], lo, hi;
            cm_box_cell(&r.box, i, cell);
            cm_lattice_centre(&lat, cell, x);
            double level;
            const int in_zone = x[1] == 0 && cm_int_part(c.P * x[0], &level) &&
                                cm_pdf_sticking_zone(&c, (int64_t)level, &lo, &hi) && lo <= x[0] &&
                                x[0] <= hi;
            const int labelled = g[r.group[i] - 1].kind == CM_GROUP_STICKING;
            sticking += labelled;
            misplaced += labelled != in_zone;
        }
        printf("%s: %ld periodic cells of sticking zones, %ld labelled against the analytic "
               "zones\n",
               texts[t], sticking, misplaced);
        CHECK_INT(misplaced, 0);
        CHECK(t ? sticking > 100 : sticking == 0);
        free(g);
        cm_region_free(&r);
        cm_model_release(&m);
    }
}

int main(void)
{
    test_frictionless_equals_pd();
    compare_random(&fig430, 1.2e5, 3, 200000);
    compare_random(&damped, 300, 3, 200000);
    test_grazing(&fig430);
    test_grazing(&damped);
    test_sticking_zones();
    test_registry();
    test_sticking_groups();
    CHECK_DONE();
}
