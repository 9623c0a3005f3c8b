/* Twofold quantisation of the PD map (4.84): u = Int(rho (P Int(x/rho) +
 * D Int(x'/rho))), [x, x'] -> A [x, x'] + b u. docs/models.md 7. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "models/microchaos_pd_twofold.h"

#include "models/microchaos_pd.h"
#include "models/models.h"
#include "models/params.h"

const cm_param_spec cm_microchaos_pd_twofold_spec[] = {
    {"alpha", "0.078", 1e-12, 1e3, 1, NULL, "alpha = tau sqrt(k/M) > 0 (4.59)"},
    {"beta", "0", -1e3, 1e3, 1, NULL, "beta = d tau/(2M), damping (4.59)"},
    {"P", "0.007", -1e6, 1e6, 1, NULL, "proportional gain (4.59)"},
    {"D", "0.02", -1e6, 1e6, 1, NULL, "derivative gain (4.59)"},
    {"rho", "0.5", 1e-12, 1e12, 1, NULL,
     "input/output resolution ratio rho = r_I/X_O > 0 (4.85); rho -> 0 gives microchaos-pd"},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct twofold_map {
    double a11, a12, a21, a22, b1, b2, P, D, rho, alpha2;
} twofold_map;

/* The quantised control of (4.84); false when a quantiser has no level. */
static bool twofold_control(const twofold_map *c, const double *x, double *u)
{
    double qx, qv;
    if (!cm_int_part(x[0] / c->rho, &qx) || !cm_int_part(x[1] / c->rho, &qv))
        return false;
    return cm_int_part(c->rho * (c->P * qx + c->D * qv), u);
}

static int step_twofold(const cm_model *m, const double *x, double *y)
{
    const twofold_map *c = m->ctx;
    double u;
    if (!twofold_control(c, x, &u))
        return CM_STEP_NO_IMAGE;
    y[0] = c->a11 * x[0] + c->a12 * x[1] + c->b1 * u;
    y[1] = c->a21 * x[0] + c->a22 * x[1] + c->b2 * u;
    return CM_STEP_OK;
}

/* docs/models.md 2.4 (twofold): x* = [u/alpha^2, 0] for control value u, regular
 * iff the control law at x* returns u. */
static int fixed_points_twofold(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                                size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const twofold_map *c = m->ctx;
    (void)msg;
    (void)msg_size;
    *count = 0;
    for (int64_t k = m0; k <= m1 && *count < cap; k++) {
        cm_fixed_point *fp = &out[(*count)++];
        double u;
        memset(fp, 0, sizeof *fp);
        fp->level = k;
        fp->x[0] = (double)k / c->alpha2;
        fp->band = twofold_control(c, fp->x, &u) ? (int64_t)u : INT64_MIN;
        fp->regular = fp->band == k;
    }
    return 0;
}

/* The control level of the input tile (i, k): x in [i rho, (i+1) rho), x'
 * in [k rho, (k+1) rho) (Int rounds towards zero, so the tiles are
 * numbered by Int of the tile's centre). */
static bool tile_level(const twofold_map *c, double i, double k, double *u)
{
    const double centre[2] = {(i + 0.5) * c->rho, (k + 0.5) * c->rho};
    return twofold_control(c, centre, u);
}

/* The order of the switching line collision at a corner of four tiles
 * (levels a, b below it, c, d above it; a, d and b, c diagonal), 0 if none:
 * the levels of one diagonal lie one below and one above those of the
 * other, so the lines around the lower tile and around the upper one touch
 * at the corner (SW_m and SW_m+n, n = 1 + the other diagonal's spread), and
 * the bands between are pinched there. */
int cm_twofold_collision_order(double a, double b, double c, double d)
{
    if (isnan(a) || isnan(b) || isnan(c) || isnan(d)) /* a tile without a level */
        return 0;
    const double diag[2][2] = {{a, d}, {b, c}};
    for (int k = 0; k < 2; k++) {
        const double *p = diag[k], *q = diag[1 - k];
        const double qlo = fmin(q[0], q[1]), qhi = fmax(q[0], q[1]);
        if (fmin(p[0], p[1]) < qlo && fmax(p[0], p[1]) > qhi)
            return (int)(qhi - qlo) + 1;
    }
    return 0;
}

