/* cellmap/attractor_fates.h - the fates of true orbits from given states,
 * by a solve's attractors (cellmap/attractors.h): the independent side of
 * a basin's measure. A cell's label comes from simple cell mapping (the
 * cell's sequence, then its group's attractor); the fate of a state here
 * comes from the true map alone, in full precision, followed from that
 * state until it settles on an attractor's footprint:
 *   - it makes SETTLE_MOVES moves from cell to cell that all stay on the
 *     footprint of one attractor (an orbit on a cycle or a chaotic
 *     attractor), or stays SETTLE_STEPS steps in a row on it (an orbit
 *     converged into the cell of a fixed point, or resting in a sticking
 *     zone): that attractor's id;
 *   - the map gives no image, or the orbit leaves the world:
 *     CM_LABEL_DIVERGED (0);
 *   - neither within max_steps steps: CM_LABEL_OUTSIDE (-2), undecided (an
 *     attractor the solve's cells did not hold, or a slow transient).
 * A cell that lies on two footprints counts for neither. Sampled shares of
 * the states of a box are then estimates of the true basins' measures,
 * which the cells' shares must agree with (`cellmap measure --samples`).
 *
 * Thread safety: pure functions of their inputs; the states are followed
 * on `threads` OpenMP threads with the same fates for any number.
 */
#ifndef CM_ATTRACTOR_FATES_H
#define CM_ATTRACTOR_FATES_H

#include <stdint.h>

#include "cellmap/attractors.h"
#include "cellmap/model.h"

/* Moves on one footprint, or steps on it in a row, that settle an orbit. */
#define CM_SETTLE_MOVES 8
#define CM_SETTLE_STEPS 16

/* The default budget of steps per state: maps, and flows (whose images
 * cost an integration over a period or a return to a section each). */
#define CM_FATE_STEPS 10000
#define CM_FATE_STEPS_FLOW 2000

/* n states (lat->dim coordinates each, in x) followed by m's true map:
 * their fates into fate[0..n) (an attractor id of s, CM_LABEL_DIVERGED or
 * CM_LABEL_OUTSIDE), the steps taken in all into *steps (may be NULL).
 * max_steps 0: CM_FATE_STEPS, or CM_FATE_STEPS_FLOW for a flow's map.
 * CM_ENOMEM with msg. */
cm_status cm_attractor_fates(const cm_model *m, const cm_lattice *lat, const cm_attractor_set *s,
                             const double *x, uint64_t n, uint64_t max_steps, int threads,
                             int32_t *fate, uint64_t *steps, char *msg, size_t msg_size);

/* n states drawn uniformly from the box of cells `box` (its cells' outer
 * edges) into x (box->dim coordinates each): state i from a splitmix64
 * stream seeded by seed and i alone, so the same states on every machine
 * and for any n's prefix. */
void cm_sample_states(const cm_lattice *lat, const cm_box *box, uint64_t seed, uint64_t n,
                      double *x);

#endif
