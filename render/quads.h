/* render/quads.h - axis-aligned rectangles and nearest-sampled textures
 * drawn on the CPU with the pixels OpenGL (Mesa's llvmpipe, which OSMesa
 * and EGL both use here) gives them, so that a figure's basin raster and
 * attractor markers need no GL and no texture upload.
 *
 * The rules, as llvmpipe applies them: a vertex's window position is
 * snapped to 1/256 of a pixel (round to nearest); a pixel is covered when
 * its centre lies on or after the left (lower) edge and before the right
 * (upper) one; a texture's texel is the floor of the texture coordinate,
 * interpolated at the pixel's centre between the unsnapped edges, times the
 * texture's size, clamped to the texture. Where a texel's edge passes
 * exactly through pixel centres, they show the texel above the edge (a
 * point on a cell's lower edge lies in that cell). GL decides those ties
 * by its rounding, and differently along one row or column of pixels.
 *
 * One axis at a time: a rectangle's pixels are a span of columns times a
 * span of rows. Window coordinates count pixels from the lower or left edge
 * of a panel of n pixels that shows state coordinates lo..hi. Pure
 * functions; thread-safe.
 */
#ifndef CM_RENDER_QUADS_H
#define CM_RENDER_QUADS_H

#include <stdint.h>

typedef struct cm_quad_axis {
    double lo, hi; /* the state coordinates at the panel's edges, lo < hi */
    int n;         /* its pixels */
} cm_quad_axis;

/* The pixels [*first, *end) of the axis whose centres a rectangle from
 * state coordinate a to b (a <= b) covers; *first == *end when none. */
void cm_quad_span(const cm_quad_axis *ax, double a, double b, int *first, int *end);

/* For a texture of `texels` texels spread over state a..b: texel[k] for each
 * pixel k of the axis that the texture covers is set to offset plus the
 * texel it shows; the other entries are left as they are. */
void cm_quad_texels(const cm_quad_axis *ax, double a, double b, uint64_t texels, int64_t offset,
                    int64_t *texel);

#endif