/* The overlays of the view (thesis Figs. 4.33-4.36): the stair-shaped
 * switching lines, the edges of the input tiles (rho x rho) across which
 * the control level changes; the tile corners where two switching lines
 * collide (first order, and higher); and the fixed points. Tiles finer
 * than the view can show (more than 400 across) give no stairs. */
static void overlays_twofold(const cm_model *m, const double lo[2], const double hi[2],
                             cm_overlay_list *out)
{
    const twofold_map *c = m->ctx;
    const double i0 = floor(lo[0] / c->rho) - 1, i1 = ceil(hi[0] / c->rho),
                 k0 = floor(lo[1] / c->rho) - 1, k1 = ceil(hi[1] / c->rho);
    const size_t ni = (size_t)(i1 - i0 + 2), nk = (size_t)(k1 - k0 + 2);
    double *level = i1 - i0 <= 400 && k1 - k0 <= 400 ? malloc(ni * nk * sizeof *level) : NULL;
    for (size_t t = 0; level && t < ni * nk; t++) /* tiles i0..i1+1 by k0..k1+1; NaN: none */
        if (!tile_level(c, i0 + (double)(t % ni), k0 + (double)(t / ni), &level[t]))
            level[t] = NAN;
    for (size_t kk = 0; level && kk + 1 < nk; kk++)
        for (size_t ii = 0; ii + 1 < ni; ii++) {
            const double *at = &level[kk * ni + ii], u = at[0], right = at[1], above = at[ni];
            /* the tile's right and upper edges, where the neighbour differs */
            const double x = (i0 + (double)ii + 1) * c->rho, v = (k0 + (double)kk + 1) * c->rho;
            const double edges[2][4] = {{x, v - c->rho, x, v}, {x - c->rho, v, x, v}};
            const bool differs[2] = {right != u, above != u}; /* NaN differs from all */
            for (int e = 0; e < 2; e++) {
                const double a[2] = {edges[e][0], edges[e][1]}, b[2] = {edges[e][2], edges[e][3]};
                if (differs[e] && !isnan(u) && !isnan(e ? above : right) &&
                    (cm_overlay_in_view(a, lo, hi) || cm_overlay_in_view(b, lo, hi)))
                    cm_overlay_add(out, CM_OVERLAY_SWITCHING_LINE, a, b);
            }
            const double corner[2] = {x, v};
            const int order = cm_twofold_collision_order(u, right, above, at[ni + 1]);
            if (order && cm_overlay_in_view(corner, lo, hi))
                cm_overlay_add(out, order == 1 ? CM_OVERLAY_COLLISION : CM_OVERLAY_COLLISION_HIGHER,
                               corner, NULL);
        }
    free(level);
    /* the fixed points x* = [u/alpha^2, 0], regular where the control law
     * there gives u */
    const double u0 = ceil(lo[0] * c->alpha2), u1 = floor(hi[0] * c->alpha2);
    if (lo[1] > 0 || hi[1] < 0 || u1 - u0 > 2000)
        return;
    for (double k = u0; k <= u1; k++) {
        const double p[2] = {k / c->alpha2, 0};
        double u;
        const bool regular = twofold_control(c, p, &u) && u == k;
        cm_overlay_add(out, regular ? CM_OVERLAY_FIXED_REGULAR : CM_OVERLAY_FIXED_VIRTUAL, p, p);
    }
}

cm_status cm_microchaos_pd_twofold_create(const cm_params *p, cm_model *m, char *msg,
                                          size_t msg_size)
{
    cm_status st =
        cm_model_setup(m, "microchaos-pd-twofold", 2, p, sizeof(twofold_map), msg, msg_size);
    if (st != CM_OK)
        return st;
    cm_pd_coef k;
    cm_pd_coefficients(cm_params_get(p, "alpha"), cm_params_get(p, "beta"), cm_params_get(p, "P"),
                       cm_params_get(p, "D"), &k);
    twofold_map *c = m->ctx;
    *c = (twofold_map){
        k.A[0],           k.A[1], k.A[2], k.A[3], k.b[0], k.b[1], k.P, k.D, cm_params_get(p, "rho"),
        k.alpha * k.alpha};
    m->step = step_twofold;
    m->fixed_points = fixed_points_twofold;
    m->overlays = overlays_twofold;
    m->coord_names = cm_pd_coord_names; /* the pendulum's x, v, as docs/models.md lists them */
    return CM_OK;
}
