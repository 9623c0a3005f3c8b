/* The dry friction oscillator of thesis Chapter 2: exact stick-slip
 * motion and its stroboscopic Poincare map (docs/models.md 9). */
#include "models/friction_oscillator.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "models/models.h"
#include "models/params.h"

#define TWO_PI 6.283185307179586476925286766559
#define PI 3.1415926535897932384626433832795

/* Resampled from libm after this many recurrence steps, so that the
 * rotation recurrences never drift by more than a few ulps times this. */
#define RESEED_EVERY 16
/* Absolute precision of event times (docs/models.md 9.4 asks for 1e-12). */
#define TAU_TOL 1e-14
#define MIN_XTOL 1e-13
/* A breakaway computed up to this much phase before the stick began is
 * taken as immediate (acos loses digits near its ends). */
#define PHASE_TOL 1e-12

void cm_fo_init(cm_fo *o, double S, double S0, double Omega, double phi)
{
    memset(o, 0, sizeof *o);
    o->S = S;
    o->S0 = S0;
    o->Omega = Omega;
    o->phi = phi;
    o->T = TWO_PI / Omega;
    o->step = (TWO_PI / 96) / (Omega > 1 ? Omega : 1);
}

static double forcing(const cm_fo *o, double s) { return cos(o->phi + o->Omega * s); }

int cm_fo_mode_of(const cm_fo *o, double s, double x, double v)
{
    if (v > 0)
        return CM_FO_UP;
    if (v < 0)
        return CM_FO_DOWN;
    const double F = forcing(o, s) - x;
    if (fabs(F) < o->S0)
        return CM_FO_STICK;
    return F > 0 ? CM_FO_UP : CM_FO_DOWN;
}

void cm_fo_tally_start(cm_fo_tally *t, double x)
{
    memset(t, 0, sizeof *t);
    t->x_max = t->x_min = x;
}

static void tally_x(cm_fo_tally *t, double x)
{
    if (x > t->x_max)
        t->x_max = x;
    if (x < t->x_min)
        t->x_min = x;
}

/* ---- the slip phase in closed form (docs/models.md 9.2) ---- */

/* A slip phase from (x0, v0) at local time s0 in direction sigma. */
typedef struct slip {
    double x0, v0, sigma, sS; /* sS = sigma S */
    double C, Sn;             /* cos and sin of the forcing phase at s0 */
    double Omega, inv1p;      /* 1/(1 + Omega) */
} slip;

/* cos and sin of h = (1 + Omega) tau/2 and d = (1 - Omega) tau/2: with them
 * tau = h + d and Omega tau = h - d, and the resonant terms stay exact. */
typedef struct trig {
    double tau, ch, sh, cd, sd;
} trig;

static void slip_begin(const cm_fo *o, double s0, double x0, double v0, int sigma, slip *g)
{
    const double phase = o->phi + o->Omega * s0;
    g->x0 = x0;
    g->v0 = v0;
    g->sigma = sigma;
    g->sS = sigma * o->S;
    g->C = cos(phase);
    g->Sn = sin(phase);
    g->Omega = o->Omega;
    g->inv1p = 1 / (1 + o->Omega);
}

static void trig_at(const slip *g, double tau, trig *t)
{
    const double h = 0.5 * (1 + g->Omega) * tau, d = 0.5 * (1 - g->Omega) * tau;
    t->tau = tau;
    t->ch = cos(h);
    t->sh = sin(h);
    t->cd = cos(d);
    t->sd = sin(d);
}

/* sinc((1 - Omega) tau/2), exact near resonance. */
static double sinc_d(const slip *g, const trig *t)
{
    const double d = 0.5 * (1 - g->Omega) * t->tau;
    if (fabs(d) < 1e-4) {
        const double d2 = d * d;
        return 1 - d2 / 6 + d2 * d2 / 120;
    }
    return t->sd / d;
}

