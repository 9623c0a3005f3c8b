/* models/embedding.h - nonlinear analysis of one measured scalar series
 * s[0..n-1] by delay embedding (Takens): the delay vectors
 * v_i = (s[i], s[i + lag], ..., s[i + (m - 1) lag]) of dimension m stand for
 * the states of the system that produced it. What the thesis did with
 * TISEAN (3.3, Figs. 3.12 and 3.15), from a series alone:
 *
 *   - the fraction of false nearest neighbours per dimension (Kennel,
 *     Brown and Abarbanel 1992): a vector's nearest neighbour in dimension
 *     m is false when the next coordinate puts it more than `ratio` times
 *     their distance away; the least m where few are false embeds;
 *   - Kantz's divergence curves (1994): S(k), the mean over reference
 *     vectors of the log of the mean distance, k samples later, to the
 *     neighbours within `radius`; where S rises linearly its slope is the
 *     largest Lyapunov exponent per sample, before it saturates at the
 *     attractor's size;
 *   - the local extrema of a sampled coordinate (the thesis' subsequent
 *     maxima of tau2), placed by a parabola through three samples.
 *
 * Distances are maximum norms over the delay vector. Neighbours closer in
 * index than the Theiler window are left out (they are the same stretch of
 * orbit, not a return to the same state). The search sorts the vectors by
 * their first coordinate and scans a window: work grows as n times the
 * vectors within a radius of each one's first coordinate (n^2 at worst).
 * Pure functions of their inputs: thread-safe, the same bytes every run. */
#ifndef CM_MODELS_EMBEDDING_H
#define CM_MODELS_EMBEDDING_H

#include <stddef.h>

#include "cellmap/status.h"

enum { CM_EMBED_MAX_DIM = 64 };

typedef struct cm_fnn_options {
    int lag;        /* samples between coordinates, >= 1 */
    int max_dim;    /* fractions for m = 1 .. max_dim, <= CM_EMBED_MAX_DIM */
    double ratio;   /* the threshold of falseness (Kennel et al.: 10 .. 15) */
    size_t theiler; /* neighbours |i - j| <= theiler are left out */
} cm_fnn_options;

/* fraction[m - 1] (max_dim entries, the caller's) gets the fraction of the
 * vectors whose nearest neighbour in dimension m is false in m + 1; the
 * same vectors for every m (those with an (max_dim + 1)-th coordinate).
 * NaN where no vector had a neighbour at a non-zero distance. CM_EINVAL
 * for bad options, a non-finite sample or fewer than 10 vectors. */
cm_status cm_false_neighbours(const double *s, size_t n, const cm_fnn_options *o, double *fraction,
                              char *msg, size_t msg_size);

typedef struct cm_kantz_options {
    int dim, lag;   /* the embedding, dim <= CM_EMBED_MAX_DIM */
    double radius;  /* the neighbourhoods' size, in the series' units, > 0 */
    size_t theiler; /* as above */
    int steps;      /* S(0 .. steps) */
} cm_kantz_options;

/* S[0 .. steps] (the caller's) gets the divergence curve; *n_ref the
 * reference vectors averaged over (those with a neighbour within the
 * radius; none leaves S NaN, not an error: the caller says "enlarge the
 * radius"). Neighbours at distance 0 (repeated vectors) are left out.
 * CM_EINVAL for bad options, a non-finite sample, or a series too short
 * for one vector followed steps samples. */
cm_status cm_kantz_divergence(const double *s, size_t n, const cm_kantz_options *o, double *S,
                              size_t *n_ref, char *msg, size_t msg_size);

/* The least-squares slope of y[lo .. hi] against the index (hi > lo). */
double cm_index_slope(const double *y, int lo, int hi);

/* The local maxima (sign > 0) or minima (sign < 0) of x[0], x[stride],
 * ... (n samples at times t[0 .. n-1]), each placed at the vertex of the
 * parabola through it and its two neighbours, into te and xe (n entries
 * at most, the caller's); a plateau counts once. Returns how many. */
size_t cm_series_extrema(const double *t, const double *x, size_t stride, size_t n, int sign,
                         double *te, double *xe);

#endif
