#include "render/quads.h"

#include <math.h>

enum { SUBPIXELS = 256 }; /* llvmpipe's fixed-point vertex positions */

/* A pixel centre on a texel's lower edge shows that texel, as a point on a
 * cell's lower edge lies in that cell (cm_lattice: cells are half-open);
 * the margin keeps that rule through rounding in the division. */
#define TIE 1e-9

/* The window coordinate of state coordinate v, unsnapped. */
static double window_of(const cm_quad_axis *ax, double v)
{
    return (v - ax->lo) / (ax->hi - ax->lo) * ax->n;
}

static double snapped(double w) { return nearbyint(w * SUBPIXELS) / SUBPIXELS; }

/* The first pixel whose centre lies on or after window coordinate w,
 * within 0..n. */
static int first_centre_at(double w, int n)
{
    const double k = ceil(w - 0.5);
    return k < 0 ? 0 : k > n ? n : (int)k;
}

void cm_quad_span(const cm_quad_axis *ax, double a, double b, int *first, int *end)
{
    *first = first_centre_at(snapped(window_of(ax, a)), ax->n);
    *end = first_centre_at(snapped(window_of(ax, b)), ax->n);
    if (*end < *first)
        *end = *first;
}

void cm_quad_texels(const cm_quad_axis *ax, double a, double b, uint64_t texels, int64_t offset,
                    int64_t *texel)
{
    int first, end;
    cm_quad_span(ax, a, b, &first, &end);
    const double wa = window_of(ax, a), wb = window_of(ax, b);
    const double last = (double)texels - 1;
    for (int k = first; k < end; k++) {
        double t = floor((k + 0.5 - wa) / (wb - wa) * (double)texels + TIE);
        t = t < 0 ? 0 : t > last ? last : t;
        texel[k] = offset + (int64_t)t;
    }
}
