/* Delay embedding: false nearest neighbours, Kantz's divergence curves,
 * extrema of a sampled coordinate (models/embedding.h). */
#include "models/embedding.h"

#include <math.h>
#include <stdlib.h>

/* The vectors sorted by their first coordinate (ties by index, so that
 * the order and every sum over it are the same each run). */
typedef struct keyed {
    double key;
    size_t i;
} keyed;

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

typedef struct sorted {
    keyed *k;    /* nv entries in key order */
    size_t *pos; /* pos[i]: where vector i is in k */
    size_t nv;
} sorted;

static cm_status sort_vectors(const double *s, size_t nv, sorted *o, char *msg, size_t msg_size)
{
    o->nv = nv;
    o->k = malloc(nv * sizeof *o->k);
    o->pos = malloc(nv * sizeof *o->pos);
    if (!o->k || !o->pos) {
        free(o->k), free(o->pos);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %zu delay vectors", nv);
    }
    for (size_t i = 0; i < nv; i++)
        o->k[i] = (keyed){s[i], i};
    qsort(o->k, nv, sizeof *o->k, by_key);
    for (size_t p = 0; p < nv; p++)
        o->pos[o->k[p].i] = p;
    return CM_OK;
}

static void sorted_free(sorted *o)
{
    free(o->k);
    free(o->pos);
}

static double distance(const double *s, size_t i, size_t j, int dim, int lag)
{
    double d = 0;
    for (int c = 0; c < dim; c++)
        d = fmax(d, fabs(s[i + (size_t)c * (size_t)lag] - s[j + (size_t)c * (size_t)lag]));
    return d;
}

static int far_apart(size_t i, size_t j, size_t theiler)
{
    return (i > j ? i - j : j - i) > theiler;
}

static cm_status check_series(const double *s, size_t n, size_t need, const char *what, char *msg,
                              size_t msg_size)
{
    if (n < need)
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%zu values are too few for %s (it needs %zu): give a longer series or "
                       "a smaller dimension, lag or number of steps",
                       n, what, need);
    for (size_t i = 0; i < n; i++)
        if (!isfinite(s[i]))
            return cm_fail(CM_EINVAL, msg, msg_size, "value %zu of the series is not finite", i);
    return CM_OK;
}

/* The nearest vector to i at a non-zero distance in dimension dim, outside
 * the Theiler window: scans outwards in key order until the first
 * coordinates alone differ by more than the best distance. */
static size_t nearest(const double *s, const sorted *o, size_t i, int dim, int lag, size_t theiler,
                      double *best)
{
    size_t found = o->nv;
    *best = INFINITY;
    const size_t p = o->pos[i];
    for (int dir = -1; dir <= 1; dir += 2) {
        for (size_t q = p; dir < 0 ? q-- > 0 : ++q < o->nv;) {
            const size_t j = o->k[q].i;
            if (fabs(o->k[q].key - s[i]) >= *best)
                break;
            if (!far_apart(i, j, theiler))
                continue;
            const double d = distance(s, i, j, dim, lag);
            if (d > 0 && (d < *best || (d == *best && j < found)))
                *best = d, found = j;
        }
    }
    return found;
}

cm_status cm_false_neighbours(const double *s, size_t n, const cm_fnn_options *o, double *fraction,
                              char *msg, size_t msg_size)
{
    if (o->lag < 1 || o->max_dim < 1 || o->max_dim > CM_EMBED_MAX_DIM || !(o->ratio > 0))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "false neighbours need lag >= 1, dimensions 1..%d and a ratio > 0 (lag %d, "
                       "dimensions %d, ratio %g)",
                       CM_EMBED_MAX_DIM, o->lag, o->max_dim, o->ratio);
    const size_t span = (size_t)o->max_dim * (size_t)o->lag;
    cm_status st = check_series(s, n, span + 10, "false neighbours", msg, msg_size);
    sorted so;
    if (st == CM_OK)
        st = sort_vectors(s, n - span, &so, msg, msg_size);
    if (st != CM_OK)
        return st;
    for (int m = 1; m <= o->max_dim; m++) {
        size_t counted = 0, false_ones = 0;
        const size_t next = (size_t)m * (size_t)o->lag;
        for (size_t i = 0; i < so.nv; i++) {
            double d;
            const size_t j = nearest(s, &so, i, m, o->lag, o->theiler, &d);
            if (j == so.nv)
                continue;
            counted++;
            false_ones += fabs(s[i + next] - s[j + next]) > o->ratio * d;
        }
        fraction[m - 1] = counted ? (double)false_ones / (double)counted : NAN;
    }
    sorted_free(&so);
    return CM_OK;
}

