#include "cellmap/overlay.h"

#include <math.h>

bool cm_overlay_add(cm_overlay_list *out, int kind, const double a[2], const double b[2])
{
    if (out->count >= out->cap) {
        out->truncated = true;
        return false;
    }
    cm_overlay *o = &out->items[out->count++];
    o->kind = kind;
    o->a[0] = a[0];
    o->a[1] = a[1];
    o->b[0] = b ? b[0] : a[0];
    o->b[1] = b ? b[1] : a[1];
    return true;
}

/* Narrows [*t0, *t1] to the t where lo <= q + t r <= hi (Liang-Barsky).
 * False when nothing is left. */
static bool clip_slab(double q, double r, double lo, double hi, double *t0, double *t1)
{
    if (r == 0.0)
        return q >= lo && q <= hi;
    double a = (lo - q) / r, b = (hi - q) / r;
    if (a > b) {
        const double s = a;
        a = b;
        b = s;
    }
    *t0 = a > *t0 ? a : *t0;
    *t1 = b < *t1 ? b : *t1;
    return *t0 <= *t1;
}

void cm_overlay_add_line(cm_overlay_list *out, int kind, const double p[2], const double d[2],
                         const double lo[2], const double hi[2], const double *n, double z_lo,
                         double z_hi)
{
    double t0 = -INFINITY, t1 = INFINITY;
    for (int k = 0; k < 2; k++)
        if (!clip_slab(p[k], d[k], lo[k], hi[k], &t0, &t1))
            return;
    if (n && !clip_slab(n[0] * p[0] + n[1] * p[1], n[0] * d[0] + n[1] * d[1], z_lo, z_hi, &t0, &t1))
        return;
    if (!isfinite(t0) || !isfinite(t1))
        return;
    const double a[2] = {p[0] + t0 * d[0], p[1] + t0 * d[1]};
    const double b[2] = {p[0] + t1 * d[0], p[1] + t1 * d[1]};
    cm_overlay_add(out, kind, a, b);
}

bool cm_overlay_in_view(const double p[2], const double lo[2], const double hi[2])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
}
