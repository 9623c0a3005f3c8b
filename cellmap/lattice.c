#include "cellmap/lattice.h"

#include "cellmap/numtext.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

cm_status cm_lattice_check(const cm_lattice *lat, char *msg, size_t msg_size)
{
    if (!lat || lat->dim < 1 || lat->dim > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "lattice dimension must be 1..%d", CM_MAX_DIM);
    for (int d = 0; d < lat->dim; d++) {
        if (!isfinite(lat->origin[d]))
            return cm_fail(CM_EINVAL, msg, msg_size, "lattice origin[%d] is not finite", d);
        if (!(lat->width[d] >= DBL_MIN) || !isfinite(lat->width[d]))
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "cell width in dimension %d must be positive and finite (got %g)", d,
                           lat->width[d]);
        /* every cell of the world must have a finite centre, distinct from
         * its neighbours' */
        const double reach = fabs(lat->origin[d]) + lat->width[d] * (double)CM_WORLD_LIMIT;
        if (!isfinite(reach) || fabs(lat->origin[d]) / lat->width[d] > 0x1p50)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "the lattice in dimension %d (origin %g, cell width %g) cannot be "
                           "resolved in double precision: make the cells wider or the "
                           "coordinates smaller",
                           d, lat->origin[d], lat->width[d]);
    }
    return CM_OK;
}

bool cm_lattice_cell(const cm_lattice *lat, const double *x, int64_t *cell)
{
    const double limit = (double)CM_WORLD_LIMIT;
    double u[CM_MAX_DIM];
    for (int d = 0; d < lat->dim; d++) {
        u[d] = (x[d] - lat->origin[d]) / lat->width[d];
        /* NaN fails both comparisons, so it is caught here too. */
        if (!(u[d] >= -limit && u[d] < limit))
            return false;
    }
    /* floor without a libm call: truncate, then step down for negative
     * non-integers. Exact for every |u| < 2^40. */
    for (int d = 0; d < lat->dim; d++) {
        const int64_t t = (int64_t)u[d];
        cell[d] = t - ((double)t > u[d]);
    }
    return true;
}

void cm_lattice_centre(const cm_lattice *lat, const int64_t *cell, double *x)
{
    for (int d = 0; d < lat->dim; d++)
        x[d] = lat->origin[d] + ((double)cell[d] + 0.5) * lat->width[d];
}

cm_status cm_box_check(const cm_box *box, char *msg, size_t msg_size)
{
    if (!box || box->dim < 1 || box->dim > CM_MAX_DIM)
        return cm_fail(CM_EINVAL, msg, msg_size, "box dimension must be 1..%d", CM_MAX_DIM);
    for (int d = 0; d < box->dim; d++) {
        if (box->lo[d] >= box->hi[d])
            return cm_fail(CM_EINVAL, msg, msg_size, "box is empty in dimension %d", d);
        if (box->lo[d] < -CM_WORLD_LIMIT || box->hi[d] > CM_WORLD_LIMIT)
            return cm_fail(CM_ERANGE, msg, msg_size, "box leaves the world in dimension %d", d);
    }
    if (cm_box_cells(box) == 0)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "box has too many cells");
    return CM_OK;
}

uint64_t cm_box_cells(const cm_box *box)
{
    uint64_t n = 1;
    for (int d = 0; d < box->dim; d++) {
        if (box->hi[d] <= box->lo[d])
            return 0;
        /* in unsigned arithmetic: exact for any lo < hi, never overflowing */
        const uint64_t side = (uint64_t)box->hi[d] - (uint64_t)box->lo[d];
        if (side != 0 && n > UINT64_MAX / side)
            return 0;
        n *= side;
    }
    return n;
}

bool cm_box_contains(const cm_box *box, const int64_t *cell)
{
    for (int d = 0; d < box->dim; d++)
        if (cell[d] < box->lo[d] || cell[d] >= box->hi[d])
            return false;
    return true;
}

bool cm_lattice_equal(const cm_lattice *a, const cm_lattice *b)
{
    if (a->dim != b->dim)
        return false;
    for (int d = 0; d < a->dim; d++)
        if (a->origin[d] != b->origin[d] || a->width[d] != b->width[d])
            return false;
    return true;
}

bool cm_box_intersect(const cm_box *a, const cm_box *b, cm_box *out)
{
    cm_box both = *a;
    for (int d = 0; d < a->dim; d++) {
        both.lo[d] = a->lo[d] > b->lo[d] ? a->lo[d] : b->lo[d];
        both.hi[d] = a->hi[d] < b->hi[d] ? a->hi[d] : b->hi[d];
        if (both.lo[d] >= both.hi[d])
            return false;
    }
    *out = both;
    return true;
}

