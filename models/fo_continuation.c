/* Pseudo-arclength continuation of the friction oscillator's periodic
 * solutions (docs/models.md 9.9). A branch is a curve u = (x, v, p) of
 * G(u) = P^k(x, v; p) - (x, v) = 0. Each step predicts along the tangent
 * (the null vector of DG = [M - I | dP^k/dp], M the exact monodromy of
 * the k periods) and corrects by Newton on G = 0 with the arclength
 * condition; events are test functions that change sign between two
 * points (det(M - I) for folds, det(M + I) for period doublings, det M - 1
 * for complex pairs) or a changed signature, located by bisection along
 * the step. */
#include "models/fo_continuation.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const param_names[] = {"S", "S0", "Omega", "phi"};

int cm_fo_param_of(const char *name)
{
    for (int i = 0; i < 4; i++)
        if (strcmp(name, param_names[i]) == 0)
            return i;
    return -1;
}

const char *cm_fo_param_name(int param) { return param >= 0 && param < 4 ? param_names[param] : "?"; }

void cm_fo_with(const cm_fo *o, int param, double p, cm_fo *out)
{
    double v[4] = {o->S, o->S0, o->Omega, o->phi};
    v[param] = p;
    cm_fo_init(out, v[0], v[1], v[2], v[3]);
}

/* ---- one solution: P^k, its monodromy, its signature -------------------- */

typedef struct sig_log {
    char *sig;
    size_t len;
    double *stops;
    int n_stops;
} sig_log;

static void add_mode(sig_log *l, int mode)
{
    const char c = mode == CM_FO_UP ? 'u' : mode == CM_FO_DOWN ? 'd' : 's';
    if (l->len + 1 < CM_FO_SIGNATURE && (l->len == 0 || l->sig[l->len - 1] != c)) {
        l->sig[l->len++] = c;
        l->sig[l->len] = '\0';
    }
}

static void on_fo_event(void *user, const cm_fo_event *e)
{
    sig_log *l = user;
    if (e->kind == CM_FO_EV_STICK && l->n_stops < CM_FO_MAX_STOPS)
        l->stops[l->n_stops++] = e->x;
    add_mode(l, e->mode);
}

/* The modes as a cycle: the last one merged into the first when they
 * agree, then the rotation that comes first alphabetically. */
static void canonical_cycle(char *sig)
{
    size_t n = strlen(sig);
    if (n > 1 && sig[n - 1] == sig[0])
        sig[--n] = '\0';
    char best[CM_FO_SIGNATURE], rot[CM_FO_SIGNATURE];
    snprintf(best, sizeof best, "%s", sig);
    for (size_t r = 1; r < n; r++) {
        memcpy(rot, sig + r, n - r);
        memcpy(rot + (n - r), sig, r);
        rot[n] = '\0';
        if (strcmp(rot, best) < 0)
            memcpy(best, rot, n + 1);
    }
    memcpy(sig, best, n + 1);
}

/* 2x2 row-major: A = B A */
static void left_mul(double A[4], const double B[4])
{
    const double r[4] = {B[0] * A[0] + B[1] * A[2], B[0] * A[1] + B[1] * A[3],
                         B[2] * A[0] + B[3] * A[2], B[2] * A[1] + B[3] * A[3]};
    memcpy(A, r, sizeof r);
}

/* P^k(z) into end and its monodromy into M (may be NULL), the solution's
 * description into s (may be NULL). */
static bool compose(const cm_fo *o, const double z[2], int k, double end[2], double M[4],
                    cm_fo_solution *s)
{
    if (!(o->S > 0 && o->S0 >= o->S && o->Omega > 0)) /* (2.3) holds only there */
        return false;
    double cur[2] = {z[0], z[1]};
    if (M) {
        M[0] = M[3] = 1;
        M[1] = M[2] = 0;
    }
    sig_log log = {s ? s->signature : NULL, 0, s ? s->stops : NULL, 0};
    if (s) {
        s->signature[0] = '\0';
        s->x_max = s->x_min = z[0];
        s->psi = 0;
        s->n_stick = 0;
        add_mode(&log, cm_fo_mode_of(o, 0, z[0], z[1]));
    }
    for (int i = 0; i < k; i++) {
        cm_fo_tally t;
        double next[2], J[4];
        /* the monodromy's propagation gives the image too; a description
         * needs the tally and the events of one of its own */
        if ((s || !M) &&
            !cm_fo_poincare(o, cur, next, s ? &t : NULL, s ? on_fo_event : NULL, &log))
            return false;
        if (M) {
            if (!cm_fo_monodromy(o, cur, J, s ? NULL : next))
                return false;
            left_mul(M, J);
        }
        if (s) {
            s->x_max = fmax(s->x_max, t.x_max);
            s->x_min = fmin(s->x_min, t.x_min);
            s->psi += t.x_zero_sum;
            s->n_stick += t.n_stick;
        }
        cur[0] = next[0];
        cur[1] = next[1];
    }
    if (s) {
        s->n_stops = log.n_stops;
        canonical_cycle(s->signature);
    }
    end[0] = cur[0];
    end[1] = cur[1];
    return isfinite(end[0]) && isfinite(end[1]);
}

static void multipliers(const double M[4], double mult[2][2])
{
    const double tr = M[0] + M[3], det = M[0] * M[3] - M[1] * M[2], disc = tr * tr - 4 * det;
    if (disc >= 0) {
        const double q = -0.5 * (tr + copysign(sqrt(disc), tr)); /* no cancellation */
        double a = q != 0 ? det / q : 0, b = -q;                 /* the roots */
        if (fabs(a) < fabs(b)) {
            const double t = a;
            a = b;
            b = t;
        }
        mult[0][0] = a, mult[0][1] = 0, mult[1][0] = b, mult[1][1] = 0;
    } else {
        mult[0][0] = mult[1][0] = tr / 2;
        mult[0][1] = sqrt(-disc) / 2;
        mult[1][1] = -mult[0][1];
    }
}

bool cm_fo_solution_at(const cm_fo *o, const double z[2], int period, cm_fo_solution *out)
{
    double end[2], M[4];
    memset(out, 0, sizeof *out);
    if (!compose(o, z, period, end, M, out))
        return false;
    out->z[0] = z[0];
    out->z[1] = z[1];
    out->phi = o->phi;
    out->period = period;
    multipliers(M, out->mult);
    out->stable = hypot(out->mult[0][0], out->mult[0][1]) < 1;
    out->symmetric = fabs(out->psi) < 1e-6;
    out->asymmetry = fabs((out->x_max + out->x_min) / (out->x_max - out->x_min));
    return true;
}

/* Solves the 2x2 system A x = b; false if singular. */
static bool solve2(const double A[4], const double b[2], double x[2])
{
    const double det = A[0] * A[3] - A[1] * A[2];
    if (det == 0 || !isfinite(det))
        return false;
    x[0] = (A[3] * b[0] - A[1] * b[1]) / det;
    x[1] = (-A[2] * b[0] + A[0] * b[1]) / det;
    return isfinite(x[0]) && isfinite(x[1]);
}

