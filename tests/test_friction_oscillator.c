/* Tests of the dry friction oscillator (thesis Chapter 2, docs/models.md 9)
 * against the thesis' analytic results: the slip solution in its textbook
 * form (2.5)/(2.6) and by RK4 at resonance, the symmetric amplitude (2.25)
 * with its slipping limits (2.27), (2.36), the resonant asymmetric family
 * (2.57)-(2.61), the Floquet multipliers (A.5)-(A.8), the 2s and 1a
 * solutions of Sec. 2.5.2 with their Lyapunov exponents, the sticking
 * segments of Figs. 2.12-2.13, and the mirror symmetry of the cell-mapped
 * basins at S = 0.32. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/scm.h"
#include "check.h"
#include "mix.h"
#include "models/fo_continuation.h"
#include "models/fo_transients.h"
#include "models/friction_oscillator.h"
#include "models/registry.h"

#define TWO_PI 6.283185307179586476925286766559
#define PI (TWO_PI / 2)

static double uniform(uint64_t *seed, double lo, double hi)
{
    *seed = mix(*seed + 1);
    return lo + (hi - lo) * (double)(*seed >> 11) * 0x1.0p-53;
}

/* ---- independent references ---- */

/* (2.5)/(2.6) from (xs, vs) at forcing phase psi, sliding in direction
 * sigma, Omega != 1. */
static void textbook_slip(double S, double W, double psi, double xs, double vs, int sigma,
                          double tau, double *x, double *v)
{
    const double r = 1 / (1 - W * W);
    const double A = xs + sigma * S - cos(psi) * r, B = vs + W * sin(psi) * r;
    *x = A * cos(tau) + B * sin(tau) + cos(psi + W * tau) * r - sigma * S;
    *v = -A * sin(tau) + B * cos(tau) - W * sin(psi + W * tau) * r;
}

