/* The fates of true orbits by a solve's attractors (cellmap/attractor_fates.h). */
#include "cellmap/attractor_fates.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* A footprint cell and its attractor (0: on two footprints, nobody's). */
typedef struct owned_cell {
    int64_t c[CM_MAX_DIM]; /* unused coordinates 0 */
    int32_t owner;
} owned_cell;

static int owned_compare(const void *a, const void *b)
{
    const int64_t *x = ((const owned_cell *)a)->c, *y = ((const owned_cell *)b)->c;
    return cm_cell_less(x, y, CM_MAX_DIM) ? -1 : cm_cell_less(y, x, CM_MAX_DIM);
}

/* Every footprint cell of s, sorted, a cell on two footprints kept once
 * with owner 0; returns how many, or UINT64_MAX out of memory. */
static uint64_t footprint_table(const cm_attractor_set *s, int dim, owned_cell **out)
{
    const uint64_t total = s->n ? s->footprint_at[s->n] : 0;
    owned_cell *t = calloc((size_t)total + 1, sizeof *t);
    *out = t;
    if (!t)
        return UINT64_MAX;
    for (uint32_t k = 0; k < s->n; k++)
        for (uint64_t i = s->footprint_at[k]; i < s->footprint_at[k + 1]; i++) {
            memcpy(t[i].c, s->footprint + i * dim, (size_t)dim * sizeof *t[i].c);
            t[i].owner = (int32_t)s->a[k].id;
        }
    qsort(t, total, sizeof *t, owned_compare);
    uint64_t n = 0;
    for (uint64_t i = 0; i < total; i++) {
        if (n && owned_compare(&t[i], &t[n - 1]) == 0) {
            if (t[n - 1].owner != t[i].owner)
                t[n - 1].owner = 0;
            continue;
        }
        t[n++] = t[i];
    }
    return n;
}

/* The attractor whose footprint holds cell c, 0 for none. */
static int32_t owner_of(const owned_cell *t, uint64_t n, const int64_t *c)
{
    owned_cell key;
    memcpy(key.c, c, sizeof key.c);
    const owned_cell *hit = bsearch(&key, t, n, sizeof *t, owned_compare);
    return hit ? hit->owner : 0;
}

/* One state's fate: followed until it settles on a footprint, diverges
 * or spends the budget; the steps taken into *taken. */
static int32_t fate_of(const cm_model *m, const cm_lattice *lat, const owned_cell *t,
                       uint64_t n, const double *start, uint64_t max_steps, uint64_t *taken)
{
    const int dim = lat->dim;
    double x[CM_MAX_DIM], y[CM_MAX_DIM];
    int64_t at[CM_MAX_DIM] = {0}, cell[CM_MAX_DIM] = {0};
    memcpy(x, start, (size_t)dim * sizeof *x);
    int32_t on = 0;
    uint32_t moves = 0, stay = 0;
    bool placed = false;
    for (uint64_t step = 1; step <= max_steps; step++) {
        *taken = step;
        if (m->step(m, x, y) != CM_STEP_OK || !cm_lattice_cell(lat, y, cell))
            return CM_LABEL_DIVERGED;
        memcpy(x, y, (size_t)dim * sizeof *x);
        const bool moved = !placed || memcmp(cell, at, sizeof at) != 0;
        if (moved) {
            memcpy(at, cell, sizeof at);
            placed = true;
            const int32_t owner = owner_of(t, n, cell);
            moves = owner && owner == on ? moves + 1 : owner != 0;
            stay = owner && owner == on ? stay + 1 : owner != 0;
            on = owner;
        } else {
            stay = on ? stay + 1 : 0;
        }
        if (on && (moves >= CM_SETTLE_MOVES || stay >= CM_SETTLE_STEPS))
            return on;
    }
    return CM_LABEL_OUTSIDE;
}

cm_status cm_attractor_fates(const cm_model *m, const cm_lattice *lat, const cm_attractor_set *s,
                             const double *x, uint64_t n, uint64_t max_steps, int threads,
                             int32_t *fate, uint64_t *steps, char *msg, size_t msg_size)
{
    if (!max_steps)
        max_steps = m->flow.field ? CM_FATE_STEPS_FLOW : CM_FATE_STEPS;
    owned_cell *t;
    const uint64_t cells = footprint_table(s, lat->dim, &t);
    if (cells == UINT64_MAX)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the attractors' footprints");
    uint64_t sum = 0;
    const int nthreads = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 16) num_threads(nthreads) reduction(+ : sum)
    for (int64_t i = 0; i < (int64_t)n; i++) {
        uint64_t taken = 0;
        fate[i] = fate_of(m, lat, t, cells, x + (size_t)i * lat->dim, max_steps, &taken);
        sum += taken;
    }
    free(t);
    if (steps)
        *steps = sum;
    return CM_OK;
}

/* splitmix64 (Steele, Lea and Flood 2014) of z: a full-period mix. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94D049BB133111EB);
    return z ^ (z >> 31);
}

void cm_sample_states(const cm_lattice *lat, const cm_box *box, uint64_t seed, uint64_t n,
                      double *x)
{
    const int dim = box->dim;
    const uint64_t golden = UINT64_C(0x9E3779B97F4A7C15);
    for (uint64_t i = 0; i < n; i++) {
        uint64_t z = mix64(seed * golden + mix64(i + 1));
        for (int d = 0; d < dim; d++) {
            z += golden;
            const double u = (double)(mix64(z) >> 11) * 0x1.0p-53; /* [0, 1) */
            const double lo = lat->origin[d] + (double)box->lo[d] * lat->width[d];
            const double hi = lat->origin[d] + (double)box->hi[d] * lat->width[d];
            x[i * dim + d] = lo + u * (hi - lo);
        }
    }
}