bool cm_fo_periodic_point(const cm_fo *o, double z[2], int period)
{
    double end[2], M[4];
    if (!compose(o, z, period, end, M, NULL))
        return false;
    double r[2] = {end[0] - z[0], end[1] - z[1]}, norm = hypot(r[0], r[1]);
    for (int it = 0; it < 50; it++) {
        if (norm < 1e-11)
            return true;
        const double A[4] = {M[0] - 1, M[1], M[2], M[3] - 1};
        double dz[2];
        if (!solve2(A, r, dz))
            return false;
        bool accepted = false; /* damped, as the corrector */
        for (double lambda = 1; lambda > 1e-4 && !accepted; lambda /= 2) {
            const double trial[2] = {z[0] - lambda * dz[0], z[1] - lambda * dz[1]};
            double te[2], tM[4];
            if (compose(o, trial, period, te, tM, NULL) &&
                hypot(te[0] - trial[0], te[1] - trial[1]) < norm) {
                memcpy(z, trial, sizeof trial);
                memcpy(M, tM, sizeof tM);
                r[0] = te[0] - z[0];
                r[1] = te[1] - z[1];
                norm = hypot(r[0], r[1]);
                accepted = true;
            }
        }
        if (!accepted)
            return false;
    }
    return false;
}

int cm_fo_minimal_period(const cm_fo *o, const double z[2], int k)
{
    double end[2];
    for (int d = 1; d < k; d++)
        if (k % d == 0) {
            if (!compose(o, z, d, end, NULL, NULL))
                return 0;
            if (hypot(end[0] - z[0], end[1] - z[1]) < 1e-9 * fmax(1, hypot(z[0], z[1])))
                return d;
        }
    return k;
}

int cm_fo_find_periodic(const cm_fo *o, double z[2], int settle, int max_period)
{
    double cur[2] = {z[0], z[1]};
    for (int i = 0; i < settle; i++)
        if (!cm_fo_poincare(o, cur, cur, NULL, NULL, NULL))
            return 0;
    double end[2];
    for (int k = 1; k <= max_period; k++) {
        if (!compose(o, cur, k, end, NULL, NULL))
            return 0;
        if (hypot(end[0] - cur[0], end[1] - cur[1]) < 1e-6) {
            double p[2] = {cur[0], cur[1]};
            if (cm_fo_periodic_point(o, p, k)) {
                z[0] = p[0];
                z[1] = p[1];
                return k;
            }
        }
    }
    return 0;
}

/* ---- the branch ---------------------------------------------------------- */

typedef struct branch {
    cm_fo base; /* its section phase moves along the branch */
    int param, period;
} branch;

/* The derivative in p from values at p - h, p, p + h: central where the
 * one-sided differences agree, else the smaller one. Where the map jumps
 * within h of p (at a grazing), the central difference straddles the jump
 * and is meaningless; the side without the jump is the solution's own. */
static double p_derivative(double minus, double at, double plus, double h)
{
    const double back = (at - minus) / h, ahead = (plus - at) / h;
    if (fabs(ahead - back) <= 0.5 * (fabs(ahead) + fabs(back)) + 1e-6)
        return 0.5 * (ahead + back);
    return fabs(ahead) < fabs(back) ? ahead : back;
}

/* G(u) and DG (2 x 3, row-major) at u = (x, v, p). */
static bool residual(const branch *b, const double u[3], double G[2], double DG[6])
{
    cm_fo o, op, om;
    cm_fo_with(&b->base, b->param, u[2], &o);
    double end[2], M[4];
    if (!compose(&o, u, b->period, end, M, NULL))
        return false;
    G[0] = end[0] - u[0];
    G[1] = end[1] - u[1];
    if (!DG)
        return true;
    const double h = 1e-7 * fmax(1, fabs(u[2]));
    double ep[2], em[2];
    cm_fo_with(&b->base, b->param, u[2] + h, &op);
    cm_fo_with(&b->base, b->param, u[2] - h, &om);
    if (!compose(&op, u, b->period, ep, NULL, NULL) || !compose(&om, u, b->period, em, NULL, NULL))
        return false;
    DG[0] = M[0] - 1, DG[1] = M[1], DG[2] = p_derivative(em[0], end[0], ep[0], h);
    DG[3] = M[2], DG[4] = M[3] - 1, DG[5] = p_derivative(em[1], end[1], ep[1], h);
    return true;
}

/* The unit tangent: the cross product of DG's rows, oriented along prev
 * (or with dp of the sign of `direction` when prev is NULL). */
static bool tangent(const double DG[6], const double *prev, double direction, double t[3])
{
    t[0] = DG[1] * DG[5] - DG[2] * DG[4];
    t[1] = DG[2] * DG[3] - DG[0] * DG[5];
    t[2] = DG[0] * DG[4] - DG[1] * DG[3];
    const double n = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (!(n > 0) || !isfinite(n))
        return false;
    const double s = prev ? (t[0] * prev[0] + t[1] * prev[1] + t[2] * prev[2] < 0 ? -1 : 1)
                          : (t[2] * direction < 0 ? -1 : 1);
    for (int i = 0; i < 3; i++)
        t[i] *= s / n;
    return true;
}

/* Solves the 3 x 3 system A x = r by Cramer's rule; false if singular. */
static bool solve3(const double A[9], const double r[3], double x[3])
{
    const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                       A[2] * (A[3] * A[7] - A[4] * A[6]);
    if (det == 0 || !isfinite(det))
        return false;
    for (int c = 0; c < 3; c++) {
        double B[9];
        memcpy(B, A, sizeof B);
        for (int row = 0; row < 3; row++)
            B[3 * row + c] = r[row];
        x[c] = (B[0] * (B[4] * B[8] - B[5] * B[7]) - B[1] * (B[3] * B[8] - B[5] * B[6]) +
                B[2] * (B[3] * B[7] - B[4] * B[6])) /
               det;
    }
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]);
}

/* G(u), the arclength condition's residual *arc, and both together in *norm. */
static bool corrector_norm(const branch *b, const double u0[3], const double t[3], double h,
                           const double u[3], double G[2], double DG[6], double *arc,
                           double *norm)
{
    if (!residual(b, u, G, DG))
        return false;
    *arc = t[0] * (u[0] - u0[0]) + t[1] * (u[1] - u0[1]) + t[2] * (u[2] - u0[2]) - h;
    *norm = hypot(hypot(G[0], G[1]), *arc);
    return isfinite(*norm);
}

/* Newton from the prediction u0 + h t (or from `guess`, if not NULL) onto
 * G = 0 with t . (u - u0) = h, damped: a step is halved until the residual
 * shrinks, since near a change of signature the map's Jacobian holds only
 * on one side. */
static bool correct_from(const branch *b, const double u0[3], const double t[3], double h,
                         const double *guess, double u[3], int *iterations)
{
    for (int i = 0; i < 3; i++)
        u[i] = guess ? guess[i] : u0[i] + h * t[i];
    double G[2], DG[6], arc, norm;
    if (!corrector_norm(b, u0, t, h, u, G, DG, &arc, &norm))
        return false;
    for (int it = 0; it < 40; it++) {
        if (hypot(G[0], G[1]) < 1e-11 && norm < 1e-10) {
            *iterations = it;
            return true;
        }
        const double A[9] = {DG[0], DG[1], DG[2], DG[3], DG[4], DG[5], t[0], t[1], t[2]};
        const double r[3] = {-G[0], -G[1], -arc};
        double du[3];
        if (!solve3(A, r, du))
            return false;
        bool accepted = false;
        for (double lambda = 1; lambda > 1e-4 && !accepted; lambda /= 2) {
            /* trials by G alone (a third of the work); DG where one is kept */
            double trial[3], Gt[2], at, nt;
            for (int i = 0; i < 3; i++)
                trial[i] = u[i] + lambda * du[i];
            if (corrector_norm(b, u0, t, h, trial, Gt, NULL, &at, &nt) && nt < norm) {
                memcpy(u, trial, sizeof trial);
                arc = at;
                norm = nt;
                accepted = true;
            }
        }
        if (!accepted || !corrector_norm(b, u0, t, h, u, G, DG, &arc, &norm))
            return false;
    }
    return false;
}