/* RK4 of x'' + x = cos(psi + W t) - sigma S, 20000 steps. */
static void rk4_slip(double S, double W, double psi, double xs, double vs, int sigma, double tau,
                     double *x, double *v)
{
    const int n = 20000;
    const double h = tau / n;
    double X = xs, V = vs;
#define ACC(t, X) (cos(psi + W * (t)) - (X)-sigma * S)
    for (int i = 0; i < n; i++) {
        const double t = i * h;
        const double k1x = V, k1v = ACC(t, X);
        const double k2x = V + 0.5 * h * k1v, k2v = ACC(t + 0.5 * h, X + 0.5 * h * k1x);
        const double k3x = V + 0.5 * h * k2v, k3v = ACC(t + 0.5 * h, X + 0.5 * h * k2x);
        const double k4x = V + h * k3v, k4v = ACC(t + h, X + h * k3x);
        X += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        V += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
#undef ACC
    *x = X;
    *v = V;
}

typedef struct event_list {
    cm_fo_event e[256];
    int n;
} event_list;

static void collect(void *user, const cm_fo_event *e)
{
    event_list *l = user;
    if (l->n < 256)
        l->e[l->n++] = *e;
}

/* The Jacobian of P by central differences (step 1e-6). */
static bool central_jacobian(const cm_fo *o, const double z[2], double J[4])
{
    const double h = 1e-6;
    for (int k = 0; k < 2; k++) {
        double zp[2] = {z[0], z[1]}, zm[2] = {z[0], z[1]}, pp[2], pm[2];
        zp[k] += h;
        zm[k] -= h;
        if (!cm_fo_poincare(o, zp, pp, NULL, NULL, NULL) ||
            !cm_fo_poincare(o, zm, pm, NULL, NULL, NULL))
            return false;
        J[k] = (pp[0] - pm[0]) / (2 * h);
        J[2 + k] = (pp[1] - pm[1]) / (2 * h);
    }
    return true;
}

/* Iterates P n times from z (in place); the last period's tally. */
static bool settle(const cm_fo *o, double z[2], int n, cm_fo_tally *t)
{
    for (int i = 0; i < n; i++) {
        double p[2];
        if (!cm_fo_poincare(o, z, p, t, NULL, NULL))
            return false;
        z[0] = p[0];
        z[1] = p[1];
    }
    return true;
}

/* ---- the slip phase ---- */

static void test_slip_closed_form(void)
{
    uint64_t seed = 7;
    double worst = 0;
    for (int i = 0; i < 2000; i++) {
        const double W = i % 2 ? 0.7 : 1.9, S = 0.3;
        const double phi = uniform(&seed, 0, TWO_PI), x0 = uniform(&seed, -2, 2);
        const int sigma = i % 3 ? 1 : -1;
        const double v0 = sigma * uniform(&seed, 3, 6), tau = uniform(&seed, 0.01, 0.4);
        cm_fo o;
        cm_fo_init(&o, S, S, W, phi);
        cm_fo_state st = {0, x0, v0, cm_fo_mode_of(&o, 0, x0, v0)};
        event_list l = {.n = 0};
        CHECK(cm_fo_propagate(&o, &st, tau, NULL, collect, &l));
        double x, v;
        textbook_slip(S, W, phi, x0, v0, sigma, tau, &x, &v);
        CHECK_INT(l.n, 0);
        worst = fmax(worst, fmax(fabs(st.x - x), fabs(st.v - v)));
    }
    CHECK(worst <= 1e-13);
    /* at and next to resonance, where (2.5)/(2.6) divide by zero */
    for (int k = 0; k < 3; k++) {
        const double W = k == 0 ? 1 : 1 + (k == 1 ? 1e-9 : -3e-6), tau = 1.2;
        cm_fo o;
        cm_fo_init(&o, 0.1, 0.1, W, 0.4);
        cm_fo_state st = {0, 0.2, 50, CM_FO_UP};
        CHECK(cm_fo_propagate(&o, &st, tau, NULL, NULL, NULL));
        double x, v;
        rk4_slip(0.1, W, 0.4, 0.2, 50, 1, tau, &x, &v);
        CHECK_NEAR(st.x, x, 1e-11);
        CHECK_NEAR(st.v, v, 1e-11);
    }
    printf("slip: closed form = (2.5)/(2.6) within %.1e; = RK4 at Omega = 1\n", worst);
}

/* A slip whose velocity dips 1e-9 below zero between two samples: the zero
 * must not be missed (docs/models.md 9.4, interior and start minima). */
static void test_grazing_dip(void)
{
    const double S = 0.2, W = 0.8, eps = 1e-9;
    cm_fo o;
    cm_fo_init(&o, S, 0.3, W, 0);
    const double psi_use = 4.0;          /* sin < 0 there: v has a minimum */
    const double x_m = cos(psi_use) - S; /* a = 0 at the minimum, sliding up */
    for (int k = 0; k < 2; k++) {
        /* start before the minimum: 0.3 (start-segment test) or 1.5 steps */
        const double back = (k == 0 ? 0.3 : 1.5) * o.step;
        double xs, vs;
        textbook_slip(S, W, psi_use, x_m, -eps, 1, -back, &xs, &vs);
        CHECK(vs > 0);
        cm_fo_init(&o, S, 0.3, W, psi_use - W * back); /* the start is at s = 0 */
        cm_fo_state st = {0, xs, vs, CM_FO_UP};
        event_list l = {.n = 0};
        CHECK(cm_fo_propagate(&o, &st, 2 * back, NULL, collect, &l));
        /* the exact first zero, by bisection on the textbook velocity */
        double lo = 0, hi = back;
        for (int i = 0; i < 200; i++) {
            const double mid = 0.5 * (lo + hi);
            double x, v;
            textbook_slip(S, W, psi_use - W * back, xs, vs, 1, mid, &x, &v);
            if (v > 0)
                lo = mid;
            else
                hi = mid;
        }
        CHECK(l.n >= 1);
        if (l.n >= 1) {
            CHECK_NEAR(l.e[0].s, lo, 1e-9); /* a double-ish root: its time is ill-conditioned */
            CHECK_INT(l.e[0].kind, CM_FO_EV_STICK);
        }
    }
}

/* ---- the symmetric non-sticking solution (2.22)-(2.25) ---- */

/* (x0, 0) at phase Omega t0 returns to itself after one period, turning
 * at -x0 half a period later: (2.25) against the integrator to 1e-9. */
static void test_symmetric_amplitude(void)
{
    const double omegas[] = {0.55, 0.7, 0.85, 0.95, 1.2, 1.6, 2.5, 4.0};
    for (size_t i = 0; i < sizeof omegas / sizeof omegas[0]; i++) {
        const double W = omegas[i], S = 0.05;
        double x0, phase;
        CHECK(cm_fo_symmetric_amplitude(S, W, &x0, &phase));
        CHECK(x0 >= S / (W * W)); /* (2.27); for Omega >= 0.5 it implies (2.29) */
        cm_fo o;
        cm_fo_init(&o, S, S, W, phase < 0 ? phase + TWO_PI : phase);
        const double z[2] = {x0, 0};
        double p[2];
        cm_fo_tally t;
        event_list l = {.n = 0};
        CHECK(cm_fo_poincare(&o, z, p, &t, collect, &l));
        CHECK_NEAR(p[0], x0, 1e-9);
        CHECK(fabs(p[1]) <= 1e-9);
        CHECK_NEAR(t.x_min, -x0, 1e-9);
        CHECK_INT(t.n_stick, 0);
        CHECK(l.n >= 1 && l.e[0].kind == CM_FO_EV_TURN);
        if (l.n >= 1)
            CHECK(fabs(l.e[0].s - o.T / 2) <= 1e-12); /* the event time, to 1e-12 */
        /* Floquet multipliers (A.5)-(A.8) vs the saltation monodromy and
         * central differences of P, at a section 0.3 after the turnaround
         * (the map's Jacobian there is conjugate to C) */
        const double cW = x0 * (1 - W * W), a_minus = -cW + x0 + S, a_plus = cW - x0 - S;
        const double hp = PI / W, c = cos(hp), s = sin(hp);
        const double s1 = 1 - 2 * S / a_minus, s2 = 1 + 2 * S / a_plus;
        const double P1[4] = {c, s, -s1 * s, s1 * c}; /* S(- to +) Phi(pi/Omega) */
        const double P2[4] = {c, s, -s2 * s, s2 * c}; /* S(+ to -) Phi(pi/Omega) */
        const double trC = P2[0] * P1[0] + P2[1] * P1[2] + P2[2] * P1[1] + P2[3] * P1[3];
        const double detC = s1 * s2;
        cm_fo_state st = {0, x0, 0, cm_fo_mode_of(&o, 0, x0, 0)};
        CHECK(cm_fo_propagate(&o, &st, 0.3, NULL, NULL, NULL));
        cm_fo later;
        cm_fo_init(&later, S, S, W, fmod(o.phi + 0.3 * W, TWO_PI));
        const double zl[2] = {st.x, st.v};
        double J[4], F[4];
        CHECK(cm_fo_monodromy(&later, zl, J, NULL));
        CHECK(central_jacobian(&later, zl, F));
        CHECK_NEAR(J[0] + J[3], trC, 1e-9);
        CHECK_NEAR(J[0] * J[3] - J[1] * J[2], detC, 1e-9);
        CHECK_NEAR(F[0] + F[3], trC, 1e-6);
        CHECK_NEAR(F[0] * F[3] - F[1] * F[2], detC, 1e-6);
    }
    /* Omega = 1/(2n): x0 = (1 - 1/(4n^2))^-1 whatever S */
    for (int n = 1; n <= 3; n++) {
        double x0, phase;
        CHECK(cm_fo_symmetric_amplitude(0.013 * n, 1.0 / (2 * n), &x0, &phase));
        CHECK_NEAR(x0, 1 / (1 - 1.0 / (4 * n * n)), 1e-12);
    }
}

/* The slipping limit (2.27): the symmetric solution survives while
 * Omega^2 x0 >= S0; just beyond, the block sticks at the turnaround. At
 * Omega = 1/2 this is the resonant bound S0 <= 1/(4n^2 - 1) = 1/3 (2.36). */
static void test_slipping_limit(void)
{
    const double cases[][2] = {{0.8, 0.2}, {0.5, 0.1}}; /* Omega, S */
    for (int k = 0; k < 2; k++) {
        const double W = cases[k][0], S = cases[k][1];
        double x0, phase;
        CHECK(cm_fo_symmetric_amplitude(S, W, &x0, &phase));
        const double limit = W * W * x0;
        if (k == 1)
            CHECK_NEAR(limit, 1.0 / 3, 1e-12);
        for (int side = 0; side < 2; side++) {
            const double S0 = limit * (side ? 1.001 : 0.999);
            cm_fo o;
            cm_fo_init(&o, S, S0, W, phase < 0 ? phase + TWO_PI : phase);
            double z[2] = {x0, 0}, p[2];
            cm_fo_tally t;
            CHECK(cm_fo_poincare(&o, z, p, &t, NULL, NULL));
            if (side == 0) {
                CHECK_INT(t.n_stick, 0);
                CHECK_NEAR(p[0], x0, 1e-9);
            } else { /* stuck at the turnaround; the steady state sticks */
                CHECK_INT(cm_fo_mode_of(&o, 0, x0, 0), CM_FO_STICK);
                CHECK(fabs(p[0] - x0) > 1e-6);
                CHECK(settle(&o, z, 400, &t));
                CHECK(t.n_stick >= 1);
            }
        }
    }
}

/* (2.57)-(2.61): at Omega = 1/(2n), (x0, 0) at t = 0 is 4 n pi-periodic,
 * turning at t = 2 n pi at x1 = x0 - 8 n^2/(4n^2 - 1), for x0 in
 * [1 + S0, (4n^2+1)/(4n^2-1) - S0]. The thesis' (2.82) prints "- S" at the
 * upper end; but at x1 the block slips on only if x1 <= -1 - S0, which
 * gives "- S0" (and with it (2.81)). Just above that end it sticks. */
static void test_resonant_family(void)
{
    for (int n = 1; n <= 2; n++) {
        const double q = 4.0 * n * n, S = n == 1 ? 0.1 : 0.01, S0 = n == 1 ? 0.2 : 0.03;
        const double lo = 1 + S0, hi = (q + 1) / (q - 1) - S0;
        cm_fo o;
        cm_fo_init(&o, S, S0, 1.0 / (2 * n), 0);
        for (int k = 0; k <= 5; k++) {
            const bool beyond = k == 5; /* still below the printed "- S" bound */
            const double x0 = beyond ? hi + 0.5 * (S0 - S) : lo + (hi - lo) * (k + 0.5) / 5;
            const double z[2] = {x0, 0};
            double p[2];
            event_list l = {.n = 0};
            CHECK(cm_fo_poincare(&o, z, p, NULL, collect, &l));
            CHECK(l.n >= 1);
            if (beyond) {
                CHECK(l.n >= 1 && l.e[0].kind == CM_FO_EV_STICK);
                continue;
            }
            CHECK_NEAR(p[0], x0, 1e-9);
            CHECK(fabs(p[1]) <= 1e-9);
            if (l.n >= 1) {
                CHECK_INT(l.e[0].kind, CM_FO_EV_TURN);
                CHECK(fabs(l.e[0].s - 2 * n * PI) <= 1e-12);
                CHECK_NEAR(l.e[0].x, x0 - 2 * q / (q - 1), 1e-10);
            }
        }
    }
}

/* The eigenvalues' largest modulus of a 2x2 matrix. */
static double spectral_radius(const double J[4])
{
    const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2], disc = tr * tr / 4 - det;
    if (disc < 0)
        return sqrt(det);
    return fmax(fabs(tr / 2 + sqrt(disc)), fabs(tr / 2 - sqrt(disc)));
}

