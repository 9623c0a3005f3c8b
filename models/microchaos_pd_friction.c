/* Hybrid micro-chaos map with dry friction (4.81). docs/models.md 8. */
#include "models/microchaos_pd_friction.h"

#include <math.h>
#include <string.h>

#include "models/microchaos_pd.h"
#include "models/models.h"
#include "models/params.h"

/* mu_s = -1 stands for "the same as mu", the thesis' single coefficient. */
#define MU_S_SAME -1.0

const cm_param_spec cm_microchaos_pd_friction_spec[] = {
    {"alpha", "6.53e-3", 1e-12, 1e3, 1, NULL, "alpha = tau sqrt(k/M) > 0 (4.59)"},
    {"beta", "0", -1e3, 1e3, 1, NULL, "beta = d tau/(2M), damping (4.59)"},
    {"P", "5.5e-5", -1e6, 1e6, 1, NULL, "proportional gain P = P~ tau^2/M (4.59)"},
    {"D", "2.5e-3", -1e6, 1e6, 1, NULL, "derivative gain D = D~ tau/M (4.59)"},
    {"mu", "0.095", 0, 1e6, 1, NULL, "kinetic dry friction force, in control levels (4.81)"},
    {"mu_s", "-1", -1, 1e6, 1, NULL, "static friction force >= mu; -1 (default) takes mu"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

void cm_pdf_coefficients(double alpha, double beta, double P, double D, double mu, double mu_s,
                         cm_pdf_coef *c)
{
    cm_pd_coef pd;
    cm_pd_coefficients(alpha, beta, P, D, &pd);
    memset(c, 0, sizeof *c);
    c->alpha2 = alpha * alpha;
    c->beta = beta;
    c->gamma = pd.gamma;
    c->P = P;
    c->D = D;
    c->mu = mu;
    c->mu_s = mu_s;
    memcpy(c->A, pd.A, sizeof c->A);
    memcpy(c->b, pd.b, sizeof c->b);
    c->tanh_gamma = tanh(pd.gamma);
}

/* Slides for local time tau under the constant force -q (docs/models.md 6.2). */
static void slide(const cm_pdf_coef *c, double q, double tau, double *x, double *v)
{
    const double xq = q / c->alpha2, xi = *x - xq, v0 = *v;
    const double decay = exp(-c->beta * tau);
    const double sh = sinh(c->gamma * tau) / c->gamma, ch = cosh(c->gamma * tau);
    *x = xq + decay * ((ch + c->beta * sh) * xi + sh * v0);
    *v = decay * (c->alpha2 * sh * xi + (ch - c->beta * sh) * v0);
}

/* Local time in (0, 1] at which the velocity of a block sliding from (x, v)
 * under -q reaches zero, or -1 if it keeps its sign (docs/models.md 8.2). */
static double velocity_zero(const cm_pdf_coef *c, double q, double x, double v)
{
    const double den = c->alpha2 * (x - q / c->alpha2) - c->beta * v;
    if (den == 0)
        return -1;
    const double w = -c->gamma * v / den;
    if (!(w > 0 && w <= c->tanh_gamma))
        return -1;
    const double t = 0.5 * log1p(2 * w / (1 - w)) / c->gamma; /* atanh(w)/gamma */
    return t < 1 ? t : 1; /* w = tanh(gamma) may round just past the sample */
}

static double sign(double z) { return z > 0 ? 1 : -1; }

bool cm_pdf_step(const cm_pdf_coef *c, double x, double v, cm_pdf_result *out)
{
    double level;
    memset(out, 0, sizeof *out);
    if (!cm_int_part(c->P * x + c->D * v, &level))
        return false;
    out->level = (int64_t)level;
    double sigma;
    if (v == 0) { /* at rest at the sampling instant */
        const double F = c->alpha2 * x - level;
        if (fabs(F) <= c->mu_s) {
            *out = (cm_pdf_result){x, 0, out->level, CM_PDF_STUCK_WHOLE, 0, x};
            return true;
        }
        sigma = sign(F);
    } else {
        sigma = sign(v);
        const double q = level + c->mu * sigma; /* the constant force is -q */
        const double t = velocity_zero(c, q, x, v);
        if (t < 0) { /* the sign of the friction force holds: (4.81) */
            out->x = c->A[0] * x + c->A[1] * v + c->b[0] * q;
            out->v = c->A[2] * x + c->A[3] * v + c->b[1] * q;
            return true;
        }
        slide(c, q, t, &x, &v);
        v = 0;
        out->event_time = t;
        out->event_x = x;
        const double F = c->alpha2 * x - level;
        if (fabs(F) <= c->mu_s) { /* stuck until the next sample */
            out->x = x;
            out->v = 0;
            out->event = CM_PDF_STICK;
            return true;
        }
        out->event = CM_PDF_REVERSE;
        sigma = sign(F);
        if (t == 1) { /* the zero is at the sample: the rest rule decides next */
            out->x = x;
            out->v = 0;
            return true;
        }
    }
    /* From rest with |F| > mu_s >= mu the velocity keeps sigma's sign to the
     * end of the interval (docs/models.md 8.2): no further event. */
    const double tau = out->event ? 1 - out->event_time : 1;
    slide(c, level + c->mu * sigma, tau, &x, &v);
    out->x = x;
    out->v = v;
    return true;
}

bool cm_pdf_at_rest(const cm_pdf_coef *c, double x, double v)
{
    double level;
    return v == 0 && cm_int_part(c->P * x, &level) && fabs(c->alpha2 * x - level) <= c->mu_s;
}

bool cm_pdf_sticking_zone(const cm_pdf_coef *c, int64_t m, double *x_lo, double *x_hi)
{
    /* |alpha^2 x - m| <= mu_s, intersected with the band Int(P x) = m */
    double lo = ((double)m - c->mu_s) / c->alpha2, hi = ((double)m + c->mu_s) / c->alpha2;
    double band_lo, band_hi; /* Int(P x) = m for x in [band_lo, band_hi] (P > 0) */
    if (!(c->P > 0))
        return false;
    if (m > 0) {
        band_lo = (double)m / c->P;
        band_hi = nextafter((double)(m + 1) / c->P, 0);
    } else if (m < 0) {
        band_lo = nextafter((double)(m - 1) / c->P, 0);
        band_hi = (double)m / c->P;
    } else {
        band_lo = nextafter(-1 / c->P, 0);
        band_hi = nextafter(1 / c->P, 0);
    }
    lo = lo > band_lo ? lo : band_lo;
    hi = hi < band_hi ? hi : band_hi;
    /* the ends as cm_pdf_at_rest rounds them: a few ulps inwards at most */
    for (int k = 0; k < 8 && lo <= hi && !cm_pdf_at_rest(c, lo, 0); k++)
        lo = nextafter(lo, hi);
    for (int k = 0; k < 8 && lo <= hi && !cm_pdf_at_rest(c, hi, 0); k++)
        hi = nextafter(hi, lo);
    *x_lo = lo;
    *x_hi = hi;
    return lo <= hi && cm_pdf_at_rest(c, lo, 0) && cm_pdf_at_rest(c, hi, 0);
}

typedef struct pdf_model {
    cm_pdf_coef c;
} pdf_model;

static int step_pdf(const cm_model *m, const double *x, double *y)
{
    const pdf_model *f = m->ctx;
    cm_pdf_result r;
    if (!cm_pdf_step(&f->c, x[0], x[1], &r))
        return CM_STEP_NO_IMAGE;
    y[0] = r.x;
    y[1] = r.v;
    return CM_STEP_OK;
}

static bool at_rest_pdf(const cm_model *m, const double *y)
{
    const pdf_model *f = m->ctx;
    return cm_pdf_at_rest(&f->c, y[0], y[1]);
}

/* The fixed points of the frictionless map (4.71): without motion,
 * friction does not move them; they lie inside their sticking zones. */
static int fixed_points_pdf(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                            size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const pdf_model *f = m->ctx;
    (void)msg;
    (void)msg_size;
    *count = cm_pd_fixed_points(f->c.alpha2, f->c.P, m0, m1, out, cap);
    return 0;
}

/* As the PD map, plus each level's sticking zone on x' = 0. */
static void overlays_pdf(const cm_model *m, const double lo[2], const double hi[2],
                         cm_overlay_list *out)
{
    const pdf_model *f = m->ctx;
    const cm_pdf_coef *c = &f->c;
    cm_pd_overlays(c->alpha2, c->beta, c->P, c->D, lo, hi, out);
    if (!(lo[1] <= 0.0 && hi[1] >= 0.0))
        return;
    /* the zone of level k lies within mu_s/alpha^2 of its fixed point k/alpha^2 */
    const double reach = c->mu_s + 1.0;
    const double k0 = floor(lo[0] * c->alpha2 - reach), k1 = ceil(hi[0] * c->alpha2 + reach);
    if (!(k0 > -4e18 && k1 < 4e18))
        return;
    for (int64_t k = (int64_t)k0; k <= (int64_t)k1 && !out->truncated; k++) {
        double x_lo, x_hi;
        if (!cm_pdf_sticking_zone(c, k, &x_lo, &x_hi) || x_hi < lo[0] || x_lo > hi[0])
            continue;
        const double a[2] = {x_lo > lo[0] ? x_lo : lo[0], 0.0};
        const double b[2] = {x_hi < hi[0] ? x_hi : hi[0], 0.0};
        cm_overlay_add(out, CM_OVERLAY_STICKING_ZONE, a, b);
    }
}

cm_status cm_microchaos_pd_friction_create(const cm_params *p, cm_model *m, char *msg,
                                           size_t msg_size)
{
    const double mu = cm_params_get(p, "mu");
    double mu_s = cm_params_get(p, "mu_s");
    if (mu_s == MU_S_SAME)
        mu_s = mu;
    if (mu_s < mu)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "mu_s = %g is below mu = %g: static friction must be at least the kinetic "
                       "one (or -1 for mu_s = mu)",
                       mu_s, mu);
    cm_status st =
        cm_model_setup(m, "microchaos-pd-friction", 2, p, sizeof(pdf_model), msg, msg_size);
    if (st != CM_OK)
        return st;
    pdf_model *f = m->ctx;
    cm_pdf_coefficients(cm_params_get(p, "alpha"), cm_params_get(p, "beta"), cm_params_get(p, "P"),
                        cm_params_get(p, "D"), mu, mu_s, &f->c);
    m->step = step_pdf;
    m->at_rest = at_rest_pdf;
    m->fixed_points = fixed_points_pdf;
    m->overlays = overlays_pdf;
    m->coord_names = cm_pd_coord_names;
    return CM_OK;
}
