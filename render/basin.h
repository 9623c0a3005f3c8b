/* render/basin.h - off-screen basin images with OSMesa.
 *
 * Draws the basin raster of a solved region (a colour per group, the sink in
 * its own colour, cells outside the region as "not computed") and the
 * periodic cells as markers that stay visible at any zoom, into a caller
 * RGBA buffer of width*height*4 bytes, row 0 at the top.
 *
 * The view is a rectangle of state space in dimensions 0 and 1. Models of
 * one dimension are drawn as a strip (the y range is ignored); models of more
 * than two are drawn as the slice through slice[d] (cell coordinates) in the
 * other dimensions. Deterministic: the same inputs give the same bytes.
 * Not thread-safe (one OSMesa context at a time per thread).
 */
#ifndef CM_RENDER_BASIN_H
#define CM_RENDER_BASIN_H

#include <stdint.h>

#include "cellmap/scm.h"

typedef struct cm_render_options {
    int width, height;         /* pixels */
    double lo[2], hi[2];       /* view in state coordinates; all zero: the region */
    int64_t slice[CM_MAX_DIM]; /* cells of dimensions >= 2; used when set_slice */
    int set_slice;             /* 0: the middle of the region */
    int markers;               /* draw periodic cells */
} cm_render_options;

cm_status cm_render_basin(const cm_lattice *lat, const cm_region *r, const cm_group_info *groups,
                          const cm_render_options *opt, uint8_t *rgba, char *msg, size_t msg_size);

#endif