static bool correct(const branch *b, const double u0[3], const double t[3], double h, double u[3],
                    int *iterations)
{
    return correct_from(b, u0, t, h, NULL, u, iterations);
}

/* Bisection of a step's arclength from a point at lo to one at hi, both
 * on the hyperplanes t . (u - u0) = lo, hi: the point at mid, from the
 * chord between them (which lies on its hyperplane), else from the
 * tangent's prediction. The chord stays on the branch's side near a
 * corner, where the tangent's prediction does not. */
static bool correct_between(const branch *b, const double u0[3], const double t[3], double lo,
                            const double ulo[3], double hi, const double uhi[3], double mid,
                            double u[3])
{
    double guess[3];
    const double w = (mid - lo) / (hi - lo);
    for (int i = 0; i < 3; i++)
        guess[i] = ulo[i] + w * (uhi[i] - ulo[i]);
    int iters;
    return correct_from(b, u0, t, mid, guess, u, &iters) || correct(b, u0, t, mid, u, &iters);
}

/* A converged point: the solution and its test functions. */
typedef struct point {
    double u[3], t[3];
    cm_fo_solution s;
    double fold, pd, ns; /* det(M - I), det(M + I), det M - 1 (complex pairs; else NaN) */
} point;

static bool describe(const branch *b, const double u[3], const double *prev_t, double direction,
                     point *pt)
{
    cm_fo o;
    cm_fo_with(&b->base, b->param, u[2], &o);
    double G[2], DG[6];
    if (!cm_fo_solution_at(&o, u, b->period, &pt->s) || !residual(b, u, G, DG) ||
        !tangent(DG, prev_t, direction, pt->t))
        return false;
    memcpy(pt->u, u, sizeof pt->u);
    pt->s.p = u[2];
    /* from the multipliers: (l1 - 1)(l2 - 1) and (l1 + 1)(l2 + 1) */
    const double tr = pt->s.mult[0][0] + pt->s.mult[1][0];
    const double det = pt->s.mult[0][0] * pt->s.mult[1][0] + pt->s.mult[0][1] * pt->s.mult[0][1];
    pt->fold = det - tr + 1;
    pt->pd = det + tr + 1;
    pt->ns = pt->s.mult[0][1] != 0 ? det - 1 : NAN;
    return true;
}

/* The direction, at the state `at` a time s later, of the tangent of
 * point pt: a point a little along the tangent carried there as pt itself
 * was; false if it is lost. */
static bool carried_along(const branch *b, const point *pt, double s, const double at[2],
                          double along[3])
{
    const double eps = 1e-6;
    cm_fo oe;
    cm_fo_with(&b->base, b->param, pt->u[2] + eps * pt->t[2], &oe);
    const double ze[2] = {pt->u[0] + eps * pt->t[0], pt->u[1] + eps * pt->t[1]};
    cm_fo_state se = {0, ze[0], ze[1], cm_fo_mode_of(&oe, 0, ze[0], ze[1])};
    if (!cm_fo_propagate(&oe, &se, s, NULL, NULL, NULL))
        return false;
    along[0] = se.x - at[0];
    along[1] = se.v - at[1];
    along[2] = eps * pt->t[2];
    return true;
}

/* Moves the section of point pt to the phase, among 64 of the period,
 * where the solution slides fastest, and pt with it (the same solution,
 * its state at the new phase); false if the phase is the parameter or
 * nothing better is found. */
static bool rephase(branch *b, point *pt)
{
    if (b->param == CM_FO_P_PHI)
        return false;
    cm_fo o;
    cm_fo_with(&b->base, b->param, pt->u[2], &o);
    cm_fo_state st = {0, pt->u[0], pt->u[1], cm_fo_mode_of(&o, 0, pt->u[0], pt->u[1])};
    double best_v = fabs(pt->u[1]), best_s = 0, at[2] = {0, 0};
    for (int i = 1; i < 64; i++) {
        const double s = o.T * i / 64;
        if (!cm_fo_propagate(&o, &st, s, NULL, NULL, NULL))
            return false;
        if (fabs(st.v) > 1.5 * best_v) {
            best_v = fabs(st.v);
            best_s = s;
            at[0] = st.x, at[1] = st.v;
        }
    }
    if (best_s == 0)
        return false;
    const double phi = fmod(b->base.phi + o.Omega * best_s, 6.283185307179586476925286766559);
    /* the tangent's direction at the new phase: the parameter's sign where
     * the branch moves in it clearly; where it is steep, a point a little
     * along the tangent carried there as the point itself was (where the
     * old phase was a bad one, its tangent's state part is unreliable) */
    const bool steep = fabs(pt->t[2]) < 0.05;
    double along[3];
    if (steep && !carried_along(b, pt, best_s, at, along))
        return false;
    branch moved = *b;
    cm_fo_init(&moved.base, b->base.S, b->base.S0, b->base.Omega, phi);
    double u[3] = {at[0], at[1], pt->u[2]};
    cm_fo_with(&moved.base, b->param, u[2], &o);
    point q;
    if (!cm_fo_periodic_point(&o, u, b->period) ||
        !describe(&moved, u, steep ? along : NULL, pt->t[2] < 0 ? -1 : 1, &q))
        return false;
    *b = moved;
    *pt = q;
    return true;
}

/* What the sticking segments of a cyclic signature adjoin: for each 's',
 * the modes before and after it, sorted ("du,ud"). Crossing-sliding
 * changes this; a slip segment that appears or goes elsewhere does not. */
