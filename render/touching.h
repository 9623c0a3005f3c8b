/* render/touching.h - which basins touch in a view: the pairs of distinct
 * labels whose cells are drawn side by side. The palette keeps such pairs
 * apart in colour (render/palette.h).
 *
 * A figure samples one cell per pixel; when a pixel spans several cells,
 * the cells of neighbouring pixels lie up to `reach` cells apart, so labels
 * closer than that along a row or column count as touching too (a
 * superset of what the pixels show, never less).
 */
#ifndef CM_RENDER_TOUCHING_H
#define CM_RENDER_TOUCHING_H

#include <stddef.h>
#include <stdint.h>

#include "cellmap/status.h"

typedef struct cm_touching {
    uint64_t *pair; /* (uint64_t)a << 32 | b with a < b, ascending, each once */
    size_t n;
} cm_touching;

/* The touching pairs of an nx x ny grid of labels (label[j * row_stride +
 * i]; any uint32 values, CM_GROUP_NONE included), cells up to reach_x
 * apart along rows and reach_y along columns (>= 1). The caller owns
 * out->pair (cm_touching_free). Deterministic; parallel over rows. */
cm_status cm_touching_collect(const uint32_t *label, uint64_t nx, uint64_t ny, uint64_t row_stride,
                              uint32_t reach_x, uint32_t reach_y, cm_touching *out, char *msg,
                              size_t msg_size);
void cm_touching_free(cm_touching *t);

/* Cells of the source per pixel, rounded up (at least 1): the reach of a
 * figure drawing `cells` cells over `pixels` pixels. */
uint32_t cm_touching_reach(uint64_t cells, int pixels);

#endif