/* The mirror image of a state z at phase 0: -(its orbit half a period on). */
static void mirror(const cm_fo *o, const double z[2], double out[2])
{
    cm_fo_state st = {0, z[0], z[1], cm_fo_mode_of(o, 0, z[0], z[1])};
    CHECK(cm_fo_propagate(o, &st, o->T / 2, NULL, NULL, NULL));
    out[0] = -st.x;
    out[1] = -st.v;
}

typedef struct orbit {
    double z[2];
    cm_fo_tally t;
    double psi;     /* (2.90) */
    double lambda;  /* Benettin, docs/models.md 9.8 */
    double floquet; /* ln(spectral radius of the saltation monodromy)/T */
} orbit;

/* The steady state from z0 (400 periods, docs/models.md 9.6), refined by
 * Newton, with its asymmetry, counters and exponents. */
static void steady_orbit(const cm_fo *o, double x0, double v0, orbit *r)
{
    r->z[0] = x0;
    r->z[1] = v0;
    CHECK(settle(o, r->z, 400, &r->t));
    double res;
    CHECK(cm_fo_fixed_point(o, r->z, 20, &res));
    CHECK(res <= 1e-10);
    double p[2], J[4];
    CHECK(cm_fo_poincare(o, r->z, p, &r->t, NULL, NULL));
    r->psi = fabs((r->t.x_max + r->t.x_min) / (r->t.x_max - r->t.x_min));
    CHECK(cm_fo_monodromy(o, r->z, J, NULL));
    r->floquet = log(spectral_radius(J)) / o->T;
    CHECK(cm_fo_lyapunov(o, r->z[0], r->z[1], 1e-8, 3000, &r->lambda));
}