/* The velocity times sigma: positive while the slip lasts. */
static double slip_g(const slip *g, const trig *t)
{
    const double cos_t = t->ch * t->cd - t->sh * t->sd, sin_t = t->sh * t->cd + t->ch * t->sd;
    const double sin_wt = t->sh * t->cd - t->ch * t->sd;
    const double k = sinc_d(g, t);
    const double G1 = t->tau * t->sh * k * g->inv1p;
    const double G1d = (sin_wt + t->tau * t->ch * k) * g->inv1p;
    const double v = -(g->x0 + g->sS) * sin_t + g->v0 * cos_t + g->C * G1d - g->Sn * g->Omega * G1;
    return g->sigma * v;
}

/* The state and the acceleration tau after the start. */
static void slip_state(const slip *g, double tau, double *x, double *v, double *a)
{
    trig t;
    trig_at(g, tau, &t);
    const double cos_t = t.ch * t.cd - t.sh * t.sd, sin_t = t.sh * t.cd + t.ch * t.sd;
    const double cos_wt = t.ch * t.cd + t.sh * t.sd, sin_wt = t.sh * t.cd - t.ch * t.sd;
    const double k = sinc_d(g, &t);
    const double G1 = tau * t.sh * k * g->inv1p;
    const double G2 = (sin_t - tau * t.ch * k) * g->inv1p;
    /* 1 - cos tau without cancellation for small tau */
    const double omc = cos_t > 0 ? sin_t * sin_t / (1 + cos_t) : 1 - cos_t;
    *x = g->x0 * cos_t + g->v0 * sin_t - g->sS * omc + g->C * G1 - g->Sn * G2;
    *v = g->sigma * slip_g(g, &t); /* sigma is +-1: exact */
    if (a)
        *a = g->C * cos_wt - g->Sn * sin_wt - *x - g->sS;
}

static double g_at(const slip *g, double tau)
{
    trig t;
    trig_at(g, tau, &t);
    return slip_g(g, &t);
}

/* ---- the first velocity zero (docs/models.md 9.4) ---- */

/* A zero of g in [a, b] with g(a) > 0 >= g(b): Newton steps on the
 * analytic derivative, bisection whenever a step leaves the bracket. */
static double refine_zero(const slip *g, double a, double b, double ga, double gb)
{
    double t = a + (b - a) * ga / (ga - gb);
    for (int it = 0; it < 200; it++) {
        if (!(t > a && t < b))
            t = 0.5 * (a + b);
        double x, v, acc;
        slip_state(g, t, &x, &v, &acc);
        const double gt = g->sigma * v, dg = g->sigma * acc;
        if (gt > 0)
            a = t;
        else
            b = t;
        if (b - a <= TAU_TOL)
            return b;
        const double next = dg != 0 ? t - gt / dg : 0.5 * (a + b);
        if (fabs(next - t) <= 4 * DBL_EPSILON * fabs(t) && next >= a && next <= b)
            return next;
        t = next;
    }
    return b;
}

/* The minimum of g on [a, b] by golden section (docs/models.md 9.4: it must
 * not miss a dip of g below zero between two samples). */