/* The first position in key order whose key is >= x. */
static size_t lower_bound(const sorted *o, double x)
{
    size_t lo = 0, hi = o->nv;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (o->k[mid].key < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Adds to sum[0 .. steps] the distances k samples on from vector i to each
 * of its neighbours; returns how many there were. */
static size_t follow_neighbours(const double *s, const sorted *o, size_t i,
                                const cm_kantz_options *ko, double *sum)
{
    size_t count = 0;
    for (size_t q = lower_bound(o, s[i] - ko->radius); q < o->nv; q++) {
        if (o->k[q].key > s[i] + ko->radius)
            break;
        const size_t j = o->k[q].i;
        if (!far_apart(i, j, ko->theiler))
            continue;
        const double d0 = distance(s, i, j, ko->dim, ko->lag);
        if (!(d0 > 0 && d0 <= ko->radius))
            continue;
        count++;
        for (int k = 0; k <= ko->steps; k++)
            sum[k] += distance(s, i + (size_t)k, j + (size_t)k, ko->dim, ko->lag);
    }
    return count;
}

cm_status cm_kantz_divergence(const double *s, size_t n, const cm_kantz_options *o, double *S,
                              size_t *n_ref, char *msg, size_t msg_size)
{
    *n_ref = 0;
    if (o->dim < 1 || o->dim > CM_EMBED_MAX_DIM || o->lag < 1 || o->steps < 1 ||
        !(o->radius > 0) || !isfinite(o->radius))
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "divergence curves need dimension 1..%d, lag >= 1, steps >= 1 and a "
                       "radius > 0 (dimension %d, lag %d, steps %d, radius %g)",
                       CM_EMBED_MAX_DIM, o->dim, o->lag, o->steps, o->radius);
    const size_t span = (size_t)(o->dim - 1) * (size_t)o->lag + (size_t)o->steps;
    cm_status st = check_series(s, n, span + 2, "divergence curves", msg, msg_size);
    sorted so;
    if (st == CM_OK)
        st = sort_vectors(s, n - span, &so, msg, msg_size);
    if (st != CM_OK)
        return st;
    double *sum = malloc((size_t)(o->steps + 1) * sizeof *sum);
    if (!sum) {
        sorted_free(&so);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %d steps", o->steps);
    }
    for (int k = 0; k <= o->steps; k++)
        S[k] = 0;
    for (size_t i = 0; i < so.nv; i++) {
        for (int k = 0; k <= o->steps; k++)
            sum[k] = 0;
        const size_t count = follow_neighbours(s, &so, i, o, sum);
        int k = 0;
        while (count && k <= o->steps && sum[k] > 0)
            k++;
        if (!count || k <= o->steps) /* none, or the neighbours met again exactly */
            continue;
        for (k = 0; k <= o->steps; k++)
            S[k] += log(sum[k] / (double)count);
        (*n_ref)++;
    }
    for (int k = 0; k <= o->steps; k++)
        S[k] = *n_ref ? S[k] / (double)*n_ref : NAN;
    free(sum);
    sorted_free(&so);
    return CM_OK;
}

double cm_index_slope(const double *y, int lo, int hi)
{
    const double m = hi - lo + 1, xm = (lo + hi) / 2.0;
    double ym = 0, sxy = 0, sxx = 0;
    for (int k = lo; k <= hi; k++)
        ym += y[k];
    ym /= m;
    for (int k = lo; k <= hi; k++)
        sxy += (k - xm) * (y[k] - ym), sxx += (k - xm) * (k - xm);
    return sxy / sxx;
}

size_t cm_series_extrema(const double *t, const double *x, size_t stride, size_t n, int sign,
                         double *te, double *xe)
{
    size_t found = 0;
    const double g = sign < 0 ? -1 : 1;
    for (size_t i = 1; i + 1 < n; i++) {
        const double y0 = g * x[(i - 1) * stride], y1 = g * x[i * stride],
                     y2 = g * x[(i + 1) * stride];
        if (!(y1 > y0 && y1 >= y2))
            continue;
        /* the parabola's vertex, as a fraction of the sample interval */
        const double curve = y0 - 2 * y1 + y2;
        const double off = curve < 0 ? 0.5 * (y0 - y2) / curve : 0;
        const double h = off < 0 ? t[i] - t[i - 1] : t[i + 1] - t[i];
        te[found] = t[i] + off * h;
        xe[found] = g * (y1 - 0.25 * (y0 - y2) * off);
        found++;
    }
    return found;
}