/* Sec. 2.5.2 at Omega = 0.5, S0 = 0.4: the symmetric two-stick solution 2s
 * at S = 0.4 and the mirror pair of one-stick asymmetric solutions 1a at
 * S = 0.32; their Lyapunov exponents equal ln|multiplier|/T. */
static void test_2s_and_1a(void)
{
    cm_fo o;
    cm_fo_init(&o, 0.4, 0.4, 0.5, 0);
    orbit s2;
    steady_orbit(&o, 0, 0, &s2);
    CHECK_INT(s2.t.n_stick, 2);
    CHECK_INT(s2.t.n_turn, 0);
    CHECK(s2.psi < 1e-9);
    double m[2];
    mirror(&o, s2.z, m); /* symmetric: its own mirror image */
    CHECK(hypot(m[0] - s2.z[0], m[1] - s2.z[1]) <= 1e-9);
    CHECK(s2.floquet < 0);
    CHECK_NEAR(s2.lambda, s2.floquet, 0.01 * fabs(s2.floquet));
    double J[4], F[4];
    CHECK(cm_fo_monodromy(&o, s2.z, J, NULL) && central_jacobian(&o, s2.z, F));
    CHECK_NEAR(spectral_radius(J), spectral_radius(F), 1e-6);
    printf("2s (S = 0.4): z = (%.12f, %.12f), %d sticks, Psi %.1e, LLE %.6f, ln|mult|/T %.6f\n",
           s2.z[0], s2.z[1], s2.t.n_stick, s2.psi, s2.lambda, s2.floquet);

    cm_fo_init(&o, 0.32, 0.4, 0.5, 0);
    orbit a[2];
    steady_orbit(&o, 0, 0, &a[0]);
    steady_orbit(&o, 1.36, 0, &a[1]);
    CHECK(hypot(a[0].z[0] - a[1].z[0], a[0].z[1] - a[1].z[1]) > 0.1); /* two attractors */
    for (int k = 0; k < 2; k++) {
        CHECK_INT(a[k].t.n_stick, 1);
        CHECK(a[k].psi > 0.05);
        mirror(&o, a[k].z, m); /* each is the other's mirror image */
        CHECK(hypot(m[0] - a[1 - k].z[0], m[1] - a[1 - k].z[1]) <= 1e-9);
        CHECK(a[k].floquet < 0);
        CHECK_NEAR(a[k].lambda, a[k].floquet, 0.01 * fabs(a[k].floquet));
        printf("1a (S = 0.32): z = (%.12f, %.12f), %d stick, Psi %.4f, LLE %.6f, "
               "ln|mult|/T %.6f\n",
               a[k].z[0], a[k].z[1], a[k].t.n_stick, a[k].psi, a[k].lambda, a[k].floquet);
    }
    const int sliding = a[0].z[1] != 0 ? 0 : 1; /* the other one is stuck at the section */
    CHECK(cm_fo_monodromy(&o, a[sliding].z, J, NULL) && central_jacobian(&o, a[sliding].z, F));
    CHECK_NEAR(spectral_radius(J), spectral_radius(F), 1e-6);
}

