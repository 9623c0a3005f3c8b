/* 2D micro-chaos map of the PD-controlled inverted pendulum (4.66).
 * docs/models.md 6. */
#include "models/microchaos_pd.h"

#include <math.h>
#include <string.h>

#include "models/models.h"
#include "models/params.h"

const cm_param_spec cm_microchaos_pd_spec[] = {
    {"alpha", "0.078", 1e-12, 1e3, 1, NULL, "alpha = tau sqrt(k/M) > 0 (4.59)"},
    {"beta", "0", -1e3, 1e3, 1, NULL, "beta = d tau/(2M), damping (4.59)"},
    {"P", "0.007", -1e6, 1e6, 1, NULL, "proportional gain P = P~ tau^2/M (4.59)"},
    {"D", "0.02", -1e6, 1e6, 1, NULL, "derivative gain D = D~ tau/M (4.59)"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

void cm_pd_coefficients(double alpha, double beta, double P, double D, cm_pd_coef *c)
{
    const double a2 = alpha * alpha;
    const double g = sqrt(a2 + beta * beta);
    const double s = sinh(g), ch = cosh(g), e = exp(beta);
    memset(c, 0, sizeof *c);
    c->alpha = alpha;
    c->beta = beta;
    c->P = P;
    c->D = D;
    c->gamma = g;
    c->A[0] = (g * ch + beta * s) / (e * g);
    c->A[1] = s / (e * g);
    c->A[2] = a2 * s / (e * g);
    c->A[3] = (g * ch - beta * s) / (e * g);
    c->b[0] = (e - ch) / (e * a2) - beta * s / (e * g * a2);
    c->b[1] = -s / (e * g);
    c->S[0] = c->A[0] + c->b[0] * P;
    c->S[1] = c->A[1] + c->b[0] * D;
    c->S[2] = c->A[2] + c->b[1] * P;
    c->S[3] = c->A[3] + c->b[1] * D;
    c->lambda_u = exp(g - beta);
    c->lambda_s = exp(-g - beta);
    c->e_u[0] = 1.0;
    c->e_u[1] = g - beta;
    c->e_s[0] = 1.0;
    c->e_s[1] = -g - beta;
}

void cm_pd_switching_line(double P, double D, int64_t m, double *slope, double *intercept)
{
    *slope = -P / D;
    *intercept = (double)m / D;
}

void cm_pd_stability_at(double alpha, double beta, double P, double D, cm_pd_stability *st)
{
    const double a2 = alpha * alpha;
    const double g = sqrt(a2 + beta * beta);
    const double s = sinh(g), c = cosh(g), e = exp(beta);
    st->p = ((s * D - 2 * g * c) * a2 - P * (g * (e - c) - beta * s)) / (e * g * a2);
    st->q = (g * a2 - D * e * s * a2 - P * (e * beta * s - e * g * c + g)) / (e * e * g * a2);
    st->b2 = (P - a2) * g * (2 * c * e - 1 - e * e);
    st->b1 = -a2 * (-2 * s * D * e + 2 * g * (1 - e * e)) - 2 * P * (e * c * g - e * s * beta - g);
    st->b0 = a2 * (g * (e * e + 1 + 2 * c * e) - 2 * s * D * e) -
             P * (2 * e * s * beta + g * (1 - e * e));
    st->D_b0 = (a2 * (1 + 2 * c * e + e * e) * g + P * ((e * e - 1) * g - 2 * beta * e * s)) /
               (2 * a2 * e * s);
    st->D_b1 = (a2 * (g - e * e * g) + P * ((c * e - 1) * g - beta * e * s)) / (a2 * e * s);
    st->stable = st->b0 > 0 && st->b1 > 0 && st->b2 > 0;
}

double cm_pd_P_max(double alpha, double beta)
{
    const double g = sqrt(alpha * alpha + beta * beta);
    const double c = cosh(g), e = exp(beta);
    return alpha * alpha * (1 - 2 * c * e - 3 * e * e) / (1 - 2 * c * e + e * e);
}

double cm_pd_D_at_P_max(double alpha, double beta)
{
    const double g = sqrt(alpha * alpha + beta * beta);
    const double s = sinh(g), c = cosh(g), e = exp(beta);
    const double den = 2 * c * e - e * e - 1;
    return (-3 * e + 2 * c * c * e + e * e * e + c * (-1 + e * e)) * g / (den * s) +
           (1 - 2 * c * e - 3 * e * e) * beta / den;
}

void cm_pd_eigen_curves_at(double alpha, double beta, double P, cm_pd_eigen_curves *out)
{
    const double a2 = alpha * alpha;
    const double g = sqrt(a2 + beta * beta);
    const double s = sinh(g), c = cosh(g), e = exp(beta);
    out->D_1 = (2 * c * g * a2 + (e * g - c * g - beta * s) * P) / (a2 * s);
    out->D_0 = (g * a2 + (c * e * g - g - beta * e * s) * P) / (a2 * e * s);
    const double mid = (g * (P - 2 * a2) * (e - c) - P * beta * s) / (a2 * s);
    const double r = (a2 - P) * (1 + e * e - 2 * e * c); /* >= 0 for P >= alpha^2 */
    const double half = r >= 0 ? 2 * g * sqrt(r) / (alpha * s) : NAN;
    out->D_c_minus = mid - half;
    out->D_c_plus = mid + half;
}

double cm_pd_P_quick(double alpha, double beta)
{
    const double g = sqrt(alpha * alpha + beta * beta);
    const double c = cosh(g), e = exp(beta);
    return alpha * alpha * (1 - 2 * c * e) / (1 - 2 * c * e + e * e);
}

/* x - origin in the eigenbasis of A: x - origin = a e_u + b e_s. */
static void eigen_coordinates(const cm_pd_coef *k, const double origin[2], const double x[2],
                              double *a, double *b)
{
    const double dx = x[0] - origin[0], dv = x[1] - origin[1];
    const double det = k->e_s[1] - k->e_u[1]; /* e_u = (1, u), e_s = (1, s): det [e_u e_s] */
    *a = (dx * k->e_s[1] - dv) / det;
    *b = (dv - dx * k->e_u[1]) / det;
}

/* f restricted to level q: A x + b q. */
static void restricted(const cm_pd_coef *k, double q, const double x[2], double y[2])
{
    y[0] = k->A[0] * x[0] + k->A[1] * x[1] + k->b[0] * q;
    y[1] = k->A[2] * x[0] + k->A[3] * x[1] + k->b[1] * q;
}

void cm_pd_horseshoe_at(double alpha, double beta, double P, double D, int64_t m,
                        cm_pd_horseshoe *h)
{
    cm_pd_coef k;
    cm_pd_coefficients(alpha, beta, P, D, &k);
    const double a2 = alpha * alpha, g = k.gamma, md = (double)m, gb = g - beta;
    h->m = m;
    h->x_l[0] = (md - 1) / a2, h->x_l[1] = 0;
    h->x_r[0] = md / a2, h->x_r[1] = 0;
    h->RULS[0] = (-beta + (2 * md - 1) * g) / (2 * a2 * g), h->RULS[1] = -1 / (2 * g);
    h->LURS[0] = (beta + (2 * md - 1) * g) / (2 * a2 * g), h->LURS[1] = 1 / (2 * g);
    const double den = a2 * (P + D * gb);
    h->RUSW[0] = (a2 + D * gb) * md / den, h->RUSW[1] = gb * md * (a2 - P) / den;
    h->LUSW[0] = (D * gb * (md - 1) + a2 * md) / den;
    h->LUSW[1] = gb * (a2 * md - P * (md - 1)) / den;
    const double *corner[2] = {h->LUSW, h->RUSW};
    for (int i = 0; i < 2; i++) {
        double y[2], a, b;
        restricted(&k, md - 1, corner[i], y); /* f_l: right of W_R^S */
        eigen_coordinates(&k, h->x_r, y, &a, &b);
        h->escape[i] = a > 0;
        restricted(&k, md, corner[i], y); /* f_r: left of W_L^S */
        eigen_coordinates(&k, h->x_l, y, &a, &b);
        h->escape[2 + i] = a < 0;
    }
    h->stretches = h->escape[0] || h->escape[1] || h->escape[2] || h->escape[3];
    h->full_shift = h->escape[0] && h->escape[1] && h->escape[2] && h->escape[3];
}

uint64_t cm_pd_horseshoe_periodic(double alpha, double beta, double P, double D, int64_t m, int n)
{
    if (n < 1 || n > 24)
        return 0;
    cm_pd_coef k;
    cm_pd_coefficients(alpha, beta, P, D, &k);
    cm_pd_horseshoe h;
    cm_pd_horseshoe_at(alpha, beta, P, D, m, &h);
    double a_r, b_r; /* Q_m: 0 <= a <= a_r, b between 0 and b_r, from x_l* */
    eigen_coordinates(&k, h.x_l, h.x_r, &a_r, &b_r);
    /* A^n and the powers for the fixed point of the composition */
    uint64_t count = 0;
    for (uint64_t word = 0; word < (UINT64_C(1) << n); word++) {
        /* x = F(x), F = f_{s_n} o ... o f_{s_1}: x = M x + c with M = A^n */
        double M[4] = {1, 0, 0, 1}, c[2] = {0, 0};
        for (int j = 0; j < n; j++) {
            const double q = (double)(m - 1) + (double)((word >> j) & 1);
            const double M2[4] = {k.A[0] * M[0] + k.A[1] * M[2], k.A[0] * M[1] + k.A[1] * M[3],
                                  k.A[2] * M[0] + k.A[3] * M[2], k.A[2] * M[1] + k.A[3] * M[3]};
            const double c2[2] = {k.A[0] * c[0] + k.A[1] * c[1] + k.b[0] * q,
                                  k.A[2] * c[0] + k.A[3] * c[1] + k.b[1] * q};
            memcpy(M, M2, sizeof M);
            memcpy(c, c2, sizeof c);
        }
        const double I_M[4] = {1 - M[0], -M[1], -M[2], 1 - M[3]};
        const double det = I_M[0] * I_M[3] - I_M[1] * I_M[2];
        double x[2] = {(I_M[3] * c[0] - I_M[1] * c[1]) / det, (I_M[0] * c[1] - I_M[2] * c[0]) / det};
        bool follows = isfinite(x[0]) && isfinite(x[1]);
        /* a point of the invariant set may lie on Q_m's edge or on SW_m (the
         * fixed points are corners), and the solve and the orbit lose a few
         * digits to the expansion lambda_u^n: 10^-7 of the cell's size */
        const double tol = 1e-7;
        for (int j = 0; j < n && follows; j++) {
            const double q = (double)(m - 1) + (double)((word >> j) & 1);
            double a, b;
            eigen_coordinates(&k, h.x_l, x, &a, &b);
            const double u = P * x[0] + D * x[1]; /* in band q: q <= u < q + 1 (m >= 1) */
            follows = a >= -tol * a_r && a <= a_r * (1 + tol) && b * b_r >= -tol * b_r * b_r &&
                      fabs(b) <= fabs(b_r) * (1 + tol) && u >= q - tol && u < q + 1 + tol;
            double y[2];
            restricted(&k, q, x, y);
            x[0] = y[0], x[1] = y[1];
        }
        count += follows;
    }
    return count;
}

int64_t cm_pd_m_fix_max(double alpha, double P)
{
    const double a2 = alpha * alpha;
    if (!(P > a2))
        return -1;
    /* The band test decides: the largest m >= 0 whose x_m* = m/alpha^2 lies in
     * band m. Start from the closed form (4.75) and correct at the border. */
    double level;
    int64_t m = cm_int_part(a2 / (P - a2), &level) ? (int64_t)level : -1;
    while (m > 0 && !(cm_int_part(P * ((double)m / a2), &level) && (int64_t)level == m))
        m--;
    return m;
}

int64_t cm_pd_m_max(double alpha, double P)
{
    const int64_t m = cm_pd_m_fix_max(alpha, P);
    return m < 0 ? -1 : m + 1;
}

typedef struct pd_map {
    double a11, a12, a21, a22, b1, b2, P, D, alpha2, beta;
} pd_map;

static int step_pd(const cm_model *m, const double *x, double *y)
{
    const pd_map *c = m->ctx;
    double level;
    if (!cm_int_part(c->P * x[0] + c->D * x[1], &level))
        return CM_STEP_NO_IMAGE;
    y[0] = c->a11 * x[0] + c->a12 * x[1] + c->b1 * level;
    y[1] = c->a21 * x[0] + c->a22 * x[1] + c->b2 * level;
    return CM_STEP_OK;
}

CM_VECTOR_LOOP
static void step_n_pd(const cm_model *m, size_t n, const double *const *x, double *const *y,
                      int *rc)
{
    const pd_map *c = m->ctx;
    /* locals and restrict: the compiler may then keep the coefficients in
     * registers and vectorise */
    const double P = c->P, D = c->D, a11 = c->a11, a12 = c->a12, a21 = c->a21, a22 = c->a22,
                 b1 = c->b1, b2 = c->b2;
    const double *restrict x0 = x[0], *restrict x1 = x[1];
    double *restrict y0 = y[0], *restrict y1 = y[1];
    for (size_t i = 0; i < n; i++) {
        const double level = cm_int_part_value(P * x0[i] + D * x1[i]);
        y0[i] = a11 * x0[i] + a12 * x1[i] + b1 * level;
        y1[i] = a21 * x0[i] + a22 * x1[i] + b2 * level;
    }
    for (size_t i = 0; i < n; i++) /* apart: the loop above vectorises only in doubles */
        rc[i] = cm_int_part_status(P * x0[i] + D * x1[i]);
}

size_t cm_pd_fixed_points(double alpha2, double P, int64_t m0, int64_t m1, cm_fixed_point *out,
                          size_t cap)
{
    size_t count = 0;
    for (int64_t k = m0; k <= m1 && count < cap; k++) {
        cm_fixed_point *fp = &out[count++];
        double band;
        memset(fp, 0, sizeof *fp);
        fp->level = k;
        fp->x[0] = (double)k / alpha2;
        fp->x[1] = 0.0;
        fp->band = cm_int_part(P * fp->x[0] + 0.0, &band) ? (int64_t)band : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return count;
}

/* The band of level m as z_lo <= P x + D x' <= z_hi (docs/models.md 1.1; band 0
 * is twice as wide). */
static void band_of(int64_t m, double *z_lo, double *z_hi)
{
    *z_lo = m > 0 ? (double)m : (double)m - 1.0;
    *z_hi = m < 0 ? (double)m : (double)m + 1.0;
}

static void add_switching_lines(double P, double D, const double lo[2], const double hi[2],
                                cm_overlay_list *out)
{
    const double n[2] = {P, D}, nn = P * P + D * D;
    if (nn == 0.0)
        return;
    double z_min = INFINITY, z_max = -INFINITY;
    for (int k = 0; k < 4; k++) {
        const double z = P * (k & 1 ? hi[0] : lo[0]) + D * (k & 2 ? hi[1] : lo[1]);
        z_min = z < z_min ? z : z_min;
        z_max = z > z_max ? z : z_max;
    }
    if (!(z_min > -4e18 && z_max < 4e18))
        return;
    const double d[2] = {-D, P};
    for (double z = ceil(z_min); z <= z_max && !out->truncated; z++) {
        if (z == 0.0)
            continue;
        const double p[2] = {z * n[0] / nn, z * n[1] / nn};
        cm_overlay_add_line(out, CM_OVERLAY_SWITCHING_LINE, p, d, lo, hi, NULL, 0, 0);
    }
}

void cm_pd_overlays(double alpha2, double beta, double P, double D, const double lo[2],
                    const double hi[2], cm_overlay_list *out)
{
    add_switching_lines(P, D, lo, hi, out);
    if (!(lo[1] <= 0.0 && hi[1] >= 0.0)) /* every fixed point lies on x' = 0 */
        return;
    const double gamma = sqrt(alpha2 + beta * beta);
    const double e_u[2] = {1.0, gamma - beta}, e_s[2] = {1.0, -gamma - beta}, n[2] = {P, D};
    const double m0 = ceil(lo[0] * alpha2), m1 = floor(hi[0] * alpha2);
    if (!(m0 > -4e18 && m1 < 4e18))
        return;
    for (int64_t m = (int64_t)m0; m <= (int64_t)m1 && !out->truncated; m++) {
        cm_fixed_point fp;
        cm_pd_fixed_points(alpha2, P, m, m, &fp, 1);
        cm_overlay_add(out, fp.regular ? CM_OVERLAY_FIXED_REGULAR : CM_OVERLAY_FIXED_VIRTUAL, fp.x,
                       NULL);
        if (!fp.regular)
            continue;
        double z_lo, z_hi;
        band_of(m, &z_lo, &z_hi);
        cm_overlay_add_line(out, CM_OVERLAY_UNSTABLE_MANIFOLD, fp.x, e_u, lo, hi, n, z_lo, z_hi);
        cm_overlay_add_line(out, CM_OVERLAY_STABLE_MANIFOLD, fp.x, e_s, lo, hi, n, z_lo, z_hi);
    }
}

static void overlays_pd(const cm_model *m, const double lo[2], const double hi[2],
                        cm_overlay_list *out)
{
    const pd_map *c = m->ctx;
    cm_pd_overlays(c->alpha2, c->beta, c->P, c->D, lo, hi, out);
}

const char *const cm_pd_coord_names[] = {"x", "v"}; /* v: x', the dimensionless velocity */

static int fixed_points_pd(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                           size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const pd_map *c = m->ctx;
    (void)msg;
    (void)msg_size;
    *count = cm_pd_fixed_points(c->alpha2, c->P, m0, m1, out, cap);
    return 0;
}

cm_status cm_microchaos_pd_create(const cm_params *p, cm_model *m, char *msg, size_t msg_size)
{
    cm_status st = cm_model_setup(m, "microchaos-pd", 2, p, sizeof(pd_map), msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_pd_coef k;
    cm_pd_coefficients(cm_params_get(p, "alpha"), cm_params_get(p, "beta"), cm_params_get(p, "P"),
                       cm_params_get(p, "D"), &k);
    pd_map *c = m->ctx;
    *c = (pd_map){k.A[0], k.A[1], k.A[2], k.A[3], k.b[0], k.b[1], k.P, k.D, k.alpha * k.alpha,
                  k.beta};
    m->step = step_pd;
    m->step_n = step_n_pd;
    m->fixed_points = fixed_points_pd;
    m->overlays = overlays_pd;
    m->coord_names = cm_pd_coord_names;
    return CM_OK;
}
