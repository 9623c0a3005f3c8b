/* models/pd_strips.c - images and pre-images of the horseshoe trapezoids
 * (models/pd_strips.h). */
#include "models/pd_strips.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "models/microchaos_pd.h"

double cm_polygon_area(const cm_polygon *p)
{
    double s = 0;
    for (int i = 0; i < p->n; i++) {
        const double *a = p->p[i], *b = p->p[(i + 1) % p->n];
        s += a[0] * b[1] - a[1] * b[0];
    }
    return s / 2;
}

/* Which side of the line a -> b the point p lies on (positive: left). */
static double side_of(const double a[2], const double b[2], const double p[2])
{
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

/* The part of the convex polygon in on the inner side of each edge of the
 * convex polygon clip (Sutherland-Hodgman); false when a result would
 * need more than CM_POLYGON_MAX corners. */
static bool clip_convex(const cm_polygon *in, const cm_polygon *clip, cm_polygon *out)
{
    const double orient = cm_polygon_area(clip) >= 0 ? 1 : -1;
    cm_polygon cur = *in;
    for (int e = 0; e < clip->n && cur.n > 0; e++) {
        const double *a = clip->p[e], *b = clip->p[(e + 1) % clip->n];
        cm_polygon next = {0};
        for (int i = 0; i < cur.n; i++) {
            const double *p = cur.p[i], *q = cur.p[(i + 1) % cur.n];
            const double sp = orient * side_of(a, b, p), sq = orient * side_of(a, b, q);
            if (next.n + 2 > CM_POLYGON_MAX)
                return false;
            if (sp >= 0)
                memcpy(next.p[next.n++], p, sizeof next.p[0]);
            if ((sp >= 0) != (sq >= 0)) {
                const double t = sp / (sp - sq);
                next.p[next.n][0] = p[0] + t * (q[0] - p[0]);
                next.p[next.n][1] = p[1] + t * (q[1] - p[1]);
                next.n++;
            }
        }
        cur = next;
    }
    *out = cur;
    return true;
}

/* The map of one side, forwards (A x + b q) or backwards, on every corner. */
static void map_polygon(const cm_pd_coef *k, double q, bool inverse, cm_polygon *p)
{
    const double det = k->A[0] * k->A[3] - k->A[1] * k->A[2];
    for (int i = 0; i < p->n; i++) {
        double x = p->p[i][0], v = p->p[i][1];
        if (inverse) {
            x -= k->b[0] * q, v -= k->b[1] * q;
            p->p[i][0] = (k->A[3] * x - k->A[1] * v) / det;
            p->p[i][1] = (k->A[0] * v - k->A[2] * x) / det;
        } else {
            p->p[i][0] = k->A[0] * x + k->A[1] * v + k->b[0] * q;
            p->p[i][1] = k->A[2] * x + k->A[3] * v + k->b[1] * q;
        }
    }
}

/* The trapezoids L and R of Q_m, and Q_m's area. */
static double trapezoids(double alpha, double beta, double P, double D, int64_t m,
                         cm_polygon side[2])
{
    cm_pd_horseshoe h;
    cm_pd_horseshoe_at(alpha, beta, P, D, m, &h);
    const double *L[4] = {h.x_l, h.RULS, h.RUSW, h.LUSW}, *R[4] = {h.LUSW, h.RUSW, h.x_r, h.LURS};
    side[0].n = side[1].n = 4;
    for (int c = 0; c < 4; c++) {
        memcpy(side[0].p[c], L[c], sizeof side[0].p[c]);
        memcpy(side[1].p[c], R[c], sizeof side[1].p[c]);
    }
    return fabs(cm_polygon_area(&side[0])) + fabs(cm_polygon_area(&side[1]));
}

/* Appends piece (on side s) to out unless it is empty; false when full. */
static bool keep(const cm_polygon *piece, int s, double min_area, cm_polygon *out, int *sides,
                 int *n, int max)
{
    if (piece->n < 3 || fabs(cm_polygon_area(piece)) <= min_area)
        return true;
    if (*n == max)
        return false;
    out[*n] = *piece;
    if (sides)
        sides[*n] = s;
    (*n)++;
    return true;
}

enum { WORK = 1 << CM_STRIP_MAX_STEPS };

int cm_pd_strip_images(double alpha, double beta, double P, double D, int64_t m, int side, int k,
                       cm_polygon *out, int max)
{
    cm_pd_coef c;
    cm_pd_coefficients(alpha, beta, P, D, &c);
    cm_polygon t[2], cur[WORK], next[WORK];
    int cur_side[WORK], next_side[WORK], n = 1;
    const double min_area = 1e-12 * trapezoids(alpha, beta, P, D, m, t);
    if (k < 1 || k > CM_STRIP_MAX_STEPS || side < 0 || side > 1)
        return -1;
    cur[0] = t[side], cur_side[0] = side;
    for (int step = 1; step <= k; step++) {
        int nn = 0;
        for (int i = 0; i < n; i++) {
            cm_polygon y = cur[i];
            map_polygon(&c, (double)(m - 1 + cur_side[i]), false, &y);
            if (step == k) {
                if (!keep(&y, cur_side[i], min_area, out, NULL, &nn, max))
                    return -1;
                continue;
            }
            for (int s = 0; s < 2; s++) {
                cm_polygon part;
                if (!clip_convex(&y, &t[s], &part) ||
                    !keep(&part, s, min_area, next, next_side, &nn, WORK))
                    return -1;
            }
        }
        if (step < k) {
            memcpy(cur, next, sizeof(cm_polygon) * (size_t)nn);
            memcpy(cur_side, next_side, sizeof(int) * (size_t)nn);
        }
        n = nn;
    }
    return n;
}

int cm_pd_strip_preimages(double alpha, double beta, double P, double D, int64_t m, int side,
                          int k, cm_polygon *out, int max)
{
    cm_pd_coef c;
    cm_pd_coefficients(alpha, beta, P, D, &c);
    cm_polygon t[2], cur[WORK], next[WORK];
    int n = 1;
    const double min_area = 1e-12 * trapezoids(alpha, beta, P, D, m, t);
    if (k < 1 || k > CM_STRIP_MAX_STEPS || side < 0 || side > 1)
        return -1;
    cur[0] = t[side];
    for (int step = 1; step <= k; step++) {
        int nn = 0;
        for (int i = 0; i < n; i++)
            for (int s = 0; s < 2; s++) { /* the points of t[s] that f_s takes into cur[i] */
                cm_polygon back = cur[i], part;
                map_polygon(&c, (double)(m - 1 + s), true, &back);
                if (!clip_convex(&back, &t[s], &part) ||
                    !keep(&part, s, min_area, step == k ? out : next, NULL, &nn,
                          step == k ? max : WORK))
                    return -1;
            }
        if (step < k)
            memcpy(cur, next, sizeof(cm_polygon) * (size_t)nn);
        n = nn;
    }
    return n;
}