/* A run started mid-period at any time (t0 < 0 too, as the thesis' random
 * starts) reaches the section instants (phi + 2 pi k)/Omega, restarting
 * local time every period, and stays on the 1a orbit; the simulation form
 * of Psi (thesis 2.6.1) vanishes on 2s and not on 1a. */
static void test_runs(void)
{
    const double phis[2] = {0, 1.1};
    for (int f = 0; f < 2; f++) {
        cm_fo o;
        cm_fo_init(&o, 0.32, 0.4, 0.5, phis[f]);
        double z[2] = {1.36, 0}, res;
        for (int k = 0; k < 400; k++)
            CHECK(cm_fo_poincare(&o, z, z, NULL, NULL, NULL));
        CHECK(cm_fo_fixed_point(&o, z, 20, &res));
        cm_fo_state q = {0, z[0], z[1], cm_fo_mode_of(&o, 0, z[0], z[1])};
        CHECK(cm_fo_propagate(&o, &q, 0.3 * o.T, NULL, NULL, NULL));
        const long ks[3] = {5, -7, 0};
        for (int i = 0; i < 3; i++) {
            const double t_section = (phis[f] + 2 * PI * (double)ks[i]) / o.Omega;
            cm_fo_run r;
            cm_fo_run_start(&o, t_section + 0.3 * o.T, q.x, q.v, &r);
            CHECK_INT(r.k, ks[i]);
            CHECK_NEAR(r.st.s, 0.3 * o.T, 1e-12);
            CHECK(cm_fo_run_period(&o, &r, NULL, NULL, NULL));
            CHECK_INT(r.k, ks[i] + 1);
            CHECK_NEAR(r.t_section, t_section + o.T, 1e-12);
            CHECK_NEAR(r.st.s, 0, 0);
            CHECK(hypot(r.st.x - z[0], r.st.v - z[1]) <= 1e-9);
        }
    }
    const double S[2] = {0.4, 0.32};
    double psi[2];
    for (int k = 0; k < 2; k++) {
        cm_fo o;
        cm_fo_init(&o, S[k], 0.4, 0.5, 0);
        cm_fo_run r;
        cm_fo_run_start(&o, -3.3, 0.2, -0.4, &r);
        for (int p = 0; p < 1000; p++)
            CHECK(cm_fo_run_period(&o, &r, NULL, NULL, NULL));
        double sum = 0;
        for (int p = 0; p < 20; p++) {
            cm_fo_tally t;
            cm_fo_tally_start(&t, r.st.x);
            CHECK(cm_fo_run_period(&o, &r, &t, NULL, NULL));
            sum += t.x_zero_sum;
        }
        psi[k] = fabs(sum) / 20;
    }
    CHECK(psi[0] < 1e-9);
    CHECK(psi[1] > 0.1);
    printf("Psi per period (2.6.1) after 1000 periods from a random start: 2s %.1e, 1a %.4f\n",
           psi[0], psi[1]);
}