void cm_box_grow(cm_box *box, const cm_box *b)
{
    for (int d = 0; d < box->dim; d++) {
        box->lo[d] = b->lo[d] < box->lo[d] ? b->lo[d] : box->lo[d];
        box->hi[d] = b->hi[d] > box->hi[d] ? b->hi[d] : box->hi[d];
    }
}

uint64_t cm_box_index(const cm_box *box, const int64_t *cell)
{
    uint64_t index = 0;
    for (int d = box->dim - 1; d >= 0; d--)
        index = index * (uint64_t)(box->hi[d] - box->lo[d]) + (uint64_t)(cell[d] - box->lo[d]);
    return index;
}

void cm_box_cell(const cm_box *box, uint64_t index, int64_t *cell)
{
    for (int d = 0; d < box->dim; d++) {
        const uint64_t side = (uint64_t)(box->hi[d] - box->lo[d]);
        cell[d] = box->lo[d] + (int64_t)(index % side);
        index /= side;
    }
}

bool cm_index_next(int dim, const int64_t *lo, const int64_t *hi, int64_t *index)
{
    for (int d = 0; d < dim; d++) {
        if (index[d] < hi[d]) {
            index[d]++;
            return true;
        }
        index[d] = lo[d];
    }
    return false;
}

void cm_box_text(const cm_lattice *lat, const cm_box *box, char *out, size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int d = 0; d < box->dim && used < size; d++) {
        const double tol = CM_CELL_TOLERANCE * lat->width[d];
        used += (size_t)snprintf(
            out + used, size - used, "%s%s:%s", d ? "," : "",
            cm_num_text_near(cm_lattice_edge(lat, d, box->lo[d]), tol, (char[CM_NUM_TEXT]){0}),
            cm_num_text_near(cm_lattice_edge(lat, d, box->hi[d]), tol,
                             (char[CM_NUM_TEXT]){0}));
    }
}

void cm_point_text(const cm_lattice *lat, const double *x, const char *sep, char *out,
                  size_t size)
{
    size_t used = 0;
    out[0] = 0;
    for (int d = 0; d < lat->dim && used < size; d++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", d ? sep : "",
                                 cm_num_text_near(x[d], CM_CELL_TOLERANCE * lat->width[d],
                                                  (char[CM_NUM_TEXT]){0}));
}

double cm_lattice_edge(const cm_lattice *lat, int d, int64_t border)
{
    return lat->origin[d] + (double)border * lat->width[d];
}

int64_t cm_lattice_border(const cm_lattice *lat, int d, double x, int round_up)
{
    const double c = (x - lat->origin[d]) / lat->width[d], nearest = floor(c + 0.5);
    const double limit = (double)CM_WORLD_LIMIT; /* beyond it, the world's edge */
    if (!(c > -limit))
        return -CM_WORLD_LIMIT;
    if (!(c < limit))
        return CM_WORLD_LIMIT;
    if (fabs(c - nearest) < 1e-9 * (fabs(c) + 1))
        return (int64_t)nearest;
    return (int64_t)(round_up ? ceil(c) : floor(c));
}

void cm_box_rect(const cm_lattice *lat, const cm_box *box, int n, double *lo, double *hi)
{
    for (int d = 0; d < n; d++) {
        lo[d] = cm_lattice_edge(lat, d, box->lo[d]);
        hi[d] = cm_lattice_edge(lat, d, box->hi[d]);
    }
}

void cm_rect_box(const cm_lattice *lat, int n, const double *lo, const double *hi, cm_box *box)
{
    for (int d = 0; d < n; d++) {
        box->lo[d] = cm_lattice_border(lat, d, lo[d], 0);
        box->hi[d] = cm_lattice_border(lat, d, hi[d], 1);
    }
}

cm_status cm_cell_table_rebuild(uint32_t **table, uint64_t *table_size, uint64_t size,
                                const int64_t *cells, uint64_t n, int dim)
{
    uint32_t *t = calloc((size_t)size, sizeof *t);
    if (!t)
        return CM_ENOMEM;
    for (uint64_t k = 0; k < n; k++) { /* distinct cells: no comparing (cache misses) */
        uint64_t i = cm_cell_hash(cells + k * (uint64_t)dim, dim) & (size - 1);
        while (t[i])
            i = (i + 1) & (size - 1);
        t[i] = (uint32_t)(k + 1);
    }
    free(*table);
    *table = t;
    *table_size = size;
    return CM_OK;
}