static void stick_pattern(const char *sig, char *out, size_t size)
{
    const size_t n = strlen(sig);
    char pairs[CM_FO_SIGNATURE][3];
    size_t np = 0;
    for (size_t i = 0; i < n; i++)
        if (sig[i] == 's') {
            pairs[np][0] = sig[(i + n - 1) % n];
            pairs[np][1] = sig[(i + 1) % n];
            pairs[np++][2] = '\0';
        }
    for (size_t i = 1; i < np; i++) /* a few pairs: insertion sort */
        for (size_t j = i; j > 0 && strcmp(pairs[j - 1], pairs[j]) > 0; j--) {
            char t[3];
            memcpy(t, pairs[j], 3);
            memcpy(pairs[j], pairs[j - 1], 3);
            memcpy(pairs[j - 1], t, 3);
        }
    size_t used = 0;
    out[0] = '\0';
    for (size_t i = 0; i < np && used + 4 < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", i ? "," : "", pairs[i]);
}

/* Besides the reported types: a turning point of the branch in the
 * parameter where the multiplier only touches +1 (the side branch of a
 * symmetry-breaking branch point), located by the tangent's parameter
 * component and reported as a fold. */
enum { EVENT_TURN = CM_FO_EVENT_SS + 1 };

/* The pauses in a stick pattern: sticks between two slips the same way
 * ("dd", "uu"), after which the block goes on as it went. */
static int pauses(const char *pattern)
{
    int n = 0;
    for (const char *c = pattern; c[0] && c[1]; c++)
        if ((c == pattern || c[-1] == ',') && c[0] == c[1])
            n++;
    return n;
}

/* The events between a and b: bit `type` set for each. */
static unsigned events_between(const point *a, const point *b)
{
    unsigned set = 0;
    if (a->fold * b->fold < 0)
        set |= 1u << CM_FO_EVENT_SN;
    else if (a->t[2] * b->t[2] < 0)
        set |= 1u << EVENT_TURN;
    if (a->pd * b->pd < 0)
        set |= 1u << CM_FO_EVENT_PD;
    if (!isnan(a->ns) && !isnan(b->ns) && a->ns * b->ns < 0)
        set |= 1u << CM_FO_EVENT_NS;
    if (strcmp(a->s.signature, b->s.signature) != 0) {
        char pa[2 * CM_FO_SIGNATURE], pb[2 * CM_FO_SIGNATURE];
        stick_pattern(a->s.signature, pa, sizeof pa);
        stick_pattern(b->s.signature, pb, sizeof pb);
        set |= 1u << (strcmp(pa, pb) == 0                            ? CM_FO_EVENT_T
                      : pauses(pa) != pauses(pb) ? CM_FO_EVENT_SS
                                                 : CM_FO_EVENT_CS);
    }
    return set;
}

static double test_value(int type, const point *p)
{
    switch (type) {
    case CM_FO_EVENT_SN: return p->fold;
    case CM_FO_EVENT_PD: return p->pd;
    case CM_FO_EVENT_NS: return p->ns;
    case EVENT_TURN: return p->t[2];
    default: return 0;
    }
}

/* Locates the event of `type` between a and b (a step h along a's
 * tangent) by bisection of the step: test functions by sign, signatures by
 * which side they agree with, until the corrector cannot go on (at a
 * branch point the extended system is singular; where a sticking segment
 * is born the map is barely differentiable). A test function's zero is
 * interpolated between the two closest points (described by the side
 * before: the solution that the event ends); a signature change is put at
 * the last point of the old signature. */
static void locate(const branch *b, const point *a, const point *bp, double h, int type,
                   cm_fo_branch_event *e)
{
    double lo = 0, hi = h;
    point near_a = *a, near_b = *bp;
    const bool by_signature =
        type == CM_FO_EVENT_CS || type == CM_FO_EVENT_T || type == CM_FO_EVENT_SS;
    for (int it = 0; it < 60 && fabs(hi - lo) > 1e-10; it++) {
        const double mid = 0.5 * (lo + hi);
        double u[3];
        point m;
        if (!correct_between(b, a->u, a->t, lo, near_a.u, hi, near_b.u, mid, u) ||
            !describe(b, u, a->t, 0, &m))
            break;
        const bool on_a_side = by_signature
                                   ? strcmp(m.s.signature, a->s.signature) == 0
                                   : test_value(type, &m) * test_value(type, a) > 0;
        if (on_a_side) {
            lo = mid;
            near_a = m;
        } else {
            hi = mid;
            near_b = m;
        }
    }
    memset(e, 0, sizeof *e);
    e->type = type == EVENT_TURN ? CM_FO_EVENT_SN : type;
    e->fold = (type == CM_FO_EVENT_SN || type == EVENT_TURN) && a->t[2] * bp->t[2] < 0;
    e->touch = type == EVENT_TURN;
    e->at = near_a.s; /* the solution that the event ends, as it was */
    e->other = near_b.s;
    /* near a branch point the bisection may land on the other branch: the
     * kind of solution is the branch's, as at its last regular point */
    e->at.symmetric = a->s.symmetric;
    e->at.n_stick = a->s.n_stick;
    e->width = fabs(near_b.u[2] - near_a.u[2]);
    if (!by_signature) { /* the zero of the test function, linearly between them */
        const double fa = test_value(type, &near_a), fb = test_value(type, &near_b);
        const double w = fa / (fa - fb);
        e->at.p = near_a.u[2] + w * (near_b.u[2] - near_a.u[2]);
        e->at.z[0] = near_a.u[0] + w * (near_b.u[0] - near_a.u[0]);
        e->at.z[1] = near_a.u[1] + w * (near_b.u[1] - near_a.u[1]);
    }
    snprintf(e->before, sizeof e->before, "%s", a->s.signature);
    snprintf(e->after, sizeof e->after, "%s", bp->s.signature);
}

/* Steps this short are taken only at corners of a branch; where a branch
 * takes MAX_CREEP of them in a row, the map is nearly singular (a segment
 * nearly grazes a boundary: Newton converges only from within about 1e-7),
 * and the branch is given up. */
#define H_CORNER 1e-6
enum { MAX_CREEP = 200 };

/* A corrected step from a to b of length h is kept only if the branch
 * stayed near the prediction and turned little: otherwise the corrector
 * may have landed on a neighbouring branch (they lie close where sticking
 * segments appear), and a smaller step is tried, or the corner is crossed
 * (cross_corner). Steps shorter than H_CORNER may turn, as a branch does
 * at a corner at every scale, but must still end near the prediction. */
static bool step_acceptable(const point *a, const point *b, double h)
{
    double dist2 = 0, cos_turn = 0;
    for (int i = 0; i < 3; i++) {
        const double d = b->u[i] - (a->u[i] + h * a->t[i]);
        dist2 += d * d;
        cos_turn += a->t[i] * b->t[i];
    }
    const double dist = sqrt(dist2);
    return (dist <= 0.3 * h && cos_turn >= 0.95) || (h <= H_CORNER && dist <= 2 * h);
}

/* Whether parameter value p lies at the edge of the oscillator's domain
 * (S0 >= S > 0, Omega > 0), where the branch must end. */
static bool at_model_limit(const branch *b, double p)
{
    const double near = 1e-5;
    switch (b->param) {
    case CM_FO_P_S: return fabs(p - b->base.S0) < near || p < near;
    case CM_FO_P_S0: return fabs(p - b->base.S) < near;
    case CM_FO_P_OMEGA: return p < near;
    default: return false;
    }
}

/* How far G(u) moves from G(a) = Ga to the point d ahead of a along
 * direction dir, and the motion from there to ahead (may be NULL); NaN if
 * it is lost. */
static double motion_ahead(const branch *b, const point *a, const double Ga[2],
                           const double dir[3], double d, cm_fo_solution *ahead)
{
    double u[3], Gu[2];
    for (int i = 0; i < 3; i++)
        u[i] = a->u[i] + d * dir[i];
    cm_fo o;
    cm_fo_with(&b->base, b->param, u[2], &o);
    if (!residual(b, u, Gu, NULL) || (ahead && !cm_fo_solution_at(&o, u, b->period, ahead)))
        return NAN;
    return hypot(Gu[0] - Ga[0], Gu[1] - Ga[1]);
}

/* Where the corrector fails even at the smallest step: whether the
 * motion from the last point a changes just ahead along the branch, so
 * that the solution past it, if any, is no smooth continuation: its
 * signature changes (a segment meets a boundary), or P^period jumps (a
 * slip segment grazes v = 0 inside the stick band: on one side the block
 * sticks there, on the other it slides on). If so, the change as an event
 * at a, to e. */
static bool signature_breaks(const branch *b, const point *a, cm_fo_branch_event *e)
{
    /* ahead along the tangent, and in the parameter alone (where the
     * branch is steep, the tangent hardly moves it) */
    const double in_p[3] = {0, 0, a->t[2] < 0 ? -1 : 1};
    const double *const dirs[2] = {a->t, in_p};
    double Ga[2];
    if (!residual(b, a->u, Ga, NULL))
        return false;
    for (int k = 24; k >= 10; k--) {
        const double *dir = dirs[k % 2];
        const double d = pow(10, -k / 2);
        cm_fo_solution ahead;
        const double moved = motion_ahead(b, a, Ga, dir, d, &ahead);
        if (isnan(moved))
            continue;
        /* G moves by O(d) on a smooth map and by O(sqrt d) where a segment
         * is born tangentially: ten times d moves it 3 to 10 times as far,
         * unless it jumps in between */
        const bool jump = moved > 1e-6 && moved > 100 * motion_ahead(b, a, Ga, dir, d / 10, NULL);
        if (!jump && strcmp(ahead.signature, a->s.signature) == 0)
            continue;
        point next = *a;
        next.s = ahead;
        memset(e, 0, sizeof *e);
        e->jump = jump;
        const unsigned found = events_between(a, &next);
        e->type = found & (1u << CM_FO_EVENT_SS)   ? CM_FO_EVENT_SS
                  : found & (1u << CM_FO_EVENT_CS) ? CM_FO_EVENT_CS
                                                   : CM_FO_EVENT_T;
        e->at = a->s;
        e->other = a->s; /* no solution was found past it */
        snprintf(e->before, sizeof e->before, "%s", a->s.signature);
        snprintf(e->after, sizeof e->after, "%s", ahead.signature);
        return true;
    }
    return false;
}

/* Whether a turning point e found with a step h is a fold of its own, not
 * a corner where a segment appears (steps that short turn at corners) or
 * the period doubling that a branch of period 2k comes from: there it
 * meets the period-k solution, whose multiplier is -1, and turns back onto
 * its other half. */
static bool smooth_turn(const branch *b, const cm_fo_branch_event *e, double h)
{
    if (h <= H_CORNER)
        return false;
    if (b->period % 2)
        return true;
    cm_fo o;
    cm_fo_solution half;
    cm_fo_with(&b->base, b->param, e->at.p, &o);
    if (!cm_fo_solution_at(&o, e->at.z, b->period / 2, &half))
        return true;
    double end[2];
    const bool near_half = compose(&o, e->at.z, b->period / 2, end, NULL, NULL) &&
                           hypot(end[0] - e->at.z[0], end[1] - e->at.z[1]) < 1e-3;
    const bool flips = half.mult[0][1] == 0 &&
                       (fabs(half.mult[0][0] + 1) < 1e-2 || fabs(half.mult[1][0] + 1) < 1e-2);
    return !(near_half && flips);
}

/* A step of length h from a that is not smooth and changes the signature
 * crosses a corner of the branch, where a segment appears or vanishes:
 * the step is bisected to the corner, and the first point past it, in
 * *out, goes on along its own side's tangent, oriented away from a. False
 * where the corner cannot be closed in on (the corrector fails: the
 * branch ends there, or the new signature lies on another branch). */
/* A step of length h from a that is not smooth and changes the signature
 * may cross a corner of the branch, where a segment appears or vanishes:
 * the step is bisected to where the signature changes (as far as the
 * corrector converges), and if the points on either side are as close as
 * the bracket (the branch is continuous there, not a jump onto another
 * one), the first point past it, in *out, goes on
 * along its own side's tangent, oriented away from a; the step's length
 * to it goes to *h. False where there
 * is no such corner (or the corrector fails: the branch ends there). */
static bool cross_corner(const branch *b, const point *a, double *h, point *out)
{
    double lo = 0, hi = *h;
    point before = *a, after;
    bool found = false;
    while (hi - lo > 1e-13 * fmax(1, *h)) {
        const double mid = 0.5 * (lo + hi);
        double u[3];
        point m;
        if (!correct_between(b, a->u, a->t, lo, before.u, hi, found ? after.u : a->u, mid, u) ||
            !describe(b, u, a->t, 0, &m))
            break; /* the map is barely differentiable at the corner */
        if (strcmp(m.s.signature, a->s.signature) == 0) {
            lo = mid;
            before = m;
        } else {
            hi = mid;
            after = m;
            found = true;
        }
    }
    double gap2 = 0, away = 0;
    for (int i = 0; i < 3 && found; i++) {
        gap2 += (after.u[i] - before.u[i]) * (after.u[i] - before.u[i]);
        away += after.t[i] * (after.u[i] - a->u[i]);
    }
    if (!found || sqrt(gap2) > 1e-6 + 10 * (hi - lo))
        return false;
    *out = after;
    *h = hi;
    if (away < 0)
        for (int i = 0; i < 3; i++)
            out->t[i] = -out->t[i];
    return true;
}

/* Whether the segment from a to b (n coordinates) passes through s, to 5%
 * of its length. */
static bool segment_passes(int n, const double *a, const double *b, const double *s)
{
    double dd = 0, rd = 0;
    for (int i = 0; i < n; i++) {
        dd += (b[i] - a[i]) * (b[i] - a[i]);
        rd += (s[i] - a[i]) * (b[i] - a[i]);
    }
    const double w = dd > 0 ? rd / dd : -1;
    if (w < 0 || w > 1)
        return false;
    double off2 = 0;
    for (int i = 0; i < n; i++) {
        const double d = s[i] - a[i] - w * (b[i] - a[i]);
        off2 += d * d;
    }
    return off2 <= 0.0025 * dd + 1e-18;
}

/* Whether the branch, going from a to b, passes through the solution s
 * (it has closed into a loop), in the solution's parameter and range of
 * x, which do not depend on the section's phase. */
static bool passes_by(const cm_fo_solution *s, const cm_fo_solution *a, const cm_fo_solution *b)
{
    const double sa[3] = {s->p, s->x_max, s->x_min};
    const double aa[3] = {a->p, a->x_max, a->x_min};
    const double ba[3] = {b->p, b->x_max, b->x_min};
    return segment_passes(3, aa, ba, sa);
}

int cm_fo_continue(const cm_fo *o, const cm_fo_continue_options *opt, double p0,
                   const double z[2], int period, cm_fo_point_fn on_point,
                   cm_fo_event_fn2 on_event, void *user, int *stop)
{
    branch b = {*o, opt->param, period};
    const double h_min = opt->h_min > 0 ? opt->h_min : 1e-9;
    const double h_max = opt->h_max > 0 ? opt->h_max : 2e-2;
    const int max_points = opt->max_points > 0 ? opt->max_points : 5000;
    double h = opt->h0 > 0 ? opt->h0 : 1e-3;
    point cur;
    const double u0[3] = {z[0], z[1], p0};
    *stop = CM_FO_STOP_LOST;
    if (!describe(&b, u0, NULL, opt->direction < 0 ? -1 : 1, &cur))
        return 0;
    rephase(&b, &cur); /* or stay where it is */
    const cm_fo_solution start = cur.s;
    int creep = 0; /* steps in a row no longer than H_CORNER */
    bool rephased = false; /* at this point already */
    int n = 1;
    if (on_point && on_point(user, &cur.s)) {
        *stop = CM_FO_STOP_POINTS;
        return n;
    }
    while (n < max_points) {
        double u[3];
        int iters = 0;
        point next;
        bool ok = correct(&b, cur.u, cur.t, h, u, &iters) && describe(&b, u, cur.t, 0, &next);
        double step = h;
        if (ok && !step_acceptable(&cur, &next, h)) {
            ok = strcmp(cur.s.signature, next.s.signature) != 0 &&
                 cross_corner(&b, &cur, &step, &next);
            if (ok) {
                h = fmin(h, 1e-4); /* the new side, from a short step */
                iters = 4;
            }
        }
        if (!ok) {
            h /= 2;
            if (h >= h_min)
                continue;
            if (rephased || !rephase(&b, &cur)) {
                cm_fo_branch_event e;
                *stop = CM_FO_STOP_STEP;
                if (at_model_limit(&b, cur.u[2]))
                    *stop = CM_FO_STOP_BOUND;
                else if (signature_breaks(&b, &cur, &e)) {
                    *stop = CM_FO_STOP_SIGNATURE;
                    if (on_event)
                        on_event(user, &e);
                }
                return n;
            }
            rephased = true;
            h = opt->h0 > 0 ? opt->h0 : 1e-3;
            continue;
        }
        rephased = false;
        const unsigned found = on_event ? events_between(&cur, &next) : 0;
        for (int type = 0; type <= EVENT_TURN; type++) {
            if (!(found & (1u << type)))
                continue;
            cm_fo_branch_event e;
            locate(&b, &cur, &next, step, type, &e);
            if (type == EVENT_TURN &&
                (strcmp(cur.s.signature, next.s.signature) != 0 || !smooth_turn(&b, &e, step)))
                continue; /* a corner turns the branch: the CS event says so */
            /* a test function that changes sign only where the signature
             * does jumps at the corner: no event of its own */
            if (type <= CM_FO_EVENT_NS || type == EVENT_TURN)
                if (strcmp(e.at.signature, e.other.signature) != 0)
                    continue;
            if (on_event(user, &e)) {
                *stop = CM_FO_STOP_POINTS;
                return n;
            }
        }
        const bool closes = n > 3 && passes_by(&start, &cur.s, &next.s);
        creep = step <= H_CORNER ? creep + 1 : 0;
        cur = next;
        n++;
        if (on_point && on_point(user, &cur.s)) {
            *stop = CM_FO_STOP_POINTS;
            return n;
        }
        if (closes) {
            *stop = CM_FO_STOP_LOOP;
            return n;
        }
        if (creep == MAX_CREEP) {
            *stop = CM_FO_STOP_STEP;
            return n;
        }
        if (cur.u[2] < opt->lo || cur.u[2] > opt->hi) {
            *stop = CM_FO_STOP_BOUND;
            return n;
        }
        /* a short step grows whatever Newton needed: near a corner it needs
         * many iterations, and would creep up to it */
        if (iters <= 3 || h <= H_CORNER)
            h = fmin(h * 1.5, h_max);
    }
    *stop = CM_FO_STOP_POINTS;
    return n;
}

bool cm_fo_period_doubled(const cm_fo *o, int param, const cm_fo_branch_event *e, double z[2],
                          double *p)
{
    if (e->type != CM_FO_EVENT_PD)
        return false;
    const int k = e->at.period;
    cm_fo at;
    cm_fo_with(o, param, e->at.p, &at);
    cm_fo_init(&at, at.S, at.S0, at.Omega, param == CM_FO_P_PHI ? e->at.p : e->at.phi);
    double end[2], M[4];
    if (!compose(&at, e->at.z, k, end, M, NULL))
        return false;
    /* the null vector of M + I, from its larger row */
    double v[2] = {-M[1], M[0] + 1};
    if (hypot(M[2], M[3] + 1) > hypot(M[0] + 1, M[1]))
        v[0] = M[3] + 1, v[1] = -M[2];
    const double n = hypot(v[0], v[1]);
    if (!(n > 0))
        return false;
    const double scale = fmax(1e-3, fabs(e->at.p));
    for (int side = -1; side <= 1; side += 2)
        for (double eps = 3e-2; eps > 1e-3; eps /= 3) {
            cm_fo past;
            const double q = e->at.p + side * 1e-3 * scale;
            cm_fo_with(&at, param, q, &past);
            double guess[2] = {e->at.z[0] + eps * v[0] / n, e->at.z[1] + eps * v[1] / n};
            if (!cm_fo_periodic_point(&past, guess, 2 * k) ||
                !compose(&past, guess, k, end, NULL, NULL) ||
                hypot(end[0] - guess[0], end[1] - guess[1]) < 1e-6) /* the period-k one */
                continue;
            z[0] = guess[0];
            z[1] = guess[1];
            *p = q;
            return true;
        }
    return false;
}

double cm_fo_turn_h(double t, double Omega)
{
    const double a = 3.14159265358979323846 / Omega;
    const double den = Omega * sin(Omega * t) * (1 + cos(a));
    return (sin(t) + sin(a) * cos(Omega * t) + sin(t - a)) / den;
}

double cm_fo_turn_hmax_at(double Omega, double *t_max)
{
    const double w = Omega, a = 3.14159265358979323846 / w;
    double best = 1 / (w * w); /* the limit at t -> 0 (2.30) */
    *t_max = 0;
    enum { SAMPLES = 4000 };
    for (int i = 0; i < SAMPLES; i++) {
        const double t = (i + 0.5) * a / SAMPLES, H = cm_fo_turn_h(t, w);
        if (isfinite(H) && H > best)
            best = H, *t_max = t;
    }
    return best;
}

double cm_fo_turn_hmax(double Omega)
{
    double t;
    return cm_fo_turn_hmax_at(Omega, &t);
}

/* The symmetric non-sticking solution at o: from its turnaround (x0, 0) at
 * phase `phase`, a quarter period on (off the turnaround, where P is
 * smooth), refined by Newton; its multipliers if its cycle never sticks. */
static bool symmetric_solution(const cm_fo *o, double x0, double phase, cm_fo_solution *s)
{
    cm_fo at_turn, quarter;
    cm_fo_init(&at_turn, o->S, o->S0, o->Omega, phase);
    cm_fo_state st = {0, x0, 0, cm_fo_mode_of(&at_turn, 0, x0, 0)};
    if (!cm_fo_propagate(&at_turn, &st, at_turn.T / 4, NULL, NULL, NULL))
        return false;
    cm_fo_init(&quarter, o->S, o->S0, o->Omega, fmod(phase + 1.5707963267948966, 6.283185307179586));
    double z[2] = {st.x, st.v};
    return cm_fo_periodic_point(&quarter, z, 1) && cm_fo_solution_at(&quarter, z, 1, s) &&
           strchr(s->signature, 's') == NULL && fabs(s->x_max - x0) < 1e-6 * fmax(1, x0);
}

void cm_fo_amplitude_at(const cm_fo *o, int periods, int record, cm_fo_amplitude *out)
{
    double x0 = NAN, phase = 0;
    if (!cm_fo_symmetric_amplitude(o->S, o->Omega, &x0, &phase))
        x0 = NAN;
    out->x0 = x0;
    out->slip_limit = o->S0 / (o->Omega * o->Omega);
    out->turn_limit = o->S * cm_fo_turn_hmax(o->Omega);
    out->valid = x0 >= out->slip_limit && x0 >= out->turn_limit;
    out->mult_max = NAN;
    out->stable = false;
    cm_fo_solution s;
    if (out->valid && symmetric_solution(o, x0, phase, &s)) {
        out->mult_max = hypot(s.mult[0][0], s.mult[0][1]);
        out->stable = s.stable;
    }
    /* the simulation */
    cm_fo start;
    cm_fo_init(&start, o->S, o->S0, o->Omega, 0);
    double z[2] = {1 + 0.9 * o->S0, 0}, lo = INFINITY, hi = -INFINITY;
    int sticks = 0;
    bool lost = false;
    for (int k = 0; k < periods && !lost; k++) {
        cm_fo_tally t;
        lost = !cm_fo_poincare(&start, z, z, k >= periods - record ? &t : NULL, NULL, NULL);
        if (!lost && k >= periods - record) {
            lo = fmin(lo, t.x_min);
            hi = fmax(hi, t.x_max);
            sticks += t.n_stick;
        }
    }
    out->sim_amplitude = lost ? NAN : (hi - lo) / 2;
    out->sim_sticks = lost ? NAN : (double)sticks / record;
}

/* ---- two-parameter curves -------------------------------------------- */

typedef struct curve {
    cm_fo base; /* phase of the event */
    int param, param2, period;
    double sign; /* -1: det(M - I) (SN); +1: det(M + I) (PD) */
} curve;

/* F(u) at u = (x, v, p, p2): P^k(z) - z and det(M + sign I). */
static bool curve_f(const curve *c, const double u[4], double F[3])
{
    cm_fo a, o;
    cm_fo_with(&c->base, c->param, u[2], &a);
    cm_fo_with(&a, c->param2, u[3], &o);
    double end[2], M[4];
    if (!compose(&o, u, c->period, end, M, NULL))
        return false;
    F[0] = end[0] - u[0];
    F[1] = end[1] - u[1];
    F[2] = (M[0] + c->sign) * (M[3] + c->sign) - M[1] * M[2];
    return isfinite(F[2]);
}

/* DF (3 x 4, row-major) by central differences. */
static bool curve_jacobian(const curve *c, const double u[4], double J[12])
{
    for (int col = 0; col < 4; col++) {
        const double h = 1e-7 * fmax(1, fabs(u[col]));
        double up[4], um[4], Fp[3], Fm[3];
        memcpy(up, u, sizeof up);
        memcpy(um, u, sizeof um);
        up[col] += h;
        um[col] -= h;
        if (!curve_f(c, up, Fp) || !curve_f(c, um, Fm))
            return false;
        for (int row = 0; row < 3; row++)
            J[4 * row + col] = (Fp[row] - Fm[row]) / (2 * h);
    }
    return true;
}

static double det3(const double *a, const double *b, const double *c)
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* The unit null vector of the 3 x 4 matrix J (signed cofactors), oriented
 * along prev (or with the sign of `direction` in component 3). */
static bool curve_tangent(const double J[12], const double *prev, int direction, double t[4])
{
    double n2 = 0;
    for (int k = 0; k < 4; k++) {
        double r[3][3];
        for (int row = 0; row < 3; row++)
            for (int col = 0, m = 0; col < 4; col++)
                if (col != k)
                    r[row][m++] = J[4 * row + col];
        t[k] = (k % 2 ? -1 : 1) * det3(r[0], r[1], r[2]);
        n2 += t[k] * t[k];
    }
    if (!(n2 > 0) || !isfinite(n2))
        return false;
    double dot = 0;
    for (int k = 0; k < 4; k++)
        dot += prev ? t[k] * prev[k] : 0;
    const double s = (prev ? dot : t[3] * direction) < 0 ? -1 : 1;
    for (int k = 0; k < 4; k++)
        t[k] *= s / sqrt(n2);
    return true;
}

/* Solves the 4 x 4 system A x = b by Gaussian elimination with pivoting. */
static bool solve4(double A[16], double b[4], double x[4])
{
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(A[4 * r + c]) > fabs(A[4 * piv + c]))
                piv = r;
        if (A[4 * piv + c] == 0)
            return false;
        for (int k = 0; k < 4; k++) {
            const double t = A[4 * c + k];
            A[4 * c + k] = A[4 * piv + k];
            A[4 * piv + k] = t;
        }
        const double tb = b[c];
        b[c] = b[piv];
        b[piv] = tb;
        for (int r = c + 1; r < 4; r++) {
            const double f = A[4 * r + c] / A[4 * c + c];
            for (int k = c; k < 4; k++)
                A[4 * r + k] -= f * A[4 * c + k];
            b[r] -= f * b[c];
        }
    }
    for (int r = 3; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < 4; k++)
            s -= A[4 * r + k] * x[k];
        x[r] = s / A[4 * r + r];
    }
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(x[3]);
}

