/* 1D transient micro-chaos map with Coulomb friction (4.23). docs/models.md 4. */
#include <math.h>
#include <string.h>

#include "cellmap/overlay.h"
#include "models/models.h"
#include "models/params.h"
#include "models/transient_escape.h"

const cm_param_spec cm_microchaos_1d_friction_spec[] = {
    {"a", "1.5", 1.0000001, 1e6, 1, NULL, "a = exp(g N tau/M) > 1 (4.24)"},
    {"b", "1.2", 0, 1e6, 1, NULL, "b = (D/(g N))(a - 1) >= 0 (4.25)"},
    {"c", "0.13333333333333333", 0, 1e6, 1, NULL,
     "c = (a-1) C/(g N h) >= 0; Fig. 4.4 uses |I0| = 0.1, i.e. c = 0.1333..."},
    {NULL, NULL, 0, 0, 0, NULL, NULL},
};

typedef struct friction1d {
    double a, b, c, dead; /* dead = c/a: [-dead, dead] maps to 0 */
} friction1d;

static int step_friction(const cm_model *m, const double *x, double *y)
{
    const friction1d *f = m->ctx;
    double level;
    if (!cm_int_part(x[0], &level))
        return CM_STEP_NO_IMAGE;
    if (x[0] > f->dead)
        y[0] = f->a * x[0] - f->b * level - f->c;
    else if (x[0] < -f->dead)
        y[0] = f->a * x[0] - f->b * level + f->c;
    else
        y[0] = 0.0;
    return CM_STEP_OK;
}

static void friction_point(const friction1d *f, int64_t k, double x, int branch, cm_fixed_point *fp)
{
    double band;
    memset(fp, 0, sizeof *fp);
    fp->level = k;
    fp->x[0] = x;
    fp->band = cm_int_part(x, &band) ? (int64_t)band : INT64_MIN;
    if (branch > 0)
        fp->regular = fp->band == k && x > f->dead;
    else if (branch < 0)
        fp->regular = fp->band == k && x < -f->dead;
    else
        fp->regular = true; /* the origin: stable, absorbing */
}

/* (4.26): positive branch (b m + c)/(a-1) for m >= 0, negative branch
 * (b m - c)/(a-1) for m <= 0; the origin is listed with level 0 first. */
static int fixed_points_friction(const cm_model *m, int64_t m0, int64_t m1, cm_fixed_point *out,
                                 size_t cap, size_t *count, char *msg, size_t msg_size)
{
    const friction1d *f = m->ctx;
    (void)msg;
    (void)msg_size;
    *count = 0;
    for (int64_t k = m0; k <= m1; k++) {
        if (k == 0 && *count < cap)
            friction_point(f, 0, 0.0, 0, &out[(*count)++]);
        if (k <= 0 && *count < cap)
            friction_point(f, k, (f->b * (double)k - f->c) / (f->a - 1.0), -1, &out[(*count)++]);
        if (k >= 0 && *count < cap)
            friction_point(f, k, (f->b * (double)k + f->c) / (f->a - 1.0), +1, &out[(*count)++]);
    }
    return 0;
}

/* The states x0..x1 and their mirror images -x1..-x0 as segments of the
 * graph plane's diagonal, cut to the view. */
static void diagonal_interval(cm_overlay_list *out, int kind, double x0, double x1,
                              const double view_lo[2], const double view_hi[2])
{
    for (int mirror = 0; mirror < 2; mirror++) {
        const double from = mirror ? -x1 : x0, to = mirror ? -x0 : x1;
        const double a = fmax(from, view_lo[0]), b = fmin(to, view_hi[0]);
        if (a < b)
            cm_overlay_add(out, kind, (const double[2]){a, a}, (const double[2]){b, b});
    }
}

/* On the diagonal of the graph plane: the fixed points in view, and, in the
 * case of thesis 4.3 (one positive fixed point x0* below 1), the interval
 * I_rep = [x0*, a - c] that holds the chaotic repeller and the escape
 * interval I0 = [a - b - c, x0*) next to it, with their mirror images (the
 * map is odd). */
static void overlays_friction(const cm_model *m, const double lo[2], const double hi[2],
                              cm_overlay_list *out)
{
    const friction1d *f = m->ctx;
    cm_te t;
    char why[160];
    if (cm_te_setup(f->a, f->b, f->c, &t, why, sizeof why)) {
        diagonal_interval(out, CM_OVERLAY_ESCAPE, f->a - f->b - f->c, t.x0, lo, hi);
        diagonal_interval(out, CM_OVERLAY_REPELLER, t.x0, t.rep_hi, lo, hi);
    }
    /* levels whose fixed points can lie in view: |x (a - 1) - b m| <= c */
    const double k0 = f->b > 0 ? floor(((f->a - 1) * lo[0] - f->c) / f->b) : 0,
                 k1 = f->b > 0 ? ceil(((f->a - 1) * hi[0] + f->c) / f->b) : 0;
    if (!(k0 >= -1e6 && k1 <= 1e6)) /* more points than a picture can show */
        return;
    for (int64_t k = (int64_t)k0; k <= (int64_t)k1 && !out->truncated; k++) {
        cm_fixed_point fp[3];
        size_t n = 0;
        fixed_points_friction(m, k, k, fp, 3, &n, NULL, 0);
        for (size_t i = 0; i < n; i++) {
            const double p[2] = {fp[i].x[0], fp[i].x[0]};
            if (cm_overlay_in_view(p, lo, hi))
                cm_overlay_add(out,
                               fp[i].regular ? CM_OVERLAY_FIXED_REGULAR : CM_OVERLAY_FIXED_VIRTUAL,
                               p, NULL);
        }
    }
}

cm_status cm_microchaos_1d_friction_create(const cm_params *p, cm_model *m, char *msg,
                                           size_t msg_size)
{
    cm_status st =
        cm_model_setup(m, "microchaos-1d-friction", 1, p, sizeof(friction1d), msg, msg_size);
    if (st != CM_OK)
        return st;
    friction1d *f = m->ctx;
    f->a = cm_params_get(p, "a");
    f->b = cm_params_get(p, "b");
    f->c = cm_params_get(p, "c");
    f->dead = f->c / f->a;
    m->step = step_friction;
    m->fixed_points = fixed_points_friction;
    m->overlays = overlays_friction;
    return CM_OK;
}
