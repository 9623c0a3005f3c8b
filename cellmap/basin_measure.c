/* Basin entropy, uncertain fractions and the Wada test on a window of
 * labels (cellmap/basin_measure.h). */
#include "cellmap/basin_measure.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "cellmap/attractors.h"

static void strides(const cm_label_grid *g, int64_t *s)
{
    s[g->dim - 1] = 1;
    for (int d = g->dim - 2; d >= 0; d--)
        s[d] = s[d + 1] * g->n[d + 1];
}

static uint64_t cells(const cm_label_grid *g)
{
    uint64_t n = 1;
    for (int d = 0; d < g->dim; d++)
        n *= (uint64_t)g->n[d];
    return n;
}

/* The next point of the box 0 .. n[d] - 1 in C order; false after the last. */
static bool next(int dim, int64_t *i, const int64_t *n)
{
    for (int d = dim - 1; d >= 0; d--) {
        if (++i[d] < n[d])
            return true;
        i[d] = 0;
    }
    return false;
}

/* The grid's place in its window (cm_label_grid): the core's rows, and
 * the window row of its row 0 and the window's rows. */
typedef struct slab {
    int64_t core_lo, core_hi, row0, rows;
} slab;

static slab slab_of(const cm_label_grid *g)
{
    if (g->window_rows == 0)
        return (slab){0, g->n[0], 0, g->n[0]};
    return (slab){g->core_lo, g->core_hi, g->row0, g->window_rows};
}

/* next() over first .. n[0] - 1 along dimension 0 and 0 .. n[d] - 1 along
 * the others. */
static bool next_from(int dim, int64_t *i, int64_t first, const int64_t *n)
{
    for (int d = dim - 1; d >= 0; d--) {
        if (++i[d] < n[d])
            return true;
        i[d] = d ? 0 : first;
    }
    return false;
}

static int64_t index_of(int dim, const int64_t *i, const int64_t *s)
{
    int64_t k = 0;
    for (int d = 0; d < dim; d++)
        k += i[d] * s[d];
    return k;
}

/* ---- basin entropy ---- */

typedef struct tally {
    uint32_t *count; /* per label - lo */
    int32_t *used;   /* the labels counted, to reset */
    int n_used;
} tally;

/* Counts the box's labels; false when it holds an uncomputed cell. */
static bool count_box(const cm_label_grid *g, const int64_t *s, const int64_t *corner, int eps,
                      tally *t)
{
    int64_t in[CM_MAX_DIM] = {0}, side[CM_MAX_DIM];
    for (int d = 0; d < g->dim; d++)
        side[d] = eps;
    bool computed = true;
    t->n_used = 0;
    do {
        int64_t k = 0;
        for (int d = 0; d < g->dim; d++)
            k += (corner[d] + in[d]) * s[d];
        const int32_t l = g->label[k];
        if (l == CM_LABEL_UNCOMPUTED) {
            computed = false;
            break;
        }
        if (t->count[l - g->lo]++ == 0)
            t->used[t->n_used++] = l;
    } while (next(g->dim, in, side));
    return computed;
}

cm_status cm_basin_entropy(const cm_label_grid *g, int eps, cm_entropy *out, double *map,
                           char *msg, size_t msg_size)
{
    memset(out, 0, sizeof *out);
    out->eps = eps, out->sb = out->sbb = NAN;
    const slab sl = slab_of(g);
    int64_t boxes[CM_MAX_DIM], s[CM_MAX_DIM], at[CM_MAX_DIM] = {0};
    for (int d = 0; d < g->dim; d++) {
        const int64_t n = d ? g->n[d] : sl.rows;
        boxes[d] = eps >= 1 ? n / eps : 0;
        if (boxes[d] < 1)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "boxes of %d cells a side do not fit the window's %lld cells along "
                           "dimension %d: choose a smaller box or a larger window",
                           eps, (long long)n, d + 1);
    }
    /* the boxes along dimension 0 that start in the core (window rows) */
    const int64_t first = (sl.row0 + sl.core_lo + eps - 1) / eps;
    int64_t last = (sl.row0 + sl.core_hi + eps - 1) / eps; /* past the last */
    last = last < boxes[0] ? last : boxes[0];
    if (first >= last)
        return CM_OK;
    at[0] = first, boxes[0] = last;
    strides(g, s);
    const double box_cells = pow(eps, g->dim);
    const size_t labels = (size_t)(g->hi - g->lo + 1); /* a box holds at most these */
    tally t = {calloc(labels, sizeof *t.count), malloc(labels * sizeof *t.used), 0};
    if (!t.count || !t.used) {
        free(t.count), free(t.used);
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for boxes of %d cells", eps);
    }
    double sum = 0, sum_boundary = 0;
    do {
        int64_t corner[CM_MAX_DIM];
        for (int d = 0; d < g->dim; d++)
            corner[d] = at[d] * eps - (d ? 0 : sl.row0);
        const bool computed = count_box(g, s, corner, eps, &t);
        double h = 0;
        for (int k = 0; k < t.n_used; k++) {
            uint32_t *c = &t.count[t.used[k] - g->lo];
            const double p = *c / box_cells;
            h -= computed ? p * log(p) : 0;
            *c = 0;
        }
        if (map)
            *map++ = computed ? h : NAN;
        if (!computed)
            continue;
        out->boxes++, sum += h;
        if (t.n_used > 1)
            out->boundary++, sum_boundary += h;
    } while (next_from(g->dim, at, first, boxes));
    free(t.count), free(t.used);
    out->sum = sum, out->sum_boundary = sum_boundary;
    if (out->boxes)
        out->sb = sum / (double)out->boxes;
    if (out->boundary)
        out->sbb = sum_boundary / (double)out->boundary;
    return CM_OK;
}

