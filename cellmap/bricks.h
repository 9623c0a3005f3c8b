/* cellmap/bricks.h - a coarse grid over the lattice ("bricks") mapping each
 * brick to a list of fixed-size records: the regions that meet a brick, so
 * that finding the region of a cell is O(1), and the exits that leave a
 * cluster, by the brick of their target cell, so that a join finds the
 * exits leading into a new region without looking at the others.
 *
 * Bricks are boxes of 2^shift[d] cells aligned to the lattice's cell 0. The
 * map is a hash table of the bricks that hold records; a brick's records
 * keep the order they were added in. Not thread-safe; cm_bricks_free is NULL-safe.
 */
#ifndef CM_BRICKS_H
#define CM_BRICKS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cellmap/lattice.h"

typedef struct cm_bricks cm_bricks;

/* A map of bricks 2^shift[d] cells wide whose records take record_size bytes. */
cm_status cm_bricks_alloc(int dim, const int *shift, size_t record_size, cm_bricks **out);
void cm_bricks_free(cm_bricks *b);

/* Shifts for bricks about half the size of `box` in every dimension (at
 * most 2^31 cells in a brick for a box of at most 2^32 cells). */
void cm_bricks_shift_for(const cm_box *box, int *shift);

/* The brick holding `cell` into brick[dim]. */
void cm_bricks_of(const cm_bricks *b, const int64_t *cell, int64_t *brick);

/* The bricks that meet `box`, as an inclusive box [lo, hi] of brick
 * coordinates; false when they are more than CM_BRICKS_MAX_SPAN. */
#define CM_BRICKS_MAX_SPAN 65536
bool cm_bricks_span(const cm_bricks *b, const cm_box *box, int64_t *lo, int64_t *hi);

/* The bricks that hold records or held some: n of them, brick i's
 * coordinates at cm_bricks_key(b, i). */
uint64_t cm_bricks_count(const cm_bricks *b);
const int64_t *cm_bricks_key(const cm_bricks *b, uint64_t i);

/* Adds a record to the brick holding `cell`. */
cm_status cm_bricks_add(cm_bricks *b, const int64_t *cell, const void *record);

/* Adds a record to every brick that meets `box`; CM_ETOOBIG when that is
 * more than CM_BRICKS_MAX_SPAN bricks (the caller keeps such boxes aside). */
cm_status cm_bricks_add_box(cm_bricks *b, const cm_box *box, const void *record);

/* The records of the brick with coordinates `brick`: *n records at the
 * returned address (NULL when the brick has none). The pointer stays valid
 * until the map changes. */
void *cm_bricks_find(const cm_bricks *b, const int64_t *brick, uint64_t *n);

/* Keeps the first n records of brick `brick` (which must hold records). */
void cm_bricks_truncate(cm_bricks *b, const int64_t *brick, uint64_t n);

/* A cell's place in its brick (below 2^31: bricks hold fewer cells), and
 * back: the cell at `offset` in the brick with coordinates `brick`. Records
 * keep a cell in 4 bytes this way. */
uint32_t cm_bricks_offset(const cm_bricks *b, const int64_t *cell);
void cm_bricks_cell(const cm_bricks *b, const int64_t *brick, uint32_t offset, int64_t *cell);

/* Calls fn for every record of every brick (with the brick's coordinates),
 * bricks in the order they were first used, records in their order. */
void cm_bricks_each(const cm_bricks *b,
                    void (*fn)(void *user, const int64_t *brick, const void *record), void *user);

/* Bytes held. */
uint64_t cm_bricks_bytes(const cm_bricks *b);

#endif