/* Newton onto F = 0 with t . (u - u0) = h, damped as the branch corrector. */
static bool curve_correct(const curve *c, const double u0[4], const double t[4], double h,
                          double u[4], int *iterations)
{
    for (int k = 0; k < 4; k++)
        u[k] = u0[k] + h * t[k];
    for (int it = 0; it < 30; it++) {
        double F[3], J[12];
        if (!curve_f(c, u, F) || !curve_jacobian(c, u, J))
            return false;
        double arc = -h;
        for (int k = 0; k < 4; k++)
            arc += t[k] * (u[k] - u0[k]);
        const double norm = sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2] + arc * arc);
        if (hypot(F[0], F[1]) < 1e-11 && fabs(F[2]) < 1e-9 && fabs(arc) < 1e-10) {
            *iterations = it;
            return true;
        }
        double A[16], b[4] = {-F[0], -F[1], -F[2], -arc}, du[4];
        memcpy(A, J, sizeof J);
        memcpy(A + 12, t, 4 * sizeof *t);
        if (!solve4(A, b, du))
            return false;
        bool accepted = false;
        for (double lambda = 1; lambda > 1e-4 && !accepted; lambda /= 2) {
            double trial[4], Ft[3], at = -h;
            for (int k = 0; k < 4; k++) {
                trial[k] = u[k] + lambda * du[k];
                at += t[k] * (trial[k] - u0[k]);
            }
            if (curve_f(c, trial, Ft) &&
                sqrt(Ft[0] * Ft[0] + Ft[1] * Ft[1] + Ft[2] * Ft[2] + at * at) < norm) {
                memcpy(u, trial, sizeof trial);
                accepted = true;
            }
        }
        if (!accepted)
            return false;
    }
    return false;
}