/* Sec. 2.6.1: S0 = 0.4, S = 0.05, Omega = 0.5 is chaotic; the thesis'
 * synchronisation estimate 0.0073 is an upper bound. */
static void test_chaotic_lyapunov(void)
{
    cm_fo o;
    cm_fo_init(&o, 0.05, 0.4, 0.5, 0);
    double lambda;
    CHECK(cm_fo_lyapunov(&o, 1 + 0.9 * 0.4, 0, 1e-8, 3000, &lambda));
    printf("chaotic point: LLE %.6f (thesis, synchronisation: <= 0.0073)\n", lambda);
    CHECK(lambda > 0.001 && lambda < 0.0073);
}

/* Sticking segments per period at points of Figs. 2.12 and 2.13, and the
 * large-Omega sticking threshold (2.27)/(2.87): at Omega = 10, S = S0
 * sticks iff Omega^2 x0(Omega, S) < S. */
static void test_sticking_counts(void)
{
    const struct {
        double S, W;
        int n_stick;
    } pts[] = {
        {0.02, 0.5, 1}, {0.02, 0.25, 1},              /* Fig. 2.13: asymmetric, one stick */
        {0.5, 3, 0},    {0.7, 3, 2},                  /* Fig. 2.12 (b), (c) at large Omega */
        {0.9, 0.3, 2},  {0.9, 1.5, 2},   {0.9, 3, 2}, /* (d): sticks everywhere */
        {0.3, 0.8, 0},  {0.3, 2, 0},                  /* (a): slips at Omega > 0.5 */
    };
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        cm_fo o;
        cm_fo_init(&o, pts[i].S, pts[i].S, pts[i].W, 0);
        double z[2] = {0, 0};
        cm_fo_tally t;
        CHECK(settle(&o, z, 400, &t));
        if (t.n_stick != pts[i].n_stick)
            fprintf(stderr, "S = S0 = %g, Omega = %g: %d sticks\n", pts[i].S, pts[i].W, t.n_stick);
        CHECK_INT(t.n_stick, pts[i].n_stick);
    }
    const double W = 10;
    double lo = 0.3, hi = 0.8; /* Omega^2 x0(S) - S changes sign once here */
    for (int i = 0; i < 100; i++) {
        const double mid = 0.5 * (lo + hi);
        double x0, phase;
        CHECK(cm_fo_symmetric_amplitude(mid, W, &x0, &phase));
        if (W * W * x0 > mid)
            lo = mid;
        else
            hi = mid;
    }
    printf("sticking at Omega = 10 from S = %.6f ((2.88) in the limit: %.6f)\n", lo,
           1 / sqrt(1 + PI * PI / 4));
    for (int side = 0; side < 2; side++) {
        const double S = lo * (side ? 1.01 : 0.99);
        cm_fo o;
        cm_fo_init(&o, S, S, W, 0);
        double z[2] = {0, 0};
        cm_fo_tally t;
        CHECK(settle(&o, z, 400, &t));
        CHECK_INT(t.n_stick, side ? 2 : 0);
    }
}

/* Cell mapping at S = 0.32, S0 = 0.4, Omega = 0.5 on a lattice symmetric
 * about the origin. The mirror symmetry maps a state at phase phi to its
 * negative at phase phi + pi, so P_0 and P_pi are conjugate by z -> -z:
 * cell c of P_0's basin of an attractor must be, as -c, in P_pi's basin of
 * the corresponding attractor; both maps hold the 1a pair. */