/* ---- uncertain cells ---- */

cm_status cm_uncertain_fraction(const cm_label_grid *g, int eps, double *fraction,
                                uint64_t *counted, uint64_t *uncertain_out, char *msg,
                                size_t msg_size)
{
    *fraction = NAN, *counted = 0;
    if (uncertain_out)
        *uncertain_out = 0;
    if (eps < 1)
        return cm_fail(CM_EINVAL, msg, msg_size, "eps must be at least one cell (%d)", eps);
    const slab sl = slab_of(g);
    if (sl.core_lo >= sl.core_hi)
        return CM_OK;
    int64_t s[CM_MAX_DIM], i[CM_MAX_DIM] = {sl.core_lo}, end[CM_MAX_DIM];
    memcpy(end, g->n, sizeof end);
    end[0] = sl.core_hi;
    strides(g, s);
    uint64_t uncertain = 0;
    do {
        bool inside = sl.row0 + i[0] >= eps && sl.row0 + i[0] + eps < sl.rows;
        for (int d = 1; d < g->dim && inside; d++)
            inside = i[d] >= eps && i[d] + eps < g->n[d];
        const int64_t k = index_of(g->dim, i, s);
        const int32_t own = g->label[k];
        if (!inside || own == CM_LABEL_UNCOMPUTED)
            continue;
        bool computed = true, differs = false;
        for (int d = 0; d < g->dim; d++) {
            const int32_t a = g->label[k - eps * s[d]], b = g->label[k + eps * s[d]];
            computed = computed && a != CM_LABEL_UNCOMPUTED && b != CM_LABEL_UNCOMPUTED;
            differs = differs || a != own || b != own;
        }
        if (computed)
            (*counted)++, uncertain += differs;
    } while (next_from(g->dim, i, sl.core_lo, end));
    if (*counted)
        *fraction = (double)uncertain / (double)*counted;
    if (uncertain_out)
        *uncertain_out = uncertain;
    return CM_OK;
}

/* ---- Wada ---- */

typedef struct seen {
    uint64_t *stamp; /* per label - lo: the visit that saw it last */
    uint64_t visit;
} seen;

/* How many labels of the cube of radius r about cell i (clipped to the
 * window) there are, up to `enough`; also whether any differs from own. */
static int labels_near(const cm_label_grid *g, const int64_t *s, const int64_t *i, int r,
                       int enough, seen *v)
{
    int64_t lo[CM_MAX_DIM], side[CM_MAX_DIM], in[CM_MAX_DIM] = {0};
    for (int d = 0; d < g->dim; d++) { /* a slab's rows beyond r are the window's edge */
        lo[d] = i[d] - r < 0 ? 0 : i[d] - r;
        side[d] = (i[d] + r >= g->n[d] ? g->n[d] - 1 : i[d] + r) - lo[d] + 1;
    }
    v->visit++;
    int found = 0;
    do {
        int64_t k = 0;
        for (int d = 0; d < g->dim; d++)
            k += (lo[d] + in[d]) * s[d];
        const int32_t l = g->label[k];
        if (l != CM_LABEL_UNCOMPUTED && v->stamp[l - g->lo] != v->visit) {
            v->stamp[l - g->lo] = v->visit;
            if (++found >= enough)
                break;
        }
    } while (next(g->dim, in, side));
    return found;
}

static int count_basins(const cm_label_grid *g, seen *v)
{
    int basins = 0;
    v->visit++;
    const uint64_t n = cells(g);
    for (uint64_t k = 0; k < n; k++) {
        const int32_t l = g->label[k];
        if (l != CM_LABEL_UNCOMPUTED && v->stamp[l - g->lo] != v->visit)
            v->stamp[l - g->lo] = v->visit, basins++;
    }
    return basins;
}

cm_status cm_wada_test(const cm_label_grid *g, int radius, cm_wada *out, char *msg,
                       size_t msg_size)
{
    memset(out, 0, sizeof *out);
    if (radius < 1 || radius > 16)
        return cm_fail(CM_EINVAL, msg, msg_size, "the Wada test's radius must be 1..16 (%d)",
                       radius);
    seen v = {calloc((size_t)(g->hi - g->lo + 1), sizeof *v.stamp), 0};
    if (!v.stamp)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the labels");
    out->basins = g->basins ? g->basins : count_basins(g, &v), out->radius = radius;
    if (out->basins < 3) {
        free(v.stamp);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "the Wada test needs 3 or more basins, and the window has %d: with 2 "
                       "every boundary cell touches both",
                       out->basins);
    }
    const slab sl = slab_of(g);
    int64_t s[CM_MAX_DIM], i[CM_MAX_DIM] = {sl.core_lo}, end[CM_MAX_DIM];
    memcpy(end, g->n, sizeof end);
    end[0] = sl.core_hi;
    strides(g, s);
    uint64_t *sees_all = out->seeing;
    do {
        if (sl.core_lo >= sl.core_hi)
            break;
        if (g->label[index_of(g->dim, i, s)] == CM_LABEL_UNCOMPUTED ||
            labels_near(g, s, i, 1, 2, &v) < 2)
            continue;
        out->boundary++;
        for (int r = 1; r <= radius; r++) {
            if (labels_near(g, s, i, r, out->basins, &v) == out->basins) {
                for (int q = r; q <= radius; q++) /* a larger cube sees them too */
                    sees_all[q - 1]++;
                break;
            }
        }
    } while (next_from(g->dim, i, sl.core_lo, end));
    free(v.stamp);
    for (int r = 1; r <= radius; r++)
        out->fraction[r - 1] =
            out->boundary ? (double)sees_all[r - 1] / (double)out->boundary : NAN;
    return CM_OK;
}