/* ---- signature boundaries in two parameters ---------------------------- */

/* The state at phase phi of the periodic motion through z at phase o->phi
 * (in place): z propagated over the phase difference. */
static bool to_phase(const cm_fo *o, double phi, double z[2])
{
    const double two_pi = 6.283185307179586476925286766559;
    const double dphi = fmod(fmod(phi - o->phi, two_pi) + two_pi, two_pi);
    cm_fo_state st = {0, z[0], z[1], cm_fo_mode_of(o, 0, z[0], z[1])};
    if (dphi > 0 && !cm_fo_propagate(o, &st, dphi / o->Omega, NULL, NULL, NULL))
        return false;
    z[0] = st.x;
    z[1] = st.v;
    return true;
}

/* The old side of a signature boundary, as it moves: the solution with
 * signature `before`, last seen at (p, p2) in state z at phase phi. */
typedef struct boundary {
    cm_fo base; /* the other parameters */
    int param, param2, period;
    const char *before;
    double toward; /* the sign of the step in param from the old side to the boundary */
    double p, p2, phi, z[2];
} boundary;

static int keep_last(void *user, const cm_fo_solution *s)
{
    *(cm_fo_solution *)user = *s;
    return 0;
}

/* The solution of signature `before` at (p, p2), into z at phase *phi:
 * from the boundary's last point, first along the branch in param away
 * from it (Newton from the boundary's state at fixed parameters may jump
 * across it, where the map does), then by Newton in small steps of p2. */