static double minimise(const slip *g, double a, double b, double *g_min)
{
    const double r = 0.6180339887498949;
    double c = b - r * (b - a), d = a + r * (b - a);
    double gc = g_at(g, c), gd = g_at(g, d);
    while (b - a > MIN_XTOL) {
        if (gc <= gd) {
            b = d;
            d = c;
            gd = gc;
            c = b - r * (b - a);
            gc = g_at(g, c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + r * (b - a);
            gd = g_at(g, d);
        }
    }
    *g_min = gc <= gd ? gc : gd;
    return gc <= gd ? c : d;
}

/* From rest with g(first) <= 0: halve towards 0 until g > 0. Returns the
 * first zero, or 0 for an immediate event (no motion at all). */
static double probe_from_rest(const slip *g, double first)
{
    double prev = first, g_prev = g_at(g, first);
    for (int k = 1; k <= 60; k++) {
        const double p = ldexp(first, -k), gp = g_at(g, p);
        if (gp > 0)
            return refine_zero(g, p, prev, gp, g_prev);
        prev = p;
        g_prev = gp;
    }
    return 0;
}

/* The first zero in (a, b] when g sampled at b is <= 0: a is where the
 * sampled g was last positive. Sampled values carry recurrence errors, so
 * the bracket is checked with exact values and moved back if needed. */
static double zero_before(const slip *g, double a, double b, double step)
{
    double gb = g_at(g, b), ga = g_at(g, a);
    while (!(ga > 0)) {
        if (a <= 0)
            return probe_from_rest(g, b);
        b = a;
        gb = ga;
        a = a > step ? a - step : 0;
        ga = g_at(g, a);
    }
    return refine_zero(g, a, b, ga, gb);
}

/* A dip of g below zero inside [a, b]: the first zero, or -1 if none. */
static double dip_zero(const slip *g, double a, double b)
{
    double g_min;
    const double t_min = minimise(g, a, b, &g_min);
    if (g_min > 0)
        return -1;
    const double ga = g_at(g, a);
    return ga > 0 ? refine_zero(g, a, t_min, ga, g_at(g, t_min)) : a;
}

/* Samples g every o->step along the slip, rotating the angles h and d by
 * recurrence between libm reseeds. */
typedef struct sampler {
    double rot_h[2], rot_d[2]; /* cos, sin of the per-step increments */
    trig t;
    int since_seed;
} sampler;

static void sampler_start(const slip *g, double step, sampler *sm)
{
    sm->rot_h[0] = cos(0.5 * (1 + g->Omega) * step);
    sm->rot_h[1] = sin(0.5 * (1 + g->Omega) * step);
    sm->rot_d[0] = cos(0.5 * (1 - g->Omega) * step);
    sm->rot_d[1] = sin(0.5 * (1 - g->Omega) * step);
    trig_at(g, 0, &sm->t);
    sm->since_seed = 0;
}

static double sampler_next(const slip *g, double tau, sampler *sm)
{
    trig *t = &sm->t;
    if (++sm->since_seed == RESEED_EVERY) {
        trig_at(g, tau, t);
        sm->since_seed = 0;
    } else {
        const double ch = t->ch * sm->rot_h[0] - t->sh * sm->rot_h[1];
        const double sh = t->sh * sm->rot_h[0] + t->ch * sm->rot_h[1];
        const double cd = t->cd * sm->rot_d[0] - t->sd * sm->rot_d[1];
        const double sd = t->sd * sm->rot_d[0] + t->cd * sm->rot_d[1];
        *t = (trig){tau, ch, sh, cd, sd};
    }
    return slip_g(g, t);
}

/* The first tau in (0, tau_max] at which the slip's velocity reaches zero;
 * 0 for an immediate event from rest; -1 if the slip outlasts tau_max. */
static double first_velocity_zero(const slip *g, double tau_max, double step)
{
    const long n = (long)ceil(tau_max / step);
    const double first = n > 1 ? step : tau_max;
    const bool from_rest = g->v0 == 0;
    if (from_rest && !(g_at(g, first) > 0))
        return probe_from_rest(g, first);
    sampler sm;
    sampler_start(g, step, &sm);
    double tau1 = 0, g1 = g->sigma * g->v0; /* the previous sample */
    double tau2 = 0, g2 = 0;                /* the one before it */
    if (!from_rest) {                       /* a dip right after the start */
        double x, v, acc;
        slip_state(g, 0, &x, &v, &acc);
        if (g->sigma * acc < 0 && g_at(g, first) > g1) {
            const double z = dip_zero(g, 0, first);
            if (z >= 0)
                return z;
        }
    }
    for (long i = 1; i <= n; i++) {
        const double tau = i < n ? (double)i * step : tau_max;
        double gi = i < n ? sampler_next(g, tau, &sm) : g_at(g, tau);
        if (!(gi > 0) && i < n)
            gi = g_at(g, tau); /* confirm a sampled sign change exactly */
        if (!(gi > 0))
            return zero_before(g, tau1, tau, step);
        if (i >= 2 && g1 < g2 && g1 <= gi) { /* a local minimum between samples */
            const double z = dip_zero(g, tau2, tau);
            if (z >= 0)
                return z;
        }
        tau2 = tau1;
        g2 = g1;
        tau1 = tau;
        g1 = gi;
    }
    if (g1 < g2) { /* a dip just before the end */
        double x, v, acc;
        slip_state(g, tau_max, &x, &v, &acc);
        if (g->sigma * acc > 0)
            return dip_zero(g, tau2, tau_max);
    }
    return -1;
}

/* ---- sticking and breakaway (docs/models.md 9.3) ---- */

/* The first phase > psi (or >= psi - PHASE_TOL if allow_now) of the series
 * base + 2 pi k. */
static double next_phase(double base, double psi, bool allow_now)
{
    const double from = allow_now ? psi - PHASE_TOL : psi;
    double k = floor((from - base) / TWO_PI);
    double cand = base + TWO_PI * k;
    while (cand <= from)
        cand = base + TWO_PI * ++k;
    return cand > psi ? cand : psi;
}

/* When a block stuck at x from local time s breaks away, and in which
 * direction. Returns false if it stays stuck for ever. allow_now: a
 * breakaway at s itself is allowed (not right after an immediate event). */
static bool breakaway(const cm_fo *o, double s, double x, bool allow_now, double *s_break, int *dir)
{
    const double psi = o->phi + o->Omega * s;
    const bool strict = o->S0 > o->S; /* tangency breaks away only if S0 > S */
    const double c_up = x + o->S0, c_down = x - o->S0;
    double best = INFINITY;
    if (c_up < 1 || (c_up == 1 && strict)) { /* F rises through +S0 */
        best = next_phase(-acos(fmax(c_up, -1)), psi, allow_now);
        *dir = CM_FO_UP;
    }
    if (c_down > -1 || (c_down == -1 && strict)) { /* F falls through -S0 */
        const double cand = next_phase(acos(fmin(c_down, 1)), psi, allow_now);
        if (cand < best) {
            best = cand;
            *dir = CM_FO_DOWN;
        }
    }
    if (best == INFINITY)
        return false;
    const double sb = (best - o->phi) / o->Omega;
    *s_break = sb > s ? sb : s;
    return true;
}

/* ---- propagation (docs/models.md 9.5, 9.6) ---- */

static void emit(cm_fo_event_fn on_event, void *user, double s, double x, int kind, int mode)
{
    if (on_event) {
        const cm_fo_event e = {s, x, kind, mode};
        on_event(user, &e);
    }
}

bool cm_fo_propagate(const cm_fo *o, cm_fo_state *st, double s_end, cm_fo_tally *tally,
                     cm_fo_event_fn on_event, void *user)
{
    cm_fo_tally scratch;
    if (!tally) {
        tally = &scratch;
        cm_fo_tally_start(tally, st->x);
    }
    bool allow_now = true;
    for (long events = 0; st->s < s_end; events++) {
        if (events > CM_FO_MAX_EVENTS || !isfinite(st->x) || !isfinite(st->v))
            return false;
        if (st->mode == CM_FO_STICK) {
            double sb;
            int dir;
            if (!breakaway(o, st->s, st->x, allow_now, &sb, &dir) || sb >= s_end) {
                st->s = s_end;
                st->v = 0;
                break;
            }
            st->s = sb;
            st->v = 0;
            st->mode = dir;
            tally->n_break++;
            emit(on_event, user, sb, st->x, CM_FO_EV_BREAK, dir);
        }
        slip g;
        slip_begin(o, st->s, st->x, st->v, st->mode, &g);
        const double tau_max = s_end - st->s;
        const double tau_e = first_velocity_zero(&g, tau_max, o->step);
        if (tau_e < 0) {
            slip_state(&g, tau_max, &st->x, &st->v, NULL);
            st->s = s_end;
            break;
        }
        double v;
        slip_state(&g, tau_e, &st->x, &v, NULL);
        st->s = tau_e < tau_max ? st->s + tau_e : s_end;
        st->v = 0;
        tally_x(tally, st->x);
        const double F = forcing(o, st->s) - st->x;
        const int turn_to = F > 0 ? CM_FO_UP : CM_FO_DOWN;
        allow_now = true;
        if (tau_e == 0 || (fabs(F) >= o->S0 && turn_to == st->mode)) {
            /* degenerate (S0 = S at a tangency): stuck instead, and not
             * released again at this instant (docs/models.md 9.5) */
            st->mode = CM_FO_STICK;
            allow_now = false;
        } else if (fabs(F) < o->S0) {
            st->mode = CM_FO_STICK;
            tally->n_stick++;
            tally->x_zero_sum += st->x;
            emit(on_event, user, st->s, st->x, CM_FO_EV_STICK, CM_FO_STICK);
        } else {
            st->mode = turn_to;
            tally->n_turn++;
            tally->x_zero_sum += st->x;
            emit(on_event, user, st->s, st->x, CM_FO_EV_TURN, turn_to);
        }
    }
    tally_x(tally, st->x);
    return isfinite(st->x) && isfinite(st->v);
}

bool cm_fo_poincare(const cm_fo *o, const double z[2], double out[2], cm_fo_tally *tally,
                    cm_fo_event_fn on_event, void *user)
{
    cm_fo_state st = {0, z[0], z[1], cm_fo_mode_of(o, 0, z[0], z[1])};
    if (tally)
        cm_fo_tally_start(tally, z[0]);
    if (!cm_fo_propagate(o, &st, o->T, tally, on_event, user))
        return false;
    out[0] = st.x;
    out[1] = st.v;
    return true;
}

static void run_enter_period(const cm_fo *o, long k, cm_fo_run *r)
{
    r->k = k;
    r->t_section = (o->phi + TWO_PI * (double)k) / o->Omega;
}

void cm_fo_run_start(const cm_fo *o, double t0, double x, double v, cm_fo_run *r)
{
    run_enter_period(o, (long)floor((o->Omega * t0 - o->phi) / TWO_PI), r);
    /* rounding may put t0 a hair outside [t_section, t_section + T) */
    double s = t0 - r->t_section;
    s = s < 0 ? 0 : s >= o->T ? nextafter(o->T, 0) : s;
    r->st = (cm_fo_state){s, x, v, cm_fo_mode_of(o, s, x, v)};
}

bool cm_fo_run_period(const cm_fo *o, cm_fo_run *r, cm_fo_tally *tally, cm_fo_event_fn on_event,
                      void *user)
{
    if (!cm_fo_propagate(o, &r->st, o->T, tally, on_event, user))
        return false;
    run_enter_period(o, r->k + 1, r);
    r->st.s = 0;
    return true;
}

/* ---- linearisation (docs/models.md 9.7) ---- */

typedef struct event_log {
    cm_fo_event e[64];
    int n, lost;
} event_log;

static void log_event(void *user, const cm_fo_event *e)
{
    event_log *log = user;
    if (log->n < (int)(sizeof log->e / sizeof log->e[0]))
        log->e[log->n++] = *e;
    else
        log->lost = 1;
}

/* J <- M J for 2x2 row-major matrices. */
static void left_multiply(double J[4], const double M[4])
{
    const double r[4] = {M[0] * J[0] + M[1] * J[2], M[0] * J[1] + M[1] * J[3],
                         M[2] * J[0] + M[3] * J[2], M[2] * J[1] + M[3] * J[3]};
    memcpy(J, r, sizeof r);
}

/* The variational flow of x'' + x = f(t) over tau: a rotation. */
static void free_flight(double J[4], double tau)
{
    const double c = cos(tau), s = sin(tau);
    const double R[4] = {c, s, -s, c};
    left_multiply(J, R);
}

bool cm_fo_monodromy(const cm_fo *o, const double z[2], double J[4], double image[2])
{
    event_log log = {.n = 0};
    double end[2];
    if (!cm_fo_poincare(o, z, end, NULL, log_event, &log) || log.lost)
        return false;
    if (image)
        memcpy(image, end, sizeof end);
    int mode = cm_fo_mode_of(o, 0, z[0], z[1]);
    const double I[4] = {1, 0, 0, mode == CM_FO_STICK ? 0 : 1};
    memcpy(J, I, sizeof I);
    double s = 0;
    for (int i = 0; i < log.n; i++) {
        const cm_fo_event *e = &log.e[i];
        if (mode != CM_FO_STICK)
            free_flight(J, e->s - s);
        const double F = forcing(o, e->s) - e->x;
        if (e->kind == CM_FO_EV_TURN) { /* v = 0 crossed: a+/a- scales dv */
            const double a_before = F - mode * o->S, a_after = F - e->mode * o->S;
            const double M[4] = {1, 0, 0, a_after / a_before};
            left_multiply(J, M);
        } else if (e->kind == CM_FO_EV_STICK) { /* dv is lost, dx is kept */
            const double M[4] = {1, 0, 0, 0};
            left_multiply(J, M);
        } else { /* breakaway: a shifted stop shifts the release time */
            const double F_t = -o->Omega * sin(o->phi + o->Omega * e->s);
            const double a_b = F - e->mode * o->S;
            const double M[4] = {1, 0, -a_b / F_t, 0};
            left_multiply(J, M);
        }
        mode = e->mode;
        s = e->s;
    }
    if (mode != CM_FO_STICK)
        free_flight(J, o->T - s);
    return true;
}

bool cm_fo_fixed_point(const cm_fo *o, double z[2], int max_iter, double *residual)
{
    const double h = 1e-7;
    double p[2];
    *residual = INFINITY;
    for (int it = 0; it <= max_iter; it++) {
        if (!cm_fo_poincare(o, z, p, NULL, NULL, NULL))
            return false;
        const double r0 = p[0] - z[0], r1 = p[1] - z[1];
        *residual = hypot(r0, r1);
        if (*residual <= 1e-10 || it == max_iter)
            break;
        double J[4]; /* of P(z) - z, central differences */
        for (int k = 0; k < 2; k++) {
            double zp[2] = {z[0], z[1]}, zm[2] = {z[0], z[1]}, pp[2], pm[2];
            zp[k] += h;
            zm[k] -= h;
            if (!cm_fo_poincare(o, zp, pp, NULL, NULL, NULL) ||
                !cm_fo_poincare(o, zm, pm, NULL, NULL, NULL))
                return false;
            J[k] = (pp[0] - pm[0]) / (2 * h) - (k == 0);
            J[2 + k] = (pp[1] - pm[1]) / (2 * h) - (k == 1);
        }
        const double det = J[0] * J[3] - J[1] * J[2];
        if (det == 0 || !isfinite(det))
            return false;
        z[0] -= (J[3] * r0 - J[1] * r1) / det;
        z[1] -= (-J[2] * r0 + J[0] * r1) / det;
    }
    return *residual <= 1e-10;
}

bool cm_fo_symmetric_amplitude(double S, double Omega, double *x0, double *phase)
{
    const double w2 = Omega * Omega, sp = sin(PI / Omega), cp = cos(PI / Omega);
    if (w2 == 1 || cp == -1)
        return false;
    const double q = S * sp / (Omega * (cp + 1));
    const double arg = 1 / ((w2 - 1) * (w2 - 1)) - q * q;
    if (!(arg >= 0))
        return false;
    *x0 = sqrt(arg);
    *phase = atan2(q * (w2 - 1), *x0 * (1 - w2));
    return true;
}

/* ---- Lyapunov exponent (docs/models.md 9.8) ---- */

bool cm_fo_lyapunov(const cm_fo *o, double x0, double v0, double d0, int periods, double *lambda)
{
    const int per = 32;
    const double dt = o->T / per;
    cm_fo_state a = {0, x0, v0, cm_fo_mode_of(o, 0, x0, v0)};
    cm_fo_state b = {0, x0 + d0, v0, cm_fo_mode_of(o, 0, x0 + d0, v0)};
    double acc = 0, t_last = 0; /* t_last > 0 once a sample was accepted */
    for (long k = 0; k < periods; k++) {
        for (int i = 1; i <= per; i++) {
            const double s_end = i < per ? i * dt : o->T;
            if (!cm_fo_propagate(o, &a, s_end, NULL, NULL, NULL) ||
                !cm_fo_propagate(o, &b, s_end, NULL, NULL, NULL))
                return false;
            if (a.mode == CM_FO_STICK || a.mode != b.mode || !(fabs(a.v) > 10 * d0))
                continue;
            const double dx = b.x - a.x, dv = b.v - a.v, d = hypot(dx, dv);
            if (d == 0) {
                *lambda = -INFINITY;
                return true;
            }
            acc += log(d / d0);
            t_last = (double)k * o->T + s_end;
            b.x = a.x + dx * d0 / d;
            b.v = a.v + dv * d0 / d;
        }
        a.s = b.s = 0; /* the next period starts at the same forcing phase */
    }
    if (!(t_last > 0))
        return false;
    *lambda = acc / t_last;
    return true;
}

/* ---- the Poincare map as a cell-mapping model ---- */

const cm_param_spec cm_friction_oscillator_spec[] = {
    {"S", "0.32", 1e-9, 1e3, 1, NULL, "kinetic friction S = mu m g/F0 (2.3)"},
    {"S0", "0.4", 1e-9, 1e3, 1, NULL, "static friction S0 = mu0 m g/F0 >= S (2.3)"},
    {"Omega", "0.5", 1e-3, 1e3, 1, NULL, "excitation frequency Omega = omega0 sqrt(m/k)"},
    {"phi", "0", 0, 6.283185307179586, 1, NULL,
     "section phase: states at Omega t = phi mod 2 pi (0: forcing maximum)"},
    {"alpha", "0", 0, 0, 1, NULL,
     "viscous damping 2 alpha x' of (2.3); only 0 is implemented (docs/models.md 9.1)"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

static const char *const fo_coord_names[] = {"x", "v"};

static int step_fo(const cm_model *m, const double *x, double *y)
{
    const cm_fo *o = m->ctx;
    if (!isfinite(x[0]) || !isfinite(x[1]) || !cm_fo_poincare(o, x, y, NULL, NULL, NULL))
        return CM_STEP_NO_IMAGE;
    return CM_STEP_OK;
}

/* The section's sticking segment: v = 0, |x - cos(phi)| < S0. */
static void overlays_fo(const cm_model *m, const double lo[2], const double hi[2],
                        cm_overlay_list *out)
{
    const cm_fo *o = m->ctx;
    const double c = cos(o->phi);
    const double p[2] = {c, 0}, along[2] = {1, 0};
    cm_overlay_add_line(out, CM_OVERLAY_STICKING_ZONE, p, along, lo, hi, along, c - o->S0,
                        c + o->S0);
}

const cm_fo *cm_fo_of_model(const cm_model *m) { return m->step == step_fo ? m->ctx : NULL; }

cm_status cm_friction_oscillator_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    const double S = cm_params_get(p, "S"), S0 = cm_params_get(p, "S0");
    if (S0 < S)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "S0 = %g is below S = %g: static friction must be at least the kinetic one",
                       S0, S);
    cm_status st = cm_model_setup(m, "friction-oscillator", 2, p, sizeof(cm_fo), msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_fo_init(m->ctx, S, S0, cm_params_get(p, "Omega"), cm_params_get(p, "phi"));
    m->step = step_fo;
    m->overlays = overlays_fo;
    m->coord_names = fo_coord_names;
    return CM_OK;
}