static void test_mirror_basins(void)
{
    /* cell 0 is centred on the origin, so that the states stuck at the
     * section (v = 0 exactly) lie mid-cell, not on a border */
    const int n = 121;
    const double w = 6.0 / n;
    const cm_lattice lat = {2, {-w / 2, -w / 2}, {w, w}};
    const cm_box box = {2, {-n / 2, -n / 2}, {n / 2 + 1, n / 2 + 1}};
    cm_region r[2];
    char msg[256];
    for (int k = 0; k < 2; k++) {
        const char *text =
            k ? "S=0.32,S0=0.4,Omega=0.5,phi=3.141592653589793" : "S=0.32,S0=0.4,Omega=0.5,phi=0";
        cm_model m;
        CHECK(cm_model_create("friction-oscillator", &text, 1, &m, msg, sizeof msg) == CM_OK);
        const cm_scm_options opt = {.max_steps = 1000};
        CHECK(cm_region_alloc(&r[k], &box, msg, sizeof msg) == CM_OK);
        CHECK(cm_scm_solve(&m, &lat, &opt, &r[k], msg, sizeof msg) == CM_OK);
        cm_model_release(&m);
    }
    uint32_t pair[64] = {0}; /* P_0 group -> P_pi group, 0 = unseen */
    long cells = 0, mismatched = 0, basin0[64] = {0};
    for (uint64_t i = 0; i < r[0].ncells; i++) {
        int64_t c[2], mc[2];
        cm_box_cell(&box, i, c);
        mc[0] = -c[0]; /* the cell whose centre is -centre(c) */
        mc[1] = -c[1];
        const uint32_t g0 = r[0].group[i], g1 = r[1].group[cm_box_index(&box, mc)];
        if (g0 >= 64 || g1 >= 64) {
            mismatched++;
            continue;
        }
        cells++;
        basin0[g0]++;
        if (!pair[g0])
            pair[g0] = g1;
        mismatched += pair[g0] != g1;
    }
    int big = 0; /* groups with a basin of at least 10 % of the lattice */
    for (int g = 1; g < 64; g++)
        big += basin0[g] >= cells / 10;
    printf("mirror basins: %u and %u groups, %ld of %ld cells break the symmetry, %d large "
           "basins\n",
           r[0].ngroups, r[1].ngroups, mismatched, cells, big);
    CHECK_INT(r[0].ngroups, r[1].ngroups);
    CHECK_INT(mismatched, 0);
    CHECK_INT(big, 2);
    cm_region_free(&r[0]);
    cm_region_free(&r[1]);
}

/* A block stuck where the forcing touches +S0 exactly at its maximum
 * (x + S0 = 1): with S0 > S it breaks away upwards there; with S0 = S the
 * tangency does not release it (docs/models.md 9.5), and it breaks away
 * downwards when the forcing falls through -S0 (phase 2 pi + pi / 3). */
static void test_tangency(void)
{
    const double phi = PI / 2; /* the forcing falls through 0 at s = 0 */
    const double cases[2][2] = {{0.2, 0.25}, {0.25, 0.25}}; /* S, S0; x + S0 = 1 exactly */
    for (int k = 0; k < 2; k++) {
        cm_fo o;
        cm_fo_init(&o, cases[k][0], cases[k][1], 1.0, phi);
        cm_fo_state st = {0, 1 - cases[k][1], 0, CM_FO_STICK};
        event_list l = {.n = 0};
        CHECK(cm_fo_propagate(&o, &st, 8.0, NULL, collect, &l));
        CHECK(l.n >= 1);
        if (l.n < 1)
            continue;
        CHECK_INT(l.e[0].kind, CM_FO_EV_BREAK);
        CHECK_INT(l.e[0].mode, k == 0 ? CM_FO_UP : CM_FO_DOWN);
        CHECK_NEAR(l.e[0].s, k == 0 ? 2 * PI - phi : 2 * PI + PI / 3 - phi, 1e-12);
    }
}

/* Fig. 2.5: H(t, Omega) of (2.29) against (2.30), (2.31) and the four
 * regimes of 2.2.1: the maximum at t -> 0 for Omega >= 1/2, inside
 * (0, pi/(2 Omega)) below 1/2, in (pi/(2 Omega), pi/Omega) below 1/3, and
 * again at t -> 0 at Omega = 1/4 (1/Omega^2 = 16). */
