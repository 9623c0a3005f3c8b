/* models/fo_stickmap.h - the dry friction oscillator's one-dimensional map
 * of sticking displacements (thesis 2.6.2, Fig. 2.26): every k-th place
 * where the block sticks, against the place it stuck before. A stuck block
 * leaves when its net force exceeds S0, at a time its place decides, so
 * the stick after depends on the place alone, and a transient of chaos
 * is the orbit of a one-dimensional map. Pure; thread-safe. */
#ifndef CM_MODELS_FO_STICKMAP_H
#define CM_MODELS_FO_STICKMAP_H

#include <stdbool.h>

#include "models/friction_oscillator.h"

typedef struct cm_fo_stick {
    double t, x; /* the time (the forcing is cos(Omega t)) and place of a stick */
} cm_fo_stick;

/* The sticks of the motion from (x, v) at time t0 over at most `periods`
 * periods, into out[0..cap) in time order: how many (at most cap), or -1
 * when the motion is lost. */
int cm_fo_sticks(const cm_fo *o, double t0, double x, double v, int periods, cm_fo_stick *out,
                 int cap);

/* The k-th stick after the block stuck at x at time t (the map of every
 * k-th stick), followed at most max_periods periods; false if there is
 * none. */
bool cm_fo_stick_after(const cm_fo *o, double t, double x, int k, int max_periods,
                       cm_fo_stick *out);

#endif
