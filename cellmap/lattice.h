/* cellmap/lattice.h - the global cell lattice and boxes of cells.
 *
 * One lattice per cluster: origin o[d] and cell width h[d]. Cell c (64-bit
 * integer coordinates) covers [o + c h, o + (c+1) h) in every dimension and
 * has centre o + (c + 1/2) h. Because every region of a cluster lives on the
 * same lattice, cells of different regions never partially overlap.
 *
 * A point is outside the world (the sink) when it is not finite or when its
 * cell coordinate would exceed CM_WORLD_LIMIT in magnitude.
 * All functions are pure and thread-safe.
 */
#ifndef CM_LATTICE_H
#define CM_LATTICE_H

#include <stdbool.h>
#include <stdint.h>

#include "cellmap/status.h"

#define CM_MAX_DIM 6
/* |cell coordinate| must stay below 2^40: far enough for any real analysis,
 * small enough that coordinate arithmetic never overflows int64. */
#define CM_WORLD_LIMIT ((int64_t)1 << 40)

typedef struct cm_lattice {
    int dim;                   /* 1 .. CM_MAX_DIM */
    double origin[CM_MAX_DIM]; /* state coordinates of cell 0's lower corner */
    double width[CM_MAX_DIM];  /* cell widths, > 0 and finite */
} cm_lattice;

/* A box of cells: lo[d] <= c[d] < hi[d]. Local (row-major) index puts
 * dimension 0 fastest, so a box row along x is contiguous in memory. */
typedef struct cm_box {
    int dim;
    int64_t lo[CM_MAX_DIM];
    int64_t hi[CM_MAX_DIM];
} cm_box;

/* Validates dimension and widths; fills msg on failure. */
cm_status cm_lattice_check(const cm_lattice *lat, char *msg, size_t msg_size);

/* true when both lattices have the same dimension, origin and widths. */
bool cm_lattice_equal(const cm_lattice *a, const cm_lattice *b);

/* Cell of point x. Returns false (cell untouched) when x is outside the world. */
bool cm_lattice_cell(const cm_lattice *lat, const double *x, int64_t *cell);

/* Centre of cell c in state coordinates. */
void cm_lattice_centre(const cm_lattice *lat, const int64_t *cell, double *x);

/* Validates a box (dim matches, lo < hi, inside the world). */
cm_status cm_box_check(const cm_box *box, char *msg, size_t msg_size);

/* Number of cells in a box; 0 if it is empty or the count overflows uint64. */
uint64_t cm_box_cells(const cm_box *box);

/* true when cell c is inside the box. */
bool cm_box_contains(const cm_box *box, const int64_t *cell);

/* The cells both boxes hold, into *out (which may be a or b); false, and
 * *out untouched, when they share none. */
bool cm_box_intersect(const cm_box *a, const cm_box *b, cm_box *out);

/* Grows box to the smallest box holding both it and b. */
void cm_box_grow(cm_box *box, const cm_box *b);

/* A hash of a cell's dim coordinates, for open-addressing tables of cells. */
static inline uint64_t cm_cell_hash(const int64_t *cell, int dim)
{
    uint64_t h = 0x9E3779B97F4A7C15ULL;
    for (int d = 0; d < dim; d++)
        h = (h ^ (uint64_t)cell[d]) * 0xBF58476D1CE4E5B9ULL;
    return h ^ (h >> 31);
}

/* Whether two cells are the same (inline: hash probes compare cells often,
 * and a call to memcmp costs more than the two words of a 2-D cell). */
static inline bool cm_cell_same(const int64_t *a, const int64_t *b, int dim)
{
    int d = 0;
    while (d < dim && a[d] == b[d])
        d++;
    return d == dim;
}

/* Open-addressing tables of distinct cells: entry i holds the index of a
 * cell in an array of cells (dim coordinates each) plus one, 0 an empty
 * entry; size a power of two, probed linearly from cm_cell_hash. */

/* The entry of cell in table (size entries) over cells: its own, or the
 * empty one it would take. */
static inline uint64_t cm_cell_table_place(const uint32_t *table, uint64_t size,
                                           const int64_t *cells, int dim, const int64_t *cell)
{
    uint64_t i = cm_cell_hash(cell, dim) & (size - 1);
    while (table[i] && !cm_cell_same(cells + (table[i] - 1) * (uint64_t)dim, cell, dim))
        i = (i + 1) & (size - 1);
    return i;
}

/* A table of `size` entries over cells[0..n) (distinct: they are not
 * compared) replaces *table, *table_size set; CM_ENOMEM leaves both. */
cm_status cm_cell_table_rebuild(uint32_t **table, uint64_t *table_size, uint64_t size,
                                const int64_t *cells, uint64_t n, int dim);

/* Local row-major index of a cell inside the box (caller checked contains). */
uint64_t cm_box_index(const cm_box *box, const int64_t *cell);

/* Cell coordinates of local index i. */
void cm_box_cell(const cm_box *box, uint64_t index, int64_t *cell);

/* Steps index[0..dim) to the next point of the inclusive box [lo, hi],
 * dimension 0 fastest; false (index back at lo) after the last one. */
bool cm_index_next(int dim, const int64_t *lo, const int64_t *hi, int64_t *index);

/* floor(u) exactly for |u| < 2^51, with no libm call, in a form the
 * compiler vectorises: adding and taking away 1.5 * 2^52 rounds u to an
 * integer, and stepping down where that went up floors it. The cells of
 * the engine's batched image loops and of cm_lattice_cell agree with it. */
static inline double cm_floor_exact(double u)
{
    const double magic = 0x1.8p52;
    const double t = (u + magic) - magic;
    return t - (t > u ? 1.0 : 0.0);
}

/* The box in state coordinates, "x0:x1,y0:y1,...", each edge the shortest
 * number within a billionth of a cell (0:500, not 0:500.00000000000006). */
void cm_box_text(const cm_lattice *lat, const cm_box *box, char *out, size_t size);
/* A point in state coordinates to the same resolution, joined by sep. */
void cm_point_text(const cm_lattice *lat, const double *x, const char *sep, char *out,
                   size_t size);

/* The one rule between boxes of cells and rectangles of states.
 * cm_lattice_edge: the state of cell border `border` in dimension d
 * (origin + border * width). cm_lattice_border: the cell border at state x,
 * below it (round_up 0) or above it (1), where x within a billionth of a
 * cell of a border (relative to |x - origin| / width + 1, so that the rule
 * is the same far from the origin) counts as on it; clamped to the world. */
double cm_lattice_edge(const cm_lattice *lat, int d, int64_t border);
int64_t cm_lattice_border(const cm_lattice *lat, int d, double x, int round_up);
/* The rectangle of box's first n dimensions: lo[d], hi[d] for d < n. */
void cm_box_rect(const cm_lattice *lat, const cm_box *box, int n, double *lo, double *hi);
/* The reverse: box's first n dimensions from the rectangle lo..hi (a
 * cell is in when the rectangle covers it; edges by cm_lattice_border);
 * box's other dimensions are left as they are. */
void cm_rect_box(const cm_lattice *lat, int n, const double *lo, const double *hi, cm_box *box);

#endif