static void test_turnaround_function(void)
{
    const double omegas[4] = {0.6, 0.4, 0.3, 0.25};
    for (int k = 0; k < 4; k++) {
        const double w = omegas[k], end = PI / w;
        CHECK_NEAR(cm_fo_turn_h(1e-6, w), 1 / (w * w), 1e-5);
        for (double t = 0.1; t < end; t += 0.37)
            CHECK_NEAR(cm_fo_turn_h(end - t, w), -cm_fo_turn_h(t, w), 1e-9);
    }
    double t;
    CHECK(cm_fo_turn_hmax_at(0.6, &t) == 1 / 0.36 && t == 0);
    CHECK(cm_fo_turn_hmax_at(0.4, &t) > 1 / 0.16 && t > 0 && t < PI / 0.8);
    CHECK(cm_fo_turn_hmax_at(0.3, &t) > 1 / 0.09 && t > PI / 0.6 && t < PI / 0.3);
    CHECK(cm_fo_turn_hmax_at(0.25, &t) == 16 && t == 0);
}

/* Fig. 2.10: the thesis' second-order map eps' = eps - 2 eps^2 of a
 * perturbation of the extremal asymmetric solution, "independently on the
 * friction parameter": by simulation at S = S0 = 0.1 and 0.3 (Omega = 0.5)
 * (eps' - eps)/eps^2 tends to -2 as eps -> 0. */
static void test_extremal_perturbation(void)
{
    const double S[2] = {0.1, 0.3};
    for (int k = 0; k < 2; k++) {
        cm_fo o;
        cm_fo_init(&o, S[k], S[k], 0.5, 0);
        const double eps = 5e-4, next = cm_fo_extremal_next(&o, eps);
        CHECK(fabs((next - eps) / (eps * eps) + 2) < 0.005);
        const double far = cm_fo_extremal_next(&o, 0.02); /* smaller, but not by 2 eps^2 */
        CHECK(far < 0.02 && fabs((far - 0.02) / 4e-4 + 2) > 0.02);
    }
}

/* Fig. 2.11: at S = S0 = 0.1, Omega = 0.98 the simulation from (1.09, 0)
 * converges to the symmetric solution with an envelope of slope
 * log|lambda_max|: the least-squares decay rate within 0.5 % of it, and
 * the error over |lambda_max|^n within a factor of 1.5 all the way. */
static void test_convergence(void)
{
    cm_fo o;
    cm_fo_init(&o, 0.1, 0.1, 0.98, 0);
    enum { N = 2000 };
    static double err[N + 1];
    cm_fo_convergence c;
    CHECK(cm_fo_converge(&o, (const double[2]){1.09, 0}, N, N, err, &c));
    double x0, phase;
    CHECK(cm_fo_symmetric_amplitude(0.1, 0.98, &x0, &phase));
    double lo = INFINITY, hi = 0, sn = 0, sy = 0, snn = 0, sny = 0;
    for (int n = 0; n <= N; n++) {
        const double r = err[n] / pow(c.mult_max, n), y = log(err[n]);
        lo = fmin(lo, r), hi = fmax(hi, r);
        sn += n, sy += y, snn += (double)n * n, sny += n * y;
    }
    const double slope = ((N + 1) * sny - sn * sy) / ((N + 1) * snn - sn * sn);
    CHECK(fabs(slope / log(c.mult_max) - 1) < 0.005);
    CHECK(hi / lo < 1.5 && c.mult_max > 0.99 && c.mult_max < 1);
    CHECK(c.mult_arg > 0.1); /* complex multipliers: the secondary frequency of (2.86) */
    /* the solution it reached is the symmetric non-sticking one: a period
     * from z_star turns at x0 of (2.25) and never sticks */
    cm_fo_tally t;
    cm_fo_tally_start(&t, c.z_star[0]);
    double end[2];
    CHECK(cm_fo_poincare(&o, c.z_star, end, &t, NULL, NULL));
    CHECK_NEAR(t.x_max, x0, 1e-8);
    CHECK(t.n_stick == 0 && t.n_turn == 2);
}

int main(void)
{
    test_tangency();
    test_slip_closed_form();
    test_grazing_dip();
    test_symmetric_amplitude();
    test_slipping_limit();
    test_resonant_family();
    test_2s_and_1a();
    test_runs();
    test_chaotic_lyapunov();
    test_sticking_counts();
    test_mirror_basins();
    test_turnaround_function();
    test_extremal_perturbation();
    test_convergence();
    CHECK_DONE();
}