static bool old_side_at(const boundary *w, double p, double p2, double z[2], double *phi)
{
    enum { SUBSTEPS = 8 };
    cm_fo a, o;
    cm_fo_with(&w->base, w->param, w->p, &a);
    cm_fo_with(&a, w->param2, w->p2, &o);
    cm_fo_init(&o, o.S, o.S0, o.Omega, w->phi);
    const double away = fabs(p - w->p);
    const cm_fo_continue_options opt = {w->param, fmin(w->p, p), fmax(w->p, p), p > w->p ? 1 : -1,
                                        away / 10, 0, away / 2, 100};
    cm_fo_solution last = {.p = NAN};
    int stop;
    cm_fo_continue(&o, &opt, w->p, w->z, w->period, keep_last, NULL, &last, &stop);
    if (stop != CM_FO_STOP_BOUND || strcmp(last.signature, w->before) != 0)
        return false;
    z[0] = last.z[0], z[1] = last.z[1];
    *phi = last.phi;
    for (int k = 0; k <= SUBSTEPS; k++) { /* k = 0: onto p itself */
        cm_fo_with(&w->base, w->param, p, &a);
        cm_fo_with(&a, w->param2, w->p2 + (double)k / SUBSTEPS * (p2 - w->p2), &o);
        cm_fo_init(&o, o.S, o.S0, o.Omega, *phi);
        cm_fo_solution s;
        if (!cm_fo_periodic_point(&o, z, w->period) || !cm_fo_solution_at(&o, z, w->period, &s) ||
            strcmp(s.signature, w->before) != 0)
            return false;
    }
    return true;
}

typedef struct catch_change {
    const char *before;
    bool found;
    cm_fo_branch_event e;
} catch_change;

static int catch_signature_change(void *user, const cm_fo_branch_event *e)
{
    catch_change *c = user;
    if (e->type >= CM_FO_EVENT_CS && strcmp(e->before, c->before) == 0) {
        c->e = *e;
        c->found = true;
        return 1;
    }
    return 0;
}

/* The boundary at p2: from the old side, a little before where it was,
 * the branch in param is followed towards it until the signature changes;
 * w moves there. */
static bool relocate(boundary *w, double p2, double lo, double hi)
{
    for (double back = 1e-4; back < 0.05; back *= 10) {
        const double p = w->p - w->toward * back;
        double z[2], phi;
        if (p < lo || p > hi || !old_side_at(w, p, p2, z, &phi))
            continue;
        cm_fo a, o;
        cm_fo_with(&w->base, w->param, p, &a);
        cm_fo_with(&a, w->param2, p2, &o);
        cm_fo_init(&o, o.S, o.S0, o.Omega, phi);
        /* the boundary moved by about as much as the last step moved it */
        const cm_fo_continue_options opt = {w->param, fmax(lo, p - 10 * back),
                                            fmin(hi, p + 10 * back), w->toward, back / 10, 1e-8,
                                            back, 100};
        catch_change c = {w->before, false, {0}};
        int stop;
        cm_fo_continue(&o, &opt, p, z, w->period, NULL, catch_signature_change, &c, &stop);
        if (!c.found)
            continue;
        w->p = c.e.at.p;
        w->p2 = p2;
        w->phi = c.e.at.phi;
        w->z[0] = c.e.at.z[0], w->z[1] = c.e.at.z[1];
        return true;
    }
    return false;
}

/* Hands the boundary's point to on_point, its state at phase phi, and
 * counts it; false when the curve is to end (on_point says so, or the
 * state cannot be moved to phi). */
static bool emit_boundary(const boundary *w, double phi, cm_fo_curve_fn on_point, void *user,
                          int *n)
{
    double z[2] = {w->z[0], w->z[1]};
    cm_fo a, at;
    cm_fo_with(&w->base, w->param, w->p, &a);
    cm_fo_with(&a, w->param2, w->p2, &at);
    cm_fo_init(&at, at.S, at.S0, at.Omega, w->phi);
    if (!to_phase(&at, phi, z))
        return false;
    (*n)++;
    return !(on_point && on_point(user, w->p, w->p2, z));
}

/* A CS, SS or T event e continued in two parameters by relocation: p2
 * moves in steps, and at each the event is located again on the branch in
 * param (the one-parameter machinery, which crosses the corners and finds
 * where the map jumps). Ends where p2 leaves its range, or where the
 * event cannot be found again (the boundary turns back in p2, or ends). */
static int boundary_curve(const cm_fo *o, const cm_fo_branch_event *e, int param, int param2,
                          const double lo[2], const double hi[2], int direction, int max_points,
                          cm_fo_curve_fn on_point, void *user)
{
    boundary w = {*o, param, param2, e->at.period, e->before, 0, e->at.p,
                  (double[4]){o->S, o->S0, o->Omega, o->phi}[param2], e->at.phi,
                  {e->at.z[0], e->at.z[1]}};
    /* the old side: where the solution has the signature before the event */
    for (double d = 1e-6; d < 2e-3 && w.toward == 0; d *= 10)
        for (int side = -1; side <= 1 && w.toward == 0; side += 2) {
            double z[2], phi;
            if (old_side_at(&w, e->at.p + side * d, w.p2, z, &phi))
                w.toward = -side;
        }
    if (w.toward == 0)
        return 0;
    const double span = hi[1] - lo[1];
    double step = span / 200;
    int n = 0;
    if (!emit_boundary(&w, e->at.phi, on_point, user, &n))
        return n;
    while (n < max_points) {
        const double p2 = w.p2 + direction * step;
        if (p2 < lo[1] || p2 > hi[1])
            break;
        if (!relocate(&w, p2, lo[0], hi[0])) {
            if ((step /= 4) < 1e-4 * span)
                break;
            continue;
        }
        step = fmin(1.5 * step, span / 50);
        if (!emit_boundary(&w, e->at.phi, on_point, user, &n))
            break;
    }
    return n;
}

int cm_fo_continue_curve(const cm_fo *o, const cm_fo_branch_event *e, int param, int param2,
                         const double lo[2], const double hi[2], int direction, int max_points,
                         cm_fo_curve_fn on_point, void *user)
{
    if (param == param2 || param == CM_FO_P_PHI || param2 == CM_FO_P_PHI)
        return 0;
    if (e->type >= CM_FO_EVENT_CS)
        return boundary_curve(o, e, param, param2, lo, hi, direction, max_points, on_point, user);
    if (e->type == CM_FO_EVENT_NS)
        return 0;
    curve c = {*o, param, param2, e->at.period, e->type == CM_FO_EVENT_SN ? -1.0 : 1.0};
    cm_fo_init(&c.base, o->S, o->S0, o->Omega, e->at.phi);
    const double p2 = (double[4]){o->S, o->S0, o->Omega, o->phi}[param2];
    double u[4] = {e->at.z[0], e->at.z[1], e->at.p, p2}, J[12], t[4], prev[4];
    int iters;
    /* the located point is interpolated: onto the curve first, at fixed p2 */
    const double fix[4] = {0, 0, 0, 1};
    if (!curve_correct(&c, u, fix, 0, u, &iters) || !curve_jacobian(&c, u, J) ||
        !curve_tangent(J, NULL, direction, t))
        return 0;
    int n = 0;
    if (on_point && on_point(user, u[2], u[3], u))
        return 1;
    n++;
    double h = 1e-3, start[4];
    memcpy(start, u, sizeof start);
    int creep = 0;
    while (n < max_points) {
        double next[4];
        if (!curve_correct(&c, u, t, h, next, &iters)) {
            h /= 2;
            if (h < 1e-8)
                break;
            continue;
        }
        memcpy(prev, t, sizeof prev);
        if (!curve_jacobian(&c, next, J) || !curve_tangent(J, prev, direction, t))
            break;
        /* back at the start (a closed curve, or one that retraces itself
         * through a singular point), or creeping: done */
        const bool closes = n > 3 && segment_passes(4, u, next, start);
        creep = h <= H_CORNER ? creep + 1 : 0;
        memcpy(u, next, sizeof next);
        n++;
        if (on_point && on_point(user, u[2], u[3], u))
            break;
        if (closes || creep == MAX_CREEP)
            break;
        if (u[2] < lo[0] || u[2] > hi[0] || u[3] < lo[1] || u[3] > hi[1])
            break;
        if (iters <= 3 || h <= H_CORNER)
            h = fmin(2 * h, 2e-2);
    }
    return n;
}

const char *cm_fo_event_name(int type)
{
    static const char *const names[] = {"SN", "PD", "NS", "CS", "T", "SS"};
    return type >= 0 && type < 6 ? names[type] : "?";
}

const char *cm_fo_stop_name(int stop)
{
    /* (parentheses: the split literals are meant) */
    static const char *const names[] = {
        "the parameter left its range",
        "the point limit",
        ("the corrector failed at the smallest step, or crept below 1e-6 for 200 points (the "
         "map is nearly singular there)"),
        "the motion could not be followed",
        "a change of signature or a jump of the map it cannot follow",
        ("the branch came back to its start (a loop, or from a period doubling the orbit's "
         "other point)")};
    return stop >= 0 && stop < 6 ? names[stop] : "?";
}
